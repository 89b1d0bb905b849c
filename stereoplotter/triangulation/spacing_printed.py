"""Burshtynskaya's printed Tables 1 and 2 and recommended link lengths, transcribed (declarative).

Values as printed: residual variances σ_Δ² for σ_ε² = 0.01, by the paper's point numbers 1 … N
(paper point p = base index p − 1 of :mod:`~stereoplotter.triangulation.control_spacing`).
The copy of the paper we worked from lost one cell in each row of 12 and 14 points and two in
each row of 16 points (the rows are one or two entries short; the entries that remain agree with
the computation only when the gap is put where ``None`` stands). ``None`` cells are not compared.
The three rows of 8 points (1-4-8, 1-5-8, 1-6-8) carry a ninth value in the paper's text, a
trailing 0 after point 8's 0, which stands for no point of the strip; it is left out here (the
row has 8 points). Table 2, 1-8-15-22, point 4 is printed ``0,010``: typed as printed, read as
0.10 (:data:`OCR_READINGS`).
"""

from __future__ import annotations

__all__ = ["OCR_READINGS", "RECOMMENDED_LINKS", "TABLE_1", "TABLE_1_MEAN_SQUARE", "TABLE_2"]

_ = None

# fmt: off

#: Table 1 (degree 2): control points (paper numbers) → σ_Δ² at points 1 … N.
TABLE_1: dict[tuple[int, ...], tuple[float | None, ...]] = {
    (1, 4, 8): (0, 0.01, 0.01, 0, 0.02, 0.04, 0.03, 0),
    (1, 5, 8): (0, 0.01, 0.02, 0.02, 0, 0.02, 0.03, 0),
    (1, 6, 8): (0, 0.01, 0.03, 0.03, 0.02, 0, 0.02, 0),
    (1, 5, 10): (0, 0.01, 0.02, 0.01, 0, 0.02, 0.06, 0.10, 0.08, 0),
    (1, 6, 10): (0, 0.01, 0.03, 0.04, 0.03, 0, 0.04, 0.07, 0.07, 0),
    (1, 7, 10): (0, 0.01, 0.04, 0.06, 0.06, 0.04, 0, 0.04, 0.05, 0),
    (1, 6, 12): (0, 0.01, 0.03, 0.04, 0.03, 0, 0.06, 0.14, 0.18, 0.20, _, 0),
    (1, 7, 12): (0, 0.01, 0.04, 0.06, 0.07, 0.05, 0, 0.06, 0.12, 0.15, _, 0),
    (1, 8, 12): (0, 0.02, 0.05, 0.09, 0.10, 0.09, 0.05, 0, 0.06, 0.10, _, 0),
    (1, 9, 12): (0, 0.02, 0.06, 0.11, 0.14, 0.14, 0.11, 0.06, 0, 0.05, _, 0),
    (1, 7, 14): (0, 0.01, 0.06, 0.07, 0.07, 0.05, 0, 0.07, 0.16, 0.25, 0.31, _, 0.22, 0),
    (1, 8, 14): (0, 0.02, 0.05, 0.09, 0.11, 0.10, 0.06, 0, 0.08, 0.17, 0.23, _, 0.19, 0),
    (1, 9, 14): (0, 0.02, 0.07, 0.11, 0.15, 0.15, 0.13, 0.08, 0, 0.08, 0.15, _, 0.15, 0),
    (1, 10, 14): (0, 0.02, 0.08, 0.14, 0.19, 0.21, 0.20, 0.16, 0.09, 0, 0.07, _, 0.11, 0),
    (1, 8, 16): (
        0, 0.02, 0.06, 0.09, 0.12, 0.11, 0.07, 0, 0.10,
        0.22, 0.33, 0.43, _, 0.45, 0.31, _,
    ),
    (1, 9, 16): (
        0, 0.02, 0.07, 0.12, 0.16, 0.17, 0.14, 0.09, 0,
        0.11, 0.22, 0.32, _, 0.38, 0.26, _,
    ),
    (1, 10, 16): (
        0, 0.02, 0.08, 0.14, 0.19, 0.22, 0.22, 0.17, 0.10,
        0, 0.11, 0.22, _, 0.30, 0.22, _,
    ),
    (1, 11, 16): (
        0, 0.03, 0.09, 0.17, 0.23, 0.28, 0.29, 0.26, 0.20,
        0.11, 0, 0.11, _, 0.23, 0.18, _,
    ),
}

#: Table 1, last column: m² of each row.
TABLE_1_MEAN_SQUARE: dict[tuple[int, ...], float] = {
    (1, 4, 8): 0.0006, (1, 5, 8): 0.0004, (1, 6, 8): 0.0005,
    (1, 5, 10): 0.0030, (1, 6, 10): 0.0021, (1, 7, 10): 0.0021,
    (1, 6, 12): 0.0135, (1, 7, 12): 0.0075, (1, 8, 12): 0.0061, (1, 9, 12): 0.0086,
    (1, 7, 14): 0.0312, (1, 8, 14): 0.0203, (1, 9, 14): 0.0157, (1, 10, 14): 0.0188,
    (1, 8, 16): 0.0711, (1, 9, 16): 0.0484, (1, 10, 16): 0.0370, (1, 11, 16): 0.0389,
}

#: Table 2 (degree 3): control points (paper numbers) → σ_Δ² at points 1 … N.
TABLE_2: dict[tuple[int, ...], tuple[float | None, ...]] = {
    (1, 4, 7, 10): (0, 0.01, 0.01, 0.000, 0.01, 0.01, 0.00, 0.01, 0.00, 0.00),
    (1, 5, 9, 13): (0, 0.01, 0.03, 0.02, 0.00, 0.02, 0.03, 0.03, 0.00, 0.02, 0.03, 0.01, 0.00),
    (1, 6, 11, 16): (
        0, 0.02, 0.04, 0.05, 0.03, 0.00, 0.03, 0.05, 0.06, 0.03, 0.00, 0.02, 0.04, 0.03, 0.01, 0.00,
    ),
    (1, 7, 13, 19): (
        0, 0.02, 0.05, 0.07, 0.07, 0.04, 0.00, 0.04, 0.07, 0.08, 0.07, 0.04, 0.00, 0.03, 0.06,
        0.06, 0.04, 0.01, 0.00,
    ),
    (1, 8, 15, 22): (
        0, 0.02, 0.10, 0.010, 0.11, 0.09, 0.05, 0.00, 0.05, 0.10, 0.12, 0.12, 0.10, 0.06, 0.00,
        0.05, 0.08, 0.09, 0.09, 0.05, 0.01, 0.00,
    ),
}

#: Printed cells whose digits are garbled, (control, point) → the value read: Table 2's "0,010"
#: among two-decimal entries is 0.10 with a misplaced zero (its neighbours 0.10, 0.11).
OCR_READINGS: dict[tuple[tuple[int, ...], int], float] = {((1, 8, 15, 22), 4): 0.10}

#: Recommended link lengths (bases) for degree 2: bases in the strip → (first, second).
RECOMMENDED_LINKS: dict[int, tuple[int, int]] = {
    7: (4, 3), 9: (5, 4), 11: (7, 4), 13: (8, 5), 15: (9, 6),
}
# fmt: on
