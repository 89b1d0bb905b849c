"""The xarray Dataset of a study: one row per cell, the axes as coordinates along ``cell``.

Variables (only those of the measures the study asks for):

* ``status`` (0 not run, 1 done, 2 refused) and ``message`` (the refusal's one line);
* ``pass_rate``, ``pass_rate_se`` (cell, check): each of the book's checks;
* ``y_parallax_rms_um``, ``height_rms_permille``, ``plan_rms_map_mm`` and their ``_se``: mean
  over the trials of the per-trial RMS on the working-area grid, with its standard error;
* ``procedure``, ``procedure_se``, ``formula``, ``formula_book``, ``ratio``, ``ratio_se``,
  ``ratio_book`` (cell, row): the procedure Monte Carlo's coefficient of each outcome row, the
  rigorous formula at the cell's geometry, the book's closed form there, and their ratios;
* ``budget_delta_ms``, ``budget_delta_ms_se`` (cell, term, budget_measure): the one-at-a-time
  contribution Δ MS of each error term.

A grid study is unstacked to one dimension per axis by :func:`as_grid`.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from stereoplotter.study.cells import OUTCOME_ROWS, VALUE_MEASURES, Moments, combine_chunks
from stereoplotter.study.design import AXES, StudyDesign, Task
from stereoplotter.verification.budget import MEASURES as BUDGET_MEASURES

__all__ = [
    "STATUS",
    "as_grid",
    "cell_values",
    "dominant_term",
    "empty_dataset",
]

#: Cell status codes.
STATUS = {"pending": 0, "done": 1, "refused": 2}

#: Longest refusal message kept. [characters]
MESSAGE_CHARS = 300


def _coordinate(values: list[Any]) -> np.ndarray:
    if all(isinstance(v, str) for v in values):
        return np.array(values, dtype=f"<U{max(len(v) for v in values)}")
    return np.array(values, float)


def empty_dataset(
    design: StudyDesign,
    cells: list[dict[str, Any]],
    checks: tuple[str, ...],
    terms: tuple[str, ...],
) -> xr.Dataset:
    """The study's Dataset before any cell ran (NaN, status 0)."""
    n = len(cells)
    coords: dict[str, Any] = {"cell": np.arange(n)}
    for name in design.axis_names:
        coords[name] = (
            "cell",
            _coordinate([c[name] for c in cells]),
            {
                "unit": AXES[name].unit,
                "meaning": AXES[name].meaning,
            },
        )
    data: dict[str, Any] = {
        "status": ("cell", np.zeros(n, np.int8)),
        "message": ("cell", np.full(n, "", dtype=f"<U{MESSAGE_CHARS}")),
    }

    def nan(*shape: int) -> np.ndarray:
        return np.full((n, *shape), np.nan)

    if "checks" in design.measures:
        coords["check"] = _coordinate(list(checks)) if checks else np.array([], "<U1")
        data["pass_rate"] = (("cell", "check"), nan(len(checks)))
        data["pass_rate_se"] = (("cell", "check"), nan(len(checks)))
    for name, measure in zip(VALUE_MEASURES, ("y_parallax", "heights", "plan"), strict=True):
        if measure in design.measures:
            data[name] = ("cell", nan())
            data[f"{name}_se"] = ("cell", nan())
    if "procedure" in design.measures:
        coords["row"] = _coordinate(list(OUTCOME_ROWS))
        coords["equations"] = ("row", _coordinate([v[2] for v in OUTCOME_ROWS.values()]))
        for name in ("procedure", "procedure_se", "formula", "formula_book", "ratio", "ratio_se"):
            data[name] = (("cell", "row"), nan(len(OUTCOME_ROWS)))
        data["ratio_book"] = (("cell", "row"), nan(len(OUTCOME_ROWS)))
    if "budget" in design.measures:
        coords["term"] = _coordinate(list(terms)) if terms else np.array([], "<U1")
        coords["budget_measure"] = _coordinate(list(BUDGET_MEASURES))
        shape = (len(terms), len(BUDGET_MEASURES))
        data["budget_delta_ms"] = (("cell", "term", "budget_measure"), nan(*shape))
        data["budget_delta_ms_se"] = (("cell", "term", "budget_measure"), nan(*shape))
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update(
        study=design.name,
        trials=design.trials,
        chunk_trials=design.chunk_trials,
        procedure_trials=design.procedure_trials,
        budget_trials=design.budget_trials,
        seed=design.seed,
        base_scenario=design.base.name,
    )
    return ds


def cell_values(
    design: StudyDesign,
    parts: list[tuple[Task, Any]],
    checks: tuple[str, ...],
    terms: tuple[str, ...],
) -> dict[str, Any]:
    """Variable → this cell's value (without the cell dimension) from its tasks' results."""
    refused = [r for _, r in parts if isinstance(r, tuple) and r and r[0] == "refused"]
    if refused:
        return {"status": STATUS["refused"], "message": refused[0][1][:MESSAGE_CHARS]}
    out: dict[str, Any] = {"status": STATUS["done"], "message": ""}
    chunks = [(t, r) for t, r in parts if t.kind == "chunk"]
    if chunks:
        m: Moments = combine_chunks(chunks)
        se = m.standard_error()
        k = len(checks)
        if "checks" in design.measures:
            out["pass_rate"], out["pass_rate_se"] = m.mean[:k], se[:k]
        for i, name in enumerate(VALUE_MEASURES):
            if name in _value_names(design):
                out[name], out[f"{name}_se"] = m.mean[k + i], se[k + i]
    for task, result in parts:
        if task.kind == "procedure":
            out.update(_procedure_values(result))
        elif task.kind == "budget":
            out.update(_budget_values(result, terms))
    return out


def _value_names(design: StudyDesign) -> set[str]:
    pairs = zip(VALUE_MEASURES, ("y_parallax", "heights", "plan"), strict=True)
    return {name for name, measure in pairs if measure in design.measures}


def _procedure_values(result: dict[str, tuple[float, ...]]) -> dict[str, np.ndarray]:
    rows = list(OUTCOME_ROWS)
    v = {
        k: np.full(len(rows), np.nan)
        for k in ("procedure", "procedure_se", "formula", "formula_book")
    }
    for row, (value, se, formula, book) in result.items():
        i = rows.index(row)
        v["procedure"][i], v["procedure_se"][i] = value, se
        v["formula"][i], v["formula_book"][i] = formula, book
    v["ratio"] = v["procedure"] / v["formula"]
    v["ratio_se"] = v["procedure_se"] / v["formula"]
    v["ratio_book"] = v["procedure"] / v["formula_book"]
    return v


def _budget_values(result: dict[str, dict[str, tuple]], terms: tuple[str, ...]) -> dict[str, Any]:
    measures = list(BUDGET_MEASURES)
    delta = np.full((len(terms), len(measures)), np.nan)
    se = np.full_like(delta, np.nan)
    for name, per in result.items():
        if name not in terms:
            continue
        i = terms.index(name)
        for j, m in enumerate(measures):
            delta[i, j], se[i, j] = per[m]
    return {"budget_delta_ms": delta, "budget_delta_ms_se": se}


def as_grid(ds: xr.Dataset) -> xr.Dataset:
    """A grid study with one dimension per axis (``cell`` unstacked); a sampled study as is."""
    axes = [name for name in ds.coords if ds[name].dims == ("cell",) and name != "cell"]
    sizes = [len(np.unique(ds[a].values)) for a in axes]
    if not axes or int(np.prod(sizes)) != ds.sizes["cell"]:
        return ds
    return ds.set_index(cell=axes).unstack("cell")


def dominant_term(delta: xr.DataArray) -> xr.DataArray:
    """Index of the term with the largest one-at-a-time Δ MS per cell (NaN where none ran)."""
    filled = delta.fillna(-np.inf)
    idx = filled.argmax("term").astype(float)
    return idx.where(np.isfinite(delta).any("term"))
