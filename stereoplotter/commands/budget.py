"""``stereoplotter budget``: the per-part error budget (:mod:`stereoplotter.verification.budget`).

The parser is here; the work (load → run → render → write) is
:mod:`stereoplotter.commands.error_budget`, imported when the command runs.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from stereoplotter.commands.arguments import LibraryDefault, bounded_int, seed_int

__all__ = ["MAX_BUDGET_TRIALS", "add_arguments", "run"]

#: Trials per configuration of ``budget``: one configuration's trials run in one chunk of the
#: default memory budget (``procedure.trials.chunk_trials_for``: 8 000 setup, 12 288 conventional).
MAX_BUDGET_TRIALS = 6000
#: The library's default trials per configuration (read when shown or used).
BUDGET_TRIALS = LibraryDefault("stereoplotter.verification.budget", "DEFAULT_BUDGET_TRIALS")


def add_arguments(sub: Any) -> None:
    p = sub.add_parser(
        "budget",
        help="per-part error budget: each instrument and operator error's contribution to the "
        "residual y-parallax, height and plan RMS of the simulated procedure",
    )
    p.add_argument("scenario", help="a stereopair scenario: a name (pair60) or a YAML file")
    p.add_argument("--instrument", required=True, help="sc1, spr3, sd3 or a YAML path")
    p.add_argument("--method", choices=("setup", "conventional"), default="setup")
    p.add_argument(
        "--trials",
        type=bounded_int(2, MAX_BUDGET_TRIALS),
        default=BUDGET_TRIALS,
        help="trials per configuration, the same trials in every configuration "
        f"(2 to {MAX_BUDGET_TRIALS}; default: %(default)s)",
    )
    p.add_argument("--seed", type=seed_int, help="override the scenario's seed")
    p.add_argument("--json", action="store_true", help="print the budget as JSON")
    p.add_argument("-o", "--output", help="write budget.md, budget.json and budget.png here")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    # imported here: the CLI loads no library module until a command runs (it starts fast)
    from stereoplotter.commands.error_budget import run_budget_command, write_budget
    from stereoplotter.progress import progress_bar
    from stereoplotter.report.budget import budget_json, budget_markdown

    def bar(total: int) -> Any:
        return progress_bar(total, "budget", unit="trial")

    trials = LibraryDefault.of(args.trials)
    budget = run_budget_command(args.scenario, args.instrument, args.method, trials, args.seed, bar)
    written = write_budget(budget, args.output) if args.output else []
    sys.stdout.write(budget_json(budget) if args.json else budget_markdown(budget))
    if written and not args.json:
        sys.stdout.write(f"written: {', '.join(written)} in {args.output}\n")
    return 0
