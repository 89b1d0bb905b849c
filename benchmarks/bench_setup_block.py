"""Benchmark: setup data of a block of stereopairs, vectorised vs one pair at a time.

Run ``python benchmarks/bench_setup_block.py`` (optionally ``--pairs 10000 --loop-pairs 300``).
Times the numeric part only — :func:`stereoplotter.setup.block.compute_block` on N pairs (best of
5) and the per-pair scalar oracle ``per_pair_loop`` of ``tests/oracles/setup_pair_oracle.py`` on a
subset — and prints pairs per second, their ratio and the machine. Goal: ≥ 10⁴ pairs/s
vectorised on a 2-core machine. Speed is measured here, never asserted in the test suite.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.setup.block import compute_block

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from oracles.setup_pair_oracle import per_pair_loop  # the tests' scalar oracle

MARKS = np.array([[-85.0, 0.0], [85.0, 0.0], [0.0, 85.0], [0.0, -85.0]])


def synthetic_block(n: int, seed: int = 20260501) -> dict[str, np.ndarray]:
    """n pairs like scenarios/blocks/strip60.yaml (f = 70 mm, 60 % overlap, 1:15 000–1:25 000),
    strips at random azimuths, tilts ≤ 3.5°, relief up to 45 % of H: a mix of accepted and
    refused pairs, 3 height points each."""
    rng = np.random.default_rng(seed)
    azimuth = rng.uniform(-np.pi, np.pi, n)
    height = rng.uniform(15_000, 25_000, n) * 70.0 / 1000.0
    base = 0.4 * 0.18 * height * 1000 / 70.0
    left = np.column_stack([rng.uniform(-5e4, 5e4, (n, 2)), 150 + height])
    right = left + np.column_stack(
        [base * np.cos(azimuth), base * np.sin(azimuth), rng.normal(0, 8, n)]
    )
    tilts = np.radians(rng.uniform(-3.5, 3.5, (2, n, 2)))
    kappa = azimuth[None, :, None] + np.radians(rng.uniform(-10, 10, (2, n, 1)))
    angles = np.concatenate([tilts, kappa], axis=2)
    relief = rng.uniform(0.02, 0.45, n) * height
    low = 150 - rng.uniform(0, 1, n) * relief
    return {
        "centre_left_m": left,
        "angles_left": angles[0],
        "centre_right_m": right,
        "angles_right": angles[1],
        "terrain_m": np.column_stack([low, low + relief]),
        "height_points_m": low[:, None] + rng.uniform(0, 1, (n, 3)) * relief[:, None],
    }


def best_time(function, repeat: int) -> float:
    best = np.inf
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        best = min(best, time.perf_counter() - start)
    return best


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=10_000, help="N for the vectorised run")
    parser.add_argument("--loop-pairs", type=int, default=500, help="N for the per-pair loop")
    parser.add_argument("--instrument", default="sc1")
    parser.add_argument("--repeat", type=int, default=5, help="best of REPEAT runs")
    args = parser.parse_args(argv)

    spec = load_instrument(args.instrument)
    block = synthetic_block(args.pairs)
    subset = {k: v[: args.loop_pairs] for k, v in block.items()}

    def vectorised():
        return compute_block(70.0, MARKS, spec=spec, map_scale_denominator=10000, **block)

    def loop():
        return per_pair_loop(70.0, MARKS, spec=spec, map_scale_denominator=10000, **subset)

    result = vectorised()  # warm-up, and the acceptance figure
    t_vec = best_time(vectorised, args.repeat)
    t_loop = best_time(loop, max(1, args.repeat // 2))
    rate_vec = args.pairs / t_vec
    rate_loop = args.loop_pairs / t_loop
    print(f"machine: {platform.machine()} {platform.processor() or ''}".rstrip())
    print(
        f"os.cpu_count() = {os.cpu_count()}, python {sys.version.split()[0]}, "
        f"numpy {np.__version__}"
    )
    print(
        f"instrument {spec.key}: {len(result.candidate_scales)} (M_г, M_в) candidates, "
        f"{result.accepted.mean():.0%} of the pairs accepted"
    )
    print(
        f"vectorised  N = {args.pairs:>6}: {t_vec * 1e3:9.2f} ms (best of {args.repeat})  "
        f"{rate_vec:12,.0f} pairs/s"
    )
    print(
        f"per-pair    N = {args.loop_pairs:>6}: {t_loop * 1e3:9.2f} ms "
        f"(best of {max(1, args.repeat // 2)})  {rate_loop:12,.0f} pairs/s"
    )
    print(f"ratio vectorised / per-pair: {rate_vec / rate_loop:,.0f}×")
    print(f"goal ≥ 10 000 pairs/s vectorised: {'met' if rate_vec >= 1e4 else 'NOT met'}")


if __name__ == "__main__":
    main()
