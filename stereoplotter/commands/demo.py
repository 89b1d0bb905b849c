"""``stereoplotter demo``: the main job on the default scenario, its results in a folder.

The scenario's foundation (exterior orientation, intersection, similarity), the setup sheet,
the simulated operator (a stereopair) and the layout figure: load → run → render → write, every
file rendered before any is written.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from stereoplotter.commands.arguments import seed_int
from stereoplotter.io.paths import DEFAULT_SCENARIO

__all__ = ["add_arguments", "run"]


def add_arguments(sub: Any) -> None:
    p = sub.add_parser(
        "demo",
        help="run the main job on the default scenario (or --scenario) "
        "and write its results into a folder",
    )
    p.add_argument(
        "-o", "--output", default="stereoplotter-demo", help="output folder (default: %(default)s)"
    )
    p.add_argument(
        "--scenario",
        default=DEFAULT_SCENARIO,
        help="scenario name or file (default: the shipped %(default)s)",
    )
    p.add_argument("--seed", type=seed_int, help="override the scenario's seed")
    p.add_argument(
        "--instrument", default="sc1", help="instrument of the setup sheet (default: %(default)s)"
    )
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    # imported here: the CLI loads no library module until a command runs (it starts fast)
    from stereoplotter.progress import step_progress

    with step_progress("demo") as step:
        return _demo_steps(args, step)


def _demo_steps(args: argparse.Namespace, step: Any) -> int:
    """The demo's work, reporting ``step(done, 4, what)`` as it goes."""
    # imported here, as in run()
    import numpy as np

    from stereoplotter.commands.setup import sheet_files, sheet_summary
    from stereoplotter.io.atomic_write import write_files
    from stereoplotter.io.instrument_file import load_instrument
    from stereoplotter.io.scenario_file import load_scenario
    from stereoplotter.plotting.encode import figure_bytes
    from stereoplotter.plotting.figures import plot_scenario_layout
    from stereoplotter.report.demo import format_demo, measurements_csv
    from stereoplotter.report.plain_data import json_text
    from stereoplotter.report.sheet import sheet_to_dict
    from stereoplotter.scenario.foundation import run_foundation
    from stereoplotter.setup.sheet import SetupRefusal, compute_setup_sheet

    path = Path(args.scenario)  # main() has resolved a name (default: the shipped pair60)
    scenario = load_scenario(path)
    spec = load_instrument(args.instrument)
    seed = scenario.seed if args.seed is None else args.seed
    result = run_foundation(scenario, np.random.default_rng(seed))
    measurements = result.pop("measurements")
    result["seed"] = seed
    text = format_demo(result)
    step(1, 4, "setup sheet")
    files: dict[str, bytes] = {}
    try:
        sheet = compute_setup_sheet(scenario, spec, rng=np.random.default_rng(seed))
    except SetupRefusal as exc:
        result["setup_sheet"] = {"refused": str(exc)}
        text += f"\nsetup sheet on {spec.title}: refused: {exc}\n"
    else:
        data = sheet_to_dict(sheet)
        data["seed"] = seed
        result["setup_sheet"] = data
        files.update(sheet_files(sheet, data))
        text += f"\n{sheet_summary(sheet)} (sheet.md, sheet.pdf)\n"
    step(2, 4, "simulated operator")
    if scenario.is_stereopair and "refused" not in result["setup_sheet"]:
        text += _simulation(args, path, seed, result)
    step(3, 4, "figures")
    layout = figure_bytes(plot_scenario_layout(scenario, result), "png", dpi=110)
    step(4, 4, "done")
    files.update(
        {
            "result.json": json_text(result).encode("utf-8"),
            "summary.md": text.encode("utf-8"),
            "measurements.csv": measurements_csv(scenario, measurements).encode("utf-8"),
            "layout.png": layout,
        }
    )
    out = Path(args.output)
    write_files(out, files)
    if args.json:
        sys.stdout.write(json_text(result))
    else:
        sys.stdout.write(text)
        sys.stdout.write(f"\nwritten: {', '.join(sorted(files))} in {out}\n")
    return 0


def _simulation(args: argparse.Namespace, path: Path, seed: int, result: dict) -> str:
    """Run ``simulate`` into ``OUTPUT/simulate``; its summary joins ``result``; the text."""
    # imported here, as in run()
    from stereoplotter.commands.simulation import run_simulation_command
    from stereoplotter.report.simulation import tolerance_note

    sim = run_simulation_command(
        path, instrument=args.instrument, seed=seed, output=Path(args.output) / "simulate"
    )
    result["simulation"] = sim.summary
    # name the sub-folder, not the output path: the summary stays the same wherever written
    text = "\n" + sim.text.replace(str(Path(args.output) / "simulate"), "simulate/")
    return text + "\n" + tolerance_note(sim.summary) + "\n"
