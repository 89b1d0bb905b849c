"""``stereoplotter setup``: the setup sheet (Table 24) of a stereopair, a block or a job.

The file decides the mode: a production job file (:mod:`.setup_job`), a block file of many
models (:mod:`.setup_block`), or a scenario of one stereopair (here): load → compute the sheet
(:func:`stereoplotter.setup.sheet.compute_setup_sheet`) → render (YAML, Markdown, the PDF and
PNG figure) → write, everything rendered before anything is written.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from stereoplotter.commands.arguments import scale_denominator, seed_int

__all__ = ["add_arguments", "run", "sheet_files", "sheet_summary"]


def add_arguments(sub: Any) -> None:
    p = sub.add_parser("setup", help="compute the setup sheet (Table 24) of a stereopair")
    p.add_argument(
        "scenario",
        help="a stereopair scenario (a name such as pair60, or a YAML file), a block file "
        "listing many stereopairs of one camera (one sheet per model), or a production job file "
        "(format: stereoplotter-job/1: one sheet and printable form per pair)",
    )
    p.add_argument(
        "--instrument",
        help="sc1, spr3, sd3 or a YAML path (required, except for a job file, which names its "
        "own instrument; given, it overrides the job's)",
    )
    p.add_argument(
        "-o",
        "--output",
        help="output folder for sheet.yaml, sheet.md, sheet.pdf, "
        "sheet.png (default: stereoplotter-setup; with --json "
        "nothing is written unless -o is given)",
    )
    p.add_argument(
        "--book-sign",
        action="store_true",
        help="use the printed sign of (6.4) for n_п (default: the geometric sign)",
    )
    p.add_argument(
        "--bz-scale-sense",
        type=int,
        choices=(1, -1),
        default=1,
        help="+1: the b_z scale grows when the right pivot rises (default); -1: the other way, "
        "as the printed minus of (6.11) implies",
    )
    p.add_argument("--horizontal-scale", type=scale_denominator, metavar="M", help="force M_г = M")
    p.add_argument("--vertical-scale", type=scale_denominator, metavar="M", help="force M_в = M")
    p.add_argument("--seed", type=seed_int, help="override the scenario's seed")
    p.add_argument("--json", action="store_true", help="print the sheet as JSON")
    p.add_argument(
        "--force",
        action="store_true",
        help="job file: write into an output folder that holds files, replacing the previous "
        "run's outputs as a whole (its stale pair folders removed)",
    )
    p.add_argument(
        "--strict",
        action="store_true",
        help="job file: exit 1 when any pair is refused (default: only when none is set up)",
    )
    p.add_argument(
        "--lang",
        choices=("ru", "en"),
        default="en",
        help="language of the forms and sheet.md: ru (the book's terms) or en (default)",
    )
    p.add_argument(
        "--rigorous",
        action="store_true",
        help="job forms: print the rigorous (3.17) mark targets and spans of both photos as the "
        "values to set (default: the book's (6.1)/(6.2), (6.5); the rigorous ones, the book's "
        "beside them, for a photo whose book values leave their tolerance)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    # imported here: the CLI loads no library module until a command runs (it starts fast)
    import numpy as np

    from stereoplotter.commands import setup_block, setup_job
    from stereoplotter.errors import StereoplotterError
    from stereoplotter.io.atomic_write import write_files
    from stereoplotter.io.instrument_file import load_instrument
    from stereoplotter.io.job_file import is_job_file
    from stereoplotter.io.scenario_file import load_scenario
    from stereoplotter.io.yaml_input import load_yaml_mapping
    from stereoplotter.report.plain_data import json_text
    from stereoplotter.report.sheet import sheet_to_dict
    from stereoplotter.setup.sheet import SetupOptions, compute_setup_sheet

    data, _ = load_yaml_mapping(args.scenario)
    if is_job_file(data):
        return setup_job.run(args)
    if args.instrument is None:
        raise StereoplotterError(
            f"{args.scenario}: --instrument: expected sc1, spr3, sd3 or a YAML path, found "
            "nothing (only a job file names its own instrument)"
        )
    if getattr(args, "rigorous", False):
        raise StereoplotterError(
            f"{args.scenario}: --rigorous: expected a job file (it sets the values of the job's "
            "forms), found a scenario or block file"
        )
    spec = load_instrument(args.instrument)
    if "models" in data or "models_csv" in data:
        return setup_block.run(args, spec)
    scenario = load_scenario(args.scenario)
    options = SetupOptions(
        book_sign_n_right=args.book_sign,
        horizontal_scale_denominator=args.horizontal_scale,
        vertical_scale_denominator=args.vertical_scale,
        bz_scale_sense=args.bz_scale_sense,
    )
    seed = scenario.seed if args.seed is None else args.seed
    sheet = compute_setup_sheet(scenario, spec, options, np.random.default_rng(seed))
    data = sheet_to_dict(sheet)
    data["seed"] = seed
    if args.json:
        sys.stdout.write(json_text(data))
    if args.output is None and args.json:
        return 0
    out = Path(args.output or "stereoplotter-setup")
    # everything rendered before anything is written
    files = sheet_files(sheet, data, getattr(args, "lang", "en"))
    write_files(out, files)
    if not args.json:
        sys.stdout.write(f"{sheet_summary(sheet)}\nwritten: {', '.join(files)} in {out}\n")
    return 0


def sheet_files(sheet: Any, data: dict[str, Any], lang: str = "en") -> dict[str, bytes]:
    """sheet.yaml, sheet.md, sheet.pdf and sheet.png of a setup sheet, rendered in memory
    (``data``: :func:`~stereoplotter.report.sheet.sheet_to_dict` with the seed; ``lang`` of
    sheet.md)."""
    # imported here: matplotlib and YAML load only for a command that writes a sheet
    import json

    from stereoplotter.io.yaml_output import yaml_text
    from stereoplotter.plotting.encode import figure_bytes
    from stereoplotter.plotting.figures import plot_setup_sheet
    from stereoplotter.report.plain_data import json_text
    from stereoplotter.report.sheet import sheet_markdown

    text = yaml_text(json.loads(json_text(data)), width=100)
    figure = plot_setup_sheet(sheet)
    pdf = figure_bytes(figure, "pdf", close=False)
    return {
        "sheet.yaml": text.encode("utf-8"),
        "sheet.md": sheet_markdown(sheet, lang).encode("utf-8"),
        "sheet.pdf": pdf,
        "sheet.png": figure_bytes(figure, "png", dpi=110),
    }


def sheet_summary(sheet: Any) -> str:
    """One line: the pair, the instrument, the scales, f_пр, n_л and n_п."""
    return (
        f"setup sheet of {sheet.scenario} on {sheet.instrument_title}: M_г = "
        f"1:{sheet.horizontal_scale_denominator}, M_в = 1:{sheet.vertical_scale_denominator}, "
        f"f_пр = {sheet.f_instrument_mm:.3f} mm, n_л = {sheet.n_left:.5f}, "
        f"n_п = {sheet.n_right:.5f}"
    )
