"""``stereoplotter exercise list|show|new|sheet|grades``: the trainer's exercises."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from stereoplotter.commands import exercise_grades, exercise_new, exercise_sheet

__all__ = ["add_arguments", "exercise_row", "run"]


def add_arguments(sub: Any) -> None:
    p = sub.add_parser("exercise", help="trainer exercises (docs/trainer.md)")
    exs = p.add_subparsers(dest="exercise_command", required=True, metavar="ACTION")
    e = exs.add_parser("list", help="the exercises found, easiest first")
    e.add_argument("--json", action="store_true", help="print JSON instead of text")
    e.set_defaults(func=run)
    exercise_new.add_parser(exs)
    exercise_sheet.add_parser(exs)
    exercise_grades.add_parser(exs)
    e = exs.add_parser("show", help="an exercise's settings")
    e.add_argument("name", help="an exercise name (e01-setup-stage1) or YAML file")
    e.add_argument("--json", action="store_true", help="print JSON instead of text")
    e.set_defaults(func=run)


def exercise_row(ex: Any) -> dict[str, Any]:
    """An exercise's settings as plain data (``exercise show``, a row of ``exercise list``)."""
    return {
        "name": ex.name,
        "level": ex.level,
        "title": ex.title,
        "instrument": ex.instrument,
        "scenario": ex.scenario_name,
        "method": ex.method,
        "stages": list(ex.stages),
        "preset_stages": list(ex.preset_stages),
        "terrain": ex.terrain,
        "model": ex.model,
        "unusable_points": list(ex.unusable_points),
        "errors": ex.errors,
        "tilt": ex.tilt,
        "assists": ex.assists,
        "mode": ex.mode,
        "seed": ex.seed if ex.seed is not None else "per-trainee",
        "description": ex.description,
    }


def run(args: argparse.Namespace) -> int:
    # imported here: the CLI loads no library module until a command runs (it starts fast)
    from stereoplotter.io.exercise_file import load_exercise, shipped_exercises
    from stereoplotter.report.plain_data import json_text

    if args.exercise_command == "list":
        rows = sorted(
            (exercise_row(load_exercise(p)) for p in shipped_exercises()),
            key=lambda r: (r["level"], r["name"]),
        )
        if args.json:
            sys.stdout.write(json_text(rows))
            return 0
        for r in rows:
            stages = ",".join(r["stages"])
            print(
                f"{r['level']:>2}  {r['name']:<30} {r['instrument']:<5} {r['method']:<12} "
                f"stages {stages:<11} {r['mode']:<8} {r['title']}"
            )
        return 0
    row = exercise_row(load_exercise(args.name))
    if args.json:
        sys.stdout.write(json_text(row))
        return 0
    for key, value in row.items():
        print(f"{key}: {value}")
    return 0
