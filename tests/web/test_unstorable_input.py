"""Input that cannot be stored is refused before it counts: a lone surrogate in any text field,
a number beyond its control's stops or too large to be a number at all. The socket is walked
with the malformed messages of ``test_attacks.py`` and seeded mutations of honest actions; the
server's log holds no traceback, every counted action is in the store, and the session still
grades and resumes after a restart."""

from __future__ import annotations

import json
import logging

import numpy as np

from stereoplotter.web.app import create_app
from tests.web.conftest import PRACTICE, TOKEN, ask, make_test_client, open_socket, start
from tests.web.test_attacks import MALFORMED

SURROGATE = "\ud800"
HONEST = [
    {"kind": "turn", "control": "X", "delta": 1.5},
    {"kind": "set", "control": "Z", "value": 150.0},
    {"kind": "read", "counter": "X"},
    {"kind": "record", "name": "MO_X", "value": 12.5},
    {"kind": "lock", "control": "kappa_left"},
    {"kind": "direction", "counter": "Y", "sign": -1},
    {"kind": "gear", "value": 2000},
    {"kind": "hint", "level": 1},
]
#: Values a mutation puts in a field.
BAD_VALUES = [
    SURROGATE,
    "a" + SURROGATE + "b",
    "\udfff",
    10**4000,
    -(10**400),
    10**20,
    1e308,
    -1e300,
    [SURROGATE],
    [1e300, 1],
    {"a": SURROGATE},
    "x" * 65,
    True,
    None,
    "",
]


def _cases() -> list[str]:
    """The messages sent: the malformed ones, each field of each honest action replaced by
    each bad value, the kind itself replaced, and a lone surrogate as a key; then 60 seeded
    random mutations."""
    out = [text for text, _ in MALFORMED]
    for action in HONEST:
        for key in action:
            for bad in BAD_VALUES:
                out.append(json.dumps({"action": {**action, key: bad}}))
        out.append(json.dumps({"action": {**action, SURROGATE: 1}}))
    out.append(json.dumps({"action": HONEST[0], "seq": 10**30}))
    out.append(json.dumps({"auth": SURROGATE}))
    out.append('{"action": {"kind": "turn", "control": "X", "delta": 1' + "0" * 4000 + "}}")
    out.append('{"action": {"kind": "turn", "control": "X", "delta": 1' + "0" * 5000 + "}}")
    rng = np.random.default_rng(20240607)
    for _ in range(60):
        action = dict(HONEST[int(rng.integers(len(HONEST)))])
        key = list(action)[int(rng.integers(len(action)))]
        action[key] = BAD_VALUES[int(rng.integers(len(BAD_VALUES)))]
        out.append(json.dumps({"action": action}))
    return out


def test_unstorable_input_is_refused_before_it_counts_and_nothing_is_logged(tmp_path, caplog):
    app = create_app(TOKEN, tmp_path, hosts=("testserver",), message_limit=(1e5, 10**5))
    caplog.set_level(logging.INFO)
    cases = _cases()
    assert len(cases) > 300
    with make_test_client(app) as c:
        sid, secret = start(c, PRACTICE, trainee="poison")
        ws, conn, hello = open_socket(c, sid, secret)
        try:
            counted = 0
            for text in cases:
                reply = ask(conn, text)
                assert "\n" not in (reply.get("error") or "") and "Traceback" not in str(reply)
                assert "could not carry this out" not in (reply.get("error") or ""), text[:80]
                counted = reply["n"]
            # a lone surrogate as the control's name is refused, and so is a 4 000-digit delta
            before = counted
            reply = ask(conn, json.dumps({"action": {"kind": "turn", "control": SURROGATE,
                                                     "delta": 1}}))
            assert "UTF-8" in reply["error"] and reply["n"] == before, reply
            big = '{"action": {"kind": "turn", "control": "X", "delta": 1' + "0" * 3990 + "}}"
            reply = ask(conn, big)
            assert "expected a number" in reply["error"] and reply["n"] == before, reply
            stage = hello["state"]["stage"]
            reply = ask(conn, {"action": {"kind": "claim", "step": stage}})
            assert reply["state"]["done"] and reply["n"] == before + 1, reply
        finally:
            ws.__exit__(None, None, None)
        records = c.get(f"/api/sessions/{sid}/log.jsonl", params={"token": TOKEN}).text
        assert len(records.splitlines()) == 1 + before + 1  # in memory = in the store
        r = c.get(f"/api/sessions/{sid}/grade", params={"key": secret})
        assert r.status_code == 200, r.text
        assert r.json()["grade"]["overall"]["score"] is not None
    bad = [r for r in caplog.records if r.exc_info or r.levelno >= logging.ERROR]
    assert bad == [], [r.getMessage() for r in bad]


def test_a_session_with_refused_input_resumes_after_a_restart(tmp_path):
    with make_test_client(create_app(TOKEN, tmp_path, hosts=("testserver",))) as c:
        sid, secret = start(c, PRACTICE, trainee="resumer")
        ws, conn, _ = open_socket(c, sid, secret)
        try:
            assert ask(conn, {"action": {"kind": "read", "counter": "X"}})["error"] is None
            for bad in ({"kind": "record", "name": SURROGATE, "value": 1},
                        {"kind": "turn", "control": "X", "delta": 10**4000 // 10**3990}):
                assert ask(conn, {"action": bad})["error"]
        finally:
            ws.__exit__(None, None, None)
    with make_test_client(create_app(TOKEN, tmp_path, hosts=("testserver",))) as c:
        ws, conn, hello = open_socket(c, sid, secret)
        try:
            assert hello["error"] is None and hello["n"] == 1
        finally:
            ws.__exit__(None, None, None)


def test_an_action_the_store_did_not_keep_does_not_count(tmp_path, monkeypatch):
    """The store fails on one append (a full disk): the action is answered with an error, the
    session in memory is dropped and the page, reconnecting, resumes from the store's log."""
    with make_test_client(create_app(TOKEN, tmp_path, hosts=("testserver",))) as c:
        sid, secret = start(c, PRACTICE, trainee="full disk")
        store = c.app.state.registry.store
        ws, conn, _ = open_socket(c, sid, secret)
        try:
            assert ask(conn, {"action": {"kind": "read", "counter": "X"}})["n"] == 1
            real = store.append_action

            def full(*args, **kw):
                raise OSError("disk full")

            monkeypatch.setattr(store, "append_action", full)
            reply = ask(conn, {"action": {"kind": "read", "counter": "Y"}})
            assert "could not be kept" in reply["error"]
            monkeypatch.setattr(store, "append_action", real)
        finally:
            ws.__exit__(None, None, None)
        ws, conn, hello = open_socket(c, sid, secret)
        try:
            assert hello["n"] == 1  # what the store holds, not what memory had counted
            assert ask(conn, {"action": {"kind": "read", "counter": "Y"}})["n"] == 2
        finally:
            ws.__exit__(None, None, None)
