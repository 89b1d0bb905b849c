"""``stereoplotter exercise grades``: the grades table of ``docs/trainer.md``.

For every exercise found (shipped and user folders, easiest first) three trainees on the
exercise's own seed (a per-trainee exercise: the trainee "robot"):

* **robot** — the robot trainee's script (:func:`~stereoplotter.trainer.robot.robot_script`:
  the exact simulated operator, compacted and finished) replayed through a session;
* **operator** — the simulated operator with its judgment errors (the grade's par: its score,
  and its points by the same rule, no hints);
* **hint 3 then claim** — in every stage, a hint of level 3 (show me) and the claim (an
  incomplete model refuses the claim without the substitutes: the trainee stops there).

Each is graded with ``grade(population=0)``: score (largest value/tolerance), points after the
hint cost, passed.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

__all__ = ["add_parser", "grades_markdown", "grades_rows", "run"]


def add_parser(exs: Any) -> None:
    """The ``grades`` action of ``stereoplotter exercise``."""
    e = exs.add_parser(
        "grades", help="grade the robot, the simulated operator and 'hint 3 then claim'"
    )
    e.add_argument("names", nargs="*", help="exercise names (default: every one found)")
    e.add_argument("--json", action="store_true", help="print JSON instead of Markdown")
    e.set_defaults(func=run)


def _row(exercise: Any) -> dict[str, Any]:
    # imported here: the CLI loads no library module until a command runs (it starts fast)
    from stereoplotter.errors import TrainerError
    from stereoplotter.trainer.grade_tables import PASS_POINTS, outcome_points
    from stereoplotter.trainer.grading import grade
    from stereoplotter.trainer.robot import robot_script
    from stereoplotter.trainer.session import Session

    robot = Session.start(exercise, trainee="robot")
    script = robot_script(robot)
    for action in script:
        robot.act(action)
    g = grade(robot, population=0)["overall"]
    lazy = Session.start(exercise, trainee="robot")
    for stage in exercise.stages:
        if exercise.allows("hints"):
            lazy.act({"kind": "hint", "level": 3})
        try:
            lazy.act({"kind": "claim", "step": stage})
        except TrainerError:  # an incomplete model's claim wants the substitutes: it stops here
            break
    h = grade(lazy, population=0)["overall"]
    par_points = outcome_points(g["par_score"] if g["par_score"] is not None else float("inf"))
    return {
        "name": exercise.name,
        "level": exercise.level,
        "instrument": exercise.spec.key,
        "method": exercise.method,
        "stages": ",".join(exercise.stages),
        "mode": exercise.mode,
        "robot_actions": len(script),
        "robot": {"score": g["score"], "points": g["points"], "passed": g["passed"]},
        "operator": {
            "score": g["par_score"],
            "points": par_points,
            "passed": bool(par_points >= PASS_POINTS and (g["par_score"] or 2.0) <= 1.0),
        },
        "hint3_claim": {
            "score": h["score"],
            "points": h["points"],
            "passed": h["passed"],
            "hints_allowed": exercise.allows("hints"),
        },
    }


def grades_rows(exercises: list[Any]) -> list[dict[str, Any]]:
    """One row per exercise (see the module docstring)."""
    return [_row(e) for e in sorted(exercises, key=lambda e: (e.level, e.name))]


def _cell(g: dict[str, Any]) -> str:
    verdict = "passed" if g["passed"] else "failed"
    score = "∞" if g["score"] is None else f"{g['score']:.2f}"  # JSON's null: not finite
    return f"{score} / {g['points']:.0f} / {verdict}"


def grades_markdown(rows: list[dict[str, Any]]) -> str:
    """The table of ``docs/trainer.md`` (score / points / verdict in each column)."""
    lines = [
        "| exercise | level | instrument | stages | mode | robot (actions) | operator | "
        "hint 3 then claim |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        h = r["hint3_claim"]
        lazy = _cell(h) if h["hints_allowed"] else f"{_cell(h)} (no hints: claim only)"
        lines.append(
            f"| {r['name']} | {r['level']} | {r['instrument']} | {r['stages']} | {r['mode']} | "
            f"{_cell(r['robot'])} ({r['robot_actions']}) | {_cell(r['operator'])} | {lazy} |"
        )
    return "\n".join(lines) + "\n"


def run(args: argparse.Namespace) -> int:
    # imported here: the CLI loads no library module until a command runs (it starts fast)
    from stereoplotter.io.exercise_file import load_exercise, shipped_exercises
    from stereoplotter.report.plain_data import json_text

    names = args.names or [str(p) for p in shipped_exercises()]
    rows = grades_rows([load_exercise(n) for n in names])
    sys.stdout.write(json_text(rows) if args.json else grades_markdown(rows))
    return 0
