"""docs/procedure.md's pass-rate table across the operator's published σ range is the output of
``stereoplotter study eye-range --trials 500``: the block between its markers is that command's
Markdown, its rows are the settings of ``procedure.eye_range``, and two cells (pair60, each
method, the default eye) are run again here and must print the same figures — a stale table
fails."""

from __future__ import annotations

from pathlib import Path

import pytest

from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.procedure.eye_range import SETTINGS, pass_rates, table_markdown
from stereoplotter.procedure.operator import OperatorModel

DOC = Path(__file__).resolve().parents[2] / "docs" / "procedure.md"
BEGIN = "<!-- eye-range pair60 pair80 sc1 500: begin -->"
END = "<!-- eye-range pair60 pair80 sc1 500: end -->"


def _block() -> str:
    return DOC.read_text(encoding="utf-8").split(BEGIN, 1)[1].split(END, 1)[0]


def test_block_rows_are_the_settings_of_the_command():
    rows = [line for line in _block().splitlines() if line.startswith("| ") and "µm" in line]
    assert [r.split(" | ")[0][2:] for r in rows] == [label for label, _, _ in SETTINGS]
    assert _block().startswith("\n500 trials per cell, sc1,")


@pytest.mark.parametrize(("method", "column"), [("setup", 1), ("conventional", 2)])
def test_one_cell_of_each_method_is_the_current_code(method, column):
    sc, spec = load_scenario("pair60"), load_instrument("sc1")
    r = pass_rates(sc, spec, method, OperatorModel(), 500)
    label = SETTINGS[0][0]
    rows = {(label, "pair60", method): r}

    class _Only:  # the table of one (scenario, method): its first data cell is this run's
        name = "pair60"

    line = table_markdown(rows, [_Only], methods=(method,)).splitlines()[2]
    printed = next(x for x in _block().splitlines() if x.startswith(f"| {label} |"))
    assert line.split(" | ")[1].rstrip(" |") == printed.split(" | ")[column]
