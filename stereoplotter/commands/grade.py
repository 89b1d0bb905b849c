"""``stereoplotter grade``: grade a session log (Markdown and JSON)."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from stereoplotter.commands.arguments import non_negative_int

__all__ = ["add_arguments", "run"]


def add_arguments(sub: Any) -> None:
    p = sub.add_parser("grade", help="grade a session log (Markdown and JSON)")
    p.add_argument("log", metavar="SESSION_LOG", help="a session log (JSON lines)")
    p.add_argument("--json", action="store_true", help="print JSON instead of Markdown")
    p.add_argument("-o", "--output", metavar="DIR", help="also write grade.md and grade.json here")
    p.add_argument(
        "--population",
        type=non_negative_int,
        default=10_000,
        help="simulated operators for the percentile (0: none; default: %(default)s)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    # imported here: the CLI loads no library module until a command runs (it starts fast)
    from stereoplotter.io.atomic_write import write_files
    from stereoplotter.io.exercise_file import exercise_from_mapping
    from stereoplotter.io.session_log import read_log
    from stereoplotter.progress import progress_bar
    from stereoplotter.report.grade import grade_json, grade_markdown
    from stereoplotter.trainer.grading import grade

    records = read_log(args.log)
    with progress_bar(args.population, "simulated operators", unit="operator") as advance:
        result = grade(
            records,
            population=args.population,
            progress=advance,
            read_exercise=exercise_from_mapping,
        )
    if args.output:
        write_files(
            args.output,
            {
                "grade.md": grade_markdown(result).encode("utf-8"),
                "grade.json": grade_json(result).encode("utf-8"),
            },
        )
    sys.stdout.write(grade_json(result) if args.json else grade_markdown(result))
    return 0
