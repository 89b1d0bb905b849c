"""Every draw is keyed by its identity, not by its place: a step or a verification row inserted
among the others leaves every other result unchanged, bit for bit."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.procedure import conventional, setup_method, simulate
from stereoplotter.procedure.noise_key import NoiseKey
from stereoplotter.procedure.operator import Noise
from stereoplotter.procedure.simulate import prepare_run, run_trials_chunk
from stereoplotter.procedure.step_values import Act, Line
from stereoplotter.verification import rows_chapter5, table
from stereoplotter.verification.control_variate import RecordingNoise
from stereoplotter.verification.entry import DeclaredRows

TRIALS = 4


def _dummy_step(run) -> None:
    """A step of its own identity: it judges (a draw of its own stream) and reads every counter
    it can read without moving a carriage."""
    run.op.noise.normal("dummy/judgment", 1.0)
    for control in ("X", "Y", "Z", "bx", "by", "bz"):
        run.op.read(control, f"dummy/{control}")


def _results(r) -> dict[str, bytes]:
    """Every number of a run, as bytes."""
    out = {
        "q_standard": r.q_standard_mm.tobytes(),
        "q_grid": r.q_grid_mm.tobytes(),
        "Z": np.asarray(r.instrument.state()["carriages_mm"]["Z"]).tobytes(),
    }
    for name, check in r.checks.items():
        out[f"check {name}"] = np.asarray(check.residual).tobytes()
    for name, stage in r.stages.items():
        out[f"iterations {name}"] = np.asarray(stage.iterations).tobytes()
    for name, value in r.zero_readings.items():
        out[f"zero {name}"] = np.asarray(value).tobytes()
    return out


def _run(method: str) -> dict[str, bytes]:
    sc, spec = load_scenario("scenarios/pair60.yaml"), load_instrument("sc1")
    r = simulate(sc, spec, method=method, seed=11, trials=TRIALS, evaluate=False)
    return _results(r)


@pytest.mark.parametrize(
    ("method", "module", "before"),
    [("setup", setup_method, "stage3_scale_model"), ("conventional", conventional, "c4_sheet")],
)
def test_an_inserted_step_changes_no_other_result(monkeypatch, method, module, before):
    plain = _run(method)
    step = getattr(module, before)

    def with_dummy(*args, **kwargs):
        _dummy_step(args[0])
        return step(*args, **kwargs)

    monkeypatch.setattr(module, before, with_dummy)
    inserted = _run(method)
    assert inserted.keys() == plain.keys()
    changed = [k for k in plain if plain[k] != inserted[k]]
    assert changed == []


_DUMMY_LINE = Line("dummy", "a dummy step: judge, read the counters")


def _declared_dummy(run, key: NoiseKey) -> None:
    """A declared step of its own identity: a judgment, every counter read, a line."""
    op = run.op
    e = op.noise.draw(key.at("judgment").by("q"), op.model.y_parallax_sigma_mm)
    for control in ("X", "Y", "Z", "bx", "by", "bz"):
        op.read(control, key.at(control))
    _DUMMY_LINE.log(op, judgment_error=e)


def _run_with_transcript(method: str) -> tuple[dict[str, bytes], list, int]:
    sc, spec = load_scenario("scenarios/pair60.yaml"), load_instrument("sc1")
    r = simulate(sc, spec, method=method, seed=11, trials=TRIALS, evaluate=False)
    records = r.transcript.records
    others = [dataclasses.replace(x, number=0) for x in records if x.stage != "dummy"]
    return _results(r), others, len(records) - len(others)


@pytest.mark.parametrize(
    ("method", "module", "sequence", "at"),
    [
        ("setup", setup_method, "STAGE1_STEPS", 0),
        ("setup", setup_method, "STAGE1_STEPS", 12),
        ("setup", setup_method, "STAGE2_STEPS", 3),
        ("setup", setup_method, "STAGE3_STEPS", 1),
        ("conventional", conventional, "C1_STEPS", 13),
    ],
)
def test_a_declared_step_inserted_changes_no_other_result(
    monkeypatch, method, module, sequence, at
):
    """A step inserted into a method's declared sequence draws from its own identity only:
    every number of the run and every other line of the transcript stays as it was, bit for
    bit (a step keyed by its place would shift the draws of every step after it)."""
    plain, lines, dummies = _run_with_transcript(method)
    assert dummies == 0
    declared = getattr(module, sequence)
    step = Act("a dummy step", NoiseKey("dummy"), _declared_dummy)
    monkeypatch.setattr(module, sequence, (*declared[:at], step, *declared[at:]))
    inserted, inserted_lines, dummies = _run_with_transcript(method)
    assert dummies == 1
    assert inserted.keys() == plain.keys()
    assert [k for k in plain if plain[k] != inserted[k]] == []
    assert inserted_lines == lines


@pytest.mark.parametrize("after", ["C1_STEPS", "C2: relative orientation"])
def test_a_step_inserted_into_the_conventional_method_changes_no_other_result(monkeypatch, after):
    """The conventional method's declared sequence (C1, calibration, C2, C3, C4) with a dummy
    step after C1 or after C2: every other number and transcript line as before, bit for bit."""
    plain, lines, _ = _run_with_transcript("conventional")
    declared = conventional.conventional_steps
    step = Act("a dummy step", NoiseKey("dummy"), _declared_dummy)

    def with_dummy(*args, **kwargs):
        steps = declared(*args, **kwargs)
        names = [getattr(s, "name", "") for s in steps]
        at = len(conventional.C1_STEPS) if after == "C1_STEPS" else names.index(after) + 1
        return (*steps[:at], step, *steps[at:])

    monkeypatch.setattr(conventional, "conventional_steps", with_dummy)
    inserted, inserted_lines, dummies = _run_with_transcript("conventional")
    assert dummies == 1
    assert [k for k in plain if plain[k] != inserted[k]] == []
    assert inserted_lines == lines


def _linear_rows(monkeypatch, insert: bool) -> list[dict]:
    """The linear rows; with ``insert``, a row declared in a topic module of its own placed
    first in the table (it takes the model of (5.19) under a new identity)."""
    if insert:
        dummy_rows = DeclaredRows()

        @dummy_rows.row
        def dummy(s):
            row = rows_chapter5.eq_5_19(s)
            return dataclasses.replace(row, eq="(dummy)", quantity="an inserted row")

        monkeypatch.setattr(table, "ROW_MODULES", (dummy_rows, *table.ROW_MODULES))
    return table.run_verification(trials=300, seed=5, procedure_trials=0)


def test_an_inserted_verification_row_changes_no_other_row(monkeypatch):
    plain = _linear_rows(monkeypatch, insert=False)
    inserted = _linear_rows(monkeypatch, insert=True)
    assert [r["eq"] for r in inserted] == ["(dummy)"] + [r["eq"] for r in plain]
    others = [r for r in inserted if r["eq"] != "(dummy)"]
    for a, b in zip(plain, others, strict=True):
        assert (a["mc_linear"], a["mc_linear_ci"]) == (b["mc_linear"], b["mc_linear_ci"]), a["eq"]
        assert a == b


def test_two_rows_of_one_identity_are_refused(monkeypatch):
    specs = table.row_entries
    monkeypatch.setattr(table, "row_entries", lambda g: [*specs(g), specs(g)[3]])
    with pytest.raises(ValueError, match="share the identity"):
        table.run_verification(trials=10, seed=5, procedure_trials=0)


def _run_with_noise(method: str, recording: bool) -> tuple[dict[str, bytes], set[str]]:
    """A run of ``method`` and the keys it drew: on the plain keyed stream, or on a recording
    one (every act draws, used or not)."""
    sc, spec = load_scenario("scenarios/pair60.yaml"), load_instrument("sc1")
    drawn: set[str] = set()
    plain_normal = Noise.normal

    def recorded(self, key, sigma):
        drawn.add(key)
        return plain_normal(self, key, sigma)

    mp = pytest.MonkeyPatch()
    mp.setattr(Noise, "normal", recorded)
    try:
        noise = RecordingNoise(11, TRIALS) if recording else Noise(11, TRIALS)
        prep = prepare_run(sc, spec, method, seed=11)
        r = run_trials_chunk(prep, 0, TRIALS, evaluate=False, noise=noise)
    finally:
        mp.undo()
    return _results(r), drawn


@pytest.mark.parametrize("method", ["setup", "conventional"])
def test_an_act_whose_value_nothing_uses_is_left_undrawn_and_changes_no_result(method):
    """A fusing that only reads (no y-parallax judged) and a pointing onto one line (the
    component along it not judged) do not draw those acts on the plain keyed stream; a noise
    that records its acts still gets them. Every result is the same, bit for bit."""
    plain, plain_keys = _run_with_noise(method, recording=False)
    every, every_keys = _run_with_noise(method, recording=True)
    assert plain == every
    undrawn = every_keys - plain_keys
    assert plain_keys <= every_keys
    assert undrawn and all(k.startswith(("q/", "mono/")) for k in undrawn)
