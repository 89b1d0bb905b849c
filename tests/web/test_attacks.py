"""One test per attack a classroom server meets, each asserting the refusal (and that the honest
path still works). The server: ``stereoplotter.web.app.create_app`` with a temporary store."""

from __future__ import annotations

import json
import re
import time
from importlib import resources

import pytest
from starlette.websockets import WebSocketDisconnect

from stereoplotter.trainer.exercise import trainee_seed
from stereoplotter.web.app import create_app
from stereoplotter.web.guard import BURST, CSP, MAX_MESSAGE, RATE
from tests.web.conftest import (
    EXAM,
    PRACTICE,
    TOKEN,
    ask,
    claim_all,
    make_test_client,
    open_socket,
    start,
)

MARKUP = '<img src=x onerror="window.__pwned=1">'
STATIC = resources.files("stereoplotter.web") / "static"


# --- 1. text is text ------------------------------------------------------------------------


def test_no_script_of_the_pages_parses_a_string_as_html():
    sinks = re.compile(
        r"innerHTML|outerHTML|insertAdjacentHTML|document\.write|\beval\(|"
        r"new Function|setAttribute\(\"on|DOMParser|createContextualFragment|setHTML|"
        r"parseHTML|srcdoc|createHTMLDocument"
    )
    for f in STATIC.iterdir():
        if f.name.endswith((".js", ".html")):
            text = f.read_text(encoding="utf-8")
            assert not sinks.search(text), f.name
            if f.name.endswith(".html"):  # no inline script, no inline handler, no inline style
                assert not re.search(r"<script(?![^>]*\bsrc=)|\son\w+=|\sstyle=", text), f.name


def test_every_page_forbids_inline_script(client):
    for path in ("/", "/s/0", "/grade/0", "/instructor", "/static/index.js", "/api/exercises"):
        r = client.get(path)
        csp = r.headers["content-security-policy"]
        assert csp == CSP
        assert (
            "script-src 'self'" in csp and "unsafe-inline" not in csp and "unsafe-eval" not in csp
        )
        assert r.headers["x-content-type-options"] == "nosniff"
        assert r.headers["referrer-policy"] == "no-referrer"


def test_a_name_with_markup_is_kept_as_text_and_a_control_character_is_refused(client):
    sid, _ = start(client, trainee=MARKUP)
    rows = client.get("/api/instructor/sessions", params={"token": TOKEN}).json()
    assert [r["trainee"] for r in rows if r["id"] == sid] == [MARKUP]
    r = client.post("/api/sessions", json={"exercise": PRACTICE, "trainee": "a\u0000b"})
    assert r.status_code == 400 and "printable" in r.json()["error"]
    r = client.post("/api/sessions", json={"exercise": PRACTICE, "trainee": "x" * 65})
    assert r.status_code == 400


def test_results_csv_cells_cannot_be_spreadsheet_formulas(client):
    start(client, trainee='=HYPERLINK("http://evil")')
    r = client.get("/api/instructor/results.csv", params={"token": TOKEN})
    assert r.status_code == 200
    assert "'=HYPERLINK" in r.text and "\n=HYPERLINK" not in r.text and ",=HYPERLINK" not in r.text


# --- 2. credentials that mean something ------------------------------------------------------


def test_grade_and_log_need_the_key_and_a_finished_session(client):
    sid, secret = start(client, trainee="bea")
    other_sid, other_secret = start(client, trainee="cid")
    for path in (
        f"/api/sessions/{sid}/grade",
        f"/api/sessions/{sid}/grade.md",
        f"/api/sessions/{sid}/log.jsonl",
    ):
        assert client.get(path).status_code == 403  # the id alone is no credential
        assert client.get(path, params={"key": other_secret}).status_code == 403
        r = client.get(path, headers={"Authorization": f"Bearer {secret}"})
        assert r.status_code == 403 and "claimed" in r.json()["error"]  # not finished yet
    assert client.get(f"/api/sessions/{sid}/log.jsonl", params={"token": TOKEN}).status_code == 200
    claim_all(client, sid, secret)
    r = client.get(f"/api/sessions/{sid}/grade", headers={"Authorization": f"Bearer {secret}"})
    assert r.status_code == 200 and r.json()["grade"]["trainee"] == "bea"
    # the replay is the instructor's only
    assert client.get(f"/api/instructor/replay/{sid}", params={"key": secret}).status_code == 403
    assert client.get(f"/api/instructor/replay/{sid}", params={"token": TOKEN}).status_code == 200
    assert other_sid != sid


def test_no_grade_of_an_exam_in_progress_to_anyone(client):
    """The answer oracle: after setting f_пр in e11 the grade read out |L − L′|."""
    sid, secret = start(client, EXAM, trainee="oracle")
    ws, conn, hello = open_socket(client, sid, secret)
    try:
        f = hello["state"]["controls"]["f_instrument"]
        reply = ask(
            conn,
            {
                "action": {
                    "kind": "set",
                    "control": "f_instrument",
                    "value": (f["min"] + f["max"]) / 2,
                },
                "seq": 1,
            },
        )
        assert reply["error"] is None
        assert "measures" not in json.dumps(reply)
    finally:
        ws.__exit__(None, None, None)
    for auth in ({"key": secret}, {"token": TOKEN}, {}):
        r = client.get(f"/api/sessions/{sid}/grade", params=auth)
        assert r.status_code == 403, auth
        assert "L′" not in r.text and "value" not in r.text
        assert client.get(f"/api/sessions/{sid}/grade.md", params=auth).status_code == 403


def test_exam_refuses_a_client_seed_a_demonstration_and_a_second_attempt(client):
    for extra in ({"seed": 7}, {"demonstration": True}):
        r = client.post("/api/sessions", json={"exercise": EXAM, "trainee": "dan", **extra})
        assert r.status_code == 403, extra
    sid, _ = start(client, EXAM, trainee="dan")
    head = client.get(f"/api/sessions/{sid}/log.jsonl", params={"token": TOKEN}).text
    assert json.loads(head.splitlines()[0])["seed"] != trainee_seed(EXAM, "dan")  # the server's
    for name in ("dan", "DAN", " dan "):  # the same trainee, however typed
        r = client.post("/api/sessions", json={"exercise": EXAM, "trainee": name})
        assert r.status_code == 403 and "attempt" in r.json()["error"], name
    r = client.post("/api/instructor/grant", json={"trainee": "dan", "exercise": EXAM})
    assert r.status_code == 403  # no token
    r = client.post(
        "/api/instructor/grant", params={"token": TOKEN}, json={"trainee": "dan", "exercise": EXAM}
    )
    assert r.status_code == 200 and r.json()["extra_attempts"] == 1
    start(client, EXAM, trainee="Dan")
    assert (
        client.post("/api/sessions", json={"exercise": EXAM, "trainee": "dan"}).status_code == 403
    )


def test_client_time_is_refused_and_the_server_clock_is_logged(client):
    sid, secret = start(client, trainee="eve")
    ws, conn, _ = open_socket(client, sid, secret)
    try:
        reply = ask(conn, {"action": {"kind": "read", "counter": "X", "t": 1.0}, "seq": 1})
        assert "the time t is the server's" in reply["error"] and reply["n"] == 0
        t0 = time.time()
        assert ask(conn, {"action": {"kind": "read", "counter": "X"}, "seq": 2})["error"] is None
    finally:
        ws.__exit__(None, None, None)
    lines = client.get(f"/api/sessions/{sid}/log.jsonl", params={"token": TOKEN}).text.splitlines()
    started = client.app.state.registry.rows[sid]["started"]
    t = json.loads(lines[1])["t"]
    assert abs(t - (t0 - started)) < 2.0  # the server's seconds since the start


def test_a_socket_without_its_sessions_key_is_refused(client):
    sid, _ = start(client, trainee="fay")
    _, other = start(client, trainee="gus")
    for key in ("", "x" * 43, other, None, 12):
        with client.websocket_connect(f"/ws/{sid}") as conn:
            conn.send_text(json.dumps({"auth": key}))
            assert "key is required" in json.loads(conn.receive_text())["error"]
            with pytest.raises(WebSocketDisconnect):
                conn.receive_text()
    with client.websocket_connect("/ws-instructor") as conn:
        conn.send_text(json.dumps({"auth": "wrong"}))
        assert json.loads(conn.receive_text())["error"] == "instructor token required"


def test_a_socket_from_another_origin_or_host_is_refused(client):
    sid, secret = start(client, trainee="hal")
    for headers in (
        {"origin": "http://evil.example"},
        {"origin": "null"},
        {"host": "evil.example", "origin": "http://evil.example"},
    ):
        with pytest.raises(WebSocketDisconnect):
            with client.websocket_connect(f"/ws/{sid}", headers=headers) as conn:
                conn.receive_text()
    ws, conn, hello = open_socket(client, sid, secret, headers={"origin": "http://testserver"})
    ws.__exit__(None, None, None)
    assert hello["hello"]["id"] == sid
    r = client.post(
        "/api/sessions", json={"exercise": PRACTICE}, headers={"origin": "http://evil.example"}
    )
    assert r.status_code == 403 and r.json()["error"] == "wrong Origin"
    r = client.get("/api/exercises", headers={"host": "attacker.example"})  # DNS rebinding
    assert r.status_code == 400


# --- 3. only exercises the server knows ------------------------------------------------------


@pytest.mark.parametrize(
    "name",
    [
        "/etc/passwd",
        "../../../etc/passwd",
        "/etc/hostname.yaml",
        "stereoplotter/data/exercises/e01-setup-stage1.yaml",
        "exercises/e01-setup-stage1",
        "e01-setup-stage1.yaml",
    ],
)
def test_a_path_as_exercise_is_never_opened(client, name):
    r = client.post("/api/sessions", json={"exercise": name, "trainee": "ivy"})
    assert r.status_code == 404
    err = r.json()["error"]
    assert "no exercise named" in err and "mapping" not in err and "format" not in err


def test_an_uploaded_exercise_is_validated_and_names_no_path(client, tmp_path):
    text = (
        resources.files("stereoplotter") / "data" / "exercises" / f"{PRACTICE}.yaml"
    ).read_text()
    assert client.post("/api/instructor/exercises", content=text).status_code == 403
    for bad, why in (("/etc/passwd", "scenario"), ("../scenarios/pair60", "scenario")):
        r = client.post(
            "/api/instructor/exercises",
            params={"token": TOKEN},
            content=text.replace("scenario: pair60", f"scenario: {bad}").replace(
                f"name: {PRACTICE}", "name: up1"
            ),
        )
        assert r.status_code == 400 and why in r.json()["error"]
        assert f"found {bad!r}" in r.json()["error"]  # quoted as sent, never rewritten
        assert str(tmp_path) not in r.json()["error"]
    for body in ("[1, 2]", "a: [", "\u0000", f"name: {PRACTICE}\nformat: x"):
        r = client.post("/api/instructor/exercises", params={"token": TOKEN}, content=body)
        assert r.status_code in (400, 409) and "\n" not in r.json()["error"]  # 409: name in use
        assert not re.search(r"/\w+/\w+", r.json()["error"]), r.json()
    good = text.replace(f"name: {PRACTICE}", "name: class-a1")
    r = client.post("/api/instructor/exercises", params={"token": TOKEN}, content=good)
    assert r.status_code == 200, r.text
    assert "class-a1" in [e["name"] for e in client.get("/api/exercises").json()]
    start(client, "class-a1", trainee="jon")


# --- 4. bad input gets an answer, the connection stays ---------------------------------------

MALFORMED = [
    ("not json {", "expected JSON"),
    ("[1, 2, 3]", "expected a JSON object, found list"),
    ("[" * 50_000 + "]" * 50_000, "at most"),  # oversized (and deeply nested)
    ("[" * 2_000 + "]" * 2_000, "expected JSON"),  # deeply nested, under the size limit
    ('{"action": 5}', "expected a JSON object with a kind"),
    ('{"action": {"kind": "fly"}}', "action kind"),
    ('{"action": {"kind": "turn", "control": "X", "delta": 1, "hack": 1}}', "unknown field"),
    ('{"action": {"kind": "turn", "control": {"a": {"b": 1}}, "delta": 1}}', "expected a number"),
    ('{"action": {"kind": "turn", "control": "X", "delta": 1e400}}', "expected a number"),
    ('{"seq": -1}', "seq"),
    ('{"whatever": 1}', "unknown field"),
    ("{}", "expected"),
    ('{"demo": "step"}', "expected"),
    (json.dumps({"action": {"kind": "record", "name": "z", "value": "x" * 2_000_000}}), "at most"),
    (json.dumps({"action": {"kind": "record", "name": "z", "value": "x" * 1_000}}), "at most 256"),
    (json.dumps({"action": {"kind": "record", "name": "z", "value": [[1, [2]]]}}), "expected"),
]


def test_every_malformed_message_gets_one_line_and_the_socket_stays(client):
    sid, secret = start(client, trainee="kim")
    ws, conn, _ = open_socket(client, sid, secret)
    try:
        for text, why in MALFORMED:
            reply = ask(conn, text)
            assert why in reply["error"], (text[:60], reply)
            assert "\n" not in reply["error"] and "Traceback" not in reply["error"]
        conn.send_bytes(b"\x00\x01")
        assert "text frame" in json.loads(conn.receive_text())["error"]
        reply = ask(conn, {"action": {"kind": "read", "counter": "X"}, "seq": 9})
        assert reply["error"] is None and reply["seq"] == 9  # still open, still working
        big = [
            ask(conn, {"action": {"kind": "record", "name": f"n{i}", "value": i}})
            for i in range(70)
        ]
        assert big[63]["error"] is None and "at most 64 names" in big[64]["error"]
    finally:
        ws.__exit__(None, None, None)
    assert (
        len(json.dumps(client.get(f"/api/sessions/{sid}/log.jsonl", params={"token": TOKEN}).text))
        < 100_000
    )


def test_a_flood_of_messages_is_slowed_not_served(client):
    sid, secret = start(client, trainee="lea")
    ws, conn, _ = open_socket(client, sid, secret)
    try:
        msg = json.dumps({"demo": "nothing"})
        t0 = time.monotonic()
        for _ in range(300):
            conn.send_text(msg)
        errors = [json.loads(conn.receive_text())["error"] for _ in range(300)]
        elapsed = time.monotonic() - t0
        # the bucket lets BURST through at once and RATE a second after: the rest is refused
        refused = sum("too many messages" in e for e in errors)
        assert refused >= min(300 - BURST - RATE * elapsed - 2, 100) and refused > 0
        assert all(e.startswith(("too many messages", "expected")) for e in errors)
        time.sleep(0.1)
        assert ask(conn, {"action": {"kind": "read", "counter": "X"}})["error"] is None
    finally:
        ws.__exit__(None, None, None)
    assert MAX_MESSAGE <= 4096


def test_a_flood_of_session_starts_is_refused(tmp_path):
    with make_test_client(
        create_app(TOKEN, tmp_path, hosts=("testserver",), start_limit=(0.01, 3))
    ) as c:
        codes = [
            c.post("/api/sessions", json={"exercise": PRACTICE, "trainee": f"f{i}"})
            for i in range(5)
        ]
    assert [r.status_code for r in codes] == [200, 200, 200, 429, 429]
    assert codes[-1].json()["error"].startswith("too many sessions")


def test_an_exam_refuses_hints_and_undo_on_the_socket(client):
    sid, secret = start(client, EXAM, trainee="no-help")
    ws, conn, hello = open_socket(client, sid, secret)
    try:
        assert "hint" not in hello["state"]["allowed"] and "undo" not in hello["state"]["allowed"]
        for action in ({"kind": "hint", "level": 3}, {"kind": "undo"}):
            reply = ask(conn, {"action": action})
            assert "not allowed now" in reply["error"], reply
            assert "result" not in reply
    finally:
        ws.__exit__(None, None, None)
