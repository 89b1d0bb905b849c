"""Dorozhinsky's worked example (Fig. 1 and the table of results), transcribed (declarative).

A block of 2 × 2 sub-blocks (I II / III IV, the paper's row-by-row numbering of Fig. 2) on
3 × 3 projection centres, ids ``"r{row}c{column}"`` (row 0 at the top). Twelve sides, numbered as
the table (its closure of the true values fixes the layout): 1–6 along the rows (row 0: 1, 2;
row 1: 3, 4; row 2: 5, 6), directed left → right; 7–12 across (rows 0–1: 7, 8, 9; rows 1–2:
10, 11, 12), directed top → bottom. Values are Δα in minutes of arc.

The table's "misclosures in the sides" δ̄α are the differences between the two sub-blocks'
determinations of a shared side, in the same directions as the true values; a network whose
measured side values are true + δ has exactly the paper's polygon misclosures (I +8, II −10,
III −5, IV +7; the text prints −10 and +7).

The corrections are printed, side by side, each in the clockwise sense of one polygon holding the
side (the paper reads them off its polygon cells): :data:`CORRECTION_SENSE` gives that polygon.
"""

from __future__ import annotations

import numpy as np

from stereoplotter.triangulation.polygon import PolygonNetwork

__all__ = [
    "CORRECTION_SENSE",
    "PRINTED_LS_CORRECTIONS",
    "PRINTED_M",
    "PRINTED_POLYGON_CORRECTIONS",
    "PRINTED_SIDE_MISCLOSURES",
    "PRINTED_TRUE_VALUES",
    "PRINTED_VV",
    "SIDES",
    "SUBBLOCKS",
    "example_network",
    "printed_sense",
]

#: Sides 1 … 12 (from, to).
SIDES: tuple[tuple[str, str], ...] = (
    ("r0c0", "r0c1"), ("r0c1", "r0c2"), ("r1c0", "r1c1"), ("r1c1", "r1c2"),
    ("r2c0", "r2c1"), ("r2c1", "r2c2"),
    ("r0c0", "r1c0"), ("r0c1", "r1c1"), ("r0c2", "r1c2"),
    ("r1c0", "r2c0"), ("r1c1", "r2c1"), ("r1c2", "r2c2"),
)  # fmt: skip

#: Sub-blocks I … IV as clockwise cycles (top-left corner first).
SUBBLOCKS: dict[str, tuple[str, ...]] = {
    "I": ("r0c0", "r0c1", "r1c1", "r1c0"),
    "II": ("r0c1", "r0c2", "r1c2", "r1c1"),
    "III": ("r1c0", "r1c1", "r2c1", "r2c0"),
    "IV": ("r1c1", "r1c2", "r2c2", "r2c1"),
}

#: The paper's sweep: from the largest misclosure (II) along the snake II → IV → III, then I.
SNAKE = ("I", "II", "IV", "III")

PRINTED_TRUE_VALUES = (50, -120, 90, -20, 60, -100, -70, -30, 70, 80, 50, -30)
PRINTED_SIDE_MISCLOSURES = (0, 0, 9, -7, 0, 0, 0, 17, 0, 0, -14, 0)
PRINTED_POLYGON_CORRECTIONS = (-1.5, 1.9, -2.0, 3.0, 0.5, -1.0, -1.3, -3.2, 1.9, 0.7, -1.8, -1.1)
PRINTED_LS_CORRECTIONS = (
    -1.38, 1.88, -2.00, 3.00, 0.62, -1.12, -1.38, -3.25, 1.88, 0.62, -1.75, -1.12,
)  # fmt: skip
#: [vv] and m = ±√([vv]/n) printed under the table (from the rigorous corrections).
PRINTED_VV = 40.78
PRINTED_M = 1.8

#: For side 1 … 12: the sub-block in whose clockwise sense the table prints its correction.
CORRECTION_SENSE = ("I", "II", "I", "II", "III", "IV", "I", "I", "II", "III", "IV", "IV")


def example_network() -> PolygonNetwork:
    """Fig. 1 as a network: Δα = true + δ̄α in column α (minutes), other elements 0."""
    values = np.zeros((12, 6))
    values[:, 0] = np.add(PRINTED_TRUE_VALUES, PRINTED_SIDE_MISCLOSURES)
    centres = tuple(f"r{r}c{c}" for r in range(3) for c in range(3))
    return PolygonNetwork(
        centres=centres,
        sides=SIDES,
        values=values,
        polygons=tuple(SUBBLOCKS[k] for k in SNAKE),
    )


def printed_sense(corrections: np.ndarray) -> np.ndarray:
    """Side corrections (in the side directions) turned into the table's senses."""
    out = np.empty(12)
    for s, name in enumerate(CORRECTION_SENSE):
        cycle = SUBBLOCKS[name]
        pairs = list(zip(cycle, cycle[1:] + cycle[:1], strict=True))
        out[s] = corrections[s] if SIDES[s] in pairs else -corrections[s]
    return out
