"""``stereoplotter exercise new NAME``: write a validated exercise file from options.

Every field of the exercise file (``docs/trainer.md``, "Exercises") has an option; the content
is validated exactly as a file read from disk (:func:`~stereoplotter.io.exercise_file.
exercise_from_mapping`), so a bad option is refused in one line naming the field, and the file is
written whole or not at all. ``--check`` also replays the robot trainee
(:func:`~stereoplotter.trainer.robot.robot_script`) and refuses an exercise it cannot pass.
"""

from __future__ import annotations

import argparse
from typing import Any

from stereoplotter.commands.arguments import bounded_int
from stereoplotter.trainer.exercise import (
    ERROR_MODES,
    EXERCISE_FORMAT,
    MODES,
    STAGES,
    TERRAINS,
    TILTS,
)

__all__ = ["add_parser", "exercise_content", "run"]


def add_parser(exs: Any) -> None:
    """The ``new`` action of ``stereoplotter exercise``."""
    e = exs.add_parser("new", help="write a validated exercise file from options")
    e.add_argument("name", help="the exercise's name (also the file name without .yaml)")
    e.add_argument("--title", help="one line shown to the trainee (default: from the options)")
    e.add_argument(
        "--level", type=bounded_int(1, 20), default=1, help="difficulty 1-20 (default 1)"
    )
    e.add_argument("--description", default="", help="the instructions shown to the trainee")
    e.add_argument("--instrument", default="sc1", help="sc1, spr3, sd3 or a file (default sc1)")
    e.add_argument(
        "--scenario", dest="scenario_name", default="pair60", help="a shipped scenario name"
    )
    e.add_argument("--method", default="setup", choices=tuple(STAGES), help="default setup")
    e.add_argument("--stages", default="all", help="'all' or one stage (1-5, C1-C4)")
    e.add_argument("--terrain", default="hilly", choices=TERRAINS, help="default hilly")
    e.add_argument(
        "--unusable-points",
        default="",
        help="standard points (1-6) on water or outside the overlap, comma-separated: makes "
        "the model incomplete",
    )
    e.add_argument("--errors", default="hidden", choices=ERROR_MODES, help="default hidden")
    e.add_argument("--tilt", default="small", choices=TILTS, help="default small")
    e.add_argument(
        "--readout", action="store_true", help="allow the numeric parallax read-out (practice)"
    )
    e.add_argument("--no-undo", action="store_true", help="no undo/redo")
    e.add_argument("--no-hints", action="store_true", help="no hints")
    e.add_argument("--mode", default="practice", choices=MODES, help="default practice")
    e.add_argument("--seed", default="per-trainee", help="an integer or per-trainee (default)")
    e.add_argument("-o", "--output", help="the file to write (default NAME.yaml here)")
    e.add_argument("--force", action="store_true", help="overwrite an existing file")
    e.add_argument(
        "--check", action="store_true", help="replay the robot trainee; refuse if it fails"
    )
    e.set_defaults(func=run)


def _points(text: str) -> list[Any]:
    out: list[Any] = []
    for part in (p.strip() for p in text.split(",")):
        if part:
            out.append(int(part) if part.isdigit() else part)
    return out


def exercise_content(args: argparse.Namespace) -> dict[str, Any]:
    """The exercise file's content from the options (validated later by the reader)."""
    unusable = _points(args.unusable_points)
    seed: Any = int(args.seed) if str(args.seed).isdigit() else args.seed
    title = args.title or (
        f"{args.method} method, stages {args.stages}, {args.instrument}, {args.terrain}"
    )
    return {
        "format": EXERCISE_FORMAT,
        "name": args.name,
        "title": title,
        "level": args.level,
        "description": args.description,
        "instrument": args.instrument,
        "scenario": args.scenario_name,
        "method": args.method,
        "stages": args.stages,
        "terrain": args.terrain,
        "model": "incomplete" if unusable else "complete",
        "unusable_points": unusable,
        "errors": args.errors,
        "tilt": args.tilt,
        "assists": {
            "parallax_readout": bool(args.readout),
            "undo": not args.no_undo,
            "hints": not args.no_hints,
        },
        "mode": args.mode,
        "seed": seed,
    }


def run(args: argparse.Namespace) -> int:
    # imported here: the CLI loads no library module until a command runs (it starts fast)
    from stereoplotter.errors import ConfigError
    from stereoplotter.io.exercise_file import exercise_from_mapping, write_exercise
    from stereoplotter.trainer.grading import grade
    from stereoplotter.trainer.robot import robot_script
    from stereoplotter.trainer.session import Session

    data = exercise_content(args)
    path = args.output or f"{args.name}.yaml"
    if args.check:
        exercise = exercise_from_mapping(data, path)
        session = Session.start(exercise, trainee="robot")
        for action in robot_script(session):
            session.act(action)
        overall = grade(session, population=0)["overall"]
        if not overall["passed"]:
            raise ConfigError(
                path,
                "(robot trainee)",
                "an exercise the robot trainee passes",
                f"score {overall['score']:.3f}",
            )
    write_exercise(path, data, overwrite=args.force)
    print(f"wrote {path}")
    return 0
