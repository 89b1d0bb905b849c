"""The classroom server under attack: Starlette's TestClient, no browser.

Every test plays a client the server must not trust; the server runs in-process with its
store in a temporary folder, grading and photos in worker threads.
"""

from __future__ import annotations

import json
import warnings

import pytest

from stereoplotter.web.app import create_app

with warnings.catch_warnings():  # Starlette 1.x asks for httpx2 and warns on httpx: either works
    warnings.simplefilter("ignore")
    from starlette.testclient import TestClient

TOKEN = "instructor-test-token"
PRACTICE = "e01-setup-stage1"
EXAM = "e11-setup-exam"


def make_test_client(app) -> TestClient:
    return TestClient(app)


def make_client(data_dir) -> TestClient:
    """A client of a server whose session starts are not rate-limited: a test module starts
    more sessions in a second than a classroom address may (the limit itself is tried by
    ``test_attacks.py`` on a server of its own)."""
    return TestClient(create_app(TOKEN, data_dir, hosts=("testserver",), start_limit=(1e3, 10**4)))


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    with make_client(tmp_path_factory.mktemp("trainer-data")) as c:
        yield c


def start(client, exercise=PRACTICE, trainee="ann", **extra):
    """A new session: (id, secret); fails the test on a refusal."""
    r = client.post("/api/sessions", json={"exercise": exercise, "trainee": trainee, **extra})
    assert r.status_code == 200, r.text
    return r.json()["id"], r.json()["secret"]


def open_socket(client, sid, secret, **kw):
    """A session's socket, authenticated; returns (socket context, hello frame)."""
    ws = client.websocket_connect(f"/ws/{sid}", **kw)
    conn = ws.__enter__()
    conn.send_text(json.dumps({"auth": secret}))
    return ws, conn, json.loads(conn.receive_text())


def ask(conn, body) -> dict:
    """Send one message (dict as JSON, or text as is) and return the reply frame."""
    conn.send_text(body if isinstance(body, str) else json.dumps(body))
    return json.loads(conn.receive_text())


def claim_all(client, sid, secret):
    """Finish a session of e01 (one stage): claim it."""
    ws, conn, hello = open_socket(client, sid, secret)
    try:
        reply = ask(conn, {"action": {"kind": "claim", "step": hello["state"]["stage"]}, "seq": 1})
        assert reply["error"] is None and reply["state"]["done"], reply
    finally:
        ws.__exit__(None, None, None)


_PHOTOS: dict[str, object] = {}
_PHOTOS_LOCK = __import__("threading").Lock()


@pytest.fixture(autouse=True, scope="session")
def photos_built_once():
    """Every test server of the run shares the photos of an exercise, built once (a build is
    seconds of CPU; the tests' servers are many)."""
    from stereoplotter.web import core

    build = core.build_view_cache

    def shared(source):
        key = json.dumps(source, sort_keys=True, default=str)
        with _PHOTOS_LOCK:
            if key not in _PHOTOS:
                _PHOTOS[key] = build(source)
            return _PHOTOS[key]

    core.build_view_cache = shared
    yield
    core.build_view_cache = build
