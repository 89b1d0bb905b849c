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
