"""Argument types and defaults shared by the command modules.

Every numeric option is range-checked by one of these ``type=`` functions: a bad value is one
usage line naming what was expected and what was found (argparse adds the option's name).
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from dataclasses import replace
from importlib import import_module
from typing import Any

__all__ = [
    "MAX_SCALE_DENOMINATOR",
    "MAX_SEED",
    "LibraryDefault",
    "add_fidelity_arguments",
    "bounded_float",
    "bounded_int",
    "fidelity_from_args",
    "non_negative_int",
    "positive_int",
    "scale_denominator",
    "seed_int",
]

#: The largest seed, as in scenario files (``seed``); numpy itself takes any integer ≥ 0.
MAX_SEED = 2**63 - 1
#: Scale denominators as the instrument gear sets allow (``gears.vertical_scale_denominators``).
MAX_SCALE_DENOMINATOR = 10_000_000


def bounded_int(low: int, high: int | None = None) -> Callable[[str], int]:
    """An argparse ``type=``: an integer in [low, high] (``high=None``: no upper end).

    The message names what was expected and what was found; argparse adds the option.
    """
    expected = f"an integer ≥ {low}" if high is None else f"an integer in [{low}, {high}]"

    def parse(text: str) -> int:
        try:
            value = int(text, 10)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {expected}, found {text!r}") from None
        if value < low or (high is not None and value > high):
            raise argparse.ArgumentTypeError(f"expected {expected}, found {value}")
        return value

    parse.__name__ = f"integer in [{low}, {high}]"
    return parse


def bounded_float(low: float, high: float) -> Callable[[str], float]:
    """An argparse ``type=``: a finite number in [low, high]."""
    expected = f"a number in [{low:g}, {high:g}]"

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {expected}, found {text!r}") from None
        if not (math.isfinite(value) and low <= value <= high):
            raise argparse.ArgumentTypeError(f"expected {expected}, found {text}")
        return value

    parse.__name__ = f"number in [{low:g}, {high:g}]"
    return parse


positive_int = bounded_int(1)
non_negative_int = bounded_int(0)
seed_int = bounded_int(0, MAX_SEED)
scale_denominator = bounded_int(1, MAX_SCALE_DENOMINATOR)


class LibraryDefault:
    """An option's default that is a constant of the library (``module.name``), imported only
    when shown (``--help`` of that command, ``%(default)s``) or used (:meth:`of`): building the
    parser loads no library module, so the CLI starts fast."""

    def __init__(self, module: str, name: str):
        self.module, self.name = module, name

    def value(self) -> Any:
        return getattr(import_module(self.module), self.name)

    def __str__(self) -> str:
        return str(self.value())

    @staticmethod
    def of(value: Any) -> Any:
        """``value`` itself, or the constant a :class:`LibraryDefault` stands for."""
        return value.value() if isinstance(value, LibraryDefault) else value


#: The mechanism switches of ``procedure.fidelity`` as options: flag → (dest, choices, what the
#: choices mean). Declared there (basis, default, the formula's setting); the parser repeats
#: only the names so that building it loads no library module.
_FIDELITY_FLAGS = (
    ("--bottom-stop", "bottom_stop", ("both_ways", "one_way", "free")),
    ("--bx-zero", "bx_zero", ("two_pointings", "exact")),
    ("--kappa", "kappa", ("y_parallax", "fiducials")),
    ("--tilts", "tilts", ("knob_fit", "least_squares")),
    ("--fit-scale", "fit_scale", ("as_set", "exact")),
    ("--stage3", "stage3", ("fuse", "bx_only", "none")),
)


def add_fidelity_arguments(p: argparse.ArgumentParser, linkage: bool = True) -> None:
    """The setup-data procedure's mechanism switches (``procedure.fidelity.MECHANISMS``):
    ``--as-formula`` sets every one to the formula's assumption, a flag each overrides it.
    ``linkage``: add ``--linkage`` too (``verify`` has its own)."""
    g = p.add_argument_group(
        "mechanism switches of the setup-data procedure (docs/accuracy.md: each with its basis "
        "and the setting the formulas (6.39)–(6.44) assume)"
    )
    g.add_argument(
        "--as-formula",
        action="store_true",
        help="every switch at the formula's assumption (bottom stop free, b_x zero from two "
        "pointings, κ from the fiducials, k_ω by least squares, the fits at the exact n, no "
        "stage-3 scaling, one pass per loop, independent linkage); a flag below overrides one",
    )
    for flag, dest, choices in _FIDELITY_FLAGS:
        g.add_argument(
            flag, dest=dest, choices=choices, default=None, help=f"default: {choices[0]}"
        )
    g.add_argument(
        "--passes",
        type=positive_int,
        default=None,
        help="every tolerance loop makes this many passes, no check stops it (default: until "
        "a check passes)",
    )
    if linkage:
        g.add_argument(
            "--linkage",
            choices=("drag", "independent"),
            default=None,
            help="knob–decentration linkage (default: the instrument file's)",
        )


def fidelity_from_args(args: argparse.Namespace) -> Any:
    """The :class:`~stereoplotter.procedure.fidelity.Fidelity` of the parsed switches."""
    # imported here: every command imports this module while the CLI builds its parser
    from stereoplotter.procedure.fidelity import Fidelity

    base = Fidelity.as_formula() if getattr(args, "as_formula", False) else Fidelity()
    changes = {
        dest: getattr(args, dest)
        for dest in (*(d for _, d, _ in _FIDELITY_FLAGS), "passes", "linkage")
        if getattr(args, dest, None) is not None
    }
    return replace(base, **changes)
