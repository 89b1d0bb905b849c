"""Command-line interface: ``stereoplotter`` and ``python -m stereoplotter``.

Thin: it builds the parser from the command modules (:data:`COMMANDS`, each module's
``add_arguments``), parses, and calls the chosen command's ``run``
(:mod:`stereoplotter.commands`). Every expected failure (bad input file, degenerate geometry)
is printed as one ``error:`` line and exit code 1; a usage error exits with 2. No traceback
reaches the user.

The command modules import the library inside ``run``: ``stereoplotter --help``, ``--version``
and a bad argument answer without loading scipy, matplotlib, pydantic or the web server.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence
from typing import Any, NoReturn

from stereoplotter import __version__
from stereoplotter.commands import (
    budget,
    check_sheet,
    demo,
    exercise,
    grade,
    info,
    instrument,
    job,
    render,
    scenario,
    session,
    setup,
    simulate,
    study,
    trainer,
    triangulate,
    verify,
)
from stereoplotter.errors import StereoplotterError
from stereoplotter.io.paths import resolve_data_file, set_user_folders
from stereoplotter.progress import configure_logging

__all__ = ["COMMANDS", "build_parser", "full_parser", "main"]

#: The command modules, in the order ``--help`` lists them. A new command is a module of
#: :mod:`stereoplotter.commands` with ``add_arguments(sub)`` and ``run(args)``, added here.
COMMANDS = (
    info,
    scenario,
    instrument,
    render,
    setup,
    check_sheet,
    job,
    simulate,
    verify,
    budget,
    demo,
    study,
    triangulate,
    exercise,
    session,
    grade,
    trainer,
)


class _Parser(argparse.ArgumentParser):
    """An argument parser whose usage errors are one line, ``error: …``, exit code 2."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"error: {self.prog}: {message} (see {self.prog} --help)\n")


def _add_verbosity(parser: argparse.ArgumentParser, default: Any) -> None:
    parser.add_argument(
        "-v",
        "--verbose",
        action="count",
        default=default,
        help="log what is done on stderr (-v: steps, -vv: details)",
    )
    parser.add_argument(
        "-q",
        "--quiet",
        action="store_true",
        default=default,
        help="no progress bar, warnings and errors only",
    )


def build_parser() -> argparse.ArgumentParser:
    """The command line: every command's subparser, -v/--quiet before the command only."""
    parser = _Parser(
        prog="stereoplotter",
        description="Virtual SC-1, SPR-3 and SD-3 stereoplotters and their setup data "
        "(Kushtin & Lyskov 1984, ch. 6).",
    )
    parser.add_argument("--version", action="version", version=f"stereoplotter {__version__}")
    parser.add_argument(
        "--data",
        action="append",
        default=[],
        metavar="DIR",
        help="a folder of your own instruments/ and scenarios/, searched by name before the "
        "shipped ones (may be repeated; also $STEREOPLOTTER_DATA, separated by os.pathsep)",
    )
    _add_verbosity(parser, argparse.SUPPRESS)
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for command in COMMANDS:
        command.add_arguments(sub)
    return parser


def _all_subparsers(parser: argparse.ArgumentParser) -> list[argparse.ArgumentParser]:
    found = []
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for child in action.choices.values():
                found += [child, *_all_subparsers(child)]
    return found


def full_parser() -> argparse.ArgumentParser:
    """The parser with -v/--quiet accepted before or after the command."""
    parser = build_parser()
    for child in _all_subparsers(parser):
        _add_verbosity(child, argparse.SUPPRESS)
    return parser


def _resolve_data_arguments(args: argparse.Namespace) -> None:
    """Apply ``--data`` and turn scenario names (``pair60``) into files; instrument names are
    resolved by :func:`~stereoplotter.io.instrument_file.load_instrument` itself."""
    set_user_folders(args.data)
    for attribute in ("scenario", "file", "geometry"):  # setup/simulate/demo, check, verify
        if getattr(args, attribute, None):
            setattr(args, attribute, str(resolve_data_file("scenarios", getattr(args, attribute))))


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``stereoplotter`` command. Returns the exit code."""
    try:
        args = full_parser().parse_args(argv)
    except KeyboardInterrupt:
        print("error: interrupted", file=sys.stderr)
        return 130
    configure_logging(getattr(args, "verbose", 0), getattr(args, "quiet", False))
    try:
        _resolve_data_arguments(args)
        return args.func(args)
    except KeyboardInterrupt:  # Ctrl-C: one line (a command that writes says what it kept)
        print("error: interrupted", file=sys.stderr)
        return 130
    except StereoplotterError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    except OSError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    except Exception as exc:  # a bug: say so in one line, the traceback only on request
        if os.environ.get("STEREOPLOTTER_DEBUG"):
            raise
        print(
            f"error: internal error ({type(exc).__name__}: {exc}); this is a bug in "
            "stereoplotter: please report it with the command you ran (set "
            "STEREOPLOTTER_DEBUG=1 to see the traceback)",
            file=sys.stderr,
        )
        return 3


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
