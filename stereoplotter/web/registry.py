"""The server's sessions: the live ones in memory, every one in the store (SQLite).

A session is created by :meth:`Registry.start` with an unguessable secret (256 bits, given once
to the trainee's page; the store keeps its hash) and the server's facts: the exercise's or the
trainee's own seed (a client seed is refused in an exam), the server's clock (an action's ``t``
is the wall-clock seconds since the session started, kept across a restart) and one exam
attempt per trainee and exercise unless the instructor grants another. Every action record is
written to the store as it happens; after a restart an unfinished session is replayed from its
log the first time its page reconnects.

Slow work never runs on the event loop: session start, actions and photo patches run in worker
threads; grading, replays for the instructor and building the photos' tile pyramids run in
worker processes (``Executor`` objects given to the registry). A finished session's grade is
computed once, when its last stage is claimed, and kept in the store.
"""

from __future__ import annotations

import secrets
import threading
import time
from concurrent.futures import Executor, Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any

from stereoplotter.io.session_store import SessionStore
from stereoplotter.web import core
from stereoplotter.web.guard import BURST, RATE, Refused, trainee_key

__all__ = ["MAX_ACTIONS", "Live", "Registry"]

#: Actions a session may hold (a full setup takes about 600; assumed: ten times that).
MAX_ACTIONS = 6_000


@dataclass
class Live:
    """A session in memory: the core session and what the page needs."""

    id: str
    exercise: str
    trainee: str
    demonstration: bool
    session: Any
    started: float
    script: list[dict[str, Any]] = field(default_factory=list)
    demo_next: int = 0
    last_error: str | None = None
    lock: threading.Lock = field(default_factory=threading.Lock)


class Registry:
    """Sessions by id, the instructor's token, the store and the workers."""

    def __init__(
        self,
        token: str | None,
        store: SessionStore,
        catalogue: core.Catalogue,
        grader: Executor,
        imager: Executor,
        message_limit: tuple[float, int] = (RATE, BURST),
    ):
        self.token = token or secrets.token_urlsafe(16)
        self.store = store
        self.catalogue = catalogue
        self.grader = grader
        self.imager = imager
        #: Socket messages one page may send: a rate [1/s] and a burst (``guard.RATE``, ``BURST``).
        self.message_limit = message_limit
        #: The thread that carries out every session's actions, one at a time.
        self.actor = ThreadPoolExecutor(max_workers=1, thread_name_prefix="trainer-actor")
        self.rows: dict[str, dict[str, Any]] = {r["id"]: r for r in store.sessions()}
        self.grades: dict[str, dict[str, Any]] = store.grades()
        self.live: dict[str, Live] = {}
        #: Bumped on every change the instructor's table shows (pushed, not polled).
        self.version = 0
        self._grading: dict[str, Future] = {}
        self._photos: dict[tuple, Future] = {}
        self.photo_locks: dict[tuple, threading.Lock] = {}
        self._resume_lock = threading.Lock()
        for sid, row in self.rows.items():  # finished before a restart, not yet graded
            if row["done"] and sid not in self.grades:
                self._grade_later(sid)

    # --- starting -----------------------------------------------------------------------------

    def start(
        self, exercise: str, trainee: str, *, seed: int | None = None, demonstration: bool = False
    ) -> tuple[Live, str]:
        """A new session (run in a worker thread); returns it and its secret."""
        ex = self.catalogue.get(exercise)
        if ex is None:
            raise Refused(404, f"exercise: no exercise named {str(exercise)[:64]!r}")
        key = trainee_key(trainee)
        exam = ex.mode == "exam"
        if exam and seed is not None:
            raise Refused(403, "seed: an exam uses the server's seed for each trainee")
        if exam and demonstration:
            raise Refused(403, "demonstration: not of an exam (it would show the answers)")
        if exam:
            used, extra = self.store.attempts(key, ex.name)
            if used >= 1 + extra:
                raise Refused(
                    403,
                    f"exam {ex.name}: {trainee} has had the attempt allowed; "
                    "the instructor may grant another",
                )
        session = core.start(ex, trainee, seed)
        live = Live(
            id=secrets.token_hex(8),
            exercise=ex.name,
            trainee=trainee,
            demonstration=demonstration,
            session=session,
            started=time.time(),
        )
        if demonstration:
            live.script = core.operator_script(session)
        secret = secrets.token_urlsafe(32)
        row = {
            "id": live.id,
            "trainee": trainee,
            "trainee_key": key,
            "exercise": ex.name,
            "mode": ex.mode,
            "demonstration": demonstration,
            "started": live.started,
            "stage": session.stage,
            "done": False,
            "actions": 0,
        }
        if not self.store.add_session(
            row, secret, session.header(), max_attempts=1 if exam and not demonstration else None
        ):
            raise Refused(
                403,
                f"exam {ex.name}: {trainee} has had the attempt allowed; "
                "the instructor may grant another",
            )
        self.rows[live.id] = row
        self.live[live.id] = live
        self.photos(ex)
        self.version += 1
        return live, secret

    def check(self, sid: str, secret: Any) -> bool:
        """Whether ``secret`` is session ``sid``'s own."""
        return (
            isinstance(secret, str)
            and len(secret) < 200
            and sid in self.rows
            and self.store.check_secret(sid, secret)
        )

    def resume(self, sid: str) -> Live:
        """The session in memory, replayed from the store after a restart (worker thread)."""
        live = self.live.get(sid)
        if live is not None:
            return live
        with self._resume_lock:
            if sid in self.live:
                return self.live[sid]
            records = self.store.records(sid)
            row = self.rows[sid]
            head = records[0]
            ex = self.catalogue.get(head.get("exercise_name"))
            session = core.Session.replay(records, ex)
            live = Live(
                id=sid,
                exercise=row["exercise"],
                trainee=row["trainee"],
                demonstration=bool(row["demonstration"]),
                session=session,
                started=float(row["started"]),
            )
            if live.demonstration:
                fresh = core.start(session.exercise, session.trainee, session.seed)
                live.script = core.operator_script(fresh)
                live.demo_next = len(session.log)
            self.live[sid] = live
            return live

    # --- acting -------------------------------------------------------------------------------

    def act(self, live: Live, action: dict[str, Any]) -> dict[str, Any]:
        """Carry out one action at the server's time (worker thread); the page's message."""
        with live.lock:
            session = live.session
            if len(session.log) >= MAX_ACTIONS:
                return {"error": f"this session holds its {MAX_ACTIONS} actions: start a new one"}
            was_done = session.stage is None
            before = len(session.log)
            timed = dict(action, t=round(time.time() - live.started, 3))
            error = None
            try:
                state = session.act(timed)
            except core.CoreError as exc:
                error = str(exc)
                state = session.state()
            live.last_error = error
            record = session.log[-1] if len(session.log) > before else None
            if record is not None:
                done = session.stage is None
                self.store.append_action(live.id, record, session.stage, done)
                row = self.rows[live.id]
                row.update(stage=session.stage, done=done, actions=len(session.log))
                self.version += 1
                if done and not was_done:
                    self._grade_later(live.id)
            if error:
                return {"state": state, "error": error}
            return {
                "state": state,
                "error": None,
                "result": record.get("result") if record else None,
            }

    def demo_step(self, live: Live) -> dict[str, Any]:
        """Demonstration: the simulated operator's next action."""
        if live.demo_next >= len(live.script):
            return {"state": live.session.state(), "error": "demonstration finished"}
        action = live.script[live.demo_next]
        live.demo_next += 1
        msg = self.act(live, action)
        msg["demo"] = {"done": live.demo_next, "of": len(live.script), "action": action}
        return msg

    # --- grades, replays, photos --------------------------------------------------------------

    def _grade_later(self, sid: str) -> Future:
        fut = self._grading.get(sid)
        if fut is None:
            fut = self.grader.submit(core.grade_records, self.store.records(sid))
            self._grading[sid] = fut

            def keep(f: Future) -> None:
                if f.exception() is None:
                    self.grades[sid] = f.result()
                    self.store.put_grade(sid, f.result())
                    self.version += 1

            fut.add_done_callback(keep)
        return fut

    def grade(self, sid: str) -> Future:
        """The grade of a session: the stored one of a finished session, else computed."""
        done: Future = Future()
        if sid in self.grades:
            done.set_result(self.grades[sid])
            return done
        if self.rows[sid]["done"]:
            return self._grade_later(sid)
        return self.grader.submit(core.grade_records, self.store.records(sid))

    def replay_json(self, sid: str) -> Future:
        """The instructor's replay of a session's log (JSON bytes, made in a worker)."""
        row = self.rows[sid]
        return self.grader.submit(core.replay_json, self.store.records(sid), row["trainee"],
                                  row["exercise"])

    def photos(self, exercise) -> Future:
        """The view cache of an exercise's photos (built once, in a worker)."""
        key = core.photo_key(exercise)
        fut = self._photos.get(key)
        if fut is None:
            fut = self.imager.submit(core.build_view_cache, exercise.source)
            self._photos[key] = fut
            self.photo_locks[key] = threading.Lock()  # a ViewCache is not thread-safe
        return fut

    def prepare_photos(self) -> None:
        """Start building the photos of every known exercise (at start-up, in the background)."""
        for ex in self.catalogue.by_name.values():
            self.photos(ex)

    # --- the instructor's table ---------------------------------------------------------------

    def table(self) -> list[dict[str, Any]]:
        """One row per session: who, what, where, and the stored grade's score once done."""
        out = []
        for sid, r in self.rows.items():
            live = self.live.get(sid)
            row = {
                "id": sid,
                "trainee": r["trainee"],
                "exercise": r["exercise"],
                "mode": "demonstration" if r["demonstration"] else r["mode"],
                "stage": r["stage"],
                "done": bool(r["done"]),
                "actions": r["actions"],
                "started": time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(r["started"])),
                "last_error": live.last_error if live else None,
            }
            g = self.grades.get(sid)
            if g is not None and r["done"]:
                o = g["overall"]
                row.update(
                    score=round(o["score"], 4),
                    passed=o["passed"],
                    percentile=round(o["percentile"], 1),
                )
            out.append(row)
        return out
