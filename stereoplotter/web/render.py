"""Photo patches rendered in worker processes, one process for each patch thread.

Rendering a patch (sampling the tile pyramid, rendering the tiles it needs, encoding the PNG)
holds the interpreter's lock for most of its time: in the server's process it would slow the
event loop and the session actors of every trainee while one client asks for patches. Here
each thread of the registry's fair patch pool owns one worker process and hands it the render;
the thread only waits. The workers run at a lower priority than the server
(:data:`RENDER_NICENESS`). A worker is given an exercise's photos (the tile pyramid built once by
the registry) the first time it renders a patch of them, and keeps them.

Without processes (the tests' in-memory server) a render runs in the calling thread.
"""

from __future__ import annotations

import itertools
import os
import threading
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from multiprocessing import get_context
from typing import Any

from stereoplotter.web import core
from stereoplotter.web.fair import FairCache
from stereoplotter.web.workers import watch_parent

__all__ = ["PATCHES_KEPT_BYTES", "RENDER_NICENESS", "Renderers"]

#: Niceness a render worker adds to its own (Unix ``nice``): renders take the processor only
#: when the server's event loop and session actors leave it, so a client asking for patches
#: without pause cannot slow the other trainees' actions, only share the render workers. [—]
RENDER_NICENESS = 5

# --- in the worker process --------------------------------------------------------------------

_CACHES: dict[Any, Any] = {}


def _keep(key: Any, cache: Any) -> None:
    _CACHES[key] = cache


#: Patches a worker keeps, per client address, within one budget (``fair.FairCache``: a
#: client asking for many evicts its own before another's). [bytes]
PATCHES_KEPT_BYTES = 32 * 2**20
_KEPT = FairCache(PATCHES_KEPT_BYTES)


def _render(key: Any, owner: str, *args: Any) -> bytes:
    return _kept_or_made(_KEPT, owner, key, _CACHES[key], args)


def _kept_or_made(kept: FairCache, owner: str, key: Any, cache: Any, args: tuple) -> bytes:
    """The patch ``args`` of the photos ``cache``: the one ``owner`` was given before, or made
    now (``core.photo_patch``) and kept for it."""
    png = kept.get(owner, (key, *args))
    if png is None:
        png = core.photo_patch(cache, *args)
        kept.put(owner, (key, *args), png)
    return png


def _start(parent: int) -> None:
    """A render worker's start: it ends with the server, and yields the CPU to it."""
    watch_parent(parent)
    os.nice(RENDER_NICENESS)


def _worker() -> ProcessPoolExecutor:
    # spawn: the server's threads are never forked
    return ProcessPoolExecutor(max_workers=1, mp_context=get_context("spawn"),
                               initializer=_start, initargs=(os.getpid(),))


# --- in the server ---------------------------------------------------------------------------


class Renderers:
    """``slots`` worker processes (``processes``; else in the calling thread): a calling thread
    is given a process of its own the first time it renders, so the pool's threads never
    share one."""

    def __init__(self, slots: int, processes: bool):
        self._in_processes = processes
        self._executors: list[ProcessPoolExecutor] = []
        self._kept: list[set] = []
        if processes:
            for _ in range(slots):
                self._executors.append(_worker())
                self._kept.append(set())
        self._next = itertools.count()
        self._closed = False
        self._kept_here = FairCache(PATCHES_KEPT_BYTES)  # without processes
        self._mine = threading.local()

    def offer(self, key: Any, cache: Any) -> None:
        """Hand the photos ``cache`` (known as ``key``) to every worker ahead of their first
        patch (queued before any render of them: each worker takes its jobs in order)."""
        if self._closed:
            return
        for slot, executor in enumerate(self._executors):
            if key not in self._kept[slot]:
                executor.submit(_keep, key, cache)
                self._kept[slot].add(key)

    def render(self, owner: str, key: Any, cache: Any, side: str, x_mm: float, y_mm: float,
               mag: float, size_px: int) -> bytes:
        """PNG of a patch of the photos ``cache`` (known as ``key``) for the client ``owner``
        (its address): ``core.photo_patch``, or the same patch kept from before."""
        args = (side, x_mm, y_mm, mag, size_px)
        if not self._in_processes:
            return _kept_or_made(self._kept_here, owner, key, cache, args)
        slot = getattr(self._mine, "slot", None)
        if slot is None:
            slot = self._mine.slot = next(self._next) % len(self._executors)
        try:
            return self._in(slot, owner, key, cache, args)
        except BrokenProcessPool:  # the worker died (killed, out of memory): a new one
            if self._closed:
                raise
            self._executors[slot] = _worker()
            self._kept[slot] = set()
            return self._in(slot, owner, key, cache, args)

    def _in(self, slot: int, owner: str, key: Any, cache: Any, args: tuple) -> bytes:
        executor = self._executors[slot]
        if key not in self._kept[slot]:
            executor.submit(_keep, key, cache).result()
            self._kept[slot].add(key)
        return executor.submit(_render, key, owner, *args).result()

    def this_threads_worker(self) -> ProcessPoolExecutor | None:
        """The worker process that renders for the calling thread (None before its first
        render, or without processes)."""
        slot = getattr(self._mine, "slot", None)
        return None if slot is None else self._executors[slot]

    def shutdown(self) -> None:
        """Stop the worker processes at once (a render in progress is abandoned)."""
        self._closed = True
        for executor in self._executors:
            workers = list((getattr(executor, "_processes", None) or {}).values())
            executor.shutdown(wait=False, cancel_futures=True)
            for proc in workers:
                proc.terminate()
