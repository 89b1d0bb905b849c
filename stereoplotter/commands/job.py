"""``stereoplotter job to-scenario``: one pair of a production job as a scenario."""

from __future__ import annotations

import argparse
import sys
from typing import Any

__all__ = ["add_arguments", "run"]


def add_arguments(sub: Any) -> None:
    p = sub.add_parser("job", help="work with production job files (docs/production.md)")
    jobs = p.add_subparsers(dest="job_command", required=True, metavar="ACTION")
    j = jobs.add_parser(
        "to-scenario",
        help="write one pair of a job as a scenario for simulation: the job's orientation, "
        "points and map sheet, a terrain fitted to the control heights (said in the YAML)",
    )
    j.add_argument("job", help="a job file (format: stereoplotter-job/1)")
    j.add_argument("pair", help="the pair as LEFT-RIGHT photo numbers, e.g. 101-102")
    j.add_argument("-o", "--output", required=True, metavar="FILE", help="the scenario YAML")
    j.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """One pair of a job as a scenario (:mod:`stereoplotter.io.job_scenario`)."""
    # imported here: the CLI loads no library module until a command runs (it starts fast)
    from stereoplotter.io.job_file import load_job
    from stereoplotter.io.job_scenario import write_job_scenario

    doc, fit = write_job_scenario(load_job(args.job), args.pair, args.output)
    if getattr(args, "quiet", False):  # -q: warnings and errors only
        return 0
    sys.stdout.write(
        f"scenario {doc['name']}: {len(doc['points'])} points, terrain {fit.kind} fitted to "
        f"{fit.points} control heights (rms {fit.rms_m:.3f} m, max {fit.max_m:.3f} m)\n"
        f"written: {args.output}\n"
    )
    return 0
