"""A fair worker pool: the job of the session with the least recent work first, not first come,
first served.

The server's actions and photo patches run on worker threads. With one queue, a client that
sends a hundred requests puts every other trainee's request behind them; here each job is
queued under its owner (a client address, then a session of that address), and a free worker
takes the queued job of the session that has had the least of the workers' time lately (the
CPU time its jobs took on them, decayed with a half-life of :data:`HALF_LIFE_S`: CPU, not wall
time, so a job slowed by others is not charged for them); between sessions with the
same, the address served longest ago goes first, then the job queued first. A session never
has two jobs running at once (its actions keep their order). So a trainee's request waits for
no job of a session that has had more of the workers lately, however many that session or
its address have sent; a class behind one address is served session by session like any
other. With ``per_address``, an address never has more jobs running at once than that, so
with more workers than that one client cannot occupy them all. With ``heavy_alone``, a job
does not start beside a running one whose session has had less than 1/:data:`HEAVIER` of its
own session's time lately: the server's actions hold the interpreter's lock, so a much heavier
session's action run beside a trainee's would take half of the trainee's share of it. A
lighter session's job starts beside a heavier one's at once (it waits for no job of a heavier
session); the much heavier session's next job waits for the lighter one to end (a job's time,
not a queue). Sessions within that factor of each other run side by side.

An address held to its share (:meth:`FairPool.hold_to_share`: the server does so for a while
after it refused one of the address's requests for a limit) gets no more than an even share of
the workers' time while other addresses have had work lately: when its recent time (its
sessions' together, decayed alike) exceeds what a steady 1/n of one worker's time amounts to,
n the addresses whose jobs started within :data:`ACTIVE_S`, its next job waits, even with a
worker free, until its recent time has decayed below that. Otherwise the pool gives a
flooding address whatever the others leave, and its jobs, however well ordered, keep the
workers and the interpreter's lock busy beside theirs. Addresses not held are never paced
(a class behind one address may use the workers as far as they are free).

:class:`FairCache` keeps values per owner within one budget, evicting from the owner that
holds the most. :class:`Holds` counts refusals held back before they are sent (a client that
retries at once waits for its refusal), with a bound per client and in all.
"""

from __future__ import annotations

import math
import threading
import time
from collections import OrderedDict, deque
from collections.abc import Callable
from concurrent.futures import Future
from typing import Any

__all__ = ["ACTIVE_S", "HALF_LIFE_S", "HEAVIER", "FairCache", "FairPool", "Holds"]


#: Half-life of a session's recent time on the workers: the CPU time its jobs took is forgotten
#: over a few seconds, so a trainee who drove hard a moment ago is soon served like the others
#: (assumed: a page's burst of moves lasts a second or two). [s]
HALF_LIFE_S = 1.0
#: A session with more than this many times the recent time of a running job's session waits
#: for that job to end (``heavy_alone``). Trainees at a similar pace run side by side (two of
#: them waiting for each other would only lengthen their queue); a page turning a wheel at
#: several times another's pace runs when that one's action has ended. [—]
HEAVIER = 2.0
#: A session whose recent time has decayed below this is forgotten: its next job is served as a
#: newcomer's. [s]
FORGOTTEN_S = 1e-4
#: An address whose job started within this span counts among those sharing the workers (an
#: address held to its share gets 1/n of one worker's time, n those addresses). [s]
ACTIVE_S = 1.0
#: The decayed sum of a steady use of 1 s a second: what a share of one worker's time amounts
#: to in the pool's recent time (the integral of 2^(−t/half-life) over the past). [s]
_STEADY = HALF_LIFE_S / math.log(2.0)


class FairPool:
    """``workers`` threads serving the job of the session with the least recent time on them
    first; at most ``per_address`` jobs of one address running at once (None: no cap); with
    ``heavy_alone``, a job beside a running one only if its session has had at most
    :data:`HEAVIER` times the running job's session's recent time."""

    def __init__(self, workers: int = 2, name: str = "fair", per_address: int | None = None,
                 heavy_alone: bool = False, clock: Callable[[], float] = time.monotonic):
        self._cv = threading.Condition()
        self._per_address = per_address
        self._heavy_alone = heavy_alone
        self._clock = clock
        self._busy: dict[str, int] = {}  # jobs running per address
        self._jobs: dict[tuple[str, str], deque] = {}  # queued: (future, fn, args, queued at)
        self._running: set[tuple[str, str]] = set()
        #: each session's recent time on the workers, kept as [s] × 2^((t − epoch)/half-life) at
        #: the time t it was charged: all decay alike, so these compare as the decayed values
        #: do and choosing a job needs no power of two per session
        self._used: dict[tuple[str, str], float] = {}
        self._epoch = clock()
        self._served: dict[str, float] = {}  # when an address's job last started
        #: each address's recent time, scaled as ``_used``; and the addresses held to their
        #: share, until when
        self._address_used: dict[str, float] = {}
        self._held: dict[str, float] = {}
        self._wake: float | None = None  # when a job held to its share may start
        self._pruned = clock()
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
            self._jobs.setdefault((address, session), deque()).append(
                (fut, fn, args, self._clock()))
            self._cv.notify()
        return fut

    def hold_to_share(self, address: str, seconds: float) -> None:
        """Hold ``address`` to an even share of the workers' time for ``seconds`` from now (a
        later call extends it)."""
        with self._cv:
            self._held[address] = max(self._held.get(address, -math.inf),
                                      self._clock() + seconds)
            if len(self._held) > 10_000:  # forget the expired ones rather than grow
                now = self._clock()
                self._held = {a: t for a, t in self._held.items() if t > now}

    def held_to_share(self, address: str) -> bool:
        """Whether ``address`` is held to its share now."""
        with self._cv:
            return self._held.get(address, -math.inf) > self._clock()

    def pending(self) -> int:
        """Jobs queued and not yet started."""
        with self._cv:
            return sum(len(q) for q in self._jobs.values())

    def recent(self, address: str, session: str) -> float:
        """A session's recent time on the workers [s] (decayed with :data:`HALF_LIFE_S`)."""
        with self._cv:
            return self._recent((address, session), self._clock())

    def _scale(self, now: float) -> float:
        return 2.0 ** ((now - self._epoch) / HALF_LIFE_S)

    def _recent(self, key: tuple[str, str], now: float) -> float:
        return self._used.get(key, 0.0) / self._scale(now)

    def _charge(self, key: tuple[str, str], spent: float, now: float) -> None:
        """Add ``spent`` [s] to a session's and its address's recent time (lock held)."""
        scale = self._scale(now)
        if scale > 2.0**400:  # far from the epoch: a new one (the values stay finite)
            self._used = {k: v / scale for k, v in self._used.items()}
            self._address_used = {a: v / scale for a, v in self._address_used.items()}
            self._epoch, scale = now, 1.0
        self._used[key] = self._used.get(key, 0.0) + spent * scale
        address = key[0]
        self._address_used[address] = self._address_used.get(address, 0.0) + spent * scale

    def _over_share(self, address: str, now: float, active: list[int]) -> float | None:
        """For an address held to its share whose recent time exceeds it while another
        address has had work lately: the seconds until it falls within (lock held); else
        None. ``active``: [the addresses whose job started within ACTIVE_S], or [-1] not yet
        counted (counted here once for all calls of one choice)."""
        until = self._held.get(address)
        if until is None or until <= now:
            return None
        if active[0] < 0:
            active[0] = sum(1 for t in self._served.values() if now - t < ACTIVE_S)
        others = active[0] - (now - self._served.get(address, -math.inf) < ACTIVE_S)
        if others < 1 and not any(a != address for a, _ in self._running):
            return None  # alone: nothing to share
        allowed = _STEADY / max(others + 1, 2) * self._scale(now)
        mine = self._address_used.get(address, 0.0)
        if mine <= allowed:
            return None
        return HALF_LIFE_S * math.log2(mine / allowed)

    def _next(self) -> tuple[tuple[str, str], Any] | None:
        """The next job (called with the lock held), or None."""
        used, served, cap, busy = self._used, self._served, self._per_address, self._busy
        best = best_rank = None
        now = self._clock() if self._held else 0.0
        active = [-1]
        self._wake = None
        for key, queue in self._jobs.items():
            if not queue or key in self._running:
                continue
            if cap is not None and busy.get(key[0], 0) >= cap:
                continue
            if self._held:
                wait = self._over_share(key[0], now, active)
                if wait is not None:  # beyond its share: not before it has decayed
                    wake = now + max(wait, 1e-3)
                    self._wake = wake if self._wake is None else min(self._wake, wake)
                    continue
            rank = (used.get(key, 0.0), served.get(key[0], -math.inf), queue[0][3])
            if best is None or rank < best_rank:
                best, best_rank = key, rank
        if best is None:
            return None
        key, mine = best, best_rank[0]
        if self._heavy_alone and any(mine > HEAVIER * used.get(k, 0.0) for k in self._running):
            return None  # much heavier than a running job's session: after it
        served[key[0]] = self._clock()
        return key, self._jobs[key].popleft()

    def _forget(self, key: tuple[str, str], now: float) -> None:
        """Drop an owner with nothing queued nor running (lock held), and the recent time of
        sessions long idle."""
        if not self._jobs.get(key) and key not in self._running:
            self._jobs.pop(key, None)
        if now - self._pruned > HALF_LIFE_S:
            self._pruned = now
            floor = FORGOTTEN_S * self._scale(now)
            for k in [k for k, v in self._used.items() if v < floor
                      and k not in self._jobs and k not in self._running]:
                del self._used[k]
            busy = {a for a, _ in self._jobs} | {a for a, _ in self._running}
            for a in [a for a, v in self._address_used.items() if v < floor and a not in busy]:
                del self._address_used[a]
            self._held = {a: t for a, t in self._held.items() if t > now}
            if len(self._served) > 4 * len(self._used) + 64:
                live = {a for a, _ in self._used} | {a for a, _ in self._jobs}
                self._served = {a: t for a, t in self._served.items() if a in live}

    def _work(self) -> None:
        while True:
            with self._cv:
                got = self._next()
                while got is None:
                    if self._closed:
                        return
                    wake = self._wake
                    self._cv.wait(None if wake is None else max(wake - self._clock(), 1e-3))
                    got = self._next()
                key, (fut, fn, args, _) = got
                self._running.add(key)
                self._busy[key[0]] = self._busy.get(key[0], 0) + 1
            began = time.thread_time()
            try:
                if fut.set_running_or_notify_cancel():
                    try:
                        fut.set_result(fn(*args))
                    except BaseException as exc:  # handed to the caller through the future
                        fut.set_exception(exc)
            finally:
                with self._cv:
                    now = self._clock()
                    spent = time.thread_time() - began
                    self._charge(key, spent, now)
                    self._running.discard(key)
                    left = self._busy.pop(key[0]) - 1
                    if left:
                        self._busy[key[0]] = left
                    self._forget(key, now)
                    self._cv.notify_all()

    def shutdown(self, wait: bool = True) -> None:
        """Refuse new jobs, cancel the queued ones, stop the workers after their job."""
        with self._cv:
            self._closed = True
            for q in self._jobs.values():
                for fut, _, _, _ in q:
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
