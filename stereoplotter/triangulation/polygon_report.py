"""Dorozhinsky's worked example and the inter-strip Monte Carlo, printed (text report).

``python -m stereoplotter.triangulation.polygon_report [--trials N]`` prints the figures of
``docs/triangulation-papers.md`` §2: the sides of Fig. 1 with the printed and reproduced
corrections (rigorous, hand computation to 0.1′, exact iteration to Δ = 0.1′), the steps of the
hand computation, the memory-cell counts and RMS(strips)/RMS(block) for several blocks.
"""

from __future__ import annotations

import argparse

import numpy as np

from stereoplotter.triangulation.polygon import adjust_polygons
from stereoplotter.triangulation.polygon_example import (
    PRINTED_LS_CORRECTIONS,
    PRINTED_POLYGON_CORRECTIONS,
    PRINTED_SIDE_MISCLOSURES,
    PRINTED_TRUE_VALUES,
    SNAKE,
    example_network,
    printed_sense,
)
from stereoplotter.triangulation.polygon_grid import cell_counts
from stereoplotter.triangulation.polygon_montecarlo import compare_strips_block

__all__ = ["main"]

BLOCKS = ((10, 2), (10, 3), (10, 5), (10, 10), (20, 5), (20, 10))


def _example() -> None:
    net = example_network()
    ls = adjust_polygons(net, method="least_squares")
    hand = adjust_polygons(net, tolerance=0.1, step=0.1, max_iterations=20, record=True)
    exact = adjust_polygons(net, tolerance=0.1)
    print("Fig. 1 example, Δα in minutes; corrections in the table's senses")
    print(" side  true  δ̄α | printed LS | LS exact | printed polygon | hand 0.1′ | exact Δ=0.1′")
    v_ls, v_hand, v_exact = (printed_sense(r.corrections[:, 0]) for r in (ls, hand, exact))
    for s in range(12):
        print(
            f"  {s + 1:3d} {PRINTED_TRUE_VALUES[s]:+5d} {PRINTED_SIDE_MISCLOSURES[s]:+4d} |"
            f" {PRINTED_LS_CORRECTIONS[s]:+10.2f} | {v_ls[s]:+8.3f} |"
            f" {PRINTED_POLYGON_CORRECTIONS[s]:+15.1f} | {v_hand[s]:+9.1f} | {v_exact[s]:+8.3f}"
        )
    names = dict(enumerate(SNAKE))
    f = ls.misclosures_before[:, 0]
    print("misclosures f: " + ", ".join(f"{names[i]} {f[i]:+.0f}" for i in range(4)))
    print(
        f"[vv] exact {np.sum(v_ls**2):.4f}, from the printed values "
        f"{np.sum(np.square(PRINTED_LS_CORRECTIONS)):.4f}; m = {ls.rms_correction()[0]:.3f}"
    )
    print(
        f"hand computation: {hand.iterations[0]} sweeps, stopped with residual f = "
        + ", ".join(f"{names[i]} {hand.misclosures_after[i, 0]:+.1f}" for i in range(4))
    )
    print(
        "  steps (sweep, sub-block, misclosure distributed): "
        + "; ".join(f"{sw} {names[c]} {fv:+.1f}" for e, sw, c, fv in hand.trace if e == 0)
    )
    print(
        f"exact iteration to Δ = 0.1′: {exact.iterations[0]} sweeps, residual |f| ≤ "
        f"{np.max(np.abs(exact.misclosures_after[:, 0])):.4f}, max |v − v_LS| = "
        f"{np.max(np.abs(exact.corrections - ls.corrections)):.4f}"
    )


def _counts() -> None:
    p, q, sides, blocks = cell_counts(10, 10)
    print(
        f"10 × 10 photos: p = {p}, q = {q}, 2p + q = {sides}, sub-blocks {blocks}, "
        f"cells {sides + blocks}"
    )


def _monte_carlo(trials: int, seed: int) -> None:
    rng = np.random.default_rng(seed)
    print(
        f"\nRMS centre error, strips alone / block with inter-strip conditions "
        f"({trials} trials, seed {seed}; control at both ends of every strip; unit side σ)"
    )
    print("  photos × strips: RMS strips | RMS block | ratio [95 % CI] | exact ratio")
    for a, b in BLOCKS:
        r = compare_strips_block(a, b, trials, rng)
        print(
            f"  {a:2d} × {b:2d}: {r.rms_strips:.3f} | {r.rms_block:.3f} | {r.ratio:.3f} "
            f"[{r.ratio_ci95[0]:.3f}, {r.ratio_ci95[1]:.3f}] | {r.exact_ratio:.3f}"
        )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=20_000, help="Monte Carlo blocks")
    parser.add_argument("--seed", type=int, default=29, help="Monte Carlo seed")
    args = parser.parse_args(argv)
    _example()
    _counts()
    _monte_carlo(args.trials, args.seed)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
