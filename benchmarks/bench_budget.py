"""Time `stereoplotter budget SCENARIO --instrument NAME` end to end, as a user types it.

python benchmarks/bench_budget.py                          # pair60, sc1, setup, default trials
python benchmarks/bench_budget.py --trials 200 400 1000 --instrument spr3 --method conventional

Each run is a fresh process (`python -m stereoplotter budget ... --json -q`, imports included).
Prints the wall time and the standard errors of the largest contributions, so that the default
trial count (`verification.budget.DEFAULT_BUDGET_TRIALS`) can be chosen against the goal:
≤ 60 s for pair60 on sc1 on two cores.
"""

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

from stereoplotter.verification.budget import DEFAULT_BUDGET_TRIALS


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenario", default="pair60")
    ap.add_argument("--instrument", default="sc1")
    ap.add_argument("--method", default="setup")
    ap.add_argument("--trials", type=int, nargs="+", default=[DEFAULT_BUDGET_TRIALS])
    a = ap.parse_args()
    print(f"cpu_count={os.cpu_count()} numpy={np.__version__} load={os.getloadavg()[0]:.1f}")
    for trials in a.trials:
        cmd = [
            sys.executable, "-m", "stereoplotter", "budget", a.scenario,
            "--instrument", a.instrument, "--method", a.method,
            "--trials", str(trials), "--json", "-q",
        ]  # fmt: skip
        t0 = time.perf_counter()
        done = subprocess.run(cmd, check=True, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        out = json.loads(done.stdout)
        print(f"{a.scenario} {a.instrument} {a.method} trials={trials}: {wall:.1f} s wall")
        for m, tot in out["totals"].items():
            top = max(out["terms"], key=lambda r, m=m: abs(r["one_at_a_time"][m]["rms"]))
            c = top["one_at_a_time"][m]
            print(
                f"  {m}: all on {tot['all_on']['rms']:.4g} ± {tot['all_on']['se']:.2g}, largest "
                f"{top['name']} {c['rms']:.4g} ± {c['se']:.2g}"
            )


if __name__ == "__main__":
    main()
