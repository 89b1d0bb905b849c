"""Figures. The only module that imports matplotlib (non-interactive Agg backend).

Every function takes an optional ``ax`` and returns the Figure, so tests can inspect the artists.
"""

from __future__ import annotations

from typing import Any

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np

from stereoplotter.scenario.model import Scenario
from stereoplotter.scenario.synthetic import footprint_m

__all__ = ["plot_scenario_layout"]


def plot_scenario_layout(
    scenario: Scenario, result: dict[str, Any] | None = None, ax: Any = None
) -> Any:
    """Plan view of a scenario: photo footprints on the mean point height, projection centres,
    control (triangles) and check (circles) points, the map sheet frame (from the fit (6.8)) and,
    with ``result`` from :func:`stereoplotter.foundation.run_foundation`, the plan errors of the
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
