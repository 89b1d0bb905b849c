"""Benchmark: the two mechanics back-ends (pymunk lead screw, vectorised play operator).

Run ``python benchmarks/bench_mechanics.py`` (optionally ``--trials 1000000 --repeat 5``).
Prints, best of ``--repeat``:

* one pymunk approach of the §8 reference axis (b = 20 µm, k = 1 N/µm, dt = 1 ms) with the
  long-move shortcut (place 2 mm before the target, simulate the rest), and the full 20 mm move;
  goal (``docs/design/mechanics.md`` §9): ≤ 30 ms per approach;
* bare ``space.step`` rate of one axis (3 bodies, 6 constraints), in steps/s;
* one coordinatograph setting (both chains) and one sheet orientation (ideal drives, acuity 0);
* the play operator over N trials (``PlayAxis.approach`` with a unidirectional finish, and the
  bare :func:`~stereoplotter.instrument.mechanics.play`), in trials/s.

Speed is measured here, never asserted in the test suite.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import sys
import time
from dataclasses import replace

import numpy as np
import pymunk

from stereoplotter.instrument.mechanics import (
    AxisParams,
    Coordinatograph,
    PlayAxis,
    PymunkAxis,
    half_play_mm,
    orient_sheet,
    play,
)


def best_time(function, repeat: int) -> tuple[float, object]:
    best, result = math.inf, None
    for _ in range(repeat):
        start = time.perf_counter()
        result = function()
        best = min(best, time.perf_counter() - start)
    return best, result


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=1_000_000, help="play-operator trials")
    parser.add_argument("--repeat", type=int, default=5, help="best of this many runs")
    args = parser.parse_args(argv)

    print(f"python {platform.python_version()}  numpy {np.__version__}  pymunk {pymunk.version}")
    print(f"machine {platform.machine()}  os.cpu_count() = {os.cpu_count()}")
    params = AxisParams(name="X")

    def approach(p: AxisParams, run_mm: float):
        axis = PymunkAxis(p, start_mm=500.0 - run_mm)
        axis.place(500.0 - run_mm, "below")
        axis.approach(500.0)
        return axis.steps

    for label, p in [
        ("approach, long-move shortcut", params),
        ("approach, full 20 mm simulated", replace(params, simulate_last_mm=math.inf)),
    ]:
        t, steps = best_time(lambda p=p: approach(p, 20.0), args.repeat)
        print(f"pymunk {label:32s} {t * 1e3:7.2f} ms  ({steps} steps, goal ≤ 30 ms)")

    axis = PymunkAxis(params)
    axis.nut_body.velocity = (0.2, 0.0)
    n = 100_000

    def bare() -> None:
        for _ in range(n):
            axis.space.step(params.dt_s)

    t, _ = best_time(bare, args.repeat)
    print(f"pymunk bare space.step, 1 axis          {n / t:10.0f} steps/s ({t / n * 1e6:.2f} µs)")

    rng = np.random.default_rng(1)
    targets = rng.uniform(50.0, 750.0, (12, 2))
    for side in (None, "below"):
        pen = Coordinatograph()
        t, _ = best_time(lambda pen=pen, s=side: [pen.move_pen(x, s) for x in targets], 1)
        print(
            f"coordinatograph, side={side!s:5s}           {t / len(targets) * 1e3:7.2f} ms/target"
        )
    corners = [[100.0, 100.0], [600.0, 100.0], [600.0, 600.0], [100.0, 600.0]]
    t, r = best_time(lambda: orient_sheet(corners, np.random.default_rng(0)), args.repeat)
    print(f"sheet orientation (ideal, acuity 0)     {t * 1e3:7.2f} ms  ({r.simulated_s:.2f} s sim)")

    T = args.trials
    h = half_play_mm(
        rng.uniform(0.005, 0.03, T), rng.uniform(0.05, 0.2, T), rng.uniform(1, 10, T), 1e6
    )
    bulk = PlayAxis(params, half_play_mm=h)
    bulk.place(0.0, "below")
    s = rng.uniform(-50.0, 50.0, T)
    t, _ = best_time(lambda: bulk.approach(s, "below"), args.repeat)
    print(f"PlayAxis.approach(side='below'), T={T:.0e} {t * 1e3:7.2f} ms  ({T / t:.3g} trials/s)")
    x = np.zeros(T)
    t, _ = best_time(lambda: play(x, s, h), args.repeat)
    print(f"play() bare, T={T:.0e}                   {t * 1e3:7.2f} ms  ({T / t:.3g} trials/s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
