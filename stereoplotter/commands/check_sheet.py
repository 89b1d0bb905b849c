"""``stereoplotter check-sheet``: a trainee's own setup sheet against the program's."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from stereoplotter.commands.arguments import seed_int

__all__ = ["add_arguments", "run"]


def add_arguments(sub: Any) -> None:
    p = sub.add_parser(
        "check-sheet",
        help="check a trainee's own setup sheet against the program's and name the mistakes",
    )
    p.add_argument("sheet", help="the trainee's sheet (YAML in the layout of sheet.yaml)")
    p.add_argument("--scenario", required=True, help="the stereopair (a name or a YAML file)")
    p.add_argument("--instrument", required=True, help="sc1, spr3, sd3 or a YAML path")
    p.add_argument("--seed", type=seed_int, help="override the scenario's seed")
    p.add_argument("--json", action="store_true", help="print the check as JSON")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Exit 0 when every value is within its tolerance, 1 otherwise."""
    # imported here: the CLI loads no library module until a command runs (it starts fast)
    import numpy as np

    from stereoplotter.io.instrument_file import load_instrument
    from stereoplotter.io.scenario_file import load_scenario
    from stereoplotter.io.trainee_sheet import load_trainee_sheet
    from stereoplotter.report.plain_data import json_text
    from stereoplotter.report.sheet_check import check_dict, check_text
    from stereoplotter.setup.sheet import compute_setup_sheet
    from stereoplotter.setup.sheet_check import check_sheet

    trainee = load_trainee_sheet(args.sheet)
    spec = load_instrument(args.instrument)
    scenario = load_scenario(args.scenario)
    seed = scenario.seed if args.seed is None else args.seed
    sheet = compute_setup_sheet(scenario, spec, rng=np.random.default_rng(seed))
    result = check_sheet(sheet, spec, trainee)
    sys.stdout.write(json_text(check_dict(result)) if args.json else check_text(result))
    return 0 if result.passed else 1
