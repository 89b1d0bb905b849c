"""``stereoplotter exercise sheet NAME``: the exercise's own setup sheet, as its page shows it
(:func:`stereoplotter.report.exercise_sheet.exercise_sheet`)."""

from __future__ import annotations

import argparse
import sys
from typing import Any

__all__ = ["add_parser", "run"]


def add_parser(exs: Any) -> None:
    """The ``sheet`` action of ``stereoplotter exercise``."""
    e = exs.add_parser("sheet", help="the exercise's own setup sheet (what its page shows)")
    e.add_argument("name", help="an exercise name (e03-setup-stage2) or YAML file")
    e.add_argument("--json", action="store_true", help="print JSON instead of Markdown")
    e.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    # imported here: the CLI loads no library module until a command runs (it starts fast)
    from stereoplotter.io.exercise_file import load_exercise
    from stereoplotter.report.exercise_sheet import exercise_sheet
    from stereoplotter.report.plain_data import json_text

    data = exercise_sheet(load_exercise(args.name))
    if args.json:
        sys.stdout.write(json_text(data))
    else:
        sys.stdout.write(data["markdown"])
    return 0
