"""Figure of the evaluation of a built model: the x-parallax error map over the working area.

Plotting at the edge (``style.md`` §13): the data come from the pure
:func:`stereoplotter.procedure.evaluation.parallax_map_data`; this module only draws
(non-interactive Agg
backend). The function takes an optional ``ax`` and returns the Figure, so tests can inspect the
artists.
"""

from __future__ import annotations

from typing import Any

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np

from stereoplotter.procedure.evaluation import ModelEvaluation, parallax_map_data

__all__ = ["plot_parallax_error_map"]


def plot_parallax_error_map(
    evaluation: ModelEvaluation, ax: Any = None, *, after_plane: bool = False
) -> Any:
    """Map of the x-parallax error δp of the built model over the working area (cf. Fig. 40 of
    the book, ``accuracy.md``, Plots).

    Filled contours of δp [photo µm] over the working-area grid (plan in the instrument frame,
    base along +X), the six standard points (squares, labelled 1–6), control points (triangles)
    and check points (circles), and a colour bar. For a vectorised evaluation the map shows the
    RMS over trials at each grid point.

    Parameters
    ----------
    evaluation : stereoplotter.procedure.evaluation.ModelEvaluation
    ax : matplotlib.axes.Axes, optional
        Draw into this axes; by default a new figure.
    after_plane : bool
        Map δp after removing the levelling plane fitted at the control points.

    Returns
    -------
    matplotlib.figure.Figure
    """
    data = parallax_map_data(evaluation, after_plane=after_plane)
    if ax is None:
        fig, ax = plt.subplots(figsize=(7.0, 7.0), layout="constrained")
    else:
        fig = ax.figure
    xy = np.asarray(data["grid_m"])
    z = np.asarray(data["x_parallax_error_um"])
    vmax = float(np.max(np.abs(z)))
    vmax = vmax if vmax > 0.0 else 1.0
    levels = np.linspace(-vmax, vmax, 13) if evaluation.trials is None else np.linspace(0, vmax, 7)
    contours = ax.tricontourf(xy[:, 0], xy[:, 1], z, levels=levels, cmap="RdBu_r")
    fig.colorbar(contours, ax=ax, label="δp [µm]")
    st = np.asarray(data["standard_m"])
    ax.scatter(st[:, 0], st[:, 1], marker="s", s=40, facecolor="none", edgecolor="k", zorder=3)
    for pid, (x, y) in zip(data["standard_ids"], st, strict=True):
        ax.annotate(pid, (x, y), textcoords="offset points", xytext=(4, 4), fontsize=8)
    for key, marker, face in (("control", "^", "gold"), ("check", "o", "none")):
        pts = np.asarray(data[f"{key}_m"]).reshape(-1, 2)
        ax.scatter(
            pts[:, 0],
            pts[:, 1],
            marker=marker,
            s=40,
            facecolor=face,
            edgecolor="k",
            zorder=3,
            label=f"{key} points",
        )
    ax.plot([], [], "ks", mfc="none", label="standard points 1–6")
    ax.set_aspect("equal")
    ax.set_xlabel("X along the base [m]")
    ax.set_ylabel("Y [m]")
    ax.set_title(data["title"])
    ax.legend(loc="upper right", fontsize=8)
    return fig
