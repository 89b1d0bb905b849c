"""The server's sessions: the live ones in memory, every one in the store (SQLite).

A session is created by :meth:`Registry.start` with an unguessable secret (256 bits, given once
to the trainee's page; the store keeps its hash) and the server's facts: the exercise's or the
trainee's own seed (a client seed is refused in an exam), the server's clock (an action's ``t``
is the wall-clock seconds since the session started, kept across a restart) and one exam
attempt per trainee and exercise unless the instructor grants another. Every action record is
written to the store as it happens; after a restart an unfinished session is replayed from its
log the first time its page reconnects.

Slow work never runs on the event loop: session start and actions run in worker threads;
photo patches are queued on worker threads and rendered in worker processes; grading, replays
for the instructor and building the photos' tile pyramids run in worker processes
(``Executor`` objects given to the registry). A finished session's grade is computed once,
when its last stage is claimed, and kept in the store.
"""

from __future__ import annotations

import hashlib
import hmac
import logging
import secrets
import threading
import time
from concurrent.futures import Executor, Future
from dataclasses import dataclass, field
from typing import Any

from stereoplotter.io.session_store import SessionStore, storable
from stereoplotter.trainer.session import secret_seed
from stereoplotter.web import core
from stereoplotter.web.fair import FairPool, Holds
from stereoplotter.web.guard import (
    BURST,
    RATE,
    RateLimit,
    Refused,
    quote,
    text_ok,
    trainee_key,
)
from stereoplotter.web.render import Renderers

__all__ = ["MAX_ACTIONS", "RANGE_SLACK", "Live", "Registry", "token_hash"]

log = logging.getLogger(__name__)

#: Actions a session may hold (a full setup takes about 1 400 with the exact operator;
#: assumed: several times that).
MAX_ACTIONS = 6_000
#: The store's entries: the key exam seeds derive from, the instructor token's hash.
SEED_KEY, TOKEN_HASH = "exam-seed-key", "instructor-token-sha256"
#: A set value may lie this share of the control's travel beyond a stop (a page rounds to the
#: least count; the instrument clips at the stop itself). [—]
RANGE_SLACK = 0.01
#: Photo patches a session may ask for (the page asks one when the mark leaves the patch it
#: has: a few a second while driving fast; assumed ample), and all sessions of one client
#: address together (a class of 40 behind one address). [1/s], [patches]
PATCH_LIMIT = (10.0, 30)
PATCH_ADDRESS_LIMIT = (200.0, 400)
#: Worker threads of the fair pools (actions; photo patches). Each patch thread hands its
#: renders to a worker process of its own (``render.Renderers``: a render holds the
#: interpreter's lock for most of its 0.1–0.3 s, which in the server would stall the event loop
#: and the actors). [threads]
ACTORS, PATCHERS = 2, 2
#: Worker threads that start sessions (``start``: the exercise's setup and the simulated
#: operator's targets, tens of ms of Python a session), a fair pool of their own. With every
#: start on a thread of its own (a class starting at once), each holds the interpreter's lock
#: in turn with the event loop and the actors, and a trainee already turning a wheel waits for
#: all of them at each of its message's hand-overs; on one thread a start waits for the starts
#: before it instead (a class of 40 at once: about a second for the last). [threads]
STARTERS = 1
#: Photo patches of one client address rendered at once: with PATCHERS above it, a client
#: asking for patches without pause leaves a worker free for the others. [patches]
PATCHES_AT_ONCE = 1
#: Actions of one client address run at once: one address's sessions cannot hold both actor
#: threads, so another address's action starts at once. An action is mostly Python (it holds
#: the interpreter's lock), so a second thread adds little for one address: a class behind one
#: address loses little. On the idle machine (``bench_trainer_load.py --abuser --seconds 20``)
#: the honest trainees' p95 under abuse was 149 ms without this cap and 112 ms, 90 ms with it
#: (single runs). [actions]
ACTIONS_AT_ONCE = 1
#: How long a client address refused for any of its limits (messages, sockets, patches) is
#: held to an even share of the actor threads' time (``fair.FairPool.hold_to_share``: while
#: other addresses have had actions lately, 1/n of one thread, n those addresses); each
#: refusal extends it. A class behind one address within its limits is never held; a
#: client that keeps hitting them is, as long as it does (assumed: a page's own refusals, a
#: reconnect storm after a restart, pass within seconds). [s]
REFUSED_HOLD_S = 10.0
#: Sockets a session may open (a page reconnects after a dropped network or a reload): a rate
#: and a burst; beyond, a socket is closed (4429) before any work is done for it. [1/s], [—]
CONNECT_LIMIT = (1.0, 5)
#: Sockets one client address may open, checked before the socket is accepted (a class of 40
#: behind one address reconnecting after a restart has room). [1/s], [—]
ADDRESS_CONNECT_LIMIT = (20.0, 80)
#: Refusals held back at once: of one client address, and of all (each holds a connection
#: open; beyond, a refusal is answered at once). [connections]
HELD_REFUSALS = (256, 2_048)


def token_hash(token: str) -> str:
    """SHA-256 (hex) of the instructor's token: what the data folder keeps."""
    return hashlib.sha256(token.encode("utf-8", "replace")).hexdigest()


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
    #: The session's one live socket (a newer one replaces it), and the owner its jobs are
    #: queued under in the fair pools (the client address).
    socket: Any = None
    address: str = "?"
    #: Messages the session may send, whichever socket it uses (``guard.RateLimit``).
    limit: Any = None
    #: Sockets the session may open (``CONNECT_LIMIT``).
    connects: Any = None
    #: Its last action could not be stored: the store's log is the session; reconnect.
    broken: bool = False


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
        address_limit: tuple[float, int] = (1_200.0, 2_400),
        renderers: Renderers | None = None,
    ):
        self.store = store
        #: A token made now (printed once by the server), or None when the stored one is kept.
        self.new_token: str | None = None
        if token is not None:
            self._token_hash = token_hash(token)
        else:
            kept = store.get_value(TOKEN_HASH) if store.path is not None else None
            if kept is None:
                self.rotate_token()
            else:
                self._token_hash = kept
        self.catalogue = catalogue
        self.grader = grader
        self.imager = imager
        #: Socket messages one page may send: a rate [1/s] and a burst (``guard.RATE``, ``BURST``).
        self.message_limit = message_limit
        #: Socket messages all sessions of one client address may send (``sockets``).
        self.address_limit = address_limit
        self.address_limits: dict[str, Any] = {}
        self.patch_limits: dict[tuple[str, str], RateLimit] = {}
        self.connect_limits: dict[str, RateLimit] = {}
        #: Refused sockets waiting for their refusal (``sockets.REFUSAL_DELAY_S``).
        self.refusal_holds = Holds(*HELD_REFUSALS)
        #: The threads that carry out the sessions' actions (the session with the least recent
        #: time on them first, and beside a running action no session with more than twice: a
        #: flood from one client does not queue the others behind it nor share the
        #: interpreter's lock with their actions), and render photo patches (at most
        #: PATCHES_AT_ONCE of one address at once; rendered in worker processes when
        #: ``renderers`` has them).
        self.actor = FairPool(ACTORS, "trainer-actor", per_address=ACTIONS_AT_ONCE,
                              heavy_alone=True)
        self.patcher = FairPool(PATCHERS, "trainer-patch", per_address=PATCHES_AT_ONCE)
        #: The thread that starts sessions (``STARTERS``), the address started least lately
        #: first.
        self.starter = FairPool(STARTERS, "trainer-start")
        self.renderers = renderers if renderers is not None else Renderers(PATCHERS, False)
        self._seed_key = store.server_key(SEED_KEY)
        self.rows: dict[str, dict[str, Any]] = {r["id"]: r for r in store.sessions()}
        self.grades: dict[str, dict[str, Any]] = store.grades()
        self.live: dict[str, Live] = {}
        #: Bumped on every change the instructor's table shows (pushed, not polled).
        self.version = 0
        self._grading: dict[str, Future] = {}
        self._photos: dict[tuple, Future] = {}
        self._offered: set[tuple] = set()
        self._resume_lock = threading.Lock()
        for sid, row in self.rows.items():  # finished before a restart, not yet graded
            if row["done"] and sid not in self.grades:
                self._grade_later(sid)

    # --- the instructor's token ---------------------------------------------------------------

    def rotate_token(self) -> str:
        """A new instructor token: its hash replaces the kept one (the old token stops working);
        returned once, to be printed."""
        token = secrets.token_urlsafe(24)
        self._token_hash = token_hash(token)
        if self.store.path is not None:
            self.store.put_value(TOKEN_HASH, self._token_hash)
        self.new_token = token
        return token

    def is_instructor(self, given: Any) -> bool:
        """Whether ``given`` is the instructor's token (compared by hash, in constant time)."""
        if not isinstance(given, str) or not 1 <= len(given) <= 200:
            return False
        return hmac.compare_digest(token_hash(given), self._token_hash)

    def patch_allowed(self, sid: str, address: str) -> bool:
        """Whether a session and its client address may have another photo patch now
        (:data:`PATCH_LIMIT` each session, :data:`PATCH_ADDRESS_LIMIT` each address)."""
        if len(self.patch_limits) > 20_000:
            self.patch_limits.clear()
        mine = self.patch_limits.setdefault(("s", sid), RateLimit(*PATCH_LIMIT))
        theirs = self.patch_limits.setdefault(("a", address), RateLimit(*PATCH_ADDRESS_LIMIT))
        if mine.allow() and theirs.allow():
            return True
        self.refused(address)
        return False

    def connect_allowed(self, address: str) -> bool:
        """Whether a client address may open another socket now (``ADDRESS_CONNECT_LIMIT``)."""
        if len(self.connect_limits) > 10_000:
            self.connect_limits.clear()
        bucket = self.connect_limits.setdefault(address, RateLimit(*ADDRESS_CONNECT_LIMIT))
        if bucket.allow():
            return True
        self.refused(address)
        return False

    def refused(self, address: str) -> None:
        """A request of ``address`` was refused for a limit: its actions are held to an even
        share of the actor threads for :data:`REFUSED_HOLD_S`."""
        self.actor.hold_to_share(address, REFUSED_HOLD_S)

    def run(self, pool: FairPool, address: str, session: str, fn, *args) -> Future:
        """``fn(*args)`` on a fair pool, queued under the client address and the session."""
        return pool.submit(address, session, fn, *args)

    def read(self, live: Live, address: str, fn, *args) -> Future:
        """``fn(*args)`` reading the session on the actor pool, never while an action changes
        it (the session's lock: a page and the instructor may ask from two addresses)."""

        def locked():
            with live.lock:
                return fn(*args)

        return self.run(self.actor, address, live.id, locked)

    # --- starting -----------------------------------------------------------------------------

    def start(
        self, exercise: str, trainee: str, *, seed: int | None = None, demonstration: bool = False
    ) -> tuple[Live, str]:
        """A new session (run in a worker thread); returns it and its secret."""
        ex = self.catalogue.get(exercise)
        if ex is None:
            raise Refused(404, f"exercise: no exercise named {quote(exercise, 66)}")
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
            # the server's own seed: nothing public (the names) gives it
            seed = secret_seed(self._seed_key, ex.name, key, used)
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
        self._offer_photos(ex)
        self.version += 1
        return live, secret

    def check(self, sid: str, secret: Any) -> bool:
        """Whether ``secret`` is session ``sid``'s own."""
        return (
            text_ok(secret)
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
            ex = self.catalogue.known(head.get("exercise_name"))
            session = core.replay(records) if ex is None else core.Session.replay(records, ex)
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
        """Carry out one action at the server's time (worker thread); the page's message.

        An action that could not be stored (text that is not UTF-8, a number beyond its
        control's stops) is refused before it counts; if the store fails, the session in
        memory is dropped and resumes from the store's log (nothing counts that is not kept).
        """
        with live.lock:
            session = live.session
            if live.broken:
                return {"error": "this session must be resumed: reconnect"}
            if len(session.log) >= MAX_ACTIONS:
                return {"error": f"this session holds its {MAX_ACTIONS} actions: start a new one"}
            refusal = _unstorable(session, action)
            if refusal is not None:
                return {"state": session.state(), "error": refusal}
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
                try:
                    self.store.append_action(live.id, record, session.stage, done)
                except Exception as exc:  # not kept: not counted either
                    log.warning("session %s: action not stored (%s)", live.id, type(exc).__name__)
                    self.live.pop(live.id, None)
                    live.broken = True
                    return {"error": "this action could not be kept: reconnect to resume"}
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

    def grading(self, sid: str) -> Future | None:
        """The grading of a session started in this server's life when it finished (None: not
        started here: not finished, or its grade kept from before a restart)."""
        return self._grading.get(sid)

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

    def patch(self, address: str, exercise, cache, side: str, x_mm: float, y_mm: float,
              mag: float, size_px: int) -> bytes:
        """PNG of a photo patch of ``exercise`` (its photos ``cache``) for a client ``address``,
        rendered by the patch thread's worker process (run on :attr:`patcher`), or kept from
        before for that address."""
        return self.renderers.render(address, core.photo_key(exercise), cache, side, x_mm, y_mm,
                                     mag, size_px)

    def photos(self, exercise) -> Future:
        """The view cache of an exercise's photos (built once, in a worker)."""
        key = core.photo_key(exercise)
        fut = self._photos.get(key)
        if fut is None:
            fut = self.imager.submit(core.build_view_cache, exercise.source)
            self._photos[key] = fut
        return fut

    def _offer_photos(self, exercise) -> None:
        """Build the photos of an exercise a session has started on, and hand them to the
        patch workers before its first patch (once: each worker keeps them)."""
        key = core.photo_key(exercise)
        if key in self._offered:
            return
        self._offered.add(key)

        def offer(f: Future) -> None:
            if not f.cancelled() and f.exception() is None:
                self.renderers.offer(key, f.result())

        self.photos(exercise).add_done_callback(offer)

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


def _unstorable(session: Any, action: dict[str, Any]) -> str | None:
    """Why an action may not count (one line), or None: its record could not be stored, or a
    set value or turn lies beyond what its control's stops allow."""
    if not storable(action):
        return f"action {action.get('kind')}: expected UTF-8 text and finite numbers"
    kind, control = action.get("kind"), action.get("control")
    if kind not in ("set", "turn") or not isinstance(control, str):
        return None
    rng = session.control_range(control)
    number = action.get("value" if kind == "set" else "delta")
    if rng is None or not isinstance(number, (int, float)):
        return None
    lo, hi = rng
    slack = RANGE_SLACK * (hi - lo)
    if kind == "set" and not lo - slack <= number <= hi + slack:
        return f"action set: {control}: expected a value from {lo:g} to {hi:g}, found {number:g}"
    if kind == "turn" and abs(number) > (hi - lo) + slack:
        return f"action turn: {control}: expected a delta within ±{hi - lo:g}, found {number:g}"
    return None
