"""Fair under abuse: one live socket per session, message limits per session and per address,
work served to the session with the least recent work first (a flood waits behind itself; a
heavy session's action never runs beside another's), photo patches rendered
without one shared lock and limited per session. Speeds are measured in
``benchmarks/bench_trainer_load.py``; here the rules themselves are tried."""

from __future__ import annotations

import json
import threading
import time

import numpy as np
import pytest
from starlette.websockets import WebSocketDisconnect

from stereoplotter.web import registry, sockets
from stereoplotter.web.app import create_app
from stereoplotter.web.fair import HEAVIER, FairPool
from tests.web.conftest import PRACTICE, TOKEN, ask, make_test_client, open_socket, start


def test_a_second_socket_replaces_the_first(tmp_path):
    with make_test_client(create_app(TOKEN, tmp_path, hosts=("testserver",))) as c:
        sid, secret = start(c, PRACTICE, trainee="twice")
        ws1, conn1, _ = open_socket(c, sid, secret)
        ws2, conn2, _ = open_socket(c, sid, secret)
        try:
            with pytest.raises(WebSocketDisconnect) as closed:  # closed before the hello of 2
                conn1.send_text(json.dumps({"action": {"kind": "read", "counter": "X"}}))
                conn1.receive_text()
            assert closed.value.code == 4409
            assert ask(conn2, {"action": {"kind": "read", "counter": "X"}})["error"] is None
        finally:
            ws2.__exit__(None, None, None)
            ws1.__exit__(None, None, None)


def test_the_message_limit_is_the_sessions_and_the_addresses(tmp_path):
    app = create_app(TOKEN, tmp_path, hosts=("testserver",), message_limit=(0.01, 5),
                     address_limit=(0.01, 8))
    read = {"action": {"kind": "read", "counter": "X"}}
    with make_test_client(app) as c:
        sid, secret = start(c, PRACTICE, trainee="limited")
        ws, conn, _ = open_socket(c, sid, secret)
        errors = [ask(conn, read)["error"] for _ in range(5)]
        ws.__exit__(None, None, None)
        assert errors == [None] * 5
        ws, conn, _ = open_socket(c, sid, secret)  # a new socket is no new allowance
        try:
            assert "too many messages" in ask(conn, read)["error"]
        finally:
            ws.__exit__(None, None, None)
        other, other_secret = start(c, PRACTICE, trainee="same address")
        ws, conn, _ = open_socket(c, other, other_secret)
        try:  # the address has sent 5 of its 8 (a refused message counts for neither)
            errors = [ask(conn, read)["error"] for _ in range(4)]
        finally:
            ws.__exit__(None, None, None)
        assert errors[:3] == [None] * 3 and "from this address" in errors[3], errors


def test_work_is_served_round_robin_by_address():
    """One worker; an abuser queues 40 jobs from 10 sessions, then a trainee queues one: the
    trainee's job runs second (after the job already running), not 41st."""
    pool = FairPool(1, "test")
    order: list[str] = []
    gate = threading.Event()

    def job(name: str) -> str:
        gate.wait(5)
        order.append(name)
        time.sleep(0.001)
        return name

    try:
        futures = [pool.submit("10.0.0.66", f"s{k % 10}", job, f"abuse{k}") for k in range(40)]
        time.sleep(0.05)  # the first abuse job has started and waits at the gate
        honest = pool.submit("10.0.0.7", "mine", job, "honest")
        gate.set()
        assert honest.result(5) == "honest"
        for f in futures:
            f.result(5)
    finally:
        pool.shutdown()
    assert order.index("honest") <= 1, order[:5]
    # a session's jobs keep their order
    abuse = [int(n[5:]) for n in order if n.startswith("abuse")]
    for s in range(10):
        mine = [k for k in abuse if k % 10 == s]
        assert mine == sorted(mine)


def _run_for(seconds: float) -> None:
    """Compute for ``seconds`` of this thread's CPU time (what the pool charges)."""
    began = time.thread_time()
    while time.thread_time() - began < seconds:
        pass


def test_the_session_with_the_least_recent_work_goes_first():
    """One worker, one client address (a class behind a proxy): a session that has just had
    60 ms of the worker's CPU time queues a job before a quiet session of the same address does;
    the quiet session's job runs first."""
    pool = FairPool(1, "test")
    order: list[str] = []
    gate = threading.Event()
    try:
        pool.submit("10.0.0.1", "busy", _run_for, 0.06).result(5)
        assert pool.recent("10.0.0.1", "busy") >= 0.05
        assert pool.recent("10.0.0.1", "quiet") == 0.0
        blocker = pool.submit("10.0.0.9", "other", gate.wait, 5)
        time.sleep(0.02)  # the blocker holds the worker
        busy = pool.submit("10.0.0.1", "busy", order.append, "busy")
        quiet = pool.submit("10.0.0.1", "quiet", order.append, "quiet")
        gate.set()
        for f in (blocker, busy, quiet):
            f.result(5)
    finally:
        pool.shutdown()
    assert order == ["quiet", "busy"]


def test_a_heavy_session_waits_for_the_workers_to_be_free():
    """Two workers: a session with more than ``HEAVIER`` times the recent time of the running
    job's session does not start beside it (it would share the interpreter's lock with it); a
    newcomer's job does, on the worker left free; the heavy one runs once the lighter job has
    ended."""
    pool = FairPool(2, "test", heavy_alone=True)
    events: list[str] = []
    gate = threading.Event()
    lock = threading.Lock()

    def job(name: str, wait: bool = False) -> None:
        with lock:
            events.append(f"start {name}")
        if wait:
            gate.wait(5)
        with lock:
            events.append(f"end {name}")

    try:
        pool.submit("10.0.0.66", "heavy", _run_for, 0.08).result(5)
        pool.submit("10.0.0.7", "light", _run_for, 0.001).result(5)
        assert pool.recent("10.0.0.66", "heavy") > 4 * HEAVIER * pool.recent("10.0.0.7", "light")
        held = pool.submit("10.0.0.7", "light", job, "light", True)
        time.sleep(0.02)
        heavy = pool.submit("10.0.0.66", "heavy", job, "heavy")
        newcomer = pool.submit("10.0.0.8", "new", job, "new")
        newcomer.result(5)  # a light job starts beside the running one
        time.sleep(0.05)
        assert "start heavy" not in events, events
        gate.set()
        held.result(5)
        heavy.result(5)
    finally:
        pool.shutdown()
    assert events.index("start heavy") > events.index("end light"), events


def test_an_address_held_to_its_share_waits_while_others_act():
    """One worker; ten addresses have acted lately. An address held to its share (a tenth of
    the worker's time) that has just had more than that waits, even with the worker free,
    while the others act; an address as busy but not held does not; the held one's job runs
    once its recent time has decayed (the pool's clock moved on)."""
    now = [1000.0]
    pool = FairPool(1, "test", clock=lambda: now[0])
    order: list[str] = []
    try:
        for i in range(8):
            pool.submit(f"10.0.1.{i}", "s", order.append, "light").result(5)
        pool.hold_to_share("10.0.0.66", 60.0)
        assert pool.held_to_share("10.0.0.66") and not pool.held_to_share("10.0.0.77")
        # a tenth of one worker, as recent time: 0.1 × HALF_LIFE_S / ln 2 ≈ 0.144 s
        pool.submit("10.0.0.66", "flood", _run_for, 0.2).result(5)  # within it until now
        pool.submit("10.0.0.77", "class", _run_for, 0.2).result(5)
        order.clear()
        held = pool.submit("10.0.0.66", "flood", order.append, "held")
        pool.submit("10.0.0.77", "class", order.append, "not held").result(5)
        pool.submit("10.0.1.0", "s", order.append, "light").result(5)
        time.sleep(0.1)
        assert not held.done() and order == ["not held", "light"], order
        now[0] += 5.0  # the others quiet, its recent time decayed 32-fold
        held.result(5)
    finally:
        pool.shutdown()
    assert order == ["not held", "light", "held"]


def test_a_client_refused_for_a_limit_is_held_to_its_share(tmp_path, monkeypatch):
    """A client opening sockets beyond its address's limit is held to an even share of the
    actor threads; another address is not."""
    monkeypatch.setattr(registry, "ADDRESS_CONNECT_LIMIT", (0.01, 2))
    monkeypatch.setattr(sockets, "REFUSAL_DELAY_S", 0.01)
    with make_test_client(create_app(TOKEN, tmp_path, hosts=("testserver",))) as c:
        sid, secret = start(c, PRACTICE, trainee="churn")
        actor = c.app.state.registry.actor
        for _ in range(2):
            ws, _, hello = open_socket(c, sid, secret)
            ws.__exit__(None, None, None)
            assert "hello" in hello
        assert not actor.held_to_share("testclient")
        with pytest.raises(WebSocketDisconnect):
            with c.websocket_connect(f"/ws/{sid}") as conn:
                conn.receive_text()
        assert actor.held_to_share("testclient")
        assert not actor.held_to_share("10.0.0.7")


def test_sessions_start_one_at_a_time_on_their_own_thread(tmp_path, monkeypatch):
    """Many session starts at once (a class, or a client starting sessions in a loop) run one
    after the other on the starting thread, not each on a thread of its own beside the event
    loop and the actors."""
    threads: list[str] = []
    begun = registry.core.start

    def start_here(*args):
        threads.append(threading.current_thread().name)
        return begun(*args)

    monkeypatch.setattr(registry.core, "start", start_here)
    with make_test_client(create_app(TOKEN, tmp_path, hosts=("testserver",))) as c:
        answers: list[int] = []

        def post(k: int) -> None:
            r = c.post("/api/sessions", json={"exercise": PRACTICE, "trainee": f"t{k}"})
            answers.append(r.status_code)

        posts = [threading.Thread(target=post, args=(k,)) for k in range(6)]
        for t in posts:
            t.start()
        for t in posts:
            t.join()
    assert answers == [200] * 6
    assert threads == ["trainer-start-0"] * 6


def test_patches_render_in_parallel_and_are_limited_per_session(tmp_path, monkeypatch):
    monkeypatch.setattr(registry, "PATCH_LIMIT", (0.01, 5))  # a slow machine refills no token
    with make_test_client(create_app(TOKEN, tmp_path, hosts=("testserver",))) as c:
        sid, secret = start(c, PRACTICE, trainee="patcher")
        reg = c.app.state.registry
        ex = reg.catalogue.get(PRACTICE)
        cache = reg.photos(ex).result(120)
        assert not hasattr(reg, "photo_locks")
        spots = [("left", x, 1.0, 6.0) for x in np.linspace(-5, 5, 12)]
        serial = [cache.view(side, x, y, 0.0, mag, 128).tobytes() for side, x, y, mag in spots]
        cache.forget_views()
        got: dict[int, bytes] = {}

        def render(k: int) -> None:
            side, x, y, mag = spots[k]
            got[k] = cache.view(side, x, y, 0.0, mag, 128).tobytes()

        threads = [threading.Thread(target=render, args=(k,)) for k in range(len(spots))]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        assert [got[k] for k in range(len(spots))] == serial
        q = {"side": "left", "y": 0, "mag": 0.625, "size": 16, "key": secret}
        answers = [c.get(f"/api/sessions/{sid}/patch.png", params={**q, "x": k / 10})
                   for k in range(7)]
        assert [r.status_code for r in answers] == [200] * 5 + [429] * 2
        assert answers[-1].json()["error"].startswith("too many photo patches")
        other, other_secret = start(c, PRACTICE, trainee="patcher 2")  # its own allowance
        r = c.get(f"/api/sessions/{other}/patch.png", params={**q, "x": 0, "key": other_secret})
        assert r.status_code == 200


def test_a_session_opens_only_so_many_sockets(tmp_path, monkeypatch):
    """Sockets replacing one another in a loop would cost the server a hello each: beyond a
    burst of 5 (then one a second) a session's new socket is closed before any work."""
    monkeypatch.setattr(sockets, "REFUSAL_DELAY_S", 0.01)
    with make_test_client(create_app(TOKEN, tmp_path, hosts=("testserver",))) as c:
        sid, secret = start(c, PRACTICE, trainee="reconnecting")
        hellos = []
        for _ in range(7):
            with c.websocket_connect(f"/ws/{sid}") as conn:
                conn.send_text(json.dumps({"auth": secret}))
                hellos.append(json.loads(conn.receive_text()))
        assert all("hello" in h for h in hellos[:5]), hellos[:5]
        assert "too many connections" in hellos[6]["error"], hellos[6]


def test_an_address_opens_only_so_many_sockets(tmp_path, monkeypatch):
    monkeypatch.setattr(registry, "ADDRESS_CONNECT_LIMIT", (0.01, 3))
    monkeypatch.setattr(sockets, "REFUSAL_DELAY_S", 0.01)
    with make_test_client(create_app(TOKEN, tmp_path, hosts=("testserver",))) as c:
        sid, secret = start(c, PRACTICE, trainee="churn")
        for _ in range(3):
            ws, _, hello = open_socket(c, sid, secret)
            ws.__exit__(None, None, None)
            assert "hello" in hello
        with pytest.raises(WebSocketDisconnect) as refused:
            with c.websocket_connect(f"/ws/{sid}") as conn:
                conn.receive_text()
        assert refused.value.code == 4429
