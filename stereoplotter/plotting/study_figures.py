"""The figures of ``stereoplotter study report``, as PNG bytes.

From the Dataset of a results store (``io.study_store.open_results``): heat maps of the ratio
procedure/formula of each outcome row over the two numeric axes with the most values (cells
within 5 % outlined solid, within 10 % dashed), the same ratio along every other numeric axis,
the pass rates of the book's checks, the model's errors, the setup-data method against the
conventional one, and the dominant error term per cell when the study ran the budget. Numeric
axes not drawn are held at their first value (the panel titles say which). A sampled study is
drawn as scatter plots over its first two numeric axes. The Markdown beside them is
:mod:`stereoplotter.report.study`'s.
"""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np
import xarray as xr

from stereoplotter.plotting.encode import figure_bytes
from stereoplotter.plotting.study import (
    plot_categories,
    plot_lines,
    plot_maps,
    plot_scatter,
)
from stereoplotter.study.design import AXES
from stereoplotter.study.results import as_grid, dominant_term

__all__ = ["BANDS", "study_figures"]

#: Bands of the formula's validity: |procedure/formula − 1| within 5 % and 10 %.
BANDS = (0.05, 0.10)
#: Most panels in one figure.
MAX_PANELS = 24

_MEASURES = {
    "y_parallax_rms_um": "residual y-parallax RMS [µm]",
    "height_rms_permille": "height error RMS [‰ H]",
    "plan_rms_map_mm": "plan error RMS [map mm]",
}


def _axes(grid: xr.Dataset) -> tuple[list[str], list[str]]:
    """(numeric, categorical) study axes that are dimensions, numeric by most values first."""
    dims = [d for d in AXES if d in grid.dims]
    numeric = [d for d in dims if grid[d].dtype.kind == "f"]
    numeric.sort(key=lambda d: -grid.sizes[d])
    return numeric, [d for d in dims if d not in numeric]


def _varied(grid: xr.Dataset, numeric: list[str]) -> list[str]:
    """The numeric axes with more than one value (the ones worth a line plot)."""
    return [a for a in numeric if grid.sizes[a] > 1]


def _label(axis: str) -> str:
    unit = AXES[axis].unit
    return f"{axis} [{unit}]" if unit and unit not in ("—", "") else axis


class _Slicer:
    """2-D panels (y, x) of a grid study: other numeric axes at their first value, one panel
    per combination of the categorical axes."""

    def __init__(
        self, grid: xr.Dataset, x: str, y: str, numeric: list[str], categorical: list[str]
    ):
        self.grid, self.x, self.y = grid, x, y
        self.fixed = {a: grid[a].values[0] for a in numeric if a not in (x, y)}
        self.combos = [
            dict(zip(categorical, c, strict=True))
            for c in itertools.product(*(grid[a].values for a in categorical))
        ]

    def fixed_text(self) -> str:
        return ", ".join(f"{a} = {v:g}" for a, v in self.fixed.items())

    def panels(self, da: xr.DataArray, title: str) -> list[tuple]:
        out = []
        for combo in self.combos:
            z = da.sel({**self.fixed, **combo}).transpose(self.y, self.x).values
            if np.isfinite(z).any():
                name = ", ".join(str(v) for v in combo.values())
                out.append(
                    (
                        f"{title} — {name}" if name else title,
                        self.grid[self.x].values,
                        self.grid[self.y].values,
                        z,
                    )
                )
        return out


def _ratio_figures(grid: xr.Dataset, s: _Slicer, numeric: list[str]) -> dict[str, Any]:
    figs: dict[str, Any] = {}
    if "ratio" not in grid:
        return figs
    for var, name, what in (
        ("ratio", "ratio_maps.png", "formula at the geometry"),
        ("ratio_book", "ratio_book_maps.png", "book's closed form"),
    ):
        panels = []
        for row in grid.row.values:
            eq = str(grid.equations.sel(row=row).values)
            panels += s.panels(grid[var].sel(row=row), eq)
        if panels:
            figs[name] = plot_maps(
                panels[:MAX_PANELS],
                _label(s.x),
                _label(s.y),
                label=f"procedure / {what}",
                vmin=0.7,
                vmax=1.3,
                bands=BANDS,
            )
    for axis in _varied(grid, numeric):
        others = {a: grid[a].values[0] for a in numeric if a != axis}
        panels = []
        for row in grid.row.values:
            lines = {}
            for combo in s.combos:
                sel = {**others, **combo}
                v = grid.ratio.sel(row=row).sel(sel).values
                if np.isfinite(v).any():
                    se = grid.ratio_se.sel(row=row).sel(sel).values
                    lines[", ".join(str(c) for c in combo.values()) or "ratio"] = (v, se)
            if lines:
                panels.append(
                    (f"{row} {grid.equations.sel(row=row).values}", grid[axis].values, lines)
                )
        if panels:
            figs[f"ratio_vs_{axis}.png"] = plot_lines(
                panels, _label(axis), "procedure / formula", reference=1.0, bands=BANDS
            )
    return figs


def _other_figures(grid: xr.Dataset, s: _Slicer) -> dict[str, Any]:
    figs: dict[str, Any] = {}
    xl, yl = _label(s.x), _label(s.y)
    if "pass_rate" in grid:
        panels = []
        for check in grid.check.values:
            panels += s.panels(grid.pass_rate.sel(check=check), str(check))
        if panels:
            figs["pass_rates.png"] = plot_maps(
                panels[:MAX_PANELS], xl, yl, label="pass rate", vmin=0.0, vmax=1.0, cmap="viridis"
            )
    for var, what in _MEASURES.items():
        if var in grid:
            panels = s.panels(grid[var], what)
            if panels:
                vmax = float(np.nanmax([np.nanmax(p[3]) for p in panels]))
                figs[f"{var}.png"] = plot_maps(
                    panels[:MAX_PANELS],
                    xl,
                    yl,
                    label=what,
                    vmin=0.0,
                    vmax=vmax,
                    cmap="magma_r",
                    fmt="{:.3g}",
                )
    if "height_rms_permille" in grid and "method" in grid.dims and grid.sizes["method"] == 2:
        h = grid.height_rms_permille
        ratio = h.sel({"method": "setup"}, drop=True) / h.sel({"method": "conventional"}, drop=True)
        rest = [a for a in s.combos[0] if a != "method"]
        sub = _Slicer(grid.drop_dims("method"), s.x, s.y, [], rest)
        sub.fixed = s.fixed
        panels = sub.panels(ratio, "height RMS, setup data / conventional")
        if panels:
            top = max(2.0, float(np.nanmax([np.nanmax(p[3]) for p in panels])))
            figs["methods.png"] = plot_maps(
                panels[:MAX_PANELS],
                xl,
                yl,
                label="setup data / conventional",
                vmin=0.0,
                vmax=top,
                cmap="magma_r",
            )
    if "budget_delta_ms" in grid:
        terms = [str(t) for t in grid.term.values]
        panels = []
        for m in grid.budget_measure.values:
            dominant = dominant_term(grid.budget_delta_ms.sel(budget_measure=m))
            panels += s.panels(dominant, f"dominant: {str(m).split('_rms')[0]}")
        if panels:
            figs["dominant_terms.png"] = plot_categories(panels[:MAX_PANELS], terms, xl, yl)
    return figs


def _sampled_figures(ds: xr.Dataset) -> dict[str, Any]:
    numeric = [a for a in AXES if a in ds.coords and ds[a].dtype.kind == "f"]
    if len(numeric) < 2 or "ratio" not in ds:
        return {}
    x, y = numeric[:2]
    panels = []
    for row in ds.row.values:
        r = ds.ratio.sel(row=row).values
        ok = np.isfinite(r)
        if ok.any():
            panels.append((str(row), ds[x].values[ok], ds[y].values[ok], r[ok]))
    if not panels:
        return {}
    return {
        "ratio_scatter.png": plot_scatter(
            panels, _label(x), _label(y), label="procedure / formula", vmin=0.7, vmax=1.3
        )
    }


def study_figures(ds: xr.Dataset, dpi: float = 110) -> tuple[dict[str, bytes], str]:
    """The figures of a study (name → PNG bytes) and a note on what the maps hold."""
    grid = as_grid(ds)
    numeric, categorical = _axes(grid)
    note = ""
    if "cell" in grid.dims:
        figs = _sampled_figures(ds)
    elif len(numeric) >= 2:
        s = _Slicer(grid, numeric[0], numeric[1], numeric, categorical)
        figs = {**_ratio_figures(grid, s, numeric), **_other_figures(grid, s)}
        if s.fixed:
            note = f"Maps at {s.fixed_text()} (the first value of each axis not drawn)."
    else:
        figs = {}
        note = "Fewer than two numeric axes: no maps."
    return {name: figure_bytes(fig, "png", dpi) for name, fig in figs.items()}, note
