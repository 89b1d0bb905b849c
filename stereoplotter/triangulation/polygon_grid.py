"""A regular block for the polygon method: centres, sides, sub-blocks, the paper's addressing.

a photos (projection centres) per strip, b strips. Centre ids ``"{strip}-{photo}"`` (1-based
text). Sides: along each strip photo j → j + 1, then across strip k → k + 1 at each photo.
Sub-blocks lie between adjacent strips; the paper (Dorozhinsky, Fig. 2) numbers them row by row,
N = n(k − 1) + l (n = a − 1 sub-blocks in a row, row k, place l), keeps four memory cells per
sub-block (top, right, bottom, left: 4N − 3 … 4N) and sweeps them in a snake (row 1 left →
right, row 2 right → left, …).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from stereoplotter.triangulation.polygon import PolygonNetwork

__all__ = [
    "cell_counts",
    "grid_network",
    "grid_sides",
    "neighbour_cells",
    "subblock_cells",
    "subblock_position",
]


def _cid(strip: int, photo: int) -> str:
    return f"{strip + 1}-{photo + 1}"


def cell_counts(a: int, b: int) -> tuple[int, int, int, int]:
    """(p, q, 2p + q, (a − 1)(b − 1)): shared sides, boundary sides, side cells, sub-blocks.

    p = (a − 1)(b − 2) + (a − 2)(b − 1), q = 2(a + b − 2) as printed; 2p + q = 4(a − 1)(b − 1).
    """
    p = (a - 1) * (b - 2) + (a - 2) * (b - 1)
    q = 2 * (a + b - 2)
    return p, q, 2 * p + q, (a - 1) * (b - 1)


def subblock_position(number: int, n: int) -> tuple[int, int]:
    """(row k, place l) of sub-block N: k = ⌊(N − 1)/n⌋ + 1, l = N − n(k − 1).

    ERRATA: the paper takes k as the integer part of N/n (its example: N = 35, n = 10 → k = 3),
    which is one row short except for the last sub-block of a row; N = n(k − 1) + l with
    1 ≤ l ≤ n needs k = ⌈N/n⌉ (35 → row 4, place 5; the paper's k = 3 gives l = 15 > n).
    """
    k = (number - 1) // n + 1
    return k, number - n * (k - 1)


def subblock_cells(number: int) -> tuple[int, int, int, int]:
    """Memory cells (top, right, bottom, left) of sub-block N: 4N − 3, 4N − 2, 4N − 1, 4N.

    ERRATA: printed as 4(kn + l) − 3 …; with N = n(k − 1) + l it must be 4[n(k − 1) + l] − 3.
    """
    return 4 * number - 3, 4 * number - 2, 4 * number - 1, 4 * number


def neighbour_cells(number: int, n: int, m: int) -> tuple[int | None, ...]:
    """For the top, right, bottom, left sides of sub-block N (n per row, m rows): the cell that
    holds the same side in the neighbouring sub-block (None on the block's boundary).

    Above: 4[n(k − 2) + l] − 1; right: 4[n(k − 1) + l + 1]; below: 4[nk + l] − 3; left:
    4[n(k − 1) + l − 1] − 2 (the paper's formulas).
    """
    k, place = subblock_position(number, n)
    return (
        4 * (n * (k - 2) + place) - 1 if k > 1 else None,
        4 * (n * (k - 1) + place + 1) if place < n else None,
        4 * (n * k + place) - 3 if k < m else None,
        4 * (n * (k - 1) + place - 1) - 2 if place > 1 else None,
    )


def grid_sides(a: int, b: int) -> tuple[tuple[str, str], ...]:
    """Along-strip sides (strip by strip), then across-strip sides (strip pair by pair)."""
    along = [(_cid(k, j), _cid(k, j + 1)) for k in range(b) for j in range(a - 1)]
    across = [(_cid(k, j), _cid(k + 1, j)) for k in range(b - 1) for j in range(a)]
    return tuple(along + across)


def _snake(a: int, b: int) -> tuple[tuple[str, ...], ...]:
    out = []
    for k in range(b - 1):
        places = range(a - 1) if k % 2 == 0 else range(a - 2, -1, -1)
        for j in places:  # clockwise with strips drawn top to bottom
            out.append((_cid(k, j), _cid(k, j + 1), _cid(k + 1, j + 1), _cid(k + 1, j)))
    return tuple(out)


def grid_network(
    a: int,
    b: int,
    values: np.ndarray,
    weights: np.ndarray | None = None,
    fixed: Mapping[str, np.ndarray] | None = None,
) -> PolygonNetwork:
    """A regular block's network (sides as :func:`grid_sides`, sub-blocks in the snake)."""
    if a < 2 or b < 1:
        raise ValueError(f"block: expected ≥ 2 photos and ≥ 1 strip, found {a} × {b}")
    centres = tuple(_cid(k, j) for k in range(b) for j in range(a))
    return PolygonNetwork(
        centres=centres,
        sides=grid_sides(a, b),
        values=values,
        weights=weights,
        fixed=dict(fixed or {}),
        polygons=_snake(a, b),
    )
