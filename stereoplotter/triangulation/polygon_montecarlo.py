"""Does using the inter-strip conditions improve accuracy 1.5–2 times? (Dorozhinsky's claim.)

Simulated regular blocks of a photos × b strips (:mod:`~stereoplotter.triangulation.polygon_grid`):
every side's increment has an independent error of unit σ (along and across strips alike, one
element — the six are adjusted independently and identically); the first and last centre of
every strip are control (known without error).

- *strips*: each strip adjusted alone — its along-strip sides between its two control centres
  (the misclosure distributed equally, the correlate solution of one condition);
- *block*: all sides, the sub-block conditions Σ = 0 and the same control, correlate solution.

The error of every non-control centre is linear in the side errors, e = G ε, so G is found
once (unit side errors through :func:`~stereoplotter.triangulation.polygon.adjust_polygons`) and
the trials are e = G ε for ε ~ N(0, I). Reported: the ratio RMS(strips)/RMS(block) over the
non-control centres, its Monte Carlo 95 % interval (delta method on the per-trial mean squares)
and the exact ratio √(tr G_s G_sᵀ / tr G_b G_bᵀ).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from stereoplotter.statistics import Z95
from stereoplotter.triangulation.polygon import PolygonNetwork, adjust_polygons
from stereoplotter.triangulation.polygon_grid import grid_network, grid_sides

__all__ = ["StripBlockComparison", "compare_strips_block", "error_map"]


def _control(a: int, b: int) -> dict[str, NDArray[np.float64]]:
    return {f"{k + 1}-{j + 1}": np.zeros(6) for k in range(b) for j in (0, a - 1)}


def _strip_network(a: int, b: int, values: NDArray) -> PolygonNetwork:
    n_along = b * (a - 1)
    along = grid_sides(a, b)[:n_along]
    return PolygonNetwork(
        centres=tuple(f"{k + 1}-{j + 1}" for k in range(b) for j in range(a)),
        sides=along,
        values=values[:n_along],
        fixed=_control(a, b),
        polygons=(),
    )


def error_map(a: int, b: int, inter_strip: bool) -> NDArray[np.float64]:
    """G: errors of the non-control centres per unit error of each side, (n_free, n_sides).

    Side order of :func:`~stereoplotter.triangulation.polygon_grid.grid_sides`; the strip
    solution ignores (has zero columns for) the across-strip sides.
    """
    n_sides = len(grid_sides(a, b))
    free = [f"{k + 1}-{j + 1}" for k in range(b) for j in range(1, a - 1)]
    g = np.zeros((len(free), n_sides))
    for first in range(0, n_sides, 6):
        cols = range(first, min(first + 6, n_sides))
        values = np.zeros((n_sides, 6))
        for e, s in enumerate(cols):
            values[s, e] = 1.0
        if inter_strip:
            net = grid_network(a, b, values, fixed=_control(a, b))
        else:
            net = _strip_network(a, b, values)
        result = adjust_polygons(net, method="least_squares")
        for e, s in enumerate(cols):
            g[:, s] = [result.centre_elements[c][e] for c in free]
    return g


@dataclass(frozen=True)
class StripBlockComparison:
    """RMS centre errors (units of the side σ) and their ratio strips/block."""

    a: int
    b: int
    trials: int
    rms_strips: float
    rms_block: float
    ratio: float
    ratio_ci95: tuple[float, float]
    exact_ratio: float


def compare_strips_block(
    a: int, b: int, trials: int, rng: np.random.Generator, chunk: int = 5000
) -> StripBlockComparison:
    """Monte Carlo of :func:`error_map` for both solutions on the same side errors."""
    gs, gb = error_map(a, b, False), error_map(a, b, True)
    ms_s, ms_b = [], []
    done = 0
    while done < trials:
        m = min(chunk, trials - done)
        eps = rng.standard_normal((m, gs.shape[1]))
        ms_s.append(np.mean((eps @ gs.T) ** 2, axis=1))
        ms_b.append(np.mean((eps @ gb.T) ** 2, axis=1))
        done += m
    s, bl = np.concatenate(ms_s), np.concatenate(ms_b)
    mean_s, mean_b = s.mean(), bl.mean()
    cov = np.cov(s, bl)
    var_log = (
        cov[0, 0] / mean_s**2 + cov[1, 1] / mean_b**2 - 2 * cov[0, 1] / (mean_s * mean_b)
    ) / (4 * trials)
    ratio = math.sqrt(mean_s / mean_b)
    half = Z95 * math.sqrt(var_log)
    return StripBlockComparison(
        a=a,
        b=b,
        trials=trials,
        rms_strips=math.sqrt(mean_s),
        rms_block=math.sqrt(mean_b),
        ratio=ratio,
        ratio_ci95=(ratio * math.exp(-half), ratio * math.exp(half)),
        exact_ratio=math.sqrt(np.sum(gs**2) / np.sum(gb**2)),
    )
