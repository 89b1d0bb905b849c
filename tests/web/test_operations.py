"""The classroom's operations: uploads that never replace one another and can be retired, a
server behind an HTTPS reverse proxy, workers that end with the server (kill -9 too), an
instructor token kept hashed in the data folder, and refusals that quote what was sent."""

from __future__ import annotations

import json
import os
import re
import signal
import socket
import subprocess
import sys
import time
from importlib import resources
from pathlib import Path

import pytest

from stereoplotter.io.session_store import DB_NAME
from stereoplotter.web.app import create_app
from tests.web.conftest import PRACTICE, TOKEN, ask, make_test_client, open_socket, start

ROOT = Path(__file__).resolve().parents[2]
SOURCE = (resources.files("stereoplotter") / "data" / "exercises" / f"{PRACTICE}.yaml").read_text()


def _upload(c, text, token=TOKEN):
    return c.post("/api/instructor/exercises", params={"token": token}, content=text)


def _named(name: str, text: str = SOURCE) -> str:
    return text.replace(f"name: {PRACTICE}", f"name: {name}")


# --- uploads ----------------------------------------------------------------------------------


def test_an_upload_never_replaces_and_can_be_retired(tmp_path):
    app = create_app(TOKEN, tmp_path, hosts=("testserver",))
    with make_test_client(app) as c:
        assert _upload(c, _named("class-b1")).status_code == 200
        sid, secret = start(c, "class-b1", trainee="first")
        changed = _named("class-b1").replace("level: 1", "level: 2")
        r = _upload(c, changed)
        assert r.status_code == 409 and "in use" in r.json()["error"], r.text
        r = _upload(c, SOURCE)  # a shipped name
        assert r.status_code == 409, r.text
        # what cannot start is refused at upload, with the reason
        r = _upload(c, _named("class-b2").replace("tilt: small", "tilt: large"))
        assert r.status_code == 400 and "no session can start" in r.json()["error"], r.text
        assert "tilt" in r.json()["error"]
        # bounded texts
        r = _upload(c, _named("class-b3").replace("title:", "title: " + "x" * 50_000 + " #", 1))
        assert r.status_code in (400, 413), r.text
        long_title = _named("class-b4").replace("\ntitle:", "\ntitle: " + "y" * 500 + " #", 1)
        r = _upload(c, long_title)
        assert r.status_code == 400 and "at most 160" in r.json()["error"], r.text
        # an exam with a fixed seed: anyone who saw the file knows it
        exam = _named("class-b5").replace("mode: practice", "mode: exam")
        exam = re.sub(r"(?m)^seed:.*$", "", exam) + "\nseed: 7\n"
        r = _upload(c, exam)
        assert r.status_code == 400 and "seed" in r.json()["error"], r.text
        # retire: not offered, no new session, the old one resumes
        assert c.delete("/api/instructor/exercises/class-b1").status_code == 403
        r = c.delete("/api/instructor/exercises/class-b1", params={"token": TOKEN})
        assert r.status_code == 200 and r.json()["retired"] is True
        assert "class-b1" not in [e["name"] for e in c.get("/api/exercises").json()]
        r = c.post("/api/sessions", json={"exercise": "class-b1", "trainee": "late"})
        assert r.status_code == 404
        r = c.delete(f"/api/instructor/exercises/{PRACTICE}", params={"token": TOKEN})
        assert r.status_code == 403
        assert _upload(c, _named("class-b1")).status_code == 409  # the name stays used
        ws, conn, hello = open_socket(c, sid, secret)
        try:
            assert ask(conn, {"action": {"kind": "read", "counter": "X"}})["error"] is None
        finally:
            ws.__exit__(None, None, None)
    with make_test_client(create_app(TOKEN, tmp_path, hosts=("testserver",))) as c:
        assert "class-b1" not in [e["name"] for e in c.get("/api/exercises").json()]
        ws, conn, hello = open_socket(c, sid, secret)  # resumes after a restart
        try:
            assert hello["n"] == 1 and hello["hello"]["exercise"] == "class-b1"
        finally:
            ws.__exit__(None, None, None)
        r = c.get(f"/api/sessions/{sid}/patch.png",
                  params={"side": "left", "x": 0, "y": 0, "mag": 0.625, "size": 32, "key": secret})
        assert r.status_code == 200


# --- behind a reverse proxy -------------------------------------------------------------------

PUBLIC = "https://class.example"


def test_behind_an_https_proxy_the_public_host_and_origin_are_accepted(tmp_path):
    app = create_app(TOKEN, tmp_path, public_url=PUBLIC, start_limit=(1e3, 10**4))
    proxied = {"x-forwarded-proto": "https", "x-forwarded-for": "203.0.113.7"}
    with make_test_client(app) as c:
        for host in ("class.example", "127.0.0.1:8123"):  # Host kept, or rewritten by the proxy
            headers = {**proxied, "host": host, "origin": PUBLIC}
            r = c.post("/api/sessions", json={"exercise": PRACTICE, "trainee": "p"},
                       headers=headers)
            assert r.status_code == 200, (host, r.text)
            sid, secret = r.json()["id"], r.json()["secret"]
            ws, _, hello = open_socket(c, sid, secret, headers=headers)
            try:
                assert hello["hello"]["id"] == sid
            finally:
                ws.__exit__(None, None, None)
        for origin in ("https://evil.example", "http://class.example.evil", "null"):
            r = c.post("/api/sessions", json={"exercise": PRACTICE},
                       headers={**proxied, "host": "class.example", "origin": origin})
            assert r.status_code == 403, origin
        # the page said https, the Origin says http: not this server's page
        r = c.post("/api/sessions", json={"exercise": PRACTICE},
                   headers={"host": "class.example", "origin": "http://class.example",
                            "x-forwarded-proto": "https"})
        assert r.status_code == 403
        assert c.get("/api/exercises", headers={"host": "evil.example"}).status_code == 400


def test_localhost_with_its_root_dot_is_localhost(tmp_path):
    with make_test_client(create_app(TOKEN, tmp_path)) as c:
        for host in ("localhost.", "localhost.:8000", "LOCALHOST"):
            r = c.post("/api/sessions", json={"exercise": PRACTICE},
                       headers={"host": host, "origin": f"http://{host}"})
            assert r.status_code == 200, (host, r.text)
        assert c.get("/api/exercises", headers={"host": "localhost.evil"}).status_code == 400


def test_uvicorn_behind_a_proxy_takes_its_headers(tmp_path):
    """The server under uvicorn with the settings of ``--public-url``, reached as a reverse
    proxy on this machine reaches it (what Caddy and nginx send: the public Host, the page's
    Origin, X-Forwarded-Proto and X-Forwarded-For): the proxied page starts a session and its
    socket opens, and each trainee's address is the forwarded one (one session start per
    address here: a second trainee behind the same proxy is not refused)."""
    httpx = pytest.importorskip("httpx")
    websockets = pytest.importorskip("websockets.sync.client")
    proc = subprocess.Popen(
        [sys.executable, "-m", "tests.web.proxy_server", str(tmp_path), PUBLIC],
        cwd=ROOT, stdout=subprocess.PIPE, text=True,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    try:
        port = int(proc.stdout.readline())
        headers = {"host": "class.example", "origin": PUBLIC, "x-forwarded-proto": "https",
                   "x-forwarded-for": "198.51.100.4"}
        r = httpx.post(f"http://127.0.0.1:{port}/api/sessions", headers=headers,
                       json={"exercise": PRACTICE, "trainee": "proxied"}, timeout=30)
        assert r.status_code == 200, r.text
        sid, secret = r.json()["id"], r.json()["secret"]
        sock = socket.create_connection(("127.0.0.1", port))  # the Host is the public name
        extra = {k: v for k, v in headers.items() if k != "host"}
        with websockets.connect(f"ws://class.example/ws/{sid}", sock=sock,
                                additional_headers=extra) as ws:
            ws.send(json.dumps({"auth": secret}))
            assert json.loads(ws.recv(timeout=30))["hello"]["id"] == sid
        table = httpx.get(f"http://127.0.0.1:{port}/api/instructor/sessions",
                          params={"token": TOKEN}, headers=headers, timeout=30).json()
        assert [row["trainee"] for row in table] == ["proxied"]
        url = f"http://127.0.0.1:{port}/api/sessions"
        again = httpx.post(url, headers=headers, json={"exercise": PRACTICE}, timeout=30)
        assert again.status_code == 429  # the same forwarded address
        other = {**headers, "x-forwarded-for": "198.51.100.5"}
        assert httpx.post(url, headers=other, json={"exercise": PRACTICE},
                          timeout=30).status_code == 200
    finally:
        proc.send_signal(signal.SIGINT)
        proc.wait(timeout=30)
        proc.stdout.close()


# --- workers, the token, error texts ----------------------------------------------------------


def test_worker_processes_die_with_a_killed_server(tmp_path):
    """A stand-in server starts its worker pool, prints the worker's pid and is killed with
    SIGKILL: the worker finds its parent gone and ends within seconds."""
    code = (
        "import os, sys, time\n"
        "from stereoplotter.web.app import worker_pool\n"
        "pool = worker_pool(True)\n"
        "print(pool.submit(os.getpid).result(), flush=True)\n"
        "time.sleep(600)\n"
    )
    server = subprocess.Popen([sys.executable, "-c", code], cwd=ROOT, stdout=subprocess.PIPE,
                              text=True, env={**os.environ, "PYTHONPATH": str(ROOT)})
    try:
        worker = int(server.stdout.readline())
        os.kill(worker, 0)  # alive
        server.kill()
        server.wait(timeout=10)
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline:
            try:
                os.kill(worker, 0)
            except ProcessLookupError:
                break
            _reap(worker)
            time.sleep(0.1)
        else:
            os.kill(worker, signal.SIGKILL)
            pytest.fail("the worker outlived its killed server")
    finally:
        if server.poll() is None:
            server.kill()
            server.wait(timeout=10)
        server.stdout.close()


def _reap(pid: int) -> None:
    try:  # a zombie re-parented to this test process (it is no child: nothing to reap)
        os.waitpid(pid, os.WNOHANG)
    except ChildProcessError:
        pass


def test_the_instructor_token_is_kept_hashed_and_can_be_rotated(tmp_path):
    with make_test_client(create_app(None, tmp_path, hosts=("testserver",))) as c:
        first = c.app.state.registry.new_token
        assert first and len(first) >= 24
        assert c.get("/api/instructor/sessions", params={"token": first}).status_code == 200
    assert first.encode() not in (tmp_path / DB_NAME).read_bytes()
    with make_test_client(create_app(None, tmp_path, hosts=("testserver",))) as c:
        reg = c.app.state.registry
        assert reg.new_token is None  # kept: nothing new to print
        assert c.get("/api/instructor/sessions", params={"token": first}).status_code == 200
        second = reg.rotate_token()
        assert c.get("/api/instructor/sessions", params={"token": first}).status_code == 403
    with make_test_client(create_app(None, tmp_path, hosts=("testserver",))) as c:
        assert c.get("/api/instructor/sessions", params={"token": second}).status_code == 200
        assert c.get("/api/instructor/sessions", params={"token": first}).status_code == 403
    with make_test_client(create_app("given-token-0123456", tmp_path, hosts=("testserver",))) as c:
        assert c.get("/api/instructor/sessions",
                     params={"token": "given-token-0123456"}).status_code == 200


def test_refusals_quote_what_was_sent(tmp_path):
    with make_test_client(create_app(TOKEN, tmp_path, hosts=("testserver",))) as c:
        sid, secret = start(c, PRACTICE, trainee="quoted")
        ws, conn, _ = open_socket(c, sid, secret)
        try:
            for sent in ("../../x", "!!python/object/apply:os.system", "/etc/passwd"):
                reply = ask(conn, {"action": {"kind": sent}})
                assert repr(sent) in reply["error"], reply["error"]
            reply = ask(conn, {"action": {"kind": "read", "counter": "x" * 200}})
            assert len(reply["error"]) <= 300 and "xxxx" in reply["error"]
        finally:
            ws.__exit__(None, None, None)
        r = c.post("/api/sessions", json={"exercise": "../../x", "trainee": "q"})
        assert r.status_code == 404 and "'../../x'" in r.json()["error"]
        r = _upload(c, _named("class-q1").replace("scenario: pair60",
                                                  "scenario: '!!python/object/apply:os.system'"))
        assert r.status_code == 400 and "!!python/object/apply:os.system" in r.json()["error"]


def test_sigterm_ends_the_server_as_ctrl_c_does(tmp_path):
    """A service manager's stop (SIGTERM) shuts the server down whole: the interrupt's one line
    and exit code, and the worker pools ended at exit (none of their semaphores left behind,
    which the interpreter's resource tracker reports when the process dies without ending
    them)."""
    server = subprocess.Popen(
        [sys.executable, "-m", "stereoplotter", "trainer", "--token", "sigterm-token-0123456",
         "--data-dir", str(tmp_path)],
        cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )  # fmt: skip
    try:
        assert server.stdout.readline().startswith("trainee page:")
        time.sleep(6)  # the photos' worker processes started in the background
        server.send_signal(signal.SIGTERM)
        _, err = server.communicate(timeout=60)
    finally:
        if server.poll() is None:
            server.kill()
            server.communicate(timeout=10)
    assert server.returncode == 130, err
    assert err.strip().splitlines()[-1] == "error: interrupted", err
    assert "leaked" not in err, err
