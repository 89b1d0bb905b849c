"""A class on the trainer server: 20 trainees on WebSockets and an instructor, while
sessions are graded and replayed.

The server is ``stereoplotter trainer`` in its own process (worker processes for grading,
replays and photos, as a class would run it). Phase 1 times the first eyepiece view of each
shipped exercise (a new trainee each, so an exam allows it): POST a session, open its socket,
set f_пр if the marks are not projected yet, and fetch both eyepieces' coarse-first patches,
then both sharp ×6 patches (after the start-up preparation of the photos). Phase 2 runs the
load: a demonstration session plays the simulated operator's e01 script (about 580 actions, a
long log to replay); 20 trainees each turn a handwheel ``--rate`` times a second (send, wait for
the state, sleep) for ``--seconds``; meanwhile the instructor's socket receives the pushed
table, the instructor fetches the replay of the long log and the grade of unfinished practice
sessions (computed on demand) in a loop (``--instructor-pause`` s between rounds), and every
5 s a trainee claims its stage (the finished session is graded in the worker). Prints the
turn-to-state round trip (median, p95, max) and the first-view times.

    PYTHONPATH=. python benchmarks/bench_trainer_load.py [--trainees 20] [--seconds 30]

``--abuser``: fairness under abuse instead. Each honest trainee connects from its own loopback
address (127.0.0.10, .11, …: a class of machines), turns a handwheel ``--rate`` times a second,
and trainee 0 also fetches a sharp ×6 eyepiece patch (768 px, a new position each time) twice a
second. Phase 1 (idle) times them alone; phase 2 the same while one abuser (its own process, one
address, 127.0.0.250) opens ``--abuse-sockets`` sockets over ``--abuse-sessions`` sessions, each
sending turns as fast as its answers come (reconnecting when a newer socket replaces it), and
``--abuse-patchers`` clients fetch patches as fast as they are answered. Prints each phase's
round trip (median, p95) and patch median, what the abuser got served, and how its socket
attempts ended: refused at the handshake (its address's connection rate), refused after the key
(its session's), or accepted (and then replaced by a newer socket of the session, or closed
otherwise). The honest trainees take what changed in the state after the first whole state, as
the page does (``--whole-states``: the whole state each time). It also prints the CPU time of
the two client processes (the honest trainees' in each phase, the abuser's): on the server's own
machine their work takes the server's processors, which a class's clients on their own machines
would not. ``--server-probe`` also times, inside the server, each job on the actor threads: its
wait in the queue, its run, and whether a job of the other kind (honest, abuser) ran beside it
(a hook the script puts on the server's path; the server's code is unchanged); where each
honest turn's round trip under abuse went, on the machine's one monotonic clock (from the
client's send to the server's answer beginning, the event loop before the queue, the queue
wait, the run, the event loop after it, the answer's JSON, back to the client), as means over
all turns and over the slowest 5 %; in which quarter-seconds of the phase the slowest 5 % were
sent (a stall of the whole server holds every trainee's turn in one); and the garbage
collector's passes and the actions' writes to the store in the phase.

    PYTHONPATH=. python benchmarks/bench_trainer_load.py --abuser [--seconds 20] [--server-probe]

``--action-cost``: no server; the CPU time of one honest turn (action and reply JSON, with the
whole state and with what changed in it) in this process, and the garbage collector's full pass
over the server's start-up objects.

    PYTHONPATH=. python benchmarks/bench_trainer_load.py --action-cost [--turns 3000]
"""

from __future__ import annotations

import argparse
import asyncio
import itertools
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

import httpx
from websockets.asyncio.client import connect
from websockets.exceptions import ConnectionClosed, InvalidStatus

from stereoplotter.web.statepatch import apply_patch, state_patch

TOKEN = "bench-token"


#: ``--server-probe``: loaded by the server as ``sitecustomize`` (its folder first on the
#: server's path); appends one line a job run on the actor threads to the file named by
#: ``STEREOPLOTTER_BENCH_PROBE``: address, queue wait [s], run [s], whether a job of the other
#: kind (the abuser's address or not) ran at some moment of its run; to that name + ``.turns``
#: one line an answered message with a ``seq``: address, seq, and the clock when the answer
#: began, the job was queued, began and ended, the answer was back on the event loop and its
#: JSON made, and whether an abuser's job ran beside it; to ``.gc`` one line a collector pass
#: (generation, start, end) or an action's write to the store (−1, start, end).
PROBE = r"""
import os, sys, threading, time
OUT = os.environ.get("STEREOPLOTTER_BENCH_PROBE")
if OUT and "trainer" in sys.argv:
    import contextvars
    import importlib.abc
    rows, lock, turns, answered = [], threading.Lock(), [], {}
    TURN = contextvars.ContextVar("turn", default=None)  # the message being answered
    running, started = {True: 0, False: 0}, {True: 0, False: 0}

    def patch(mod):
        submit = mod.FairPool.submit

        def timed(self, address, session, fn, *args):
            if not self._threads[0].name.startswith("trainer-actor"):
                return submit(self, address, session, fn, *args)
            queued, abuser = time.perf_counter(), address == ABUSER
            turn = TURN.get()
            if turn is not None:
                turn["queued"] = queued

            def job(*a):
                began = time.perf_counter()
                with lock:
                    beside, others = running[not abuser] > 0, started[not abuser]
                    running[abuser] += 1
                    started[abuser] += 1
                try:
                    return fn(*a)
                finally:
                    with lock:
                        running[abuser] -= 1
                        beside = beside or started[not abuser] != others
                        ended = time.perf_counter()
                        rows.append((address, began - queued, ended - began, int(beside)))
                        if turn is not None:
                            turn.update(began=began, ended=ended, beside=beside)
            return submit(self, address, session, job, *args)
        mod.FairPool.submit = timed

    def write():
        done = 0
        with open(OUT, "w") as f:
            while True:
                time.sleep(0.5)
                n = len(rows)
                f.writelines(" ".join(map(str, r)) + "\n" for r in rows[done:n])
                f.flush()
                done = n
    threading.Thread(target=write, daemon=True).start()

    def patch_sockets(mod):
        answer, dump = mod._answer, mod._dump

        async def timed(reg, live, message, *args):
            row = {"in": time.perf_counter()}
            token = TURN.set(row)
            try:
                reply = await answer(reg, live, message, *args)
            finally:
                TURN.reset(token)
            row["out"] = time.perf_counter()
            if isinstance(reply.get("seq"), int) and "began" in row:
                row["address"], row["seq"] = live.address, reply["seq"]
                answered[id(reply)] = row
            return reply

        def dumped(body):
            text = dump(body)
            row = answered.pop(id(body), None)
            if row is not None:
                turns.append((row["address"], row["seq"], row["in"], row["queued"],
                              row["began"], row["ended"], row["out"], time.perf_counter(),
                              int(row["beside"])))
            return text
        mod._answer, mod._dump = timed, dumped

    import gc
    passes, began = [], [0.0]

    def collected(phase, info):  # the garbage collector's passes: generation, start, end
        if phase == "start":
            began[0] = time.perf_counter()
        else:
            passes.append((info["generation"], began[0], time.perf_counter()))
    gc.callbacks.append(collected)

    def write_turns():
        done, done_gc = 0, 0
        with open(OUT + ".turns", "w") as f, open(OUT + ".gc", "w") as g:
            while True:
                time.sleep(0.5)
                n, m = len(turns), len(passes)
                f.writelines(" ".join(map(str, r)) + "\n" for r in turns[done:n])
                g.writelines(" ".join(map(str, r)) + "\n" for r in passes[done_gc:m])
                f.flush()
                g.flush()
                done, done_gc = n, m
    threading.Thread(target=write_turns, daemon=True).start()

    def patch_store(mod):  # an action's record written: when, how long (the store's lock held)
        append = mod.SessionStore.append_action

        def timed(self, *args):
            began = time.perf_counter()
            try:
                return append(self, *args)
            finally:
                passes.append((-1, began, time.perf_counter()))
        mod.SessionStore.append_action = timed

    hooked = {"stereoplotter.web.fair": patch, "stereoplotter.web.sockets": patch_sockets,
              "stereoplotter.io.session_store": patch_store}

    class Hook(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path, target=None):
            if name not in hooked:
                return None
            then = hooked.pop(name)
            import importlib.util
            sys.meta_path.remove(self)
            try:
                spec = importlib.util.find_spec(name)
            finally:
                if hooked:
                    sys.meta_path.insert(0, self)
            run = spec.loader.exec_module

            def exec_module(module):
                run(module)
                then(module)
            spec.loader.exec_module = exec_module
            return spec
    sys.meta_path.insert(0, Hook())
"""


def _start_server(data_dir: str, probe: str | None = None) -> tuple[subprocess.Popen, str]:
    env = dict(os.environ)
    if probe is not None:  # the probe's folder first on the server's path
        folder = os.path.join(data_dir, "probe")
        os.makedirs(folder)
        with open(os.path.join(folder, "sitecustomize.py"), "w") as f:
            f.write(PROBE.replace("ABUSER", repr(_local(250))))
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [folder, env.get("PYTHONPATH")]))
        env["STEREOPLOTTER_BENCH_PROBE"] = probe
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "stereoplotter",
            "trainer",
            "--token",
            TOKEN,
            "--data-dir",
            data_dir,
        ],
        stdout=subprocess.PIPE,
        text=True,
        env=env,
    )
    line = proc.stdout.readline()  # "trainee page:    http://localhost:PORT/"
    port = line.rsplit(":", 1)[1].strip().rstrip("/")
    return proc, f"127.0.0.1:{port}"


async def _session(http: httpx.AsyncClient, exercise: str, trainee: str, **extra):
    r = await http.post("/api/sessions", json={"exercise": exercise, "trainee": trainee, **extra})
    r.raise_for_status()
    return r.json()["id"], r.json()["secret"]


async def _open(host: str, sid: str, secret: str):
    ws = await connect(f"ws://{host}/ws/{sid}", max_size=2**24)
    await ws.send(json.dumps({"auth": secret}))
    hello = json.loads(await ws.recv())
    return ws, hello


async def _ask(ws, body: dict) -> dict:
    await ws.send(json.dumps(body))
    return json.loads(await ws.recv())


async def first_view(http, host: str, exercise: str, n: int) -> tuple[float, float]:
    """Seconds from POST of a session to both eyepieces' coarse-first patches received, and to
    both sharp ×6 patches received (what the page fetches, in that order)."""
    t0 = time.perf_counter()
    sid, secret = await _session(http, exercise, f"first-view-{n}")
    ws, hello = await _open(host, sid, secret)
    state = hello["state"]
    if state["marks"] is None:
        f = state["controls"]["f_instrument"]
        state = (
            await _ask(
                ws,
                {
                    "action": {
                        "kind": "set",
                        "control": "f_instrument",
                        "value": round((f["min"] + f["max"]) / 2, 2),
                    }
                },
            )
        )["state"]
    await ws.close()
    if state["marks"] is None:  # nothing projected yet: the eyepieces say so, no photo
        return (time.perf_counter() - t0,) * 2
    times = []
    for mag, size in ((hello["hello"]["coarse_mag"], 80), (6, 768)):
        for side in ("left", "right"):
            m = state["marks"][side]
            r = await http.get(
                f"/api/sessions/{sid}/patch.png",
                params={
                    "side": side,
                    "x": f"{m['x_mm']:.3f}",
                    "y": f"{m['y_mm']:.3f}",
                    "mag": mag,
                    "size": size,
                    "key": secret,
                },
            )
            r.raise_for_status()
        times.append(time.perf_counter() - t0)
    return times[0], times[1]


async def trainee(
    host, http, n: int, stop: float, out: list[float], claim_at: float | None, pause: float
):
    sid, secret = await _session(http, "e01-setup-stage1", f"trainee-{n:02d}")
    ws, hello = await _open(host, sid, secret)
    f = hello["state"]["controls"]["f_instrument"]
    await _ask(
        ws,
        {
            "action": {
                "kind": "set",
                "control": "f_instrument",
                "value": round((f["min"] + f["max"]) / 2, 2),
            }
        },
    )
    i = 0
    while time.monotonic() < stop:
        t0 = time.perf_counter()
        reply = await _ask(
            ws,
            {
                "action": {"kind": "turn", "control": "X", "delta": 0.05 if i % 2 else -0.05},
                "seq": i,
            },
        )
        out.append((time.perf_counter() - t0) * 1e3)
        assert reply.get("error") is None, reply
        i += 1
        if claim_at is not None and time.monotonic() > claim_at:
            await _ask(ws, {"action": {"kind": "claim", "step": "1"}})  # graded in the worker
            await ws.close()
            sid, secret = await _session(http, "e01-setup-stage1", f"trainee-{n:02d}-b{i}")
            ws, hello = await _open(host, sid, secret)
            claim_at = None
        await asyncio.sleep(pause)
    await ws.close()
    return sid


async def instructor(host, http, stop: float, replay_sid: str, stats: dict, pause: float):
    auth = {"Authorization": f"Bearer {TOKEN}"}
    ws = await connect(f"ws://{host}/ws-instructor", max_size=2**24)
    await ws.send(json.dumps({"auth": TOKEN}))

    async def pushes():
        while True:
            json.loads(await ws.recv())
            stats["pushes"] += 1

    reader = asyncio.create_task(pushes())
    while time.monotonic() < stop:
        t0 = time.perf_counter()
        r = await http.get(f"/api/instructor/replay/{replay_sid}", headers=auth, timeout=120)
        r.raise_for_status()
        stats["replays"].append(time.perf_counter() - t0)
        rows = (await http.get("/api/instructor/sessions", headers=auth)).json()
        for row in rows[:3]:
            if row["mode"] == "practice" and not row["done"]:
                t0 = time.perf_counter()
                g = await http.get(f"/api/sessions/{row['id']}/grade", headers=auth, timeout=120)
                g.raise_for_status()
                stats["grades"].append(time.perf_counter() - t0)
        await asyncio.sleep(pause)
    reader.cancel()
    await ws.close()


# --- fairness under abuse -----------------------------------------------------------------------


def _local(n: int) -> str:
    return f"127.0.0.{n}"


async def _open_from(host: str, sid: str, secret: str, address: str, patches: bool = False):
    ws = await connect(f"ws://{host}/ws/{sid}", max_size=2**24, local_addr=(address, 0))
    await ws.send(json.dumps({"auth": secret, "patches": True} if patches else {"auth": secret}))
    hello = json.loads(await ws.recv())
    return ws, hello


async def honest(host, n: int, stop: float, rtt: list, patches: list | None, pause: float,
                 whole: bool = False, trace: list | None = None):
    """A trainee turning a wheel; like the page, it takes what changed in the state after the
    first (``whole``: the whole state each time). ``trace``: each answered turn's address, seq,
    and the clock when it was sent and its answer received."""
    address = _local(10 + n)
    transport = httpx.AsyncHTTPTransport(local_address=address)
    async with httpx.AsyncClient(base_url=f"http://{host}", transport=transport,
                                 timeout=120) as http:
        sid, secret = await _session(http, "e01-setup-stage1", f"honest-{n:02d}")
        ws, hello = await _open_from(host, sid, secret, address, patches=not whole)
        f = hello["state"]["controls"]["f_instrument"]
        state = (await _ask(ws, {"action": {"kind": "set", "control": "f_instrument",
                                            "value": round((f["min"] + f["max"]) / 2, 2)}}))
        state = state["state"] if whole else apply_patch(hello["state"], state["patch"])
        held = state

        async def patch_loop():
            k = 0
            while time.monotonic() < stop:
                m = state["marks"]["left"]
                t0 = time.perf_counter()
                r = await http.get(f"/api/sessions/{sid}/patch.png", params={
                    "side": "left", "x": f"{m['x_mm'] + 0.37 * (k % 40 - 20):.3f}",
                    "y": f"{m['y_mm']:.3f}", "mag": 6, "size": 768, "key": secret})
                if r.status_code == 200:
                    patches.append((time.perf_counter() - t0) * 1e3)
                k += 1
                await asyncio.sleep(0.5)

        task = asyncio.create_task(patch_loop()) if patches is not None else None
        i = 0
        while time.monotonic() < stop:
            t0 = time.perf_counter()
            reply = await _ask(ws, {"action": {"kind": "turn", "control": "X",
                                               "delta": 0.05 if i % 2 else -0.05}, "seq": i})
            if reply.get("error") is None:
                t1 = time.perf_counter()
                rtt.append((t1 - t0) * 1e3)
                if trace is not None:
                    trace.append((address, i, t0, t1))
            if "patch" in reply:  # what the page does with it
                held = apply_patch(held, reply["patch"])
            i += 1
            await asyncio.sleep(pause)
        if task is not None:
            await task
        await ws.close()


async def _abuse(host: str, stop: float, sockets: int, sessions: int, patchers: int) -> dict:
    address = _local(250)
    got = {"served": 0, "refused": 0, "handshakes_refused": 0, "refused_after_key": 0,
           "accepted": 0, "replaced": 0, "closed_other": 0, "failed_open": 0, "patches": 0,
           "patches_refused": 0}
    transport = httpx.AsyncHTTPTransport(local_address=address, limits=httpx.Limits(
        max_connections=patchers + 4))
    async with httpx.AsyncClient(base_url=f"http://{host}", transport=transport,
                                 timeout=120) as http:
        owned = []
        for k in range(sessions):
            r = await http.post("/api/sessions", json={"exercise": "e01-setup-stage1",
                                                       "trainee": f"abuser-{k}"})
            if r.status_code == 200:
                owned.append((r.json()["id"], r.json()["secret"]))
        if not owned:
            return got

        async def flood(j: int):
            sid, secret = owned[j % len(owned)]
            while time.monotonic() < stop:
                try:
                    ws, hello = await _open_from(host, sid, secret, address)
                except InvalidStatus:  # refused before the handshake (the address's limit)
                    got["handshakes_refused"] += 1
                    await asyncio.sleep(0.01)
                    continue
                except (ConnectionClosed, OSError):
                    got["failed_open"] += 1
                    await asyncio.sleep(0.01)
                    continue
                if "hello" not in hello:  # refused after the key (the session's own limit)
                    got["refused_after_key"] += 1
                    await ws.close()
                    await asyncio.sleep(0.01)
                    continue
                got["accepted"] += 1
                try:
                    while time.monotonic() < stop:
                        await ws.send(json.dumps({"action": {"kind": "turn", "control": "X",
                                                             "delta": 0.01}}))
                        reply = json.loads(await ws.recv())
                        got["served" if reply.get("error") is None else "refused"] += 1
                except ConnectionClosed as exc:  # replaced by a newer socket of the session
                    code = exc.rcvd.code if exc.rcvd is not None else None
                    got["replaced" if code == 4409 else "closed_other"] += 1
                    await asyncio.sleep(0.01)
                await ws.close()

        async def patch_flood(j: int):
            sid, secret = owned[j % len(owned)]
            k = 0
            while time.monotonic() < stop:
                r = await http.get(f"/api/sessions/{sid}/patch.png", params={
                    "side": "right", "x": f"{(k * 7 + j * 13) % 120 - 60:.3f}", "y": "1.0",
                    "mag": 6, "size": 768, "key": secret})
                got["patches" if r.status_code == 200 else "patches_refused"] += 1
                k += 1

        await asyncio.gather(*(flood(j) for j in range(sockets)),
                             *(patch_flood(j) for j in range(patchers)))
    return got


def _abuser_process(host, stop_in, sockets, sessions, patchers, queue) -> None:
    stop = time.monotonic() + stop_in
    got = asyncio.run(_abuse(host, stop, sockets, sessions, patchers))
    got["cpu_s"] = time.process_time()  # the abuser client's own CPU, taken from the server's
    queue.put(got)


def _probe_summary(path: str) -> None:
    """``--server-probe``: the actor threads' jobs of each phase's honest trainees (by their
    addresses) and of the abuser: queue wait and run (median, p95), and the share of jobs with
    a job of the other kind running beside them."""
    groups: dict[str, list[tuple[float, float, int]]] = {"idle": [], "abuse": [], "abuser": []}
    with open(path) as f:
        for line in f:
            address, wait, run, beside = line.split()
            last = int(address.rsplit(".", 1)[1])
            group = ("abuser" if last == 250 else "abuse" if last >= 110
                     else "idle" if last >= 10 else None)
            if group is None:  # the first view before the phases
                continue
            groups[group].append((float(wait) * 1e3, float(run) * 1e3, int(beside)))

    def q(values: list[float], p: float) -> float:
        values = sorted(values)
        return values[int(p * (len(values) - 1))] if values else math.nan

    for group, rows in groups.items():
        if not rows:
            continue
        waits, runs = [r[0] for r in rows], [r[1] for r in rows]
        who = "the abuser's" if group == "abuser" else f"honest ({group} phase)"
        print(f"server probe, actor jobs of {who}: {len(rows)}; queue wait median "
              f"{q(waits, 0.5):.2f} ms, p95 {q(waits, 0.95):.2f} ms; run median "
              f"{q(runs, 0.5):.2f} ms, p95 {q(runs, 0.95):.2f} ms; with a job of the other kind "
              f"beside them {sum(r[2] for r in rows) / len(rows):.0%}")


#: The parts of an honest turn's round trip ``_turns_summary`` names, between the clocks of
#: the client (sent, received) and of the server (the message handed to the answer, the job
#: queued, begun and ended on an actor thread, the answer back on the event loop, its JSON
#: made to be sent).
TURN_PARTS = ("to the server's answer (client send, network, event loop)",
              "event loop before the queue", "queue wait", "run", "event loop after the run",
              "answer made", "to the client (send, network, client loop)")


def _turns_summary(path: str, trace: list) -> None:
    """``--server-probe``: where the time of the honest trainees' turns under abuse goes, for
    all of them and for the slowest 5 % (the client's and the server's clocks are the same
    monotonic clock of the machine)."""
    server = {}
    with open(path) as f:
        for line in f:
            address, seq, *times, beside = line.split()
            server[(address, int(seq))] = ([float(t) for t in times], int(beside))
    rows = []
    for address, seq, sent, got in trace:
        if int(address.rsplit(".", 1)[1]) < 110 or (address, seq) not in server:
            continue
        times, beside = server[(address, seq)]
        clock = [sent, *times, got]
        rows.append((got - sent, [(b - a) * 1e3 for a, b in itertools.pairwise(clock)], beside,
                     sent))
    if not rows:
        return
    rows.sort(key=lambda r: r[0])
    tail = rows[int(0.95 * (len(rows) - 1)):]
    began = min(r[3] for r in rows)
    windows: dict[int, int] = {}
    for r in tail:
        k = int((r[3] - began) / 0.25)
        windows[k] = windows.get(k, 0) + 1
    busiest = sorted(windows.items(), key=lambda kv: -kv[1])[:8]
    ended = max(r[3] for r in rows)
    with open(path[:-len(".turns")] + ".gc") as f:
        passes = [(int(g), float(a), float(b)) for g, a, b in (line.split() for line in f)]
    passes = [(g, a - began, (b - a) * 1e3) for g, a, b in passes if began <= a <= ended]
    writes = sorted(ms for g, _, ms in passes if g == -1)
    if writes:
        print(f"server probe, actions written to the store in the abuse phase: {len(writes)}, "
              f"median {writes[len(writes) // 2]:.2f} ms, longest {writes[-1]:.1f} ms; over "
              f"20 ms at (s into the phase: ms) " + ", ".join(
                  f"{a:.2f}: {ms:.0f}" for g, a, ms in passes if g == -1 and ms > 20))
    for gen in (0, 1, 2):
        mine = [ms for g, _, ms in passes if g == gen]
        if mine:
            print(f"server probe, the collector's generation-{gen} passes in the abuse phase: "
                  f"{len(mine)}, {sum(mine):.0f} ms in all, longest {max(mine):.1f} ms"
                  + ("" if gen < 1 else "; at (s into the phase: ms) " + ", ".join(
                      f"{a:.2f}: {ms:.0f}" for g, a, ms in passes if g == gen and ms > 5)))
    print(f"server probe, the slowest 5 % of the honest turns under abuse were sent in "
          f"{len(windows)} quarter-seconds of the phase's "
          f"{int((max(r[3] for r in rows) - began) / 0.25) + 1}; the busiest (s into the "
          f"phase: turns): " + ", ".join(f"{k * 0.25:.2f}: {n}" for k, n in busiest))
    for name, group in (("all", rows), ("slowest 5 %", tail)):
        parts = [statistics.mean(r[1][k] for r in group) for k in range(len(TURN_PARTS))]
        print(f"server probe, honest turns under abuse, {name} ({len(group)}, round trip mean "
              f"{statistics.mean(r[0] for r in group) * 1e3:.1f} ms; with an abuser's job "
              f"beside {sum(r[2] for r in group) / len(group):.0%}), mean ms: "
              + "; ".join(f"{p} {v:.1f}" for p, v in zip(TURN_PARTS, parts, strict=True)))


def _summary(name: str, rtt: list[float], patches: list[float]) -> str:
    rtt = sorted(rtt)
    p95 = rtt[int(0.95 * (len(rtt) - 1))] if rtt else math.nan
    return (f"{name}: turns answered {len(rtt)}, round trip median "
            f"{statistics.median(rtt or [math.nan]):.1f} ms, p95 {p95:.1f} ms; patches "
            f"{len(patches)}, median {statistics.median(patches or [math.nan]):.0f} ms")


async def abuse_async(args) -> None:
    import multiprocessing

    with tempfile.TemporaryDirectory() as data:
        probe = os.path.join(data, "probe.txt") if args.server_probe else None
        trace: list | None = [] if args.server_probe else None
        proc, host = _start_server(data, probe)
        try:
            async with httpx.AsyncClient(base_url=f"http://{host}", timeout=900) as http:
                t0 = time.perf_counter()  # the photos of every exercise built at start-up
                await first_view(http, host, (await http.get("/api/exercises")).json()[-1]["name"],
                                 0)
                print(f"photos prepared {time.perf_counter() - t0:.1f} s after start-up")
            results = {}
            for phase in ("idle", "abuse"):
                rtt: list[float] = []
                patches: list[float] = []
                stop = time.monotonic() + args.seconds
                abuser = queue = None
                if phase == "abuse":
                    ctx = multiprocessing.get_context("spawn")
                    queue = ctx.Queue()
                    abuser = ctx.Process(target=_abuser_process, args=(
                        host, args.seconds + 2, args.abuse_sockets, args.abuse_sessions,
                        args.abuse_patchers, queue))
                    abuser.start()
                    await asyncio.sleep(2.0)  # the abuser's sockets open first
                    stop = time.monotonic() + args.seconds
                cpu = time.process_time()
                await asyncio.gather(*(
                    honest(host, n + (100 if phase == "abuse" else 0), stop, rtt,
                           patches if n == 0 else None, 1 / args.rate, args.whole_states,
                           trace)
                    for n in range(args.trainees)))
                cpu = time.process_time() - cpu  # the honest clients' own CPU in the phase
                if abuser is not None:
                    results["abuser"] = queue.get(timeout=60)
                    abuser.join(30)
                results[phase] = (rtt, patches)
                print(f"{_summary(phase, rtt, patches)}; the honest clients' CPU {cpu:.1f} s",
                      flush=True)
        finally:
            proc.terminate()
            try:
                proc.wait(30)
            except subprocess.TimeoutExpired:
                proc.kill()
        if probe is not None:
            _probe_summary(probe)
            _turns_summary(probe + ".turns", trace)
    a = results["abuser"]
    idle_patch = statistics.median(results["idle"][1] or [math.nan])
    abuse_patch = statistics.median(results["abuse"][1] or [math.nan])
    print(f"abuser ({args.abuse_sockets} sockets on {args.abuse_sessions} sessions, "
          f"{args.abuse_patchers} patch clients): turns served {a['served']}, refused "
          f"{a['refused']}; socket attempts: refused at the handshake "
          f"{a['handshakes_refused']}, refused after the key {a['refused_after_key']}, "
          f"accepted {a['accepted']} (of which replaced by a newer socket {a['replaced']}, "
          f"closed otherwise {a['closed_other']}), failed to open {a['failed_open']}; "
          f"patches {a['patches']} served, "
          f"{a['patches_refused']} refused; the abuser client's CPU "
          f"{a.get('cpu_s', math.nan):.1f} s")
    print(f"patch median under abuse / idle: {abuse_patch / idle_patch:.2f} "
          f"(os.cpu_count() = {os.cpu_count()}, 1-minute load average at the end "
          f"{os.getloadavg()[0]:.1f})")


async def main_async(args) -> None:
    with tempfile.TemporaryDirectory() as data:
        proc, host = _start_server(data)
        try:
            async with httpx.AsyncClient(base_url=f"http://{host}", timeout=120) as http:
                exercises = [e["name"] for e in (await http.get("/api/exercises")).json()]
                t0 = time.perf_counter()
                cold = await first_view(http, host, exercises[-1], 0)  # the last photos queued
                print(
                    f"photos of every exercise prepared {time.perf_counter() - t0:.1f} s after "
                    f"start-up (first view of {exercises[-1]} then: {cold[0]:.2f} s)"
                )
                views = {
                    ex: await first_view(http, host, ex, i + 1)
                    for i, ex in enumerate(exercises)
                    if not args.skip_first_view
                }
                # the long log to replay: the operator's e01 script as a demonstration
                demo_sid, demo_secret = await _session(
                    http, "e01-setup-stage1", "operator", demonstration=True
                )
                ws, _ = await _open(host, demo_sid, demo_secret)
                while True:
                    reply = await _ask(ws, {"demo": "step"})
                    if reply.get("error") == "demonstration finished":
                        break
                    await asyncio.sleep(0.02)  # under the rate limit
                await ws.close()
                n_log = reply["n"]
                stop = time.monotonic() + args.seconds
                rtt: list[float] = []
                stats = {"pushes": 0, "replays": [], "grades": []}
                tasks = [
                    trainee(
                        host,
                        http,
                        n,
                        stop,
                        rtt,
                        time.monotonic() + 5 * (n + 1) if n < args.seconds // 5 else None,
                        1 / args.rate,
                    )
                    for n in range(args.trainees)
                ]
                if not args.no_instructor:
                    tasks.append(
                        instructor(host, http, stop, demo_sid, stats, args.instructor_pause)
                    )
                await asyncio.gather(*tasks)
        finally:
            proc.terminate()
            proc.wait(10)
    rtt.sort()
    first = [v[0] for v in views.values()] or [math.nan]
    sharp = [v[1] for v in views.values()] or [math.nan]
    print(
        f"first eyepiece view (POST session → both coarse patches), after preparation: "
        f"median {statistics.median(first):.2f} s, max {max(first):.2f} s; both sharp ×6: "
        f"median {statistics.median(sharp):.2f} s, max {max(sharp):.2f} s"
    )
    for ex, (a, b) in views.items():
        print(f"  {ex:32s} first {a:.2f} s, sharp {b:.2f} s")
    print(
        f"load: {args.trainees} trainees × {args.rate:g} turns/s"
        f"{'' if args.no_instructor else ' + instructor'}, {args.seconds} s; "
        f"replays of a {n_log}-action log: {len(stats['replays'])} "
        f"(median {statistics.median(stats['replays'] or [math.nan]):.2f} s), on-demand grades: "
        f"{len(stats['grades'])}, table pushes: {stats['pushes']}"
    )
    print(
        f"turn-to-state round trip: n={len(rtt)} median {statistics.median(rtt):.1f} ms, "
        f"p95 {rtt[int(0.95 * (len(rtt) - 1))]:.1f} ms, max {rtt[-1]:.1f} ms "
        f"(os.cpu_count() = {os.cpu_count()}, 1-minute load average at the end "
        f"{os.getloadavg()[0]:.1f})"
    )


def action_cost(turns: int) -> None:
    """In this process, no server: the CPU time of an honest trainee's turn (the session's
    action and the reply's JSON, what the server's threads compute for it), best of 5; and the
    garbage collector's full pass over what the server's start-up builds, before and after
    ``gc.freeze()`` (what ``stereoplotter trainer`` does before serving)."""
    import gc

    from stereoplotter.io.exercise_file import load_exercise
    from stereoplotter.trainer.session import Session
    from stereoplotter.web.app import create_app

    session = Session.start(load_exercise("e01-setup-stage1"), trainee="cost", seed=1)
    session.act({"kind": "set", "control": "f_instrument", "value": 120.0, "t": 0})
    sent = session.state()
    sizes = {}
    for patched in (False, True):
        runs = []
        for _ in range(5):
            t0 = time.process_time()
            for i in range(turns):
                state = session.act({"kind": "turn", "control": "X",
                                     "delta": 0.05 if i % 2 else -0.05, "t": i * 0.1})
                if patched:
                    body = {"patch": state_patch(sent, state), "error": None}
                    sent = state
                else:
                    body = {"state": state, "error": None}
                body["n"] = len(session.log)
                sizes[patched] = len(json.dumps(body, allow_nan=False))
            runs.append((time.process_time() - t0) / turns * 1e3)
        print(f"an honest turn, {'what changed' if patched else 'the whole state'} sent "
              f"({sizes[patched]} characters): CPU {min(runs):.3f} ms (best of 5 × {turns}; "
              f"all {', '.join(f'{r:.3f}' for r in runs)})")
    del session
    with tempfile.TemporaryDirectory() as data:
        create_app("cost-token-0123456789", data, processes=False, prepare_photos=False)

        def full_pass() -> float:
            t0 = time.process_time()
            gc.collect()
            return (time.process_time() - t0) * 1e3

        tracked = len(gc.get_objects())
        before = min(full_pass() for _ in range(3))
        gc.freeze()
        after = min(full_pass() for _ in range(3))
        gc.unfreeze()
    print(f"after the server's start-up: {tracked} objects tracked by the garbage collector, a "
          f"full pass {before:.1f} ms CPU; after gc.freeze() {after:.1f} ms")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trainees", type=int, default=20)
    ap.add_argument("--seconds", type=float, default=30.0)
    ap.add_argument("--rate", type=float, default=10.0, help="turns a second per trainee")
    ap.add_argument(
        "--instructor-pause",
        type=float,
        default=2.0,
        help="seconds between the instructor's replay-and-grade rounds",
    )
    ap.add_argument(
        "--no-instructor",
        action="store_true",
        help="trainees only: no replays nor on-demand grades (a baseline)",
    )
    ap.add_argument("--abuser", action="store_true",
                    help="fairness: honest trainees alone, then beside one abuser")
    ap.add_argument("--server-probe", action="store_true",
                    help="--abuser: time the server's actor jobs (queue wait, run, overlap)")
    ap.add_argument("--whole-states", action="store_true",
                    help="--abuser: the honest trainees take the whole state each turn")
    ap.add_argument("--abuse-sockets", type=int, default=100)
    ap.add_argument("--abuse-sessions", type=int, default=10)
    ap.add_argument("--abuse-patchers", type=int, default=8)
    ap.add_argument(
        "--skip-first-view",
        action="store_true",
        help="no first-view times (the photos are still prepared before the load)",
    )
    ap.add_argument("--action-cost", action="store_true",
                    help="no server: the CPU time of one honest turn, the collector's full pass")
    ap.add_argument("--turns", type=int, default=3000, help="turns timed by --action-cost")
    args = ap.parse_args()
    if args.action_cost:
        return action_cost(args.turns)
    asyncio.run(abuse_async(args) if args.abuser else main_async(args))


if __name__ == "__main__":
    main()
