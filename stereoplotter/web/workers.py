"""The server's worker processes end with it, however it ends.

A worker process (grading, replays, photos) started by the server runs :func:`watch_parent`
first: a daemon thread that checks every :data:`CHECK_S` seconds whether the server that
started it is still its parent, and ends the worker at once when it is not (the server was
killed, ``kill -9`` included: nothing of the server runs then to stop its workers). A normal
stop (Ctrl-C) still stops them itself.
"""

from __future__ import annotations

import os
import threading
import time

__all__ = ["CHECK_S", "watch_parent"]

#: How often a worker looks for its server. [s]
CHECK_S = 0.5


def _orphaned(parent: int) -> bool:
    if os.getppid() != parent:  # re-parented: the server is gone
        return True
    try:
        os.kill(parent, 0)
    except ProcessLookupError:
        return True
    except PermissionError:  # alive, another user's (cannot happen for our own parent)
        return False
    return False


def _watch(parent: int, interval: float) -> None:
    while True:
        if _orphaned(parent):
            os._exit(0)  # no clean-up to run: the worker's work is the server's, now gone
        time.sleep(interval)


def watch_parent(parent: int, interval: float = CHECK_S) -> None:
    """Start the watch in this (worker) process: it ends when ``parent`` is gone."""
    threading.Thread(target=_watch, args=(parent, interval), daemon=True,
                     name="parent-watch").start()
