"""Issue 13 (6): the transcript for learners. The tests hold content against independent
quantities: the true y-parallax of a record against the evaluation's q at the standard points,
the ΔZ word against the carriage's own movement (before → after of Z, the projection distance),
the summary counts against the run's checks."""

from __future__ import annotations

import re

import numpy as np
import pytest

from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.procedure import simulate
from stereoplotter.report.simulation import closing_summary, transcript_text


@pytest.fixture(scope="module", params=[3, 20261122])
def run(request):
    return simulate(load_scenario("pair60"), load_instrument("sc1"), seed=request.param)


def test_y_parallax_records_carry_the_true_value(run):
    recs = [r for r in run.transcript.records if r.step.startswith("residual y-parallax at")]
    assert recs and all(r.true is not None for r in recs)
    for r in recs:  # the judgment error is what separates the seen from the true
        assert r.residual == pytest.approx(r.true + r.judgment_error, abs=1e-12)
    # the last judgement of the six points is of the model the evaluation measures; the record's
    # true q is taken where the operator pointed (within σ_mono ≈ µm of the image point), the
    # evaluation's at the exact image point: equal within a tenth of the tolerance
    last = recs[-6:]
    q_eval = np.ravel(run.q_standard_mm)
    assert [int(r.step.split()[-1]) for r in last] == [1, 2, 3, 4, 5, 6]
    tol = run.sheet.tolerances["residual_y_parallax_mm"]
    for r, q in zip(last, q_eval, strict=True):
        assert abs(r.true - q) < 0.1 * tol  # 1.25 µm of a 12.5 µm tolerance


def test_every_seen_value_has_a_unit(run):
    text = run.transcript.to_text()
    seen = [line for line in text.splitlines() if "; seen " in line]
    assert seen
    for line in seen:
        assert re.search(r"seen [+-]\d+\.\d+ (µm|m)\b", line), line
        if "tolerance" in line:
            assert re.search(r"tolerance \d+\.\d+ (µm|m):", line), line
    knobs = [line for line in text.splitlines() if re.search(r"— k_(alpha|omega)_", line)]
    assert knobs and all("tan " in line for line in knobs)
    for line in knobs:  # the counter reading to the 0.01 mm least count, with its unit
        if "counter" in line:
            assert re.search(r"= \d+\.\d\d mm, turn", line), line
    assert "n·o⁰" not in text and "n·a⁰" not in text
    dy = [r for r in run.transcript.records if r.control.startswith("dy_")]
    assert dy and all("tan ω" in r.equation and "tan ω" in r.step for r in dy)


def test_delta_z_word_matches_the_carriage_movement(run):
    recs = [r for r in run.transcript.records if r.step.startswith("ΔZ =")]
    for r in recs:
        moved = r.after - r.before  # Z counts the projection distance: deeper = lower
        word = re.search(r"\(6\.9\): (\w+) the carriage", r.step).group(1)
        assert word == ("lower" if moved > 0 else "raise" if moved < 0 else "leave"), r.step
        assert np.sign(float(r.step.split()[2])) == np.sign(moved)


def test_closing_summary_counts_the_checks(run):
    judged = {n: c for n, c in run.checks.items() if c.tolerance is not None}
    failed = [n for n, c in judged.items() if not bool(np.ravel(c.passed)[0])]
    summary = closing_summary(run)
    m = re.search(r"Checks: (\d+) passed, (\d+) failed of (\d+)\.", summary)
    assert m is not None
    assert (int(m[1]), int(m[2]), int(m[3])) == (
        len(judged) - len(failed),
        len(failed),
        len(judged),
    )
    for name in failed:  # each failed check leads somewhere: what a real operator would do
        line = next(x for x in summary.splitlines() if x.startswith(f"- {name}: still"))
        assert "→" in line
    assert transcript_text(run).endswith(summary)


def test_conventional_y_parallax_records_carry_the_true_value():
    r = simulate(load_scenario("pair60"), load_instrument("sc1"), method="conventional", seed=3)
    recs = [x for x in r.transcript.records if "judge the y-parallax" in x.step]
    assert recs and all(x.true is not None for x in recs)
    for x in recs:
        assert x.residual == pytest.approx(x.true + x.judgment_error, abs=1e-12)
    text = r.transcript.to_text()
    assert "n·o⁰" not in text and re.search(r"true [+-]\d+\.\d µm", text)
