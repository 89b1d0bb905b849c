"""Figures of a study (``stereoplotter study report``): maps over two axes, lines, categories.

Each function takes panels of plain arrays (``report.study`` slices the Dataset) and returns the
Figure. A map panel is (title, x values, y values, Z of shape (len(y), len(x))); NaN cells
(refused, or a row that does not apply) are left blank.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import BoundaryNorm, ListedColormap

__all__ = ["plot_categories", "plot_lines", "plot_maps", "plot_scatter"]

MapPanel = tuple[str, Sequence[float], Sequence[float], np.ndarray]


def _grid(n: int, width: float = 4.2, height: float = 3.4) -> tuple[Any, list[Any]]:
    cols = min(n, 3)
    rows = math.ceil(n / cols)
    fig, axes = plt.subplots(
        rows, cols, figsize=(width * cols, height * rows), layout="constrained", squeeze=False
    )
    flat = list(axes.ravel())
    for ax in flat[n:]:
        ax.set_visible(False)
    return fig, flat[:n]


def _ticks(ax: Any, x: Sequence[float], y: Sequence[float]) -> None:
    ax.set_xticks(range(len(x)), [f"{v:g}" for v in x])
    ax.set_yticks(range(len(y)), [f"{v:g}" for v in y])


def plot_maps(
    panels: list[MapPanel],
    xlabel: str,
    ylabel: str,
    *,
    label: str,
    vmin: float,
    vmax: float,
    cmap: str = "RdBu_r",
    bands: Sequence[float] = (),
    fmt: str = "{:.2f}",
) -> Any:
    """A heat map per panel, cells annotated with their value; ``bands`` (e.g. 0.05, 0.10):
    cells with |Z − 1| within the band are outlined (solid the first band, dashed the next)."""
    fig, axes = _grid(len(panels))
    image = None
    for ax, (title, x, y, z) in zip(axes, panels, strict=True):
        z = np.asarray(z, float)
        image = ax.imshow(z, origin="lower", cmap=cmap, vmin=vmin, vmax=vmax, aspect="auto")
        _ticks(ax, x, y)
        ax.set(xlabel=xlabel, ylabel=ylabel)
        ax.set_title(title, fontsize=8)
        for (j, i), v in np.ndenumerate(z):
            if not np.isfinite(v):
                continue
            ax.text(i, j, fmt.format(v), ha="center", va="center", fontsize=7)
            for band, style in zip(bands, ("-", "--"), strict=False):
                if abs(v - 1.0) <= band:
                    ax.add_patch(
                        plt.Rectangle(
                            (i - 0.5, j - 0.5), 1, 1, fill=False, lw=1.4, ls=style, ec="k"
                        )
                    )
                    break
    if image is not None:
        fig.colorbar(image, ax=axes, label=label, shrink=0.8)
    return fig


def plot_lines(
    panels: list[tuple[str, Sequence[float], dict[str, tuple[np.ndarray, np.ndarray]]]],
    xlabel: str,
    ylabel: str,
    *,
    reference: float | None = None,
    bands: Sequence[float] = (),
) -> Any:
    """Lines with ±2 SE error bars: per panel (title, x, {label: (values, SE)}); a reference
    line and shaded bands ±band around it."""
    fig, axes = _grid(len(panels))
    for ax, (title, x, lines) in zip(axes, panels, strict=True):
        if reference is not None:
            ax.axhline(reference, color="k", lw=0.8)
            for band, alpha in zip(bands, (0.18, 0.09), strict=False):
                ax.axhspan(reference - band, reference + band, color="tab:green", alpha=alpha)
        for name, (v, se) in lines.items():
            ax.errorbar(
                x, v, yerr=2 * np.asarray(se, float), marker="o", ms=3, capsize=2, label=name
            )
        ax.set(xlabel=xlabel, ylabel=ylabel)
        ax.set_title(title, fontsize=8)
        if lines:
            ax.legend(fontsize=7)
    return fig


def plot_categories(
    panels: list[tuple[str, Sequence[float], Sequence[float], np.ndarray]],
    names: Sequence[str],
    xlabel: str,
    ylabel: str,
) -> Any:
    """A categorical map per panel: Z holds an index into ``names`` (−1: none); each cell is
    coloured by its category and labelled with its short name."""
    fig, axes = _grid(len(panels), width=4.8)
    colours = plt.get_cmap("tab20").colors[: max(len(names), 1)]
    cmap = ListedColormap(colours)
    norm = BoundaryNorm(np.arange(-0.5, len(colours) + 0.5), len(colours))
    for ax, (title, x, y, z) in zip(axes, panels, strict=True):
        z = np.asarray(z, float)
        ax.imshow(np.ma.masked_less(z, 0), origin="lower", cmap=cmap, norm=norm, aspect="auto")
        _ticks(ax, x, y)
        ax.set(xlabel=xlabel, ylabel=ylabel)
        ax.set_title(title, fontsize=8)
        for (j, i), v in np.ndenumerate(z):
            if v >= 0:
                short = names[int(v)].removeprefix("operator.").replace("_", " ")
                short = short.replace(".", ": ")
                ax.text(i, j, short, ha="center", va="center", fontsize=6, wrap=True)
    return fig


def plot_scatter(
    panels: list[tuple[str, np.ndarray, np.ndarray, np.ndarray]],
    xlabel: str,
    ylabel: str,
    *,
    label: str,
    vmin: float,
    vmax: float,
    cmap: str = "RdBu_r",
) -> Any:
    """A sampled study: the points of two ranged axes coloured by a value."""
    fig, axes = _grid(len(panels))
    art = None
    for ax, (title, x, y, c) in zip(axes, panels, strict=True):
        art = ax.scatter(x, y, c=c, cmap=cmap, vmin=vmin, vmax=vmax, s=18, edgecolor="k", lw=0.3)
        ax.set(xlabel=xlabel, ylabel=ylabel)
        ax.set_title(title, fontsize=8)
    if art is not None:
        fig.colorbar(art, ax=axes, label=label, shrink=0.8)
    return fig
