"""Residual vectors over a triangulated block (Agg backend; returns PNG bytes, no file I/O).

Plan residuals (triangulated − catalogue) of control and check points as arrows, exaggerated by
a stated factor, over the photo centres of each strip; height residuals as the colour of a
circle at the point (blue: the triangulation is low, red: high).
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from stereoplotter.plotting.encode import figure_bytes
from stereoplotter.triangulation.block import Block
from stereoplotter.triangulation.solution import BlockSolution, CatalogueResiduals

__all__ = ["residual_figure", "residual_figure_png"]


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
