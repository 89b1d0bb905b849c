"""``stereoplotter verify``: the accuracy formulas (6.28)–(6.61) against rigorous forms and
Monte Carlo. The parser is here; the work (load → run → render → write) is
:mod:`stereoplotter.commands.verification`, imported when the command runs."""

from __future__ import annotations

import argparse
from typing import Any

from stereoplotter.commands.arguments import add_fidelity_arguments, bounded_int, seed_int

__all__ = ["MAX_VERIFY_TRIALS", "add_arguments", "run"]

#: Trials of one verification row are held in memory at once (8 bytes each, per row).
MAX_VERIFY_TRIALS = 1_000_000


def add_arguments(sub: Any) -> None:
    p = sub.add_parser(
        "verify",
        help="verify the accuracy formulas (6.28)–(6.61) against rigorous forms and Monte Carlo",
    )
    p.add_argument(
        "--trials",
        type=bounded_int(2, MAX_VERIFY_TRIALS),
        default=60000,
        help=f"Monte Carlo trials per row, 2 to {MAX_VERIFY_TRIALS} (default: %(default)s)",
    )
    p.add_argument("--seed", type=seed_int, default=20240601, help="seed of the Monte Carlo")
    p.add_argument("-o", "--output", help="write Markdown, CSV, JSON and plots into this folder")
    p.add_argument("--json", action="store_true", help="print the rows as JSON")
    p.add_argument(
        "--procedure-trials",
        type=bounded_int(0, MAX_VERIFY_TRIALS),
        default=None,
        help="trials of each procedure MC run (simulated operator); default: per configuration, "
        "enough for a 1 %% CI; 0 disables",
    )
    p.add_argument(
        "--instrument",
        default="sc1",
        help="instrument of the procedure MC, ideal and with its error terms (default: "
        "%(default)s, the book's SC-1)",
    )
    p.add_argument(
        "--linkage",
        choices=("drag", "independent"),
        default=None,
        help="knob–decentration linkage of the procedure MC's instrument: drag (turning k_α, "
        "k_ω moves the decentrations, decision D1) or independent (decentrations set before "
        "the k fits); default: the instrument file's correction.decentration_linkage",
    )
    add_fidelity_arguments(p, linkage=False)
    p.add_argument(
        "--geometry",
        metavar="FILE",
        help="YAML: a scenario (f, l, n, photo base p, overlap; also runs the procedure MC on it) "
        "or a mapping of f, l, n, c, p60, a60, p80, a80",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    # imported here: the CLI loads no library module until a command runs (it starts fast)
    from stereoplotter.commands.verification import run_verify_command

    return run_verify_command(args)
