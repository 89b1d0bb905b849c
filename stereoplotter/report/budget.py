"""What ``stereoplotter budget`` prints and writes: the error budget as Markdown, JSON and a chart.

:func:`run_budget_command` loads the scenario and the instrument, runs
:func:`stereoplotter.verification.budget.run_budget` and times it; :func:`budget_markdown`
renders one table per measure; :func:`write_budget` writes ``budget.md``, ``budget.json`` and
``budget.png`` into a folder, each whole or not at all (figures rendered before any write).
"""

from __future__ import annotations

import io
import json
import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from stereoplotter.constants import ARCSEC_PER_RAD
from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.error_model import error_model_from_spec
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.io.yaml_files import atomic_write_bytes
from stereoplotter.plotting.budget import plot_budget
from stereoplotter.verification.budget import (
    DEFAULT_BUDGET_TRIALS,
    MEASURES,
    budget_work,
    run_budget,
)

__all__ = ["budget_json", "budget_markdown", "run_budget_command", "write_budget"]

#: Decimals of each measure in the Markdown tables.
_DECIMALS = {
    "residual_y_parallax_rms_um": 2,
    "height_error_rms_permille": 4,
    "plan_error_rms_map_mm": 4,
}
_FILES = ("budget.md", "budget.json", "budget.png")


def run_budget_command(
    scenario: str,
    instrument: str,
    method: str = "setup",
    trials: int = DEFAULT_BUDGET_TRIALS,
    seed: int | None = None,
    progress_bar: Callable[[int], Any] | None = None,
) -> dict[str, Any]:
    """Load, run and time the budget; ``progress_bar(total)`` is a context giving ``advance(n)``.

    The seed defaults to the scenario's own.
    """
    spec = load_instrument(instrument)
    sc = load_scenario(scenario)
    total = budget_work(error_model_from_spec(spec), trials)
    start = time.perf_counter()
    run_seed = sc.seed if seed is None else seed
    if progress_bar is None:
        out = run_budget(sc, spec, method, trials=trials, seed=run_seed)
    else:
        with progress_bar(total) as advance:
            out = run_budget(sc, spec, method, trials=trials, seed=run_seed, progress=advance)
    out["seconds"] = round(time.perf_counter() - start, 1)
    return _finite(out)


def _finite(v: Any) -> Any:
    """NaN (a measure the scenario cannot give) → None, so the JSON is standard."""
    if isinstance(v, dict):
        return {k: _finite(x) for k, x in v.items()}
    if isinstance(v, list):
        return [_finite(x) for x in v]
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


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


def write_budget(budget: dict[str, Any], folder: str | Path) -> list[str]:
    """``budget.md``, ``budget.json``, ``budget.png`` into ``folder`` (each atomically)."""
    fig = plot_budget(budget)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=100, metadata={"Software": None})
    contents = {
        "budget.md": budget_markdown(budget).encode("utf-8"),
        "budget.json": budget_json(budget).encode("utf-8"),
        "budget.png": buffer.getvalue(),
    }
    out = Path(folder)
    if out.exists() and not out.is_dir():
        raise StereoplotterError(f"{out}: -o: expected a folder, found a file")
    for name, content in contents.items():
        atomic_write_bytes(out / name, content)
    return list(_FILES)
