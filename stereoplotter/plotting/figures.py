"""Figures of a scenario and its setup: the plan layout, the setup sheet, the residual y-parallax of
a run (matplotlib, non-interactive Agg back-end).

Every function returns the Figure, so tests can inspect the artists; the plots of one axes take an
optional ``ax`` to draw into, the setup sheet an optional ``figure``.
"""

from __future__ import annotations

from typing import Any

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np

from stereoplotter.scenario.model import Scenario
from stereoplotter.scenario.synthetic import footprint_m

__all__ = ["plot_residual_y_parallax", "plot_scenario_layout", "plot_setup_sheet"]


def plot_scenario_layout(
    scenario: Scenario, result: dict[str, Any] | None = None, ax: Any = None
) -> Any:
    """Plan view of a scenario: photo footprints on the mean point height, projection centres,
    control (triangles) and check (circles) points, the map sheet frame (from the fit (6.8)) and,
    with ``result`` from :func:`stereoplotter.scenario.foundation.run_foundation`, the plan errors
    of the
    intersected points as arrows exaggerated ×1000.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if ax is None:
        fig, ax = plt.subplots(figsize=(8.0, 8.0), layout="constrained")
    else:
        fig = ax.figure
    pts = np.array([p.local_m for p in scenario.points])
    z_mean = float(pts[:, 2].mean())
    for photo, colour in zip(scenario.photos, ("tab:blue", "tab:red"), strict=False):
        fp = footprint_m(scenario, photo, z_mean)
        ring = np.vstack([fp, fp[:1]])
        ax.plot(ring[:, 0], ring[:, 1], color=colour, lw=1.2, label=f"photo {photo.name}")
        ax.plot(*photo.exterior.projection_centre_m[:2], marker="+", color=colour, ms=12)
    for role, marker in (("control", "^"), ("check", "o")):
        sel = np.array([p.role == role for p in scenario.points])
        if sel.any():
            ax.scatter(
                pts[sel, 0],
                pts[sel, 1],
                marker=marker,
                s=40,
                zorder=3,
                label=f"{role} points",
                edgecolor="k",
                facecolor="none" if role == "check" else "gold",
            )
    for p in scenario.points:
        ax.annotate(p.id, p.local_m[:2], textcoords="offset points", xytext=(4, 4), fontsize=8)
    if result is not None:
        sim = result.get("similarity") or {}
        corners = sim.get("sheet_corners_photogrammetric_m")
        if corners:
            ring = np.vstack([corners, corners[:1]])
            ax.plot(ring[:, 0], ring[:, 1], "k--", lw=1.0, label="map sheet (6.8)")
        inter = result.get("intersection")
        if inter:
            by_id = {p.id: p for p in scenario.points}
            for row in inter["points"]:
                x, y = by_id[row["id"]].local_m[:2]
                dx, dy = np.array(row["error_m"][:2]) * 1000.0
                ax.annotate(
                    "", (x + dx, y + dy), (x, y), arrowprops={"arrowstyle": "->", "color": "purple"}
                )
            ax.plot([], [], color="purple", label="plan error ×1000")
    ax.set_aspect("equal")
    ax.set_xlabel("X [m]")
    ax.set_ylabel("Y [m]")
    ax.set_title(f"{scenario.name}: layout in the photogrammetric system")
    ax.grid(True, lw=0.3)
    ax.legend(loc="upper right", fontsize=8)
    return fig


def plot_setup_sheet(sheet: Any, figure: Any = None) -> Any:
    """The setup sheet as a figure: Table 24, the map-sheet frame with its corners and the control
    points in instrument coordinates (from the left plumb), and the fiducial diagram of both
    photos (measured marks and their transformed targets, displacements ×5).

    Parameters
    ----------
    sheet : stereoplotter.setup.sheet.SetupSheet

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig = figure or plt.figure(figsize=(11.69, 8.27), layout="constrained")  # A4 landscape
    grid = fig.add_gridspec(2, 3, height_ratios=[1.0, 1.0], width_ratios=[1.1, 1.0, 1.0])
    ax_table = fig.add_subplot(grid[:, 0])
    ax_sheet = fig.add_subplot(grid[0, 1:])
    ax_left = fig.add_subplot(grid[1, 1])
    ax_right = fig.add_subplot(grid[1, 2])
    mark = " *" if any(sheet.assumed.values()) else ""

    rows = _sheet_table_rows(sheet, mark)
    _draw_sheet_table(ax_table, sheet, rows, mark)
    _draw_instrument_plan(ax_sheet, sheet)
    for ax, photo in ((ax_left, sheet.photos[0]), (ax_right, sheet.photos[1])):
        _draw_fiducials(ax, photo)
    return fig


def _r6(value: float) -> float:
    """The 6-decimal rounding of sheet.yaml, then the format."""
    return round(float(value), 6) + 0.0


def _sheet_table_rows(sheet: Any, mark: str) -> list[tuple[str, str]]:
    """Table 24's rows (quantity, value); ``mark`` flags a value on assumed parameters."""
    bx, by, bz = (_r6(v) for v in sheet.base_mm)
    rows = [
        ("M_г", f"1:{sheet.horizontal_scale_denominator}{mark}"),
        ("M_в", f"1:{sheet.vertical_scale_denominator}{mark}"),
        ("f_пр, mm", f"{_r6(sheet.f_instrument_mm):.3f}{mark}"),
        ("k", f"{_r6(sheet.transformation_coefficient):.5f}"),
        ("b_x, mm", f"{bx:.3f}{mark}"),
        ("b_y, mm", f"{by:.3f}{mark}"),
        ("b_z′, mm", f"{bz:.3f}{mark}"),
        ("n_л", f"{_r6(sheet.n_left):.5f}{mark}"),
        ("n_п", f"{_r6(sheet.n_right):.5f}{mark}"),
    ]
    for photo in sheet.photos:
        side = "л" if photo.name == "left" else "п"
        rows += [
            (f"({k[0]}⁰{k[1:]})_{side}, mm", f"{_r6(v):.3f}")
            for k, v in photo.transformed_book_mm.items()
        ]
    left, right = sheet.photos
    rows += [
        ("L_л, mm", f"{_r6(left.mark_span_mm):.3f}{mark}"),
        ("L_п, mm", f"{_r6(right.mark_span_mm):.3f}{mark}"),
    ]
    for photo in sheet.photos:
        side = "л" if photo.name == "left" else "п"
        dx, dy = (_r6(v) for v in photo.decentration_mm)
        rows.append((f"d_x, d_y {side}, mm", f"{dx:.3f}, {dy:.3f}"))
    rows += [
        (f"Z_{h['id']}, mm", f"{_r6(h['model_height_mm']):.3f}{mark}")
        for h in sheet.control_heights
    ]
    rows += [
        (
            f"x′{c['corner']}, y′{c['corner']}, mm",
            f"{_r6(c['x_mm']):.2f}, {_r6(c['y_mm']):.2f}{mark}",
        )
        for c in sheet.corners
    ]
    return rows


def _draw_sheet_table(ax_table: Any, sheet: Any, rows: list[tuple[str, str]], mark: str) -> None:
    ax_table.axis("off")
    table = ax_table.table(
        cellText=[list(r) for r in rows],
        colLabels=["quantity", "value"],
        loc="upper center",
        cellLoc="left",
        colLoc="left",
    )
    table.auto_set_font_size(False)
    table.set_fontsize(7.5)
    table.scale(1.0, 1.15)
    ax_table.set_title(
        f"Table 24 — {sheet.scenario}, {sheet.instrument.upper()}"
        + ("\n* rests on assumed instrument parameters" if mark else ""),
        fontsize=9,
    )


def _draw_instrument_plan(ax_sheet: Any, sheet: Any) -> None:
    """The map-sheet frame and the control in instrument coordinates from the left plumb."""
    # map-sheet frame and control in instrument coordinates
    if sheet.corners:
        xy = np.array([[c["x_mm"], c["y_mm"]] for c in sheet.corners])
        ring = np.vstack([xy, xy[:1]])
        ax_sheet.plot(ring[:, 0], ring[:, 1], "k-", lw=1.2, label="map sheet frame (6.7)")
        for c, (x, y) in zip(sheet.corners, xy, strict=True):
            ax_sheet.annotate(
                f"{c['corner']} ({c['position']})",
                (x, y),
                fontsize=8,
                textcoords="offset points",
                xytext=(4, 4),
            )
    for role, marker in (("control", "^"), ("check", "o")):
        pts = [(p["x_mm"], p["y_mm"]) for p in sheet.points_model_mm if p["role"] == role]
        if pts:
            pts = np.array(pts)
            ax_sheet.scatter(
                pts[:, 0],
                pts[:, 1],
                marker=marker,
                s=30,
                edgecolor="k",
                facecolor="gold" if role == "control" else "none",
                label=f"{role} points",
            )
    ax_sheet.plot([0, sheet.base_mm[0]], [0, sheet.base_mm[1]], "r-", lw=2, label="base b_x, b_y")
    ax_sheet.plot(0, 0, "r+", ms=12)
    ax_sheet.set_aspect("equal")
    ax_sheet.set_xlabel("X − MO_X [mm]")
    ax_sheet.set_ylabel("Y − MO_Y [mm]")
    ax_sheet.grid(True, lw=0.3)
    ax_sheet.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.02, 0.5))
    ax_sheet.set_title("Instrument coordinates from the left plumb (S_л)", fontsize=9)


def _draw_fiducials(ax: Any, photo: Any) -> None:
    """A photo's measured marks and the arrows to their (6.1)/(6.2) targets (×5)."""
    marks = np.array([photo.marks_measured_mm[k] for k in ("1", "2", "3", "4")])
    ax.scatter(marks[:, 0], marks[:, 1], marker="+", s=80, color="k", label="marks (measured)")
    for key, value in photo.transformed_book_mm.items():
        m = key[1:]
        x, y = photo.marks_measured_mm[m]
        tx, ty = (value, y) if key[0] == "x" else (x, value)
        ax.annotate(
            "",
            (x + 5 * (tx - x), y + 5 * (ty - y)),
            (x, y),
            arrowprops={"arrowstyle": "->", "color": "tab:blue"},
        )
        ax.annotate(
            f"{m}: {key[0]}⁰ = {value:.3f}",
            (x, y),
            fontsize=7,
            textcoords="offset points",
            xytext=(5, -10),
        )
    ax.plot([], [], color="tab:blue", label="to the (6.1)/(6.2) target ×5")
    ax.axhline(0, color="0.7", lw=0.5)
    ax.axvline(0, color="0.7", lw=0.5)
    ax.set_xlim(-140, 140)
    ax.set_ylim(-140, 140)
    ax.set_aspect("equal")
    ax.set_title(
        f"{photo.name} photo: α = {np.degrees(photo.alpha):.4f}°, "
        f"ω = {np.degrees(photo.omega):.4f}°",
        fontsize=9,
    )
    ax.set_xlabel("x [mm]")
    ax.legend(fontsize=6, loc="upper right")


def plot_residual_y_parallax(result: Any, ax: Any = None) -> Any:
    """The true residual y-parallax q of a built model over the working-area grid (trial 0 of a
    vectorised run) and the six standard points, from a ``SimulationResult``.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if ax is None:
        fig, ax = plt.subplots(figsize=(6, 5))
    else:
        fig = ax.figure
    grid = result.scene.grid_m
    q = np.asarray(result.q_grid_mm)
    q = q[0] if q.ndim > 1 else q
    sc = ax.scatter(grid[:, 0], grid[:, 1], c=q * 1e3, cmap="RdBu_r", s=80)
    std = result.scene.standard_points_m
    ax.plot(std[:, 0], std[:, 1], "k+", ms=10)
    for i, p in enumerate(std):
        ax.annotate(str(i + 1), p[:2], textcoords="offset points", xytext=(4, 4))
    fig.colorbar(sc, ax=ax, label="residual y-parallax q [µm, photo]")
    ax.set_xlabel("X [m]")
    ax.set_ylabel("Y [m]")
    ax.set_title(
        f"{result.method} method, {result.sheet.instrument}, seed {result.seed} (trial 0)"
    )
    ax.set_aspect("equal")
    return fig
