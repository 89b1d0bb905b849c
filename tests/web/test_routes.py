"""Every route with bad bodies and parameters answers 4xx with one line of JSON, never 500;
the instructor's table is pushed; the class is exported (CSV) and archived (zip of logs)."""

from __future__ import annotations

import io
import json
import re
import zipfile

from starlette.routing import Route, WebSocketRoute

from tests.web.conftest import EXAM, PRACTICE, TOKEN, ask, claim_all, open_socket, start

BAD_BODIES = [
    b"",
    b"{",
    b"[]",
    b"null",
    b'"text"',
    b"[" * 5000,
    b'{"exercise": 5}',
    b'{"exercise": "e01-setup-stage1", "trainee": 5}',
    b'{"exercise": "e01-setup-stage1", "seed": "abc"}',
    b'{"exercise": "e01-setup-stage1", "seed": 1e400}',
    b'{"exercise": "e01-setup-stage1", "seed": -1}',
    b'{"exercise": "e01-setup-stage1", "seed": true}',
    b'{"exercise": "e01-setup-stage1", "demonstration": "yes"}',
    b'{"trainee": "x", "exercise": "nope"}',
    b"\xff\xfe",
    b"x" * 70_000,
]
BAD_PATCH = [
    "",
    "side=top&x=0&y=0&mag=6",
    "side=left&x=a&y=0&mag=6",
    "side=left&x=0&y=0&mag=0",
    "side=left&x=0&y=0&mag=-2",
    "side=left&x=0&y=0&mag=nan",
    "side=left&x=0&y=0&mag=inf",
    "side=left&x=1e400&y=0&mag=6",
    "side=left&x=0&y=0&mag=6&size=0",
    "side=left&x=0&y=0&mag=6&size=99999",
    "side=left&x=0&y=0&mag=6&size=1.5",
    "side=left&x=999&y=0&mag=6",
]


def _one_line_error(r):
    assert 400 <= r.status_code < 500, (r.request.url, r.status_code, r.text[:200])
    body = r.json()
    assert set(body) == {"error"} and "\n" not in body["error"] and body["error"]
    assert "Traceback" not in body["error"]


def test_every_route_answers_bad_requests_with_one_line(client):
    sid, secret = start(client, trainee="walker")
    _, other_secret = start(client, trainee="another walker")
    paths = {"sid": sid, "name": "no-such-upload"}
    routes = [r for r in client.app.routes if isinstance(r, Route)]
    seen = set()
    for route in routes:
        path = route.path.format(**paths)
        for method in sorted(route.methods - {"HEAD"}):
            seen.add(route.path)
            for auth in ({}, {"token": "wrong"}, {"key": "wrong"}, {"token": TOKEN}):
                if method == "POST":
                    for body in BAD_BODIES:
                        r = client.post(path, params=auth, content=body)
                        if route.path == "/api/instructor/exercises" and auth == {"token": TOKEN}:
                            assert r.status_code != 200 or body == b"", body
                        if r.status_code != 200:
                            _one_line_error(r)
                elif path.startswith("/api/"):
                    r = client.get(path, params=auth)
                    assert r.status_code < 500, path
                    if r.status_code != 200:
                        _one_line_error(r)
            # another session's key opens nothing of this one
            if route.path.startswith("/api/sessions/{sid}"):
                r = client.get(path, params={"key": other_secret})
                assert r.status_code == 403, (path, r.status_code)
                _one_line_error(r)
            # unknown sessions, bad ids and wrong methods
            if "{sid}" in route.path and route.path.startswith("/api/"):
                for bad in ("nope", "0" * 16, "..%2f..%2fetc", "%00"):
                    _one_line_error(client.get(route.path.format(sid=bad), params={"token": TOKEN}))
            other = "GET" if method == "POST" else "POST"
            if other not in route.methods and route.path.startswith("/api/"):
                _one_line_error(client.request(other, path, params={"token": TOKEN}))
    for q in BAD_PATCH:
        _one_line_error(client.get(f"/api/sessions/{sid}/patch.png?{q}&key={secret}"))
    _one_line_error(client.get("/api/nothing-here"))
    for mag, size in ((0.625, 80), (6, 768)):  # the page's coarse-first patch, then the sharp one
        q = {"side": "left", "x": 1, "y": -2, "mag": mag, "size": size, "key": secret}
        r = client.get(f"/api/sessions/{sid}/patch.png", params=q)
        assert r.status_code == 200 and r.content[:8] == b"\x89PNG\r\n\x1a\n"
    assert (
        client.get(f"/api/sessions/{sid}/patch.png?side=left&x=0&y=0&mag=6&key=no").status_code
        == 403
    )
    assert len(seen) == len(routes)
    assert {r.path for r in client.app.routes if isinstance(r, WebSocketRoute)} == {
        "/ws/{sid}",
        "/ws-instructor",
    }


def test_instructor_table_is_pushed_without_regrading(client):
    with client.websocket_connect("/ws-instructor") as ins:
        ins.send_text(json.dumps({"auth": TOKEN}))
        first = json.loads(ins.receive_text())["sessions"]
        sid, secret = start(client, trainee="pushed")
        rows = json.loads(ins.receive_text())["sessions"]
        assert len(rows) == len(first) + 1 and rows[-1]["trainee"] == "pushed"
        claim_all(client, sid, secret)
        reg = client.app.state.registry
        reg.grading(sid).result(timeout=60)  # graded once, in the worker, when finished
        for _ in range(10):
            rows = json.loads(ins.receive_text())["sessions"]
            mine = next(r for r in rows if r["id"] == sid)
            if "score" in mine:
                break
        assert mine["done"] and isinstance(mine["passed"], bool)
        assert mine["score"] == round(reg.grades[sid]["overall"]["score"], 4)


def test_csv_export_and_class_archive(client):
    sid, secret = start(client, trainee="archived")
    claim_all(client, sid, secret)
    client.app.state.registry.grading(sid).result(timeout=60)
    csv = client.get("/api/instructor/results.csv", headers={"Authorization": f"Bearer {TOKEN}"})
    assert csv.status_code == 200 and csv.text.splitlines()[0].startswith("id,trainee,exercise")
    assert any(line.startswith(f"{sid},archived,{PRACTICE}") for line in csv.text.splitlines())
    z = client.get("/api/instructor/archive.zip", params={"token": TOKEN})
    assert z.status_code == 200
    with zipfile.ZipFile(io.BytesIO(z.content)) as arc:
        names = arc.namelist()
        assert "results.csv" in names and f"logs/session-{sid}.jsonl" in names
        lines = arc.read(f"logs/session-{sid}.jsonl").decode().splitlines()
        assert json.loads(lines[0])["trainee"] == "archived"
        assert json.loads(lines[-1])["action"]["kind"] == "claim"
        assert f"grades/grade-{sid}.json" in names
    assert client.get("/api/instructor/archive.zip", params={"token": "x"}).status_code == 403
    ws, _conn, hello = open_socket(client, sid, secret)
    ws.__exit__(None, None, None)
    assert hello["state"]["done"]


#: A server path in any text the page is sent (the issue saw one in a stop's refusal).
SERVER_PATH = re.compile(r"(?:[A-Za-z]:)?[\w.\-~]*(?:[\\/][\w.\-~ ]+){2,}")


def _texts(value):
    """Every string in a JSON value (keys and values)."""
    if isinstance(value, str):
        yield value
    elif isinstance(value, dict):
        for k, v in value.items():
            yield k
            yield from _texts(v)
    elif isinstance(value, list):
        for v in value:
            yield from _texts(v)


def test_sheet_and_overview_need_the_sessions_key_and_name_no_path(client):
    sid, secret = start(client, exercise="e07-setup-stage2-incomplete", trainee="sheets")
    for route in ("sheet", "overview", "checklist", "showme"):
        path = f"/api/sessions/{sid}/{route}"
        assert client.get(path).status_code == 403
        assert client.get(path, params={"key": "x" * 43}).status_code == 403
        other = f"/api/sessions/{'0' * 16}/{route}"
        assert client.get(other, params={"key": secret}).status_code == 404
        r = client.get(path, headers={"Authorization": f"Bearer {secret}"})
        assert r.status_code == 200, r.text
        paths = [m.group(0) for t in _texts(r.json()) for m in SERVER_PATH.finditer(t)]
        assert paths == []
        assert client.get(path, params={"token": TOKEN}).status_code == 200
    exam_sid, exam_secret = start(client, exercise=EXAM, trainee="sheets")
    r = client.get(f"/api/sessions/{exam_sid}/showme", params={"key": exam_secret})
    assert r.status_code == 403 and "no hints" in r.json()["error"]  # an exam shows nothing
    ov = client.get(f"/api/sessions/{sid}/overview", params={"key": secret}).json()
    photos = ov["photos"] if "photos" in ov else None
    if photos is not None:  # the core's overview: six standard points a photo, 5 and 6 unusable
        left = photos["left"]["standard_points"]
        assert [p["id"] for p in left] == ["1", "2", "3", "4", "5", "6"]
        assert [p["id"] for p in left if p["usable"] is False] == ["5", "6"]


def test_a_stops_refusal_names_the_file_not_its_path(client):
    sid, secret = start(client, trainee="stopped")
    ws, conn, hello = open_socket(client, sid, secret)
    try:
        assert [t for t in _texts(hello) if SERVER_PATH.search(t)] == []
        z = hello["state"]["controls"]["Z"]
        beyond = z["max"] + 0.005 * (z["max"] - z["min"])  # past the stop, within the slack
        reply = ask(conn, {"action": {"kind": "set", "control": "Z", "value": beyond}, "seq": 1})
        assert "refused" in reply["error"] and not SERVER_PATH.search(reply["error"]), reply
        reply = ask(conn, {"action": {"kind": "set", "control": "Z", "value": 1e4}, "seq": 2})
        assert "expected a value from" in reply["error"] and reply["n"] == 1, reply
        kinds = {a["kind"] for a in hello["hello"]["actions"]}
        assert {"record", "connect", "slip", "needle", "lock", "gear"} <= kinds
    finally:
        ws.__exit__(None, None, None)
