"""The stereo-acuity staircase on simulated observers (the figures of docs/trainer.md, "The
trainee's stereo acuity"), and the grade's population given a trainee's acuity.

    PYTHONPATH=. python3 benchmarks/bench_acuity.py
"""

from __future__ import annotations

import math

import numpy as np

from stereoplotter.io.exercise_file import load_exercise
from stereoplotter.trainer.acuity import Staircase, simulated_observer, with_acuity
from stereoplotter.trainer.grading import population_measures
from stereoplotter.trainer.session import Session

RUNS = 400


def staircase_figures() -> None:
    for sigma, start in ((10.0, 120.0), (30.0, 200.0)):
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
        a, s = np.array(logs), np.array(ses)
        inside = np.mean(np.abs(a - math.log(sigma)) <= s)
        print(
            f"σ {sigma:g}″ (start {start:g}″, {RUNS} runs): mean estimate "
            f"{math.exp(a.mean()):.2f}″ (MC se {100 * a.std(ddof=1) / math.sqrt(RUNS):.1f} %); "
            f"one run's spread {a.std(ddof=1):.3f} in ln σ, its stated error {s.mean():.3f}, "
            f"truth within ±1 stated error in {100 * inside:.1f} %; {np.mean(trials):.1f} trials"
        )


def population_figures() -> None:
    s = Session.start(load_exercise("e05-conventional-c2"), trainee="ann")
    name = "residual y-parallax at the 6 standard points (true)"
    eyes = (None, {"x_arcsec": 30.0, "y_arcsec": 10.0}, {"x_arcsec": 60.0, "y_arcsec": 40.0})
    for acuity in eyes:
        prep = with_acuity(s.prep, acuity) if acuity else s.prep
        pop = population_measures(prep, s.seed, s.exercise.stages, 128, s.inst.injected)
        q = np.median(pop["C2"][name]) * 1000.0
        print(f"e05, 128 operators, acuity {acuity or 'default'}: median worst |q| {q:.2f} µm")


if __name__ == "__main__":
    staircase_figures()
    population_figures()
