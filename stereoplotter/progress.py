"""Progress bars and log verbosity of the command line (tqdm and :mod:`logging`).

The library reports progress through plain callbacks (``progress(n)``: n more units done); the
command line turns them into a tqdm bar on stderr. A bar is shown only when stderr is a terminal
and ``--quiet`` was not given, so pipes, files and CI logs stay clean.
"""

from __future__ import annotations

import logging
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from tqdm import tqdm

__all__ = ["bars_enabled", "configure_logging", "progress_bar", "step_progress"]

_state = {"quiet": False}


class _StderrHandler(logging.StreamHandler):
    """A stream handler that writes to whatever ``sys.stderr`` is when a record comes."""

    @property  # type: ignore[override]
    def stream(self):
        return sys.stderr

    @stream.setter
    def stream(self, value) -> None:
        pass


def configure_logging(verbosity: int, quiet: bool) -> None:
    """``-v``: INFO, ``-vv``: DEBUG log lines on stderr; ``--quiet``: warnings only, no bars.

    Configures the ``stereoplotter`` logger only (one stderr handler, added once), so a host
    program's or a test's own logging set-up is left alone.
    """
    _state["quiet"] = quiet
    level = logging.WARNING
    if not quiet and verbosity >= 2:
        level = logging.DEBUG
    elif not quiet and verbosity == 1:
        level = logging.INFO
    logger = logging.getLogger("stereoplotter")
    logger.setLevel(level)
    if not any(getattr(h, "_stereoplotter", False) for h in logger.handlers):
        handler = _StderrHandler()
        handler.setFormatter(logging.Formatter("%(levelname)s %(name)s: %(message)s"))
        handler._stereoplotter = True  # type: ignore[attr-defined]
        logger.addHandler(handler)


def bars_enabled() -> bool:
    """Whether a progress bar would be drawn now (stderr a terminal, not ``--quiet``)."""
    return not _state["quiet"] and sys.stderr.isatty()


@contextmanager
def progress_bar(
    total: int, description: str, unit: str = "trial"
) -> Iterator[Callable[[int], None]]:
    """A callback ``advance(n)`` drawing a bar of ``total`` units on stderr (or doing nothing)."""
    if not bars_enabled():
        yield lambda n: None
        return
    # imported here: a command that draws no bar (`info`, `--quiet`, a pipe) does not load tqdm
    from tqdm import tqdm

    with tqdm(total=total, desc=description, unit=unit, file=sys.stderr, leave=False) as bar:
        yield bar.update


@contextmanager
def step_progress(description: str) -> Iterator[Callable[[int, int, str], None]]:
    """A callback ``step(done, total, label)`` for work counted in steps (rows, stages)."""
    bar: list[tqdm] = []

    def step(done: int, total: int, label: str) -> None:
        if not bars_enabled():
            return
        if not bar:
            # imported here: a command that draws no bar does not load tqdm
            from tqdm import tqdm

            bar.append(
                tqdm(total=total, desc=description, unit="step", file=sys.stderr, leave=False)
            )
        bar[0].set_postfix_str(label, refresh=False)
        bar[0].update(done - bar[0].n)

    try:
        yield step
    finally:
        if bar:
            bar[0].close()
