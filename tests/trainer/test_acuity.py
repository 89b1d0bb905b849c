"""The stereo-acuity staircase recovers a simulated observer's threshold within its error."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stereoplotter.trainer.acuity import Staircase, photo_um, simulated_observer

RUNS = 400


def _runs(sigma: float, start: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    logs, ses, trials = [], [], []
    for seed in range(RUNS):
        judge = simulated_observer(sigma, np.random.default_rng(seed))
        st = Staircase(start=start)
        while not st.done:
            st.answer(judge(st.level))
        est, se = st.estimate()
        logs.append(math.log(est))
        ses.append(se)
        trials.append(st.trials)
    return np.array(logs), np.array(ses), np.array(trials)


@pytest.mark.parametrize(("sigma", "start"), [(10.0, 120.0), (30.0, 200.0)])
def test_the_staircase_recovers_a_simulated_threshold(sigma, start):
    logs, ses, trials = _runs(sigma, start)
    mc_se = logs.std(ddof=1) / math.sqrt(RUNS)
    assert abs(logs.mean() - math.log(sigma)) <= 3.0 * mc_se  # unbiased within its MC error
    # one run's stated error is the spread of its estimate over runs (± 10 %: the ratio of a
    # standard deviation of 400 runs to a mean of 400 stated errors)
    assert logs.std(ddof=1) / ses.mean() == pytest.approx(1.0, abs=0.1)
    inside = np.mean(np.abs(logs - math.log(sigma)) <= ses)
    assert inside == pytest.approx(0.683, abs=3 * math.sqrt(0.683 * 0.317 / RUNS) + 0.03)
    assert trials.mean() < 50  # a short test


def test_an_acuity_in_photo_micrometres_is_the_eye_models():
    # 10″ through ×6 referred to 250 mm is the operator's σ_q, 2.02 µm (procedure.eye)
    assert photo_um(10.0)["6"] == pytest.approx(2.02, abs=0.005)
    assert photo_um(30.0)["2"] == pytest.approx(3 * photo_um(30.0)["6"], rel=1e-12)


def test_the_population_takes_the_trainees_acuity():
    from stereoplotter.io.exercise_file import load_exercise
    from stereoplotter.trainer.acuity import with_acuity
    from stereoplotter.trainer.grading import population_measures
    from stereoplotter.trainer.session import Session

    s = Session.start(load_exercise("e05-conventional-c2"), trainee="ann")
    name = "residual y-parallax at the 6 standard points (true)"

    def median_q(prep):
        pop = population_measures(prep, s.seed, s.exercise.stages, 128, s.inst.injected)
        return float(np.median(pop["C2"][name]))

    default = median_q(s.prep)
    # the textbook's 30″ and 10″ are the default operator's eye: the same population exactly
    assert median_q(with_acuity(s.prep, {"x_arcsec": 30.0, "y_arcsec": 10.0})) == default
    # a coarser eye (σ_q four times larger) leaves more y-parallax after C2
    assert median_q(with_acuity(s.prep, {"x_arcsec": 60.0, "y_arcsec": 40.0})) > 2 * default


def test_the_grade_says_which_acuity_it_compared_with():
    from stereoplotter.io.exercise_file import load_exercise
    from stereoplotter.trainer.grading import grade
    from stereoplotter.trainer.session import Session

    s = Session.start(load_exercise("e02-conventional-c1"), trainee="ann")
    s.act({"kind": "record", "name": "stereo acuity x (arcsec)", "value": 24.0})
    s.act({"kind": "record", "name": "stereo acuity y (arcsec)", "value": 12.0})
    note = grade(s, population=16)["population"]["acuity"]
    assert note["measured"] and note["x_arcsec"] == 24.0 and note["y_arcsec"] == 12.0
    assert "your measured stereo acuity: 24.0″" in note["text"]
    # (eye 1) at the SC-1's ×6 and 250 mm: 12″ → 2.42 µm
    assert note["y_parallax_sigma_um"] == pytest.approx(photo_um(12.0)["6"], rel=1e-9)
    plain = grade(Session.start(load_exercise("e02-conventional-c1"), trainee="bo"), population=16)
    assert not plain["population"]["acuity"]["measured"]
    assert "textbook's" in plain["population"]["acuity"]["text"]
