"""Benchmark: synthetic photographs and eyepiece views.

Run ``python benchmarks/bench_imagery.py`` (optionally ``--scenario mountain60 --views 200``).
Times:

* scenario raster build: :class:`~stereoplotter.imagery.cache.ViewCache` construction (both
  photos' eager levels, 0.16 and 0.32 mm) and :func:`~stereoplotter.imagery.photo.render_photo`
  of one photo at 0.08 mm (and at 0.04 mm with ``--fine``);
* view render time, median and p95, of ``ViewCache.view`` (256² px, random κ) in three regimes:
  *cold* — a fresh mark position anywhere on the photo at ×6 (the tiles under it are rendered
  first); *walk* — the mark moved in 0.05 mm steps (a trainee turning a handwheel), so a new tile
  is needed now and then; *zoom* — the same point at ×0.6 … ×20 in turn on a warm cache.

Prints the timings, ``os.cpu_count()`` and the numpy version. Speed is measured here, never
asserted in the test suite.
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

from stereoplotter.imagery.cache import ViewCache
from stereoplotter.imagery.photo import render_photo
from stereoplotter.io.scenario_file import load_scenario


def timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def summary(name: str, times: list[float]) -> str:
    ms = 1000 * np.asarray(times)
    return (
        f"{name:<34} n={len(ms):4d}  median {np.median(ms):7.1f} ms  "
        f"p95 {np.percentile(ms, 95):7.1f} ms  max {ms.max():7.1f} ms"
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", default="pair60")
    parser.add_argument("--views", type=int, default=100, help="views per regime")
    parser.add_argument("--fine", action="store_true", help="also render a photo at 0.04 mm")
    args = parser.parse_args(argv)
    scenario = load_scenario(args.scenario)
    rng = np.random.default_rng(20261125)
    print(f"{platform.machine()}, os.cpu_count() = {os.cpu_count()}, numpy {np.__version__}")
    box: dict[str, ViewCache] = {}
    t = timed(lambda: box.setdefault("c", ViewCache(scenario)))
    cache = box["c"]
    print(f"ViewCache build (both photos)      {t:7.2f} s")
    for p in (0.08, 0.04) if args.fine else (0.08,):
        t = timed(lambda p=p: render_photo(scenario, "left", pixel_mm=p))
        print(f"render_photo left at {p} mm        {t:7.2f} s")
    n = args.views
    cold = [
        timed(lambda x=x, y=y, k=k: cache.view("left", x, y, k, 6.0, 256))
        for x, y, k in zip(
            rng.uniform(-85, 85, n), rng.uniform(-85, 85, n), rng.uniform(-0.3, 0.3, n), strict=True
        )
    ]
    print(summary("cold (random mark, x6)", cold))
    steps = np.cumsum(rng.normal(0.0, 0.05, (n, 2)), axis=0) + (10.0, -20.0)
    walk = [timed(lambda s=s: cache.view("right", s[0], s[1], 0.05, 6.0, 256)) for s in steps]
    print(summary("walk (0.05 mm steps, x6)", walk))
    mags = (0.6, 1.0, 2.0, 4.0, 6.0, 10.0, 20.0)
    for m in mags:  # warm the tiles under the point at every level
        cache.view("left", 10.0, -20.0, 0.0, m, 256)
    zoom = [
        timed(lambda m=m, i=i: cache.view("left", 10.0 + 1e-4 * i, -20.0, 0.0, m, 256))
        for i in range(n // len(mags) + 1)
        for m in mags
    ]
    print(summary("zoom (warm tiles, x0.6-x20)", zoom))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
