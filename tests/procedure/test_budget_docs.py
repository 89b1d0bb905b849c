"""docs/accuracy.md's budget of pair60 on the SC-1 is the output of the command that prints it.

The section holds the Markdown of ``stereoplotter budget pair60 --instrument sc1`` verbatim between
two markers. Its deterministic figures — the error-free floors (all off) and the predicted column
(the σ² expansion of the error-free procedure, which no Monte Carlo draw enters) — are computed
again here and must match to the decimals printed: a stale number fails. The Monte Carlo figures
cannot be rerun within the test budget; the block's header must name the library's default trials
and the scenario's seed (the run that regenerates them), and every decimal figure the prose after
the block quotes must be one of the block's.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.report.budget import budget_markdown
from stereoplotter.verification.budget import DEFAULT_BUDGET_TRIALS, MEASURES, run_budget

DOC = Path(__file__).resolve().parents[2] / "docs" / "accuracy.md"
BEGIN = "<!-- budget pair60 sc1: begin -->"
END = "<!-- budget pair60 sc1: end -->"
_DECIMALS = {"residual_y_parallax_rms_um": 2, "height_error_rms_permille": 4}
_DECIMALS["plan_error_rms_map_mm"] = 4


def _sections() -> tuple[str, str]:
    text = DOC.read_text(encoding="utf-8")
    block = text.split(BEGIN, 1)[1].split(END, 1)[0]
    prose = text.split(END, 1)[1].split("\n## ", 1)[0]
    return block, prose


@pytest.fixture(scope="module")
def deterministic():
    sc, spec = load_scenario("pair60"), load_instrument("sc1")
    return run_budget(sc, spec, "setup", trials=2, seed=sc.seed), sc


def _tables(block: str) -> dict[str, list[list[str]]]:
    out: dict[str, list[list[str]]] = {}
    key = None
    for line in block.splitlines():
        if line.startswith("### "):
            key = next(k for k, (_, w) in MEASURES.items() if w in line)
            out[key] = []
        elif key and line.startswith("| `"):
            out[key].append([c.strip() for c in line.strip("|").split("|")])
    return out


def test_block_header_names_the_default_run(deterministic):
    block, _ = _sections()
    _, sc = deterministic
    assert f"{DEFAULT_BUDGET_TRIALS} trials per configuration" in block
    assert f"seed {sc.seed}" in block


def test_floors_are_the_error_free_procedure(deterministic):
    block, _ = _sections()
    out, _ = deterministic
    floors = re.findall(r"all off \(error-free floor\) (-?[\d.]+) ± ", block)
    assert len(floors) == len(MEASURES)
    for printed, m in zip(floors, MEASURES, strict=True):
        assert printed == f"{out['totals'][m]['all_off']['rms']:.{_DECIMALS[m]}f}", m


def test_predicted_column_is_the_sigma2_expansion(deterministic):
    block, _ = _sections()
    out, _ = deterministic
    rows = {r["name"]: r for r in out["terms"]}
    tables = _tables(block)
    assert set(tables) == set(MEASURES)
    checked = 0
    for m, table in tables.items():
        assert len(table) == len(rows)
        for cells in table:
            name, predicted, status = cells[0].strip("`"), cells[4], cells[6]
            if status != "validated":
                assert predicted in ("—", f"{0.0:.{_DECIMALS[m]}f}"), (name, m)
                continue
            value = max(rows[name]["linear"][m]["predicted_ms"], 0.0) ** 0.5
            assert predicted == f"{value:.{_DECIMALS[m]}f}", (name, m)
            checked += 1
    assert checked >= 10


def test_prose_quotes_only_figures_of_the_block():
    block, prose = _sections()
    quoted = re.findall(r"(?<![\w.])-?\d+\.\d+(?![\w.])", prose)
    assert quoted
    missing = [q for q in quoted if q not in block]
    assert not missing, missing


def test_block_has_the_commands_layout(deterministic):
    # the block is budget_markdown's: the same headings and table header as a fresh rendering
    block, _ = _sections()
    out, _ = deterministic
    fresh = budget_markdown(out)
    for line in fresh.splitlines():
        if line.startswith(("### ", "| term ")):
            assert line in block
