"""A fair worker pool: jobs of many clients served round-robin, not first come, first served.

The server's actions and photo patches run on worker threads. With one queue, a client that
sends a hundred requests puts every other trainee's request behind them; here each job is
queued under its owner (a client address, then a session of that address), and a free worker
takes the next job of the next address in turn, and within the address of the next session in
turn. A session never has two jobs running at once (its actions keep their order). So a
trainee's request waits for at most one job of each other address with work queued, however
many that address has sent. With ``per_address``, an address never has more jobs running at
once than that, so with more workers than that one client cannot occupy them all: a newcomer's
job starts on the worker left free.

:class:`FairCache` keeps values per owner within one budget, evicting from the owner that
holds the most. :class:`Holds` counts refusals held back before they are sent (a client that
retries at once waits for its refusal), with a bound per client and in all.
"""

from __future__ import annotations

import threading
from collections import OrderedDict, deque
from collections.abc import Callable
from concurrent.futures import Future
from typing import Any

__all__ = ["FairCache", "FairPool", "Holds"]


class FairPool:
    """``workers`` threads serving jobs round-robin by address, then by session; at most
    ``per_address`` jobs of one address running at once (None: no cap)."""

    def __init__(self, workers: int = 2, name: str = "fair", per_address: int | None = None):
        self._cv = threading.Condition()
        self._per_address = per_address
        self._busy: dict[str, int] = {}  # jobs running per address
        self._jobs: dict[tuple[str, str], deque] = {}
        self._addresses: deque[str] = deque()
        self._sessions: dict[str, deque[str]] = {}
        self._running: set[tuple[str, str]] = set()
        self._closed = False
        self._threads = [
            threading.Thread(target=self._work, name=f"{name}-{i}", daemon=True)
            for i in range(workers)
        ]
        for t in self._threads:
            t.start()

    def submit(self, address: str, session: str, fn: Callable, *args: Any) -> Future:
        """Queue ``fn(*args)`` under ``address`` and ``session``; its future."""
        fut: Future = Future()
        with self._cv:
            if self._closed:
                fut.set_exception(RuntimeError("the server is stopping"))
                return fut
            key = (address, session)
            if key not in self._jobs:
                self._jobs[key] = deque()
                if address not in self._sessions:  # a newcomer is next in turn
                    self._sessions[address] = deque()
                    self._addresses.appendleft(address)
                self._sessions[address].appendleft(session)
            self._jobs[key].append((fut, fn, args))
            self._cv.notify()
        return fut

    def pending(self) -> int:
        """Jobs queued and not yet started."""
        with self._cv:
            return sum(len(q) for q in self._jobs.values())

    def _next(self) -> tuple[tuple[str, str], Any] | None:
        """The next job in turn (called with the lock held), or None."""
        for _ in range(len(self._addresses)):
            address = self._addresses[0]
            self._addresses.rotate(-1)
            if self._per_address is not None and self._busy.get(address, 0) >= self._per_address:
                continue
            ring = self._sessions[address]
            for _ in range(len(ring)):
                session = ring[0]
                ring.rotate(-1)
                key = (address, session)
                if key not in self._running and self._jobs[key]:
                    return key, self._jobs[key].popleft()
        return None

    def _forget(self, key: tuple[str, str]) -> None:
        """Drop an owner with nothing queued nor running (lock held)."""
        if self._jobs.get(key) or key in self._running:
            return
        address, session = key
        self._jobs.pop(key, None)
        ring = self._sessions.get(address)
        if ring is not None and session in ring:
            ring.remove(session)
            if not ring:
                del self._sessions[address]
                self._addresses.remove(address)

    def _work(self) -> None:
        while True:
            with self._cv:
                got = self._next()
                while got is None:
                    if self._closed:
                        return
                    self._cv.wait()
                    got = self._next()
                key, (fut, fn, args) = got
                self._running.add(key)
                self._busy[key[0]] = self._busy.get(key[0], 0) + 1
            try:
                if fut.set_running_or_notify_cancel():
                    try:
                        fut.set_result(fn(*args))
                    except BaseException as exc:  # handed to the caller through the future
                        fut.set_exception(exc)
            finally:
                with self._cv:
                    self._running.discard(key)
                    left = self._busy.pop(key[0]) - 1
                    if left:
                        self._busy[key[0]] = left
                    self._forget(key)
                    self._cv.notify_all()

    def shutdown(self, wait: bool = True) -> None:
        """Refuse new jobs, cancel the queued ones, stop the workers after their job."""
        with self._cv:
            self._closed = True
            for q in self._jobs.values():
                for fut, _, _ in q:
                    fut.cancel()
                q.clear()
            self._cv.notify_all()
        if wait:
            for t in self._threads:
                t.join(timeout=10)


class Holds:
    """Refused sockets held back before their refusal is sent: at most ``per_address`` of one
    client address and ``total`` of all at once (each holds a connection open)."""

    def __init__(self, per_address: int, total: int):
        self.per_address, self.total = per_address, total
        self.held: dict[str, int] = {}
        self.count = 0

    def take(self, address: str) -> bool:
        """Whether one more refusal of ``address`` may be held now (then counted)."""
        if self.count >= self.total or self.held.get(address, 0) >= self.per_address:
            return False
        self.held[address] = self.held.get(address, 0) + 1
        self.count += 1
        return True

    def give(self, address: str) -> None:
        """A held refusal of ``address`` was sent."""
        self.count -= 1
        left = self.held.pop(address) - 1
        if left:
            self.held[address] = left


class FairCache:
    """Values kept per owner within one budget of bytes: when the budget is exceeded, the
    owner holding the most bytes loses its oldest value. So a client filling the cache evicts
    its own values, never another's while it holds more than they do."""

    def __init__(self, budget_bytes: int):
        self.budget = budget_bytes
        self._owners: dict[str, OrderedDict[Any, bytes]] = {}
        self._bytes: dict[str, int] = {}
        self.total = 0
        self._lock = threading.Lock()

    def get(self, owner: str, key: Any) -> bytes | None:
        with self._lock:
            mine = self._owners.get(owner)
            if mine is None or key not in mine:
                return None
            mine.move_to_end(key)
            return mine[key]

    def put(self, owner: str, key: Any, value: bytes) -> None:
        with self._lock:
            mine = self._owners.setdefault(owner, OrderedDict())
            if key in mine:
                return
            mine[key] = value
            self._bytes[owner] = self._bytes.get(owner, 0) + len(value)
            self.total += len(value)
            while self.total > self.budget:
                richest = max(self._bytes, key=self._bytes.__getitem__)
                _, dropped = self._owners[richest].popitem(last=False)
                self._bytes[richest] -= len(dropped)
                self.total -= len(dropped)
                if not self._owners[richest]:
                    del self._owners[richest], self._bytes[richest]

    def owned(self, owner: str) -> list[Any]:
        """The keys ``owner`` has kept, oldest first."""
        with self._lock:
            return list(self._owners.get(owner, ()))
