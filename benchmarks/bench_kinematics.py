"""Benchmark: the pure kinematics of the virtual instrument and its kinematic self-test.

Run ``python benchmarks/bench_kinematics.py`` (optionally ``--points 1000000 --repeat 5``).
Times, best of ``--repeat``:

* the correction unit's forward map :func:`~stereoplotter.instrument.kinematics.photo_from_rod`
  on N rod points (one unit per point, as in a Monte Carlo batch);
* the instrument's forward map :func:`~stereoplotter.instrument.kinematics.marks_from_counters`
  (counters → both photo points) on N counter triples;
* the inverse :func:`~stereoplotter.instrument.kinematics.counters_from_homologous_points`
  (both photo points → X, Y, D, q) on N pairs;
* :func:`~stereoplotter.procedure.selftest.run_kinematic_selftest` (``kinematics.md`` §5, §6:
  the CLI-facing acceptance, goal < 10 s).

Prints points per second, the wall times, ``os.cpu_count()`` and the numpy version. Speed is
measured here, never asserted in the test suite.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time

import numpy as np

from stereoplotter.instrument.kinematics import (
    InstrumentSetting,
    counters_from_homologous_points,
    marks_from_counters,
    photo_from_rod,
)
from stereoplotter.instrument.knobs import unit_for_orientation
from stereoplotter.procedure.selftest import run_kinematic_selftest


def best_of(repeat: int, fn) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=1_000_000, help="N points (default 10^6)")
    parser.add_argument("--repeat", type=int, default=5, help="best of this many runs")
    parser.add_argument("--selftest-repeat", type=int, default=3, help="runs of the self-test")
    args = parser.parse_args(argv)
    n = args.points
    rng = np.random.default_rng(20260501)
    tilts = np.radians(rng.uniform(-3.0, 3.0, (n, 4)))
    kappas = np.radians(rng.uniform(-5.0, 5.0, (n, 2)))
    left = unit_for_orientation(tilts[:, 0], tilts[:, 1], kappas[:, 0], 100.0)
    right = unit_for_orientation(tilts[:, 2], tilts[:, 3], kappas[:, 1], 100.0)
    setting = InstrumentSetting(130.0, base_x_mm=102.5, base_y_mm=1.7, base_z_mm=2.8)
    rods = rng.uniform(-90.0, 90.0, (n, 2))
    x = rng.uniform(-20.0, 120.0, n)
    y = rng.uniform(-110.0, 110.0, n)
    d = rng.uniform(165.0, 205.0, n)
    pl, pr = marks_from_counters(x, y, d, setting, left, right)

    t_unit = best_of(args.repeat, lambda: photo_from_rod(rods, left))
    t_fwd = best_of(args.repeat, lambda: marks_from_counters(x, y, d, setting, left, right))
    t_inv = best_of(
        args.repeat, lambda: counters_from_homologous_points(pl, pr, setting, left, right)
    )
    t_self = best_of(args.selftest_repeat, run_kinematic_selftest)

    print(
        f"machine: {platform.machine()}, os.cpu_count() = {os.cpu_count()}, "
        f"numpy {np.__version__}, Python {sys.version.split()[0]}"
    )
    print(f"N = {n} points, best of {args.repeat}")
    print(
        f"  unit forward map photo_from_rod:          {t_unit * 1e3:8.1f} ms  "
        f"{n / t_unit:12.3g} points/s"
    )
    print(
        f"  instrument forward marks_from_counters:    {t_fwd * 1e3:8.1f} ms  "
        f"{n / t_fwd:12.3g} points/s (both photos)"
    )
    print(
        f"  inverse counters_from_homologous_points:   {t_inv * 1e3:8.1f} ms  "
        f"{n / t_inv:12.3g} points/s"
    )
    print(f"run_kinematic_selftest() (§5 + §6, best of {args.selftest_repeat}): {t_self:.2f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
