"""The error budget as text: Markdown (one table per measure) and JSON.

The command (load, run, the chart, write) is :mod:`stereoplotter.commands.error_budget`.
"""

from __future__ import annotations

import json
from typing import Any

from stereoplotter.constants import ARCSEC_PER_RAD
from stereoplotter.verification.budget import MEASURES

__all__ = ["budget_json", "budget_markdown"]

#: Decimals of each measure in the Markdown tables.
_DECIMALS = {
    "residual_y_parallax_rms_um": 2,
    "height_error_rms_permille": 4,
    "plan_error_rms_map_mm": 4,
}


def budget_json(budget: dict[str, Any]) -> str:
    """The JSON text (``docs/schemas/budget.schema.json``)."""
    return json.dumps(budget, indent=2, ensure_ascii=False, allow_nan=False) + "\n"


def _scale(row: dict[str, Any]) -> str:
    s, unit = row["scale"], row["unit"]
    if row["distribution"] == "rounding":
        return "on" if s else "off"
    if unit == "rad":
        return f"{s * ARCSEC_PER_RAD:.3g}″"
    if unit == "—":
        return f"{s * 1e6:.3g} ppm"
    text = f"{s:.3g} {unit}"
    return text if row["distribution"] == "normal" else f"{text} ({row['distribution']})"


def _pm(entry: dict[str, Any], d: int) -> str:
    if entry["rms"] is None:
        return "—"
    return f"{_fmt(entry['rms'], d)} ± {_fmt(entry['se'], d)}"


def budget_markdown(budget: dict[str, Any]) -> str:
    """One Markdown table per measure: σ, one at a time ± SE, all but one ± SE, the predicted
    (smooth σ² expansion) value with its agreement, and the additivity; then the dropped
    predictions with their reasons."""
    z = budget.get("agreement_z", 2.0)
    lines = [
        f"Error budget of `{budget['scenario']}` on `{budget['instrument']}`, "
        f"{budget['method']} method: {budget['trials']} trials per configuration "
        f"(common random numbers), seed {budget['seed']}, {budget['configurations']} "
        "configurations. A contribution is sign(Δ)·√|Δ| of the mean-square change Δ; "
        "± one Monte Carlo standard error; predicted: the σ² order of Δ from a smooth expansion "
        "of the error-free procedure with its decisions held fixed (differences at "
        f"{budget['linearisation_step_sigma']:g} σ, checked at {budget['check_step_sigma']:g} σ), "
        f"kept where it agrees with the one-at-a-time Δ within {z:g} SE (z = (Δ_sim − Δ_pred)/SE).",
        "",
    ]
    dropped = []
    for key, (unit, meaning) in MEASURES.items():
        d = _DECIMALS[key]
        tot = budget["totals"][key]
        add = tot["additivity"]
        gap_z = add["gap_ms"] / add["gap_ms_se"] if add["gap_ms_se"] else 0.0
        verdict = (
            f"the parts add up within {z:g} SE"
            if add["adds_up"]
            else f"the parts do not add up ({gap_z:+.1f} SE)"
        )
        lines += [
            f"### {meaning} [{unit}]",
            "",
            f"All on {_pm(tot['all_on'], d)}, all off (error-free floor) "
            f"{_pm(tot['all_off'], d)}, predicted all on (floor + validated parts) "
            f"{_fmt(tot['linear_all_on_rms'], d)}; "
            f"Σ one-at-a-time Δ = {_fmt(add['sum_one_at_a_time_ms'], d + 2)} against "
            f"Δ(all on − all off) = {_fmt(tot['total_delta']['delta_ms'], d + 2)} "
            f"(gap {_fmt(add['gap_ms'], d + 2)} ± {_fmt(add['gap_ms_se'], d + 2)}) "
            f"[{unit}²]: {verdict}.",
            "",
        ]
        if add["interactions"]:
            lines.append(
                "Interactions, Δ(all but one) − Δ(one at a time) beyond "
                f"{z:g} SE [{unit}²]: "
                + "; ".join(
                    f"`{i['term']}` {_fmt(i['delta_ms'], d + 2)} ± {_fmt(i['delta_ms_se'], d + 2)}"
                    for i in add["interactions"]
                )
                + ".",
            )
            lines.append("")
        lines += [
            "| term | σ | one at a time | all but one | predicted | z | prediction |",
            "|---|---|---|---|---|---|---|",
        ]
        for r in budget["terms"]:
            lin = r["linear"][key]
            zt = "—" if lin.get("z") is None else f"{lin['z']:+.1f}"
            lines.append(
                f"| `{r['name']}` | {_scale(r)} | {_pm(r['one_at_a_time'][key], d)} | "
                f"{_pm(r['all_but_one'][key], d)} | {_fmt(lin['rms'], d)} | {zt} | "
                f"{lin.get('status', r['linear_model'])} |"
            )
            if lin.get("status") == "dropped":
                dropped.append(f"* `{r['name']}`, {meaning}: {lin['reason']}.")
        lines.append("")
    if dropped:
        lines += ["Predictions dropped, with the reason measured in this run:", "", *dropped, ""]
    return "\n".join(lines)


def _fmt(v: float | None, d: int) -> str:
    """``v`` to ``d`` decimals, "—" for None; a value that rounds to zero without its sign."""
    if v is None:
        return "—"
    return f"{v + 0.0 if round(v, d) != 0 else 0.0:.{d}f}"
