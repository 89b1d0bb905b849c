"""Photo patches under abuse: one client address never renders more than one patch at once
(another client's patch starts on the worker left free), and patches are rendered in worker
processes at a lower priority, not in the server's own (where a render would hold the
interpreter's lock); the patches kept for reuse are kept per client address, and a client
filling the cache evicts its own."""

from __future__ import annotations

import os
import threading
import time

import pytest

from stereoplotter.imagery.cache import ViewCache
from stereoplotter.io.exercise_file import load_exercise
from stereoplotter.web import core, render
from stereoplotter.web.app import create_app
from stereoplotter.web.fair import FairCache, FairPool
from stereoplotter.web.render import RENDER_NICENESS, Renderers
from tests.web.conftest import PRACTICE, TOKEN, make_test_client


@pytest.fixture(scope="module")
def server_pools(tmp_path_factory):
    """The server's own pools: its actors (actions, state reads) and its patch threads."""
    app = create_app(TOKEN, tmp_path_factory.mktemp("pools"), hosts=("testserver",))
    with make_test_client(app) as c:
        reg = c.app.state.registry
        yield {"actor": reg.actor, "patcher": reg.patcher}


@pytest.mark.parametrize("which", ["actor", "patcher", "a pool of its own"])
def test_one_address_never_occupies_every_worker(server_pools, which):
    """Two workers, at most one job of an address at once: an abuser queues 20 jobs over
    5 sessions; while its first is running, a trainee's job starts on the other worker (the
    server's actor pool, its patch pool, and a pool made with the cap)."""
    own = which not in server_pools
    pool = FairPool(2, "test", per_address=1) if own else server_pools[which]
    running: list[str] = []
    most = {"abuser": 0}
    gate = threading.Event()
    honest_started = threading.Event()
    lock = threading.Lock()

    def job(who: str) -> str:
        with lock:
            running.append(who)
            most["abuser"] = max(most["abuser"], running.count("abuser"))
        if who == "honest":
            honest_started.set()
        else:
            gate.wait(5)
        with lock:
            running.remove(who)
        return who

    try:
        flood = [pool.submit("10.0.0.66", f"s{k % 5}", job, "abuser") for k in range(20)]
        time.sleep(0.05)
        honest = pool.submit("10.0.0.7", "mine", job, "honest")
        # started while the abuser's first job still holds its worker
        assert honest_started.wait(5)
        assert not gate.is_set()
        gate.set()
        assert honest.result(5) == "honest"
        assert [f.result(5) for f in flood] == ["abuser"] * 20
    finally:
        gate.set()
        if own:
            pool.shutdown()
    assert most["abuser"] == 1


def test_patches_are_rendered_in_worker_processes():
    ex = load_exercise(PRACTICE)
    cache = ViewCache(ex.scenario, ex.seed, pixel_mm=0.32)  # coarse photos: quick to build
    here = core.photo_patch(cache, "left", 1.5, -2.0, 0.625, 64)
    renderers = Renderers(2, processes=True)
    got: dict[str, tuple[bytes, int, int]] = {}

    def one(name: str) -> None:  # each thread of the pool gets a process of its own
        png = renderers.render(name, core.photo_key(ex), cache, "left", 1.5, -2.0, 0.625, 64)
        worker = renderers.this_threads_worker()
        assert worker is not None
        got[name] = (png, worker.submit(os.getpid).result(), worker.submit(os.nice, 0).result())

    try:
        threads = [threading.Thread(target=one, args=(n,)) for n in ("a", "b")]
        for t in threads:
            t.start()
        for t in threads:
            t.join(120)
    finally:
        renderers.shutdown()
    pids = {pid for _, pid, _ in got.values()}
    assert [png for png, _, _ in got.values()] == [here, here]  # the same bytes as in-process
    assert len(pids) == 2 and os.getpid() not in pids
    # and at a lower priority than the server (its niceness plus RENDER_NICENESS, at most 19)
    assert {nice for _, _, nice in got.values()} == {min(19, os.nice(0) + RENDER_NICENESS)}


def test_a_client_filling_the_patch_cache_evicts_its_own(monkeypatch):
    made: list[tuple] = []

    def photo_patch(cache, side, x, y, mag, size):  # a patch of 100 bytes, counted
        made.append((side, x))
        return bytes(100)

    monkeypatch.setattr(core, "photo_patch", photo_patch)
    monkeypatch.setattr(render, "PATCHES_KEPT_BYTES", 1_000)
    renderers = Renderers(2, processes=False)
    renderers.render("10.0.0.7", "photos", None, "left", 1.0, 0.0, 6.0, 768)  # the trainee's
    for k in range(50):  # the abuser's, each new
        renderers.render("10.0.0.66", "photos", None, "right", float(k), 0.0, 6.0, 768)
    assert len(made) == 51
    renderers.render("10.0.0.7", "photos", None, "left", 1.0, 0.0, 6.0, 768)  # kept for it
    renderers.render("10.0.0.66", "photos", None, "right", 0.0, 0.0, 6.0, 768)  # evicted
    assert len(made) == 52 and made[-1] == ("right", 0.0)


def test_the_fair_cache_evicts_from_the_richest_owner():
    kept = FairCache(budget_bytes=500)
    kept.put("a", 1, bytes(200))
    kept.put("a", 2, bytes(200))
    kept.put("b", 1, bytes(100))
    kept.put("b", 2, bytes(100))  # 600 > 500: a holds the most and loses its oldest
    assert kept.owned("a") == [2] and kept.owned("b") == [1, 2] and kept.total == 400
    assert kept.get("b", 1) == bytes(100) and kept.get("a", 1) is None
