"""Time `run_verification` (default settings, the book's scenarios in the procedure MC) and its
parts.

python benchmarks/bench_verify.py [--trials T] [--repeat R]
"""

import argparse
import os
import time

import numpy as np

from stereoplotter.io.book_setting import book_instrument, book_scenarios
from stereoplotter.verification import linear_mc as mc
from stereoplotter.verification import table as v


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--trials", type=int, default=60000)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    scenarios, spec = book_scenarios(), book_instrument()
    best = min(
        _timed(
            lambda: v.run_verification(
                trials=a.trials, procedure_scenarios=scenarios, instrument=spec
            )
        )
        for _ in range(a.repeat)
    )
    specs = v.row_entries(dict(v.BOOK))
    t_spec = _timed(lambda: v.row_entries(dict(v.BOOK)))
    t_cov = _timed(lambda: [mc.covariance_rms(e.model) for e in specs])
    rng = np.random.default_rng(0)
    t_mc = _timed(lambda: [mc.mc_rms(e.model, a.trials, rng) for e in specs])
    print(f"cpu_count={os.cpu_count()} numpy={np.__version__} rows={len(specs)} trials={a.trials}")
    print(f"run_verification best of {a.repeat}: {best:.2f} s")
    print(
        f"  row models + formulas {t_spec:.3f} s, covariance {t_cov:.3f} s, linear MC {t_mc:.2f} s"
    )


def _timed(fn):
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


if __name__ == "__main__":
    main()
