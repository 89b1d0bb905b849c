"""The tilt above which the book's (6.1)/(6.2) and (6.5) leave the stage tolerances (issue 27).

Run from the repository root::

    python3 docs/make_book_limits.py

Prints, for the camera of ``jobs/strip8`` (f′ = 70 mm, marks 1–4 at ±85 mm) on the SC-1 (n_л =
D_max/f_пр = 185/109.371), the mark targets n·x⁰₂, n·y⁰₃, n·y⁰₄ and the span L = n·(y⁰₃ − y⁰₄) by
the book's single-axis (6.1)/(6.2), (6.5) and by the rigorous (3.17) (κ = 0), for equal tilts
α = ω = t and for opposite ones α = −ω = t, and the smallest t at which the difference on the
counters exceeds the mark-4 tolerance 0.02·n_л (targets) or the span tolerance 0.03/n_л
(``docs/setup-data.md``, "The method's limits").
"""

from __future__ import annotations

import numpy as np

from stereoplotter.geometry.rotation import rotation_matrix
from stereoplotter.geometry.transformed import (
    transformed_coordinates,
    transformed_x_single_tilt,
    transformed_y_single_tilt,
)
from stereoplotter.setup.equations import mark_span

F_MM, MARK_MM, D_MAX_MM, F_INSTRUMENT_MM = 70.0, 85.0, 185.0, 109.371


def deviations(t_deg: np.ndarray, sign: float) -> dict[str, np.ndarray]:
    """Book − rigorous on the counters [mm] for α = t, ω = sign·t."""
    n = D_MAX_MM / F_INSTRUMENT_MM
    alpha, omega = np.radians(t_deg), sign * np.radians(t_deg)
    marks = np.array([[MARK_MM, 0.0], [0.0, MARK_MM], [0.0, -MARK_MM]])
    rot = rotation_matrix(alpha, omega, np.zeros_like(alpha))  # (T, 3, 3)
    rig = transformed_coordinates(marks[None], rot[:, None], F_MM)  # (T, 3, 2), (3.17)
    x2 = transformed_x_single_tilt(MARK_MM, alpha, F_MM)  # (6.1)
    y3 = transformed_y_single_tilt(MARK_MM, omega, F_MM)  # (6.2)
    y4 = transformed_y_single_tilt(-MARK_MM, omega, F_MM)
    return {
        "x2": n * (x2 - rig[:, 0, 0]),
        "y3": n * (y3 - rig[:, 1, 1]),
        "y4": n * (y4 - rig[:, 2, 1]),
        "L": mark_span(n, y3, y4) - mark_span(n, rig[:, 1, 1], rig[:, 2, 1]),  # (6.5)
    }


def main() -> None:
    n = D_MAX_MM / F_INSTRUMENT_MM
    tol_mark, tol_span = 0.02 * n, 0.03 / n
    t = np.round(np.arange(0.0, 3.0001, 0.01), 2)
    print(
        f"n_л = {n:.5f}; mark-4 tolerance {tol_mark * 1000:.1f} µm, span {tol_span * 1000:.1f} µm"
    )
    print("| tilts | t ° | x2 µm | y3 µm | y4 µm | L µm |")
    print("|---|---|---|---|---|---|")
    for sign, name in ((1.0, "α = ω = t"), (-1.0, "α = −ω = t")):
        dev = deviations(t, sign)
        for show in (0.5, 1.0, 1.5, 2.0, 3.0):
            i = int(np.argmin(abs(t - show)))
            cells = " | ".join(f"{dev[k][i] * 1000:+.1f}" for k in ("x2", "y3", "y4", "L"))
            print(f"| {name} | {show:.1f} | {cells} |")
        marks = np.max([abs(dev[k]) for k in ("x2", "y3", "y4")], axis=0)
        over_mark = t[marks > tol_mark]
        over_span = t[abs(dev["L"]) > tol_span]
        first = lambda a: f"{a[0]:.2f}°" if a.size else "none up to 3°"  # noqa: E731
        print(f"{name}: targets exceed ±{tol_mark * 1000:.1f} µm from t = {first(over_mark)}; "
              f"L exceeds ±{tol_span * 1000:.1f} µm from t = {first(over_span)}")  # fmt: skip


if __name__ == "__main__":
    main()
