"""The declared conditions of conditional steps reach the transcript records they write."""

from __future__ import annotations

from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.procedure import simulate
from stereoplotter.procedure.step_values import BOTTOM_STOP, CONDITIONS, L_CHECK_FAILED


def test_conditional_records_name_their_declared_condition():
    """pair60 on the SC-1 (seed 3, one run): the stage-1 L-check corrects ΔZ and Δb_z and
    meets the carriage's bottom stop; those records, and only conditional ones, carry their
    step's condition."""
    sc, spec = load_scenario("scenarios/pair60.yaml"), load_instrument("sc1")
    records = simulate(sc, spec, seed=3, evaluate=False).transcript.records
    names = {c.name for c in CONDITIONS}
    conditional = [r for r in records if r.condition]
    assert {r.condition for r in conditional} <= names
    by_text = {
        "ΔZ = ": L_CHECK_FAILED.name,
        "Δb_z (6.10)": L_CHECK_FAILED.name,
        "n = D/f_пр at the carriage's bottom stop": BOTTOM_STOP.name,
    }
    for r in records:
        expected = next((c for t, c in by_text.items() if r.step.startswith(t)), "")
        assert r.condition == expected, r.step
    assert {r.condition for r in conditional} == {L_CHECK_FAILED.name, BOTTOM_STOP.name}
