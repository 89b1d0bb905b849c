"""The work of ``stereoplotter budget``: load → run → render → write.

Load the scenario and the instrument (:mod:`stereoplotter.io`), run
:func:`stereoplotter.verification.budget.run_budget` and time it, render the Markdown and JSON
(:mod:`stereoplotter.report.budget`) and the chart (:mod:`stereoplotter.plotting.budget`), write
``budget.md``, ``budget.json`` and ``budget.png`` into a folder, each whole or not at all (all
rendered before any write). Imported by :mod:`stereoplotter.commands.budget` only when the command
runs, so the library is imported here at the top.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.error_model import error_model_from_spec
from stereoplotter.io.atomic_write import write_files
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.plotting.budget import plot_budget
from stereoplotter.plotting.encode import figure_bytes
from stereoplotter.report.budget import budget_json, budget_markdown
from stereoplotter.verification.budget import DEFAULT_BUDGET_TRIALS, budget_work, run_budget

__all__ = ["run_budget_command", "write_budget"]

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


def write_budget(budget: dict[str, Any], folder: str | Path) -> list[str]:
    """``budget.md``, ``budget.json``, ``budget.png`` into ``folder`` (each atomically)."""
    contents = {
        "budget.md": budget_markdown(budget).encode("utf-8"),
        "budget.json": budget_json(budget).encode("utf-8"),
        "budget.png": figure_bytes(plot_budget(budget), "png", dpi=100),
    }
    out = Path(folder)
    if out.exists() and not out.is_dir():
        raise StereoplotterError(f"{out}: -o: expected a folder, found a file")
    write_files(out, contents)
    return list(_FILES)
