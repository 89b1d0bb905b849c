"""docs/studies.md quotes only figures its commands regenerate.

Each study's section sits between two markers and gives the `study run` and `study report`
commands of its run. The test parses the `study run` command with the CLI's own parser and
checks that the report beside the section (docs/img/studies/NAME/study.md) is of that run (its
cells, trials, seed); every decimal figure of the section's prose must be one the report or its
cells.md prints; and two cells of formula-validity (the setup-data and the conventional method
at f = 70 mm, 56 %) are run again from the command here and must print the figures cells.md
holds for them — a stale figure fails.
"""

from __future__ import annotations

import argparse
import json
import re
import shlex
from pathlib import Path

import pytest

pytest.importorskip("xarray")

from stereoplotter.cli import main
from stereoplotter.commands.study import add_arguments, reduced
from stereoplotter.io.study_file import load_study, study_from_mapping
from stereoplotter.study.cells import VALUE_MEASURES, run_task
from stereoplotter.study.design import Task
from stereoplotter.study.runner import study_checks

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "studies.md"
STUDIES = ("formula-validity", "operator-skill")
_DECIMALS = {"y_parallax_rms_um": 2, "height_rms_permille": 4, "plan_rms_map_mm": 4}


def _section(name: str) -> str:
    text = DOC.read_text(encoding="utf-8")
    return text.split(f"<!-- study {name}: begin -->", 1)[1].split(f"<!-- study {name}: end -->")[0]


def _command(name: str) -> argparse.Namespace:
    block = _section(name).split("```", 2)[1]
    line = next(x for x in block.replace("\\\n", " ").splitlines() if "study run" in x)
    tokens = shlex.split(line.split("stereoplotter", 1)[1])
    parser = argparse.ArgumentParser()
    add_arguments(parser.add_subparsers())
    return parser.parse_args(tokens)


def _generated(name: str) -> str:
    folder = ROOT / "docs" / "img" / "studies" / name
    return "".join((folder / f).read_text(encoding="utf-8") for f in ("study.md", "cells.md"))


@pytest.mark.parametrize("name", STUDIES)
def test_report_is_of_the_command_run(name):
    args = _command(name)
    design = study_from_mapping(reduced(load_study(args.study)[1], args))
    head = _generated(name).splitlines()[2]
    assert f"{len(design.cells())} cells (" in head
    assert f"{design.trials} trials per cell" in head
    assert f"procedure Monte Carlo {design.procedure_trials} trials" in head
    assert f"budget {design.budget_trials} trials; seed {design.seed}." in head


@pytest.mark.parametrize("name", STUDIES)
def test_every_quoted_figure_is_printed_by_the_report(name):
    prose = "".join(_section(name).split("```")[2::2])
    generated = _generated(name)
    missing = [
        x
        for x in sorted(set(re.findall(r"(?<![\w.])\d+\.\d+(?![\d])", prose)))
        if not re.search(rf"(?<![\d.]){re.escape(x)}(?![\d])", generated)
    ]
    assert not missing, missing


def _row(cells_md: str, cell: int) -> list[str]:
    line = next(x for x in cells_md.splitlines() if x.startswith(f"| {cell} |"))
    return [c.strip() for c in re.split(r"(?<!\\)\|", line.strip().strip("|"))]


def test_two_cells_are_the_current_code():
    args = _command("formula-validity")
    design = study_from_mapping(reduced(load_study(args.study)[1], args))
    cells = design.cells()
    checks = study_checks(design, cells)
    cells_md = (ROOT / "docs/img/studies/formula-validity/cells.md").read_text(encoding="utf-8")
    head = [c.strip() for c in re.split(r"(?<!\\)\|", cells_md.splitlines()[4].strip("|"))]
    for cell in (0, 1):
        _, m = run_task(design, cells[cell], Task("chunk", cell, 0, design.trials), checks)
        se = m.standard_error()
        printed = dict(zip(head, _row(cells_md, cell), strict=True))
        for k, name in enumerate(checks):
            key = "pass: " + name.replace("|", "\\|")
            want = printed[key]
            got = "—" if m.n[k] == 0 else f"{m.mean[k]:.3f} ± {se[k]:.3f}"
            assert got == want, (cell, name)
        for j, v in enumerate(VALUE_MEASURES):
            k = len(checks) + j
            d = _DECIMALS[v]
            assert f"{m.mean[k]:.{d}f} ± {se[k]:.{d}f}" == printed[v], (cell, v)


def test_the_book_pairs_row_of_pair60_is_the_current_code(capsys):
    """§The book's pairs: pair60's row (both methods' height RMS ± SE, their ratio, the plan
    RMS) is what the printed `simulate` commands give now."""

    text = DOC.read_text(encoding="utf-8").split("### The book's pairs", 1)[1]
    row = next(x for x in text.splitlines() if x.startswith("| pair60 |"))
    got = {}
    for method in ("setup", "conventional"):
        args = ["simulate", "pair60", "--instrument", "sc1", "--method", method]
        assert f"stereoplotter {' '.join(args)} --trials 2000 --json" in text
        assert main([*args, "--trials", "2000", "--json", "--workers", "1", "-q"]) == 0
        grid = json.loads(capsys.readouterr().out)["evaluation"]["grid"]
        got[method] = (grid["height_error_rms_permille"], grid["plan_error_rms_map_mm"])
    (hs, ps), (hc, pc) = got["setup"], got["conventional"]
    want = (
        f"| pair60 | {hs['mean']:.4f} ± {hs['mean_se']:.4f} | {hc['mean']:.4f} ± "
        f"{hc['mean_se']:.4f} | {hs['mean'] / hc['mean']:.2f} | {ps['mean']:.4f} / "
        f"{pc['mean']:.4f} |"
    )
    assert row == want
