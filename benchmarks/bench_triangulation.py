"""Benchmark: bundle block adjustment of large synthetic blocks, with point σ and reliability.

Run ``python benchmarks/bench_triangulation.py`` (default 25 strips × 40 photos = 1000 photos;
``--scaling`` for 250, 500 and 1000 photos; ``--strip-method`` adds the strip method). Numeric
part only (no file read or written): the synthetic block is made first
(:mod:`stereoplotter.triangulation.synth`), then, each timed in CPU seconds of this process
(``time.process_time``: the machine is shared, wall time follows its load) and wall seconds:

1. the adjustment alone (``covariance=False``);
2. what ``triangulate`` runs: iterated data snooping with the σ of every photo and point from
   the selected inverse and the reliability of every observation
   (:func:`stereoplotter.triangulation.reliability.snooped_block`).

Prints photos, observations, iterations, the times, the peak memory traced by ``tracemalloc``
(numpy and scipy arrays) per observation, and the RMS at the check points. Goal: 1000 photos with
point σ and reliability ≤ 30 s CPU, memory linear in the observations. BLAS threads compete with
the machine's other jobs: run with ``OPENBLAS_NUM_THREADS=1`` for CPU times that count work, not
spinning. Speed is measured here, never asserted in the test suite.
"""

from __future__ import annotations

import argparse
import os
import time
import tracemalloc

import numpy as np

from stereoplotter.triangulation.bundle import bundle_adjust, problem
from stereoplotter.triangulation.reliability import snooped_block
from stereoplotter.triangulation.solution import catalogue_residuals
from stereoplotter.triangulation.strip import strip_block
from stereoplotter.triangulation.synth import SynthSpec, synthesize_block


def _timed(fn):
    tracemalloc.start()
    cpu, wall = time.process_time(), time.perf_counter()
    out = fn()
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return out, cpu, wall, peak


def run(strips: int, photos: int, full: bool, with_strip: bool) -> None:
    block, _ = synthesize_block(
        SynthSpec(strips=strips, photos_per_strip=photos), np.random.default_rng(29)
    )
    p = problem(block)
    n_obs = 2 * p.obs_photo.size + int(np.count_nonzero(p.control_weight))
    s, cpu, wall, peak = _timed(lambda: bundle_adjust(p, covariance=False))
    rms = catalogue_residuals(block, s).rms(block, "check")
    print(
        f"bundle {strips} × {photos} = {len(block.photos)} photos, {n_obs} observations: "
        f"adjustment {s.iterations} iterations, {cpu:.2f} s CPU ({wall:.2f} s wall), peak "
        f"{peak / 2**20:.0f} MiB ({peak / n_obs:.0f} B per observation), RMS check X Y Z "
        f"{rms[0]:.3f} {rms[1]:.3f} {rms[2]:.3f} m"
    )
    if full:
        (s, sn), cpu, wall, peak = _timed(lambda: snooped_block(block))
        se = s.point_standard_errors
        print(
            f"  with snooping ({len(sn.flags)} flagged), photo and point σ, reliability: "
            f"{cpu:.2f} s CPU ({wall:.2f} s wall), peak {peak / 2**20:.0f} MiB "
            f"({peak / n_obs:.0f} B per observation); band of the selected inverse "
            f"{sn.first.inverse.inverse.width} photos; RMS point σ "
            f"{np.sqrt(np.nanmean(se**2)):.3f} m"
        )
    if with_strip:
        start = time.process_time()
        s = strip_block(block)
        rms = catalogue_residuals(block, s).rms(block, "check")
        print(
            f"strip (independent, degree 3): {time.process_time() - start:.2f} s CPU, RMS "
            f"check X Y Z {rms[0]:.3f} {rms[1]:.3f} {rms[2]:.3f} m"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--strips", type=int, default=25)
    parser.add_argument("--photos", type=int, default=40)
    parser.add_argument("--scaling", action="store_true", help="250, 500 and 1000 photos")
    parser.add_argument("--strip-method", action="store_true", help="also the strip method")
    args = parser.parse_args()
    load = os.getloadavg()[0]
    threads = os.environ.get("OPENBLAS_NUM_THREADS", "unset")
    print(
        f"os.cpu_count() = {os.cpu_count()}, load average {load:.1f}, OPENBLAS_NUM_THREADS "
        f"{threads}, numpy {np.__version__}"
    )
    if args.scaling:
        for strips, photos in ((10, 25), (20, 25), (25, 40)):
            run(strips, photos, True, False)
        return
    run(args.strips, args.photos, True, args.strip_method)


if __name__ == "__main__":
    main()
