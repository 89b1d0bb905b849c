"""Benchmark: full five-stage setup-data procedures per second.

python benchmarks/bench_procedure.py                 # T = 10 000 vectorised, 20 in the loop
python benchmarks/bench_procedure.py --trials 1000 --loop 10 --no-pymunk
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.procedure import simulate, simulate_per_trial


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("--trials", type=int, default=10_000)
    p.add_argument("--loop", type=int, default=20)
    p.add_argument("--no-pymunk", action="store_true")
    a = p.parse_args()
    sc = load_scenario("scenarios/pair60.yaml")
    spec = load_instrument("sc1")
    t = time.perf_counter()
    simulate(sc, spec, seed=1, trials=a.trials, evaluate=False)
    vec = time.perf_counter() - t
    t = time.perf_counter()
    simulate_per_trial(sc, spec, seed=1, trials=a.loop)
    loop = time.perf_counter() - t
    rate_v, rate_l = a.trials / vec, a.loop / loop
    print(f"cpu_count={os.cpu_count()} numpy={np.__version__}")
    print(f"vectorised T={a.trials}: {vec:.2f} s = {rate_v:.0f} procedures/s")
    print(f"per-trial loop N={a.loop}: {loop:.2f} s = {rate_l:.1f} procedures/s")
    print(f"ratio {rate_v / rate_l:.0f}x")
    if not a.no_pymunk:
        t = time.perf_counter()
        simulate(sc, spec, seed=1, backend="pymunk", evaluate=False)
        print(f"pymunk single procedure incl. coordinatograph: {time.perf_counter() - t:.2f} s")


if __name__ == "__main__":
    main()
