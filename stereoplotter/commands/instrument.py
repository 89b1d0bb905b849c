"""``stereoplotter instrument show|test``: an instrument's parameters; its kinematic self-test."""

from __future__ import annotations

import argparse
import math
import sys
from typing import Any

from stereoplotter.commands.arguments import bounded_float

__all__ = ["MAX_TILT_DEG", "add_arguments", "run"]

#: Tilts of the kinematic self-test: near-vertical photos, as in scenario files.
MAX_TILT_DEG = 15.0


def add_arguments(sub: Any) -> None:
    p = sub.add_parser("instrument", help="instrument specifications")
    inst = p.add_subparsers(dest="instrument_command", required=True, metavar="ACTION")
    s = inst.add_parser("show", help="print an instrument's parameters, documented or assumed")
    s.add_argument("name", help="sc1, spr3, sd3 or a path to an instrument YAML")
    s.add_argument("--json", action="store_true", help="print JSON instead of text")
    s.set_defaults(func=run)
    t = inst.add_parser(
        "test",
        help="kinematic acceptance on a synthetic grid pair (kinematics.md §5–§6): residual "
        "y-parallax per decentration variant and tilt",
    )
    t.add_argument("name", help="sc1, spr3, sd3 or a path to an instrument YAML")
    t.add_argument(
        "--tilts",
        type=bounded_float(-MAX_TILT_DEG, MAX_TILT_DEG),
        nargs="+",
        default=[0.5, 1.0, 3.0],
        metavar="DEG",
        help="tilt magnitudes [deg] (default: 0.5 1 3)",
    )
    t.add_argument(
        "--variants",
        nargs="+",
        default=["L", "A", "B", "B2", "S"],
        choices=["L", "A", "B", "B2", "S"],
        help="decentration variants",
    )
    t.add_argument("--json", action="store_true", help="print JSON instead of text")
    t.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    # imported here: the CLI loads no library module until a command runs (it starts fast)
    from stereoplotter.io.instrument_file import load_instrument
    from stereoplotter.procedure.selftest import format_selftest, run_kinematic_selftest
    from stereoplotter.report.plain_data import json_text
    from stereoplotter.spec.instrument_spec import format_instrument, instrument_to_dict

    spec = load_instrument(args.name)
    if args.instrument_command == "test":
        tilts = [math.radians(t) for t in args.tilts]
        result = run_kinematic_selftest(tilts=tilts, variants=tuple(args.variants), instrument=spec)
        result["instrument"] = spec.key
        sys.stdout.write(json_text(result) if args.json else format_selftest(result))
        return 0
    sys.stdout.write(json_text(instrument_to_dict(spec)) if args.json else format_instrument(spec))
    return 0
