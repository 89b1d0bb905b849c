"""``stereoplotter trainer``: serve the browser trainer (the extra ``stereoplotter[trainer]``)."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from stereoplotter.commands.arguments import non_negative_int

__all__ = ["add_arguments", "run"]


def add_arguments(sub: Any) -> None:
    p = sub.add_parser(
        "trainer",
        help="serve the browser trainer (needs the extra stereoplotter[trainer]; docs/trainer.md)",
    )
    p.add_argument(
        "--host", default="127.0.0.1", help="address to listen on (default: %(default)s)"
    )
    p.add_argument(
        "--port",
        type=non_negative_int,
        default=0,
        help="port (default: 0, a free port chosen by the system; the address is printed)",
    )
    p.add_argument(
        "--token",
        help="the instructor's token (default: the one kept hashed in the data folder; made "
        "and printed on the first start)",
    )
    p.add_argument(
        "--rotate-token",
        action="store_true",
        help="make a new instructor token (printed once; the old one stops working)",
    )
    p.add_argument(
        "--public-url",
        metavar="URL",
        help="the address trainees use behind a reverse proxy, e.g. https://class.example "
        "(its Host and Origin accepted, X-Forwarded-* headers of a local proxy trusted)",
    )
    p.add_argument(
        "--data-dir",
        metavar="DIR",
        help="folder of the trainer's SQLite file: sessions, logs, grades (default: "
        "~/.local/share/stereoplotter/trainer, or $XDG_DATA_HOME/stereoplotter/trainer)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    try:
        # imported here: the web server (Starlette) is an optional extra, loaded only to serve
        from stereoplotter.web.server import serve
    except ImportError as exc:
        print(
            f"error: the browser trainer needs the extra stereoplotter[trainer] "
            f"(pip install 'stereoplotter[trainer]'); missing module {exc.name}",
            file=sys.stderr,
        )
        return 1
    try:
        serve(args.host, args.port, args.token, args.data_dir, public_url=args.public_url,
              rotate_token=args.rotate_token)
    except OSError as exc:
        print(
            f"error: trainer: cannot listen on {args.host}:{args.port} ({exc.strerror or exc})",
            file=sys.stderr,
        )
        return 1
    return 0
