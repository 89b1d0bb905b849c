"""The bar chart of an error budget (``verification.budget``; Agg backend, no file I/O).

One panel per measure, one horizontal bar per error term: its one-at-a-time contribution
(signed RMS, a negative bar: the measure fell when the term was switched on) with ±1 SE, the
all-but-one contribution as a hollow bar, and the validated prediction (smooth σ² expansion,
none where dropped) as a black tick. A linear
axis: the contributions range over two or three decades but carry signs, which a log axis
cannot show. Terms that change no measure at all (exactly zero Δ in every configuration, e.g. a
term at σ = 0 or one the evaluated model does not depend on) are left out and counted in the
title.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.figure import Figure

__all__ = ["plot_budget"]


def _inert(row: dict[str, Any]) -> bool:
    return all(
        row[kind][m]["delta_ms"] == 0.0
        for kind in ("one_at_a_time", "all_but_one")
        for m in row[kind]
    )


def plot_budget(budget: dict[str, Any]) -> Any:
    """The figure of :func:`stereoplotter.verification.budget.run_budget`'s result."""
    rows = [r for r in budget["terms"] if not _inert(r)]
    left_out = len(budget["terms"]) - len(rows)
    measures = budget["measures"]
    height = max(3.0, 0.32 * len(rows) + 1.6)
    fig = Figure(figsize=(15.0, height), layout="constrained")  # no pyplot state to close
    axes = fig.subplots(1, len(measures), sharey=True)
    y = np.arange(len(rows))[::-1]
    for ax, (key, desc) in zip(np.atleast_1d(axes), measures.items(), strict=True):
        one = np.array([_num(r["one_at_a_time"][key]["rms"]) for r in rows])
        se = np.array([_num(r["one_at_a_time"][key]["se"]) for r in rows])
        abo = np.array([_num(r["all_but_one"][key]["rms"]) for r in rows])
        lin = np.array([_num(r["linear"][key]["rms"]) for r in rows])
        ax.barh(y + 0.18, one, height=0.36, xerr=se, color="tab:blue", label="one at a time")
        ax.barh(y - 0.18, abo, height=0.36, fill=False, edgecolor="tab:orange", label="all but one")
        ax.plot(lin, y, "k|", ms=12, mew=2, label="predicted (validated)")
        ax.axvline(0.0, color="0.4", lw=0.8)
        ax.set_xlabel(f"contribution, RMS [{desc['unit']}]")
        ax.set_title(desc["meaning"], fontsize=9)
        ax.grid(axis="x", alpha=0.3)
    first = np.atleast_1d(axes)[0]
    first.set_yticks(y, [r["name"] for r in rows], fontsize=9)
    first.legend(loc="lower right", fontsize=8)
    fig.suptitle(
        f"error budget: {budget['scenario']} on {budget['instrument']}, {budget['method']} "
        f"method, {budget['trials']} trials per configuration"
        + (f" ({left_out} terms with no effect left out)" if left_out else ""),
        fontsize=11,
    )
    return fig


def _num(v: float | None) -> float:
    return np.nan if v is None else float(v)
