"""The commands layer: the CLI starts without the library, every command module
follows the protocol (``add_arguments``, ``run``), the one figure encoder is reproducible."""

from __future__ import annotations

import argparse
import subprocess
import sys
from typing import Any

import pytest
from matplotlib.figure import Figure

from stereoplotter.cli import COMMANDS, build_parser
from stereoplotter.commands.arguments import LibraryDefault
from stereoplotter.plotting.encode import figure_bytes
from stereoplotter.procedure.trials import DEFAULT_MEMORY_BUDGET_MB
from stereoplotter.verification.budget import DEFAULT_BUDGET_TRIALS

#: What building the parser must not load (the CLI starts fast; the web is an optional extra).
HEAVY = ("scipy", "matplotlib", "starlette", "pydantic", "yaml", "pyproj", "fpdf")


def test_importing_the_cli_loads_no_heavy_library():
    code = (
        "import sys, stereoplotter.cli as c; c.build_parser(); "
        f"print(','.join(m for m in {HEAVY!r} if m in sys.modules))"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=60
    )
    assert done.stdout.strip() == ""


def _leaves(parser: argparse.ArgumentParser, prefix: str = "") -> list[tuple[str, Any]]:
    found = []
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, child in action.choices.items():
                found += _leaves(child, f"{prefix}{name} ") or [(f"{prefix}{name}", child)]
    return found


def test_every_command_has_a_run_and_every_leaf_calls_one():
    for module in COMMANDS:
        assert callable(module.add_arguments) and callable(module.run), module.__name__
    leaves = _leaves(build_parser())
    before = {"info", "scenario check", "instrument show", "instrument test", "render", "setup",
              "check-sheet", "job to-scenario", "simulate", "verify", "budget", "demo",
              "exercise list", "exercise show", "session run", "grade", "trainer"}  # fmt: skip
    assert before <= {name for name, _ in leaves}  # every command of the monolithic cli.py
    for name, child in leaves:
        assert callable(child.get_default("func")), name


def test_a_library_default_is_shown_and_used_as_the_library_has_it(capsys):
    args = build_parser().parse_args(["simulate", "pair60", "--instrument", "sc1"])
    assert LibraryDefault.of(args.memory_mb) == DEFAULT_MEMORY_BUDGET_MB
    args = build_parser().parse_args(["budget", "pair60", "--instrument", "sc1"])
    assert LibraryDefault.of(args.trials) == DEFAULT_BUDGET_TRIALS
    with pytest.raises(SystemExit):
        build_parser().parse_args(["simulate", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    assert f"(default: {DEFAULT_MEMORY_BUDGET_MB} MB)" in help_text


def test_the_figure_encoder_gives_the_same_bytes_without_date_or_program():
    def figure():
        fig = Figure(figsize=(2, 2))
        fig.add_subplot().plot([0, 1], [1, 0])
        return fig

    png, pdf = figure_bytes(figure(), "png", dpi=50), figure_bytes(figure(), "pdf")
    assert png.startswith(b"\x89PNG\r\n\x1a\n") and pdf.startswith(b"%PDF")
    assert figure_bytes(figure(), "png", dpi=50) == png
    assert figure_bytes(figure(), "pdf") == pdf
    assert b"Software" not in png and b"matplotlib" not in pdf and b"CreationDate" not in pdf
