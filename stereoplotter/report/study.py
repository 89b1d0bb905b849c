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

from typing import Any

import numpy as np
import xarray as xr

from stereoplotter.study.design import AXES
from stereoplotter.study.results import STATUS, dominant_term

__all__ = ["study_report_files", "study_summary"]


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
    if summary["refusals"]:
        lines += ["", "## Refused cells", ""] + [f"- {m}" for m in summary["refusals"]]
    lines += ["", "## Figures", ""] + [f"![{f}]({f})" for f in figures]
    return "\n".join(lines) + "\n"


def _cell(text: str) -> str:
    """Text for a Markdown table cell (a check named "|L − L′|" keeps its bars)."""
    return text.replace("|", "\\|")


def _values(values: np.ndarray) -> str:
    return ", ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in np.unique(values))


def study_report_files(
    ds: xr.Dataset, figures: dict[str, bytes], note: str = ""
) -> dict[str, bytes]:
    """``study.md`` beside the figures (name → PNG bytes, from
    :func:`stereoplotter.plotting.study_figures.study_figures`): name → bytes, figures first."""
    text = _markdown(ds, study_summary(ds), list(figures), note)
    return {**figures, "study.md": text.encode("utf-8")}
