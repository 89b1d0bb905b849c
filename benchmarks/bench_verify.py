"""Time `run_verification` (default settings, the book's scenarios in the procedure MC) and its
parts.

python benchmarks/bench_verify.py [--trials T] [--repeat R]
python benchmarks/bench_verify.py --jobs     # CPU seconds of each procedure-MC job, serially

``--jobs`` runs the default ``verify``'s procedure-MC jobs one after another in this process
(one BLAS thread, as in a worker) and prints each job's CPU seconds (user + system), their sum
and the linear rows' CPU: on two cores the wall of ``verify`` cannot go below about half their
total plus the start-up (imports, loading the scenarios).
"""

import argparse
import os
import time

import numpy as np
from threadpoolctl import threadpool_limits

from stereoplotter.io.book_setting import book_instrument, book_scenarios
from stereoplotter.verification import linear_mc as mc
from stereoplotter.verification import table as v


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--trials", type=int, default=60000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--jobs", action="store_true", help="CPU seconds of each procedure-MC job")
    a = ap.parse_args()
    if a.jobs:
        jobs_cpu(a.trials)
        return
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


def jobs_cpu(trials):
    """Each procedure-MC job of the default ``verify`` and the linear rows, CPU seconds."""
    pending = v.start_procedure_mc(
        None, 20240601, book_scenarios(), instrument=book_instrument(), workers=1
    )
    total = 0.0
    with threadpool_limits(limits=1, user_api="blas"):
        for i in pending.order:
            job = pending.jobs[i]
            cpu = _cpu(lambda job=job: v.run_procedure_job(job))
            total += cpu
            print(f"{cpu:6.2f} s  {' '.join(pending.keys[i][0])}  trials {job.trials}")
        entries = v.row_entries(dict(v.BOOK))
        rows = _cpu(lambda: [_linear(e, trials) for e in entries])
    print(f"procedure MC jobs {total:.2f} s CPU, linear rows {rows:.2f} s CPU")
    half = (total + rows) / 2
    print(f"half of their sum (the wall floor on two cores, start-up aside): {half:.2f} s")


def _linear(entry, trials):
    """The linear MC of a row as the table runs it (a squared statistic: 4 × the trials)."""
    n = 4 * trials if entry.squared else trials
    return mc.mc_rms(entry.model, n, v.row_stream(20240601, entry))


def _cpu(fn):
    t0 = os.times()
    fn()
    t1 = os.times()
    return (t1.user - t0.user) + (t1.system - t0.system)


def _timed(fn):
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


if __name__ == "__main__":
    main()
