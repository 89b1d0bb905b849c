"""``stereoplotter session run``: a trainee's session without a browser, and its log."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from stereoplotter.commands.arguments import seed_int

__all__ = ["add_arguments", "run"]


def add_arguments(sub: Any) -> None:
    p = sub.add_parser("session", help="run a trainee's session without a browser")
    ses = p.add_subparsers(dest="session_command", required=True, metavar="ACTION")
    r = ses.add_parser(
        "run",
        help="carry out the actions of a file (JSON lines or a JSON list; 'operator' for the "
        "simulated operator's own) and write the session log",
    )
    r.add_argument("exercise", help="an exercise name or YAML file")
    r.add_argument("--actions", required=True, metavar="FILE", help="actions file, or 'operator'")
    r.add_argument("-o", "--output", required=True, metavar="LOG", help="session log to write")
    r.add_argument("--trainee", default="trainee", help="trainee's name (per-trainee seeds)")
    r.add_argument("--seed", type=seed_int, help="seed when the exercise has none fixed")
    r.add_argument(
        "--keep-going", action="store_true", help="log a refused action and go on (default: stop)"
    )
    r.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    # imported here: the CLI loads no library module until a command runs (it starts fast)
    from stereoplotter.errors import TrainerError
    from stereoplotter.io.actions_file import read_actions
    from stereoplotter.io.exercise_file import load_exercise
    from stereoplotter.io.session_log import write_log
    from stereoplotter.trainer.session import Session

    session = Session.start(load_exercise(args.exercise), trainee=args.trainee, seed=args.seed)
    actions = (
        session.operator_script() if args.actions == "operator" else read_actions(args.actions)
    )
    refused = 0
    try:
        for action in actions:
            try:
                session.act(action)
            except TrainerError as exc:
                refused += 1
                if not args.keep_going:
                    print(f"error: {exc}", file=sys.stderr)
                    return 1
                print(f"refused: {exc}", file=sys.stderr)
    finally:
        write_log(args.output, session)
    state = session.state()
    print(
        f"{len(session.log)} actions ({refused} refused), stage {state['stage'] or 'all done'}; "
        f"log: {args.output}"
    )
    return 0
