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
    """One Markdown table per measure: σ, one at a time ± SE, all but one ± SE, linear."""
    lines = [
        f"Error budget of `{budget['scenario']}` on `{budget['instrument']}`, "
        f"{budget['method']} method: {budget['trials']} trials per configuration "
        f"(common random numbers), seed {budget['seed']}, {budget['configurations']} "
        "configurations. A contribution is sign(Δ)·√|Δ| of the mean-square change Δ; "
        "± one Monte Carlo standard error; linear: first-order prediction "
        f"(central differences, step {budget['linearisation_step_sigma']} σ).",
        "",
    ]
    for key, (unit, meaning) in MEASURES.items():
        d = _DECIMALS[key]
        tot = budget["totals"][key]
        add = tot["additivity"]
        lines += [
            f"### {meaning} [{unit}]",
            "",
            f"All on {_pm(tot['all_on'], d)}, all off (error-free floor) "
            f"{_pm(tot['all_off'], d)}, linear all on {_fmt(tot['linear_all_on_rms'], d)}; "
            f"Σ one-at-a-time Δ = {_fmt(add['sum_one_at_a_time_ms'], d + 2)} against "
            f"Δ(all on − all off) = {_fmt(tot['total_delta']['delta_ms'], d + 2)} "
            f"(gap {_fmt(add['gap_ms'], d + 2)} ± {_fmt(add['gap_ms_se'], d + 2)}) "
            f"[{unit}²].",
            "",
            "| term | σ | one at a time | all but one | linear | linear model |",
            "|---|---|---|---|---|---|",
        ]
        for r in budget["terms"]:
            lin = r["linear"][key]["rms"]
            lines.append(
                f"| `{r['name']}` | {_scale(r)} | {_pm(r['one_at_a_time'][key], d)} | "
                f"{_pm(r['all_but_one'][key], d)} | {_fmt(lin, d)} | {r['linear_model']} |"
            )
        lines.append("")
    return "\n".join(lines)


def _fmt(v: float | None, d: int) -> str:
    """``v`` to ``d`` decimals, "—" for None; a value that rounds to zero without its sign."""
    if v is None:
        return "—"
    return f"{v + 0.0 if round(v, d) != 0 else 0.0:.{d}f}"
