"""Benchmark: the trainer's session round trip and the grading population.

python benchmarks/bench_trainer.py                      # e08 (setup) and e09 (conventional)
python benchmarks/bench_trainer.py --population 2000 --exercise e03-setup-stage2

Prints: Session.start (the simulated operator's run included), one act (state before/after,
digests, log record) over the operator's whole script, one state() alone, the byte-for-byte
replay of the log, and the population of simulated operators (vectorised, chunks of
``grading.CHUNK``) with its peak RSS growth.
"""

from __future__ import annotations

import argparse
import os
import resource
import time

import numpy as np

from stereoplotter.io.exercise_file import exercise_from_mapping, load_exercise
from stereoplotter.io.session_log import log_bytes
from stereoplotter.trainer.grading import CHUNK, population_measures
from stereoplotter.trainer.session import Session


def _rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def bench(name: str, population: int) -> None:
    ex = load_exercise(name)
    t = time.perf_counter()
    s = Session.start(ex, trainee="bench")
    start = time.perf_counter() - t
    script = s.operator_script()
    t = time.perf_counter()
    for action in script:
        s.act(action)
    acts = time.perf_counter() - t
    t = time.perf_counter()
    for _ in range(50):
        s.state()
    state = (time.perf_counter() - t) / 50
    data = log_bytes([s.header(), *s.log])
    t = time.perf_counter()
    r = Session.replay([s.header(), *s.log], read_exercise=exercise_from_mapping)
    replay = time.perf_counter() - t
    assert log_bytes([r.header(), *r.log]) == data
    rss0 = _rss_mb()
    t = time.perf_counter()
    pop = population_measures(s.prep, s.seed, ex.stages, population, s.inst.injected)
    pop_s = time.perf_counter() - t
    assert all(np.all(np.isfinite(v)) for vs in pop.values() for v in vs.values())
    print(
        f"{name}: start {start:.2f} s; {len(script)} actions in {acts:.2f} s = "
        f"{1000 * acts / len(script):.2f} ms/act; state() {1000 * state:.2f} ms; "
        f"replay {replay:.2f} s; log {len(data) / 1e6:.2f} MB"
    )
    print(
        f"{name}: population {population} operators in {pop_s:.2f} s "
        f"({population / pop_s:.0f}/s, chunks of {CHUNK}); peak RSS +{_rss_mb() - rss0:.0f} MB"
    )


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("--population", type=int, default=10_000)
    p.add_argument("--exercise", nargs="+", default=["e08-setup-full", "e09-conventional-full"])
    a = p.parse_args()
    print(f"cpu_count={os.cpu_count()} numpy={np.__version__}")
    for name in a.exercise:
        bench(name, a.population)


if __name__ == "__main__":
    main()
