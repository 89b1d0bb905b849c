"""``stereoplotter render``: synthetic photos and eyepiece views as PNG files."""

from __future__ import annotations

import argparse
from typing import Any

from stereoplotter.commands.arguments import bounded_float, seed_int

__all__ = ["add_arguments", "run"]


def add_arguments(sub: Any) -> None:
    p = sub.add_parser(
        "render", help="render synthetic photos and eyepiece views as PNG (docs/imagery.md)"
    )
    p.add_argument("scenario", help="a scenario name (pair60) or YAML file")
    p.add_argument("--side", choices=["left", "right"], help="one photo only (default: both)")
    p.add_argument(
        "--at",
        type=bounded_float(-1e7, 1e7),
        nargs=2,
        metavar=("X", "Y"),
        help="ground point [m] the views centre on (default: below the centres' midpoint)",
    )
    p.add_argument(
        "--magnification",
        type=bounded_float(0.5, 60.0),
        default=6.0,
        help="eyepiece magnification of the views (default: 6)",
    )
    p.add_argument(
        "--pixel",
        type=bounded_float(0.02, 0.5),
        default=0.08,
        metavar="MM",
        help="pixel of the photo files [mm] (default 0.08: 3.6 s a photo; 0.02 takes a minute)",
    )
    p.add_argument("--seed", type=seed_int, help="texture seed (default: the scenario's)")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="folder for the PNG files")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    # imported here: the CLI loads no library module until a command runs (it starts fast)
    from stereoplotter.io.images import write_render
    from stereoplotter.io.scenario_file import load_scenario

    scenario = load_scenario(args.scenario)
    sides = (args.side,) if args.side else tuple(p.name for p in scenario.photos)
    written = write_render(
        scenario,
        args.output,
        sides=sides,
        at_m=tuple(args.at) if args.at else None,
        magnification=args.magnification,
        pixel_mm=args.pixel,
        seed=args.seed,
    )
    for path in written:
        print(path)
    return 0
