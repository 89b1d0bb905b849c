"""A scripted trainee that replays the simulated operator's actions through :class:`Session`
reaches the same instrument state and the same grade as the operator.

The operator's own instrument (``session.par.instrument``, driven by the procedure code) is
compared with the trainee's (driven only by logged session actions): two independent paths to
one state.
"""

from __future__ import annotations

import numpy as np
import pytest

from stereoplotter.io.exercise_file import exercise_from_mapping, load_exercise
from stereoplotter.io.session_log import read_log, write_log
from stereoplotter.trainer.grading import grade, population_measures
from stereoplotter.trainer.outcome import stage_measures
from stereoplotter.trainer.session import Session


def _same_state(a, b):
    sa, sb = a.state(), b.state()
    for key in ("carriages_mm", "base_mm", "zero_readings"):
        for name in sa[key]:
            assert float(sa[key][name]) == float(sb[key][name]), (key, name)
    assert float(sa["f_instrument_mm"]) == float(sb["f_instrument_mm"])
    assert sa["units"] == sb["units"]
    for counter in ("X", "Y", "Z", "bx", "by", "bz", "H"):
        assert a.read(counter, exact=True) == b.read(counter, exact=True), counter


@pytest.fixture(scope="module", params=["e08-setup-full", "e05-conventional-c2"])
def replayed(request, tmp_path_factory):
    ex = load_exercise(request.param)
    s = Session.start(ex, trainee="scripted")
    for action in s.operator_script():
        s.act(action)
    path = tmp_path_factory.mktemp("log") / "operator.jsonl"
    write_log(path, s)
    return s, path


def test_the_scripted_trainee_reaches_the_operators_instrument_state(replayed):
    s, _ = replayed
    assert s.state()["done"]
    _same_state(s.inst, s.par.instrument)


def test_the_scripted_trainee_gets_the_operators_grade(replayed):
    s, path = replayed
    g = grade(read_log(path), population=64, read_exercise=exercise_from_mapping)
    for stage, body in g["stages"].items():
        assert body["claimed"]
        for row in body["measures"]:
            assert row["value"] == row["par"], (stage, row["name"])
    assert g["overall"]["score"] == g["overall"]["par_score"]
    mine = {k: v for k, v in g["process"].items() if k != "time_s"}
    par = {k: v for k, v in g["par_process"].items() if k != "time_s"}
    assert mine == par
    # and the measures on the operator's own instrument (not the replayed one) are the same
    last = s.stages[-1]
    own = stage_measures(s.par.instrument, s.prep, last)
    graded = g["stages"][last]["measures"]
    assert [float(m.value) for m in own] == [r["value"] for r in graded[: len(own)]]


def test_trial_zero_of_the_vectorised_population_is_the_par(replayed):
    """The population runs T operators at once on one instrument; its trial 0 has the par's
    judgments (same keyed noise), so the vectorised path must give the par's measures."""
    s, _ = replayed
    pop = population_measures(s.prep, s.seed, s.stages, 3, s.inst.injected)
    g = grade(s, population=0)
    for stage, values in pop.items():
        rows = {row["name"]: row for row in g["stages"][stage]["measures"]}
        assert set(values) == set(rows)
        for name, v in values.items():
            assert v[0] == pytest.approx(rows[name]["par"], rel=1e-12, abs=1e-15), (stage, name)
            assert np.all(np.isfinite(v))
