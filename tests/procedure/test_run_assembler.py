"""One run assembler: every caller builds its instrument, operator and Run through
``stereoplotter.procedure.run``, so what one caller passes (the SC complex's options, the
back-end, the mechanics) cannot drift from what another passes."""

from __future__ import annotations

import ast
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import stereoplotter
from stereoplotter.instrument.sc1_complex import SC1Options
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.procedure.run import build_instrument, build_run
from stereoplotter.procedure.simulate import prepare_run, run_trials_chunk

PACKAGE = Path(stereoplotter.__file__).parent
ASSEMBLER = PACKAGE / "procedure" / "run.py"

#: The names whose call builds a run's parts: outside the assembler, only the instrument's own
#: package may call them (a subclass calling its parent, a copy of an instrument).
BUILDERS = {"Run", "Instrument"}

#: The callers the issue names, and the assembler's function each must call.
CALLERS = {
    "procedure/simulate.py": "build_run",
    # the relative orientation alone builds its runs itself; procedure_mc.py runs its trials
    # through procedure/simulate.py (run_trials_chunk, whose runs build_run assembles)
    "verification/relative_orientation_mc.py": "build_run",
    "trainer/grading.py": "build_run",
    "trainer/operator_steps.py": "build_run",
}


def _called_names(path: Path) -> list[tuple[str, int]]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            f = node.func
            name = (
                f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else ""
            )
            out.append((name, node.lineno))
    return out


def test_no_module_but_the_assembler_builds_a_run_or_an_instrument():
    offenders = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        if path == ASSEMBLER or rel.startswith("instrument/"):
            continue
        for name, line in _called_names(path):
            if name in BUILDERS:
                offenders.append(f"{rel}:{line}: {name}(…)")
    assert offenders == []


@pytest.mark.parametrize("rel, function", sorted(CALLERS.items()))
def test_each_caller_goes_through_the_assembler(rel, function):
    assert function in {name for name, _ in _called_names(PACKAGE / rel)}


def test_budget_goes_through_simulate():
    """The error budget runs its designed trials by ``run_trials_chunk`` (which calls
    ``build_run``), never by an assembly of its own."""
    names = {name for name, _ in _called_names(PACKAGE / "verification" / "budget.py")}
    assert {"prepare_run", "run_trials_chunk"} <= names


@pytest.fixture(scope="module")
def prep_with_servo():
    scenario = load_scenario("scenarios/pair60.yaml")
    spec = load_instrument("sc1")
    return prepare_run(scenario, spec, options=SC1Options(automatic_coordinatograph=True), seed=3)


def test_the_options_reach_every_instrument(prep_with_servo):
    """Before the assembler only ``simulate`` passed ``options=``; the trainer's and the
    verification's instruments had the automatic coordinatograph off whatever the run said."""
    prep = prep_with_servo
    assert build_instrument(prep).options.automatic_coordinatograph
    run = build_run(prep, 0, 4, transcript=True)
    assert run.op.inst.options.automatic_coordinatograph
    assert run.op.inst.trials == 4
    assert "automatic coordinatograph" in run.op.log.records[0].step
    assert run.practice == prep.practice


def test_the_options_are_checked_once_per_run(monkeypatch):
    """Issue 23: the SC complex's options are checked against the instrument file by
    ``prepare_run`` alone; the instruments of the run's chunks take them as checked."""
    calls = []
    checked = SC1Options.fitted_to

    def counting(self, spec):
        calls.append(spec.key)
        return checked(self, spec)

    monkeypatch.setattr(SC1Options, "fitted_to", counting)
    scenario, spec = load_scenario("scenarios/pair60.yaml"), load_instrument("sc1")
    prep = prepare_run(scenario, spec, options=SC1Options(automatic_coordinatograph=True))
    for first in (0, 2, 4):
        run_trials_chunk(prep, first, 2, evaluate=False, transcript=False)
    assert calls == [spec.key]


def test_the_trials_never_read_the_scenario():
    """Issue 23, compute once: the prepared pair carries every fact the procedure and the
    evaluation read (points, standard points and their images, fiducials, the residual grid
    and the evaluation's truth), so trials run on a prepared run stripped of its scenario give
    the same numbers."""
    scenario, spec = load_scenario("scenarios/pair60.yaml"), load_instrument("sc1")
    for method in ("setup", "conventional"):
        prep = prepare_run(scenario, spec, method, seed=5)
        a = run_trials_chunk(prep, 0, 3, transcript=False)
        b = run_trials_chunk(replace(prep, scenario=None), 0, 3, transcript=False)
        np.testing.assert_array_equal(a.q_grid_mm, b.q_grid_mm)
        np.testing.assert_array_equal(a.q_standard_mm, b.q_standard_mm)
        assert a.evaluation.to_dict() == b.evaluation.to_dict()
