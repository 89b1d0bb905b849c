"""The procedure Monte Carlo of `stereoplotter verify`: every run of
`verification.table.run_procedure_mc` at its default trials, its time, the relative 99.9 % CI of
each outcome row (controlled and plain), and the wall time with two workers. The conventional
configurations of a slot are one shared run.

python benchmarks/bench_procedure_verify.py            # the defaults (PROCEDURE_TRIALS, ...)
python benchmarks/bench_procedure_verify.py --trials 3000
"""

import argparse
import os
import time

import numpy as np

from stereoplotter.io.book_setting import book_instrument, book_scenarios
from stereoplotter.verification import table as v


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--trials", type=int, default=None, help="every run (default: per config)")
    ap.add_argument("--workers", type=int, default=2)
    a = ap.parse_args()
    scenarios, spec = book_scenarios(), book_instrument()
    t0 = time.perf_counter()
    proc = v.run_procedure_mc(a.trials, 20240601, scenarios, instrument=spec, workers=a.workers)
    wall = time.perf_counter() - t0
    print(f"cpu_count={os.cpu_count()} numpy={np.__version__} workers={a.workers}")
    # a shared run (the conventional configurations of a slot) reports its seconds in each of
    # its results; count it once, at its first block (first_trial 0)
    runs = sum(r["seconds"] for r in proc.values() if not r.get("first_trial"))
    print(f"procedure MC wall {wall:.1f} s, sum of runs {runs:.1f} s")
    for key, r in proc.items():
        shared = "" if "first_trial" not in r else f"  (shared run, from trial {r['first_trial']})"
        print(f"  {' '.join(key):<28} T = {r['trials']:>6}  {r['seconds']:5.1f} s{shared}")
    print(
        f"{'row':<8}{'value':>8}{'CI %':>7}{'plain CI %':>11}{'formula':>9}{'instr.':>8}{'CI %':>7}"
    )
    for eq, (slot, config, field, scaled) in v.procedure_rows().items():
        r, ri = proc[(slot, config)], proc[(slot, config, "instrument")]
        val, ci, ref = v.procedure_value(r, field, scaled)
        vi, cii, _ = v.procedure_value(ri, field, scaled)
        pc, ph = r["plain"] if field is None else r["fields"][field]["plain"]
        plain = ph / pc  # relative: the same with or without the factor f/p
        print(
            f"{eq:<8}{val:8.4f}{100 * ci / val:7.2f}{100 * plain:11.2f}{ref:9.4f}"
            f"{vi:8.4f}{100 * cii / vi:7.2f}"
        )


if __name__ == "__main__":
    main()
