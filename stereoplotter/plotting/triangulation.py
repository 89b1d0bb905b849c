"""Figures of a triangulated block (Agg back-end: Figures, and PNG bytes from the ``*_png``
functions; no file I/O).

``residuals.png``: plan residuals (triangulated − catalogue) of control and check points as
arrows, exaggerated by a stated factor, over the photo centres of each strip; height residuals
as the colour of a circle at the point (blue: the triangulation is low, red: high).
``photo_residuals.png``: every photo's measurement residuals as vectors in the photo.
``precision.png``: every point's plan σ ellipse and σ_Z over the block.
"""

from __future__ import annotations

import numpy as np
from matplotlib.collections import EllipseCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from stereoplotter.plotting.encode import figure_bytes
from stereoplotter.triangulation.block import Block, interior_orientation
from stereoplotter.triangulation.solution import (
    BlockSolution,
    CatalogueResiduals,
    photo_residuals,
)

__all__ = [
    "photo_residual_figure",
    "photo_residual_figure_png",
    "precision_figure",
    "precision_figure_png",
    "residual_figure",
    "residual_figure_png",
]


def residual_figure(block: Block, solution: BlockSolution, residuals: CatalogueResiduals) -> Figure:
    """The figure: photo centres by strip, plan residual arrows, height residual colours [m]."""
    seen = np.all(np.isfinite(residuals.residuals_m), axis=1)  # measured on ≥ 2 photos
    xyz = residuals.catalogue_m[seen] / 1000.0
    v = residuals.residuals_m[seen]
    kinds = np.array([block.catalogue[i].kind for i in residuals.index[seen]])
    roles = np.array([block.catalogue[i].role for i in residuals.index[seen]])
    v_plan = np.where((kinds == "height")[:, None], 0.0, v[:, :2])
    v_height = np.where(kinds == "plan", 0.0, v[:, 2])
    span = float(np.ptp(xyz[:, :2], axis=0).max()) or 1.0
    biggest = float(np.max(np.hypot(v_plan[:, 0], v_plan[:, 1]))) or 1.0
    exaggeration = 10 ** np.floor(np.log10(0.06 * span * 1000.0 / biggest))
    fig = Figure(figsize=(11.0, 7.0), layout="constrained")  # no pyplot state to close
    ax = fig.subplots()
    centres = solution.orientations[:, 3:5] / 1000.0
    strip = block.strip_of_photo
    for s in range(len(block.strips)):
        c = centres[strip == s]
        ax.plot(c[:, 0], c[:, 1], "-", color="0.7", lw=0.8, zorder=1)
        ax.plot(c[:, 0], c[:, 1], "+", color="0.4", ms=5, zorder=1)
    limit = float(np.max(np.abs(v_height))) or 1.0
    for role, marker in (("control", "^"), ("check", "o")):
        m = roles == role
        sc = ax.scatter(
            xyz[m, 0],
            xyz[m, 1],
            c=v_height[m],
            cmap="coolwarm",
            vmin=-limit,
            vmax=limit,
            marker=marker,
            s=28,
            edgecolors="k",
            linewidths=0.4,
            label=f"{role} points",
            zorder=2,
        )
    ax.quiver(
        xyz[:, 0],
        xyz[:, 1],
        v_plan[:, 0],
        v_plan[:, 1],
        angles="xy",
        scale_units="xy",
        scale=1000.0 / exaggeration,
        width=0.002,
        zorder=3,
    )
    fig.colorbar(sc, ax=ax, label="height residual [m]")
    ax.set_aspect("equal")
    ax.set_xlabel("X [km] (local system of §10, ≈ east)")
    ax.set_ylabel("Y [km] (≈ north)")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title(
        f"block {block.name}, {solution.method}: plan residuals × {exaggeration:g} (arrows), "
        "height residuals (colour); + photo centres",
        fontsize=10,
    )
    return fig


def residual_figure_png(
    block: Block, solution: BlockSolution, residuals: CatalogueResiduals
) -> bytes:
    """:func:`residual_figure` as PNG bytes (100 dpi)."""
    return figure_bytes(residual_figure(block, solution, residuals), "png", 100)


def photo_residual_figure(block: Block, solution: BlockSolution) -> Figure:
    """Photo residuals (measured − computed, Eq. (2.53)) of every measurement as vectors in
    their photo: each photo a square frame (its format) placed at its strip (row) and number in
    the strip (column), the vectors exaggerated by a stated factor; a photo's RMS in its corner
    colour (a photo far above the others stands out)."""
    xy = interior_orientation(block)
    v = photo_residuals(block, solution)
    ok = np.all(np.isfinite(v), axis=1)
    fmt = float(block.camera.format_mm)
    strip = block.strip_of_photo
    column = np.concatenate([np.arange(len(s)) for s in block.strips])
    gap = 1.15 * fmt
    origin = np.column_stack([column * gap, -strip * gap])  # photo centre on the sheet [mm]
    big = float(np.max(np.abs(v[ok]))) if ok.any() else 1.0
    exaggeration = 10 ** np.floor(np.log10(0.08 * fmt / max(big, 1e-9)))
    ss = np.zeros(len(block.photos))
    n = np.bincount(block.obs_photo[ok], minlength=len(block.photos))
    np.add.at(ss, block.obs_photo[ok], np.sum(v[ok] ** 2, axis=1))
    with np.errstate(invalid="ignore", divide="ignore"):
        rms = np.sqrt(ss / (2 * n)) * 1000.0  # µm per coordinate
    cols, rows = int(column.max()) + 1, len(block.strips)
    fig = Figure(figsize=(min(16.0, 2.0 + 1.1 * cols), min(12.0, 1.5 + 1.1 * rows)),
                 layout="constrained")  # fmt: skip
    ax = fig.subplots()
    half = fmt / 2.0
    for j in range(len(block.photos)):
        x0, y0 = origin[j]
        ax.plot(
            [x0 - half, x0 + half, x0 + half, x0 - half, x0 - half],
            [y0 - half, y0 - half, y0 + half, y0 + half, y0 - half],
            color="0.6",
            lw=0.6,
        )
    sc = ax.scatter(origin[:, 0] + 0.8 * half, origin[:, 1] + 0.8 * half, c=rms, cmap="viridis",
                    s=18, marker="s")  # fmt: skip
    at = origin[block.obs_photo[ok]] + xy[ok]
    ax.quiver(at[:, 0], at[:, 1], v[ok, 0], v[ok, 1], angles="xy", scale_units="xy",
              scale=1.0 / exaggeration, width=0.0015, color="C3")  # fmt: skip
    if len(block.photos) <= 60:
        for j, photo in enumerate(block.photos):
            ax.text(origin[j, 0] - 0.9 * half, origin[j, 1] + 0.75 * half, photo, fontsize=6)
    fig.colorbar(sc, ax=ax, label="photo's RMS residual [µm]")
    ax.set_aspect("equal")
    ax.set_axis_off()
    ax.set_title(
        f"block {block.name}, {solution.method}: photo residuals × {exaggeration:g} in each "
        "photo (strips in rows)",
        fontsize=10,
    )
    return fig


def precision_figure(block: Block, solution: BlockSolution) -> Figure:
    """Block overview: photo centres by strip and every determined point with its plan σ ellipse
    (1σ, from the point's X, Y covariance, exaggerated by a stated factor), control, check and
    tie points in their own colours; the σ_Z as the marker colour."""
    fig = Figure(figsize=(11.0, 7.0), layout="constrained")
    ax = fig.subplots()
    centres = solution.orientations[:, 3:5] / 1000.0
    strip = block.strip_of_photo
    for s in range(len(block.strips)):
        c = centres[strip == s]
        ax.plot(c[:, 0], c[:, 1], "-", color="0.7", lw=0.8, zorder=1)
        ax.plot(c[:, 0], c[:, 1], "+", color="0.4", ms=5, zorder=1)
    cov = solution.point_covariances
    pts = solution.points_m
    ok = np.all(np.isfinite(pts), axis=1)
    if cov is not None:
        ok &= np.all(np.isfinite(cov.reshape(len(pts), -1)), axis=1)
    role_of = {c.id: c.role for c in block.catalogue}
    roles = np.array([role_of.get(pid, "tie") for pid in block.point_ids])
    if cov is None or not ok.any():
        ax.text(0.5, 0.5, "the method gives no point σ", transform=ax.transAxes, ha="center")
        return fig
    xy = pts[ok, :2] / 1000.0
    c2 = cov[ok][:, :2, :2]
    vals, vecs = np.linalg.eigh(c2)
    axes_m = np.sqrt(np.maximum(vals, 0.0))  # semi-axes [m], ascending
    span = float(np.ptp(xy, axis=0).max()) or 1.0
    exaggeration = 10 ** np.floor(np.log10(0.05 * span * 1000.0 / max(axes_m.max(), 1e-9)))
    angle = np.degrees(np.arctan2(vecs[:, 1, 1], vecs[:, 0, 1]))
    widths = 2 * axes_m[:, 1] * exaggeration / 1000.0
    heights = 2 * axes_m[:, 0] * exaggeration / 1000.0
    sz = np.sqrt(np.maximum(cov[ok][:, 2, 2], 0.0))
    handles = []
    for role, colour in (("tie", "0.5"), ("check", "C0"), ("control", "C3")):
        m = roles[ok] == role
        if not m.any():
            continue
        handles.append(
            Line2D([], [], marker="o", mfc="none", mec=colour, ls="none", label=f"{role} points")
        )
        ax.add_collection(
            EllipseCollection(
                widths[m], heights[m], angle[m], units="xy", offsets=xy[m],
                offset_transform=ax.transData, facecolors="none", edgecolors=colour,
                linewidths=0.6,
            )
        )  # fmt: skip
    sc = ax.scatter(xy[:, 0], xy[:, 1], c=sz, cmap="magma_r", s=6, zorder=3)
    fig.colorbar(sc, ax=ax, label="σ_Z [m]")
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.set_xlabel("X [km] (local system of §10, ≈ east)")
    ax.set_ylabel("Y [km] (≈ north)")
    ax.legend(handles=handles, loc="upper right", fontsize=8)
    ax.set_title(
        f"block {block.name}, {solution.method}: plan σ ellipses (1σ) × {exaggeration:g}, σ_Z "
        "(colour); + photo centres",
        fontsize=10,
    )
    return fig


def photo_residual_figure_png(block: Block, solution: BlockSolution) -> bytes:
    """:func:`photo_residual_figure` as PNG bytes (100 dpi)."""
    return figure_bytes(photo_residual_figure(block, solution), "png", 100)


def precision_figure_png(block: Block, solution: BlockSolution) -> bytes:
    """:func:`precision_figure` as PNG bytes (100 dpi)."""
    return figure_bytes(precision_figure(block, solution), "png", 100)
