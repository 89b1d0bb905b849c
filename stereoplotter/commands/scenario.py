"""``stereoplotter scenario check``: validate a scenario file and summarise it."""

from __future__ import annotations

import argparse
import sys
from typing import Any

__all__ = ["add_arguments", "run"]


def add_arguments(sub: Any) -> None:
    p = sub.add_parser("scenario", help="work with scenario files")
    scen = p.add_subparsers(dest="scenario_command", required=True, metavar="ACTION")
    c = scen.add_parser(
        "check",
        help="validate a scenario file and summarise it: photo scale, overlap, base, B/H, relief",
    )
    c.add_argument("file", help="a scenario name (pair60) or YAML file")
    c.add_argument("--json", action="store_true", help="print JSON instead of text")
    c.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    # imported here: the CLI loads no library module until a command runs (it starts fast)
    from stereoplotter.io.scenario_file import load_scenario
    from stereoplotter.report.plain_data import json_text
    from stereoplotter.report.scenario import format_summary
    from stereoplotter.scenario import summarize_scenario

    summary = summarize_scenario(load_scenario(args.file))
    sys.stdout.write(json_text(summary) if args.json else format_summary(summary))
    return 0
