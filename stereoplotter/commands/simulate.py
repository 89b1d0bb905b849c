"""``stereoplotter simulate``: the simulated operator on a virtual instrument.

One procedure (no ``--trials``): the transcript, the evaluation of the built model (values and
per point), a Markdown summary and a parallax map. ``--trials T``: the trials run in chunks
under a memory budget (``procedure.trials``); their per-trial measures are spooled to disk
(``trial_store``) and summarised per measure with Monte Carlo standard errors; with an output
folder the per-trial columns go to ``trials.npz``, the transcript and the map are of trial 0.

The parser is here; the work (load → run → render → write) is
:mod:`stereoplotter.commands.simulation`, imported when the command runs.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from stereoplotter.commands.arguments import (
    LibraryDefault,
    add_fidelity_arguments,
    bounded_float,
    fidelity_from_args,
    positive_int,
    seed_int,
)

__all__ = ["MEMORY_BUDGET_MB", "add_arguments", "run"]

#: The memory budget of one chunk of trials, the library's (read when shown or used).
MEMORY_BUDGET_MB = LibraryDefault("stereoplotter.procedure.trials", "DEFAULT_MEMORY_BUDGET_MB")


def add_arguments(sub: Any) -> None:
    p = sub.add_parser(
        "simulate",
        help="run the simulated operator on a virtual instrument and evaluate the model",
    )
    p.add_argument("scenario", help="a stereopair scenario: a name (pair60) or a YAML file")
    p.add_argument("--instrument", required=True, help="sc1, spr3, sd3 or a YAML path")
    p.add_argument(
        "--method",
        choices=("setup", "conventional"),
        default="setup",
        help="the setup-data method (five stages) or the conventional method",
    )
    p.add_argument(
        "--errors",
        help="injected errors: a YAML of overrides, or 'zero' "
        "(default: the instrument's own, all assumed)",
    )
    p.add_argument(
        "--operator",
        help="the operator: 'zero' (no judgment, reading or setting error, no rounding), "
        "'sigma' (the free σ_p = σ_q = 0.010 mm judged in one look, before the eye model) or a "
        "YAML of OperatorModel fields (default: σ_p, σ_q from the operator's eye)",
    )
    p.add_argument(
        "--practice",
        choices=("operator", "book"),
        default="operator",
        help="'operator' (default): after a failed check the operator applies the book's "
        "remedies (repeat the setting, refine the relative orientation, refine scaling and "
        "levelling on control), bounded and logged; 'book': §27's task 1, each element set "
        "once, failed checks only recorded (both methods)",
    )
    p.add_argument(
        "--option",
        action="append",
        default=[],
        choices=("correction_unit", "automatic_coordinatograph"),
        help="fit an option of the SC complex to the SC-1 (repeatable; off by default): "
        "'correction_unit' corrects the image errors within ±100 µm to 3 µm RMS, "
        "'automatic_coordinatograph' drives the needle by a tracking servo (to 10 ×)",
    )
    p.add_argument("--seed", type=seed_int, help="override the scenario's seed")
    p.add_argument(
        "--trials", type=positive_int, help="run T trials at once (closed-form back-end)"
    )
    p.add_argument("--backend", choices=("closed-form", "pymunk"), default="closed-form")
    p.add_argument(
        "-o",
        "--output",
        help="write the transcript, the evaluation, a parallax map and (with --trials) the "
        "per-trial measures trials.npz into this folder (default: write nothing)",
    )
    p.add_argument(
        "--memory-mb",
        type=bounded_float(16.0, 1e6),  # below 16 MB no useful chunk fits
        default=MEMORY_BUDGET_MB,
        metavar="MB",
        help="memory budget of one chunk of trials (default: %(default)s MB)",
    )
    p.add_argument(
        "--workers",
        type=positive_int,
        help="processes that run the chunks of --trials (default: one per processor this "
        "process may use; the results do not depend on it)",
    )
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.add_argument(
        "--lang",
        choices=("ru", "en"),
        default="en",
        help="language of transcript.txt: ru (the book's terms, every record rendered through "
        "the glossary) or en (default)",
    )
    add_fidelity_arguments(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    # imported here: the CLI loads no library module until a command runs (it starts fast)
    from stereoplotter.commands.simulation import run_simulation_command
    from stereoplotter.progress import progress_bar
    from stereoplotter.report.plain_data import json_text

    with progress_bar(args.trials or 1, "simulate") as advance:
        outcome = run_simulation_command(
            args.scenario,
            instrument=args.instrument,
            method=args.method,
            errors=args.errors,
            operator=args.operator,
            practice=args.practice,
            options=args.option,
            seed=args.seed,
            trials=args.trials,
            backend=args.backend,
            output=args.output,
            memory_mb=LibraryDefault.of(args.memory_mb),
            progress=advance,
            lang=args.lang,
            workers=args.workers,
            fidelity=fidelity_from_args(args),
        )
    sys.stdout.write(json_text(outcome.summary) if args.json else outcome.text)
    return 0
