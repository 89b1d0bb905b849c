"""Benchmark: bundle block adjustment of large synthetic blocks (issue 29, part B).

Run ``python benchmarks/bench_triangulation.py`` (default 25 strips × 40 photos = 1000 photos;
``--strips 10 --photos 30`` for the 30 × 10 comparison block, ``--scaling`` for 250/500/1000
photos). Times the numeric part only (no file read or written): the synthetic block is made first
(:mod:`stereoplotter.triangulation.synth`), then :func:`stereoplotter.triangulation.bundle.
bundle_adjust` runs without and with the photos' covariances, and the strip method on the same
block. Prints photos, observations, iterations, wall-clock seconds, the peak traced memory of the
adjustment (tracemalloc: numpy and scipy arrays) and the RMS at check points. Goal (issue 29):
1000 photos in ≤ 60 s on two cores, memory linear in the number of observations. Speed is
measured here, never asserted in the test suite.
"""

from __future__ import annotations

import argparse
import os
import time
import tracemalloc

import numpy as np

from stereoplotter.triangulation.bundle import bundle_adjust, problem
from stereoplotter.triangulation.solution import catalogue_residuals
from stereoplotter.triangulation.strip import strip_block
from stereoplotter.triangulation.synth import SynthSpec, synthesize_block


def run(strips: int, photos: int, covariance: bool, with_strip: bool) -> None:
    block, _ = synthesize_block(
        SynthSpec(strips=strips, photos_per_strip=photos), np.random.default_rng(29)
    )
    p = problem(block)
    n_obs = 2 * p.obs_photo.size + int(np.count_nonzero(p.control_weight))
    for cov in (False, True) if covariance else (False,):
        tracemalloc.start()
        start = time.perf_counter()
        s = bundle_adjust(p, covariance=cov)
        seconds = time.perf_counter() - start
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        rms = catalogue_residuals(block, s).rms(block, "check")
        print(
            f"bundle {strips} × {photos} = {len(block.photos)} photos, {n_obs} observations, "
            f"covariance {cov}: {s.iterations} iterations, {seconds:.2f} s, peak "
            f"{peak / 2**20:.0f} MiB ({peak / n_obs:.0f} B per observation), RMS check X Y Z "
            f"{rms[0]:.3f} {rms[1]:.3f} {rms[2]:.3f} m"
        )
    if with_strip:
        start = time.perf_counter()
        s = strip_block(block)
        rms = catalogue_residuals(block, s).rms(block, "check")
        print(
            f"strip (independent, degree 3): {time.perf_counter() - start:.2f} s, RMS check "
            f"X Y Z {rms[0]:.3f} {rms[1]:.3f} {rms[2]:.3f} m"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--strips", type=int, default=25)
    parser.add_argument("--photos", type=int, default=40)
    parser.add_argument("--scaling", action="store_true", help="250, 500 and 1000 photos")
    parser.add_argument("--strip-method", action="store_true", help="also the strip method")
    args = parser.parse_args()
    print(f"os.cpu_count() = {os.cpu_count()}, numpy {np.__version__}")
    if args.scaling:
        for strips, photos in ((10, 25), (20, 25), (25, 40)):
            run(strips, photos, False, False)
        return
    run(args.strips, args.photos, True, args.strip_method)


if __name__ == "__main__":
    main()
