"""``stereoplotter study report``: the Markdown summary of a study's results.

From the Dataset of a results store (``io.study_store.open_results``): heat maps of the ratio
procedure/formula of each outcome row over the two numeric axes with the most values (cells
within 5 % outlined solid, within 10 % dashed), the same ratio along every other numeric axis,
the pass rates of the book's checks, the model's errors, the setup-data method against the
conventional one, and the dominant error term per cell when the study ran the budget. Numeric
axes not drawn are held at their first value (the panel titles say which). A sampled study is
drawn as scatter plots over its first two numeric axes.

The figures come from :mod:`stereoplotter.plotting.study_figures`; the command writes every
file whole (temp file + rename) after all are rendered.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np
import xarray as xr

from stereoplotter.study.design import AXES
from stereoplotter.study.results import STATUS, dominant_term

__all__ = ["cells_markdown", "study_report_files", "study_summary"]

#: Decimals of each per-cell value in ``cells.md`` (the figures docs/studies.md quotes).
_CELL_DECIMALS = {
    "y_parallax_rms_um": 2,
    "height_rms_permille": 4,
    "plan_rms_map_mm": 4,
}


def study_summary(ds: xr.Dataset) -> dict[str, Any]:
    """Numbers of the summary: cells, refusals, the formulas' validity, the dominant terms."""
    status = ds.status.values
    out: dict[str, Any] = {
        "cells": int(status.size),
        "done": int((status == STATUS["done"]).sum()),
        "refused": int((status == STATUS["refused"]).sum()),
        "pending": int((status == STATUS["pending"]).sum()),
        "refusals": sorted({str(m) for m in ds.message.values if str(m)})[:5],
    }
    if "ratio" in ds:
        rows = {}
        for row in ds.row.values:
            r = ds.ratio.sel(row=row).values
            r = r[np.isfinite(r)]
            if r.size:
                rows[str(row)] = {
                    "equations": str(ds.equations.sel(row=row).values),
                    "cells": int(r.size),
                    "within_5": float(np.mean(np.abs(r - 1) <= 0.05)),
                    "within_10": float(np.mean(np.abs(r - 1) <= 0.10)),
                    "min": float(r.min()),
                    "median": float(np.median(r)),
                    "max": float(r.max()),
                }
        out["validity"] = rows
    if "budget_delta_ms" in ds:
        terms = [str(t) for t in ds.term.values]
        counts = {}
        for m in ds.budget_measure.values:
            idx = dominant_term(ds.budget_delta_ms.sel(budget_measure=m)).values
            idx = idx[np.isfinite(idx)].astype(int)
            counts[str(m)] = {terms[i]: int((idx == i).sum()) for i in sorted(set(idx))}
        out["dominant_terms"] = counts
    if "pass_rate" in ds:
        pr = {}
        for check in ds.check.values:
            v = ds.pass_rate.sel(check=check).values
            v = v[np.isfinite(v)]
            if v.size:
                pr[str(check)] = (float(v.min()), float(v.max()))
        out["pass_rates"] = pr
    return out


def _markdown(ds: xr.Dataset, summary: dict[str, Any], figures: list[str], note: str) -> str:
    a = ds.attrs
    lines = [
        f"# Study {a.get('study')}",
        "",
        f"Base scenario {a.get('base_scenario')}; {summary['cells']} cells "
        f"({summary['done']} done, {summary['refused']} refused, {summary['pending']} not run); "
        f"{a.get('trials')} trials per cell in chunks of {a.get('chunk_trials')}, procedure "
        f"Monte Carlo {a.get('procedure_trials')} trials, budget {a.get('budget_trials')} "
        f"trials; seed {a.get('seed')}.",
        "",
        "Axes: "
        + "; ".join(f"{n} = {_values(ds[n].values)}" for n in AXES if n in ds.coords)
        + ".",
    ]
    if note:
        lines += ["", note]
    if summary.get("validity"):
        lines += [
            "",
            "## Where the formulas hold",
            "",
            "Cells where |procedure / formula − 1| is within 5 % and 10 % (the formula "
            "at each cell's geometry; every cell that ran the row).",
            "",
            "| row | equations | cells | within 5 % | within 10 % | min | median | max |",
            "|---|---|---:|---:|---:|---:|---:|---:|",
        ]
        for row, v in summary["validity"].items():
            lines.append(
                f"| {row} | {v['equations']} | {v['cells']} | {v['within_5']:.0%} | "
                f"{v['within_10']:.0%} | {v['min']:.3f} | {v['median']:.3f} | {v['max']:.3f} |"
            )
    if summary.get("pass_rates"):
        lines += [
            "",
            "## Pass rates of the book's checks",
            "",
            "| check | lowest | highest |",
            "|---|---:|---:|",
        ]
        for check, (lo, hi) in summary["pass_rates"].items():
            lines.append(f"| {_cell(check)} | {lo:.2f} | {hi:.2f} |")
    if summary.get("dominant_terms"):
        lines += [
            "",
            "## Dominant error term (one at a time)",
            "",
            "| measure | term: cells |",
            "|---|---|",
        ]
        for m, counts in summary["dominant_terms"].items():
            lines.append(f"| {m} | " + ", ".join(f"{t}: {n}" for t, n in counts.items()) + " |")
    lines += _methods_table(ds)
    if summary["refusals"]:
        lines += ["", "## Refused cells", ""] + [f"- {_message(m)}" for m in summary["refusals"]]
    lines += ["", "Every cell's figures: [cells.md](cells.md).", "", "## Figures", ""]
    lines += [f"![{f}]({f})" for f in figures]
    return "\n".join(lines) + "\n"


def _methods_table(ds: xr.Dataset) -> list[str]:
    """The setup-data method's height RMS against the conventional one's at each configuration
    both ran (the book's comparison of the methods), with their ratio; empty without both."""
    if "method" not in ds.coords or "height_rms_permille" not in ds:
        return []
    methods = ds.method.values
    if not {"setup", "conventional"} <= {str(m) for m in methods}:
        return []
    others = [n for n in AXES if n in ds.coords and n != "method"]
    keys = [tuple(ds[n].values[i].item() for n in others) for i in range(ds.sizes["cell"])]
    by = {(k, str(methods[i])): i for i, k in enumerate(keys)}
    h, se = ds.height_rms_permille.values, ds.height_rms_permille_se.values
    out = [
        "",
        "## Setup data against the conventional method",
        "",
        "Height RMS on the working-area grid, ‰ H (mean ± SE), and setup / conventional.",
        "",
        "| " + " | ".join(others) + " | setup | conventional | setup / conventional |",
        "|" + "---|" * (len(others) + 3),
    ]
    for k in dict.fromkeys(keys):
        i, j = by.get((k, "setup")), by.get((k, "conventional"))
        if i is None or j is None or not (np.isfinite(h[i]) and np.isfinite(h[j])):
            continue
        axes = " | ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in k)
        out.append(
            f"| {axes} | {h[i]:.4f} ± {se[i]:.4f} | {h[j]:.4f} ± {se[j]:.4f} | "
            f"{h[i] / h[j]:.2f} |"
        )
    return out


def _cell(text: str) -> str:
    """Text for a Markdown table cell (a check named "|L − L′|" keeps its bars)."""
    return text.replace("|", "\\|")


def _values(values: np.ndarray) -> str:
    return ", ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in np.unique(values))


def _message(text: str) -> str:
    """A refusal's line with an instrument file's absolute path cut to its name."""
    return re.sub(r"(?<!\S)(?:[^\s/]*/)+(\w+\.yaml)", r"\1", text)


def cells_markdown(ds: xr.Dataset) -> str:
    """``cells.md``: one row per cell — its axes, status, the mean ± SE of each measure, each
    check's pass rate and each outcome row's ratio procedure/formula — and the refusal of each
    refused cell: every figure a text may quote, as the results store holds it."""
    axes = [n for n in AXES if n in ds.coords]
    values = [v for v in _CELL_DECIMALS if v in ds]
    checks = [str(c) for c in ds.check.values] if "pass_rate" in ds else []
    rows = [str(r) for r in ds.row.values] if "ratio" in ds else []
    head = (
        ["cell", *axes, "status"]
        + values
        + [f"pass: {_cell(c)}" for c in checks]
        + [f"ratio: {r}" for r in rows]
    )
    lines = [
        f"# Study {ds.attrs.get('study')}: every cell",
        "",
        "Mean ± Monte Carlo SE per cell; pass rates ± their SE; ratio = procedure / formula at "
        "the cell's geometry ± SE. Status: done, refused (the message below), not run.",
        "",
        "| " + " | ".join(head) + " |",
        "|" + "---|" * len(head),
    ]
    names = {v: k for k, v in STATUS.items()}
    refusals = []
    for i in range(ds.sizes["cell"]):
        c = ds.isel(cell=i)
        status = names.get(int(c.status.values), "?")
        out = [str(i)] + [_axis_value(c[a].values) for a in axes] + [status]
        for v in values:
            d = _CELL_DECIMALS[v]
            out.append(_pm(c[v].values, c[f"{v}_se"].values, d))
        for check in checks:
            out.append(
                _pm(
                    c.pass_rate.sel(check=check).values,
                    c.pass_rate_se.sel(check=check).values,
                    3,
                )
            )
        for row in rows:
            out.append(_pm(c.ratio.sel(row=row).values, c.ratio_se.sel(row=row).values, 3))
        lines.append("| " + " | ".join(out) + " |")
        if status == "refused":
            refusals.append(f"- cell {i}: {_message(str(c.message.values))}")
    if refusals:
        lines += ["", "## Refused cells", "", *refusals]
    return "\n".join(lines) + "\n"


def _pm(value: Any, se: Any, decimals: int) -> str:
    v, e = float(value), float(se)
    if not np.isfinite(v):
        return "—"
    return f"{v:.{decimals}f} ± {e:.{decimals}f}" if np.isfinite(e) else f"{v:.{decimals}f}"


def _axis_value(v: Any) -> str:
    v = v.item() if hasattr(v, "item") else v
    return f"{v:g}" if isinstance(v, float) else str(v)


def study_report_files(
    ds: xr.Dataset, figures: dict[str, bytes], note: str = ""
) -> dict[str, bytes]:
    """``study.md`` beside the figures (name → PNG bytes, from
    :func:`stereoplotter.plotting.study_figures.study_figures`): name → bytes, figures first."""
    text = _markdown(ds, study_summary(ds), list(figures), note)
    return {
        **figures,
        "study.md": text.encode("utf-8"),
        "cells.md": cells_markdown(ds).encode("utf-8"),
    }
