"""A page that takes patches holds exactly the state the server holds, action after action."""

from __future__ import annotations

import json

import pytest

from stereoplotter.web.statepatch import apply_patch, same, state_patch
from tests.web.conftest import EXAM, PRACTICE, ask, start


def test_same_is_json_sameness():
    assert same({"a": [1, {"b": 2.5}]}, {"a": [1, {"b": 2.5}]})
    # equal in Python, different JSON texts: a page would show them differently
    assert not same(1, 1.0) and not same(0.0, -0.0) and not same(True, 1)
    assert not same([1, 2], [1, 2, 3]) and not same({"a": 1}, {"b": 1})
    assert not same({"a": None}, {}) and same(None, None)


def test_patch_names_only_what_changed_and_leaves_the_old_state():
    old = {"keep": {"units": "mm", "stops": [0, 10]}, "x": {"value": 1.0, "unit": "mm"},
           "gone": 3, "z": 0.0, "n": 1, "b": True}
    new = {"keep": {"units": "mm", "stops": [0, 10]}, "x": {"value": 2.0, "unit": "mm"},
           "z": -0.0, "added": None, "n": 1.0, "b": 1}
    patch = state_patch(old, new)
    assert patch == {"set": {"z": -0.0, "added": None, "n": 1.0, "b": 1}, "del": ["gone"],
                     "sub": {"x": {"set": {"value": 2.0}}}}
    frozen = json.dumps(old)
    assert same(apply_patch(old, json.loads(json.dumps(patch))), new)
    assert json.dumps(old) == frozen
    assert state_patch(new, new) == {}


ACTIONS = [
    {"kind": "read", "counter": "X"},
    {"kind": "turn", "control": "X", "delta": 1.5},
    {"kind": "set", "control": "Z", "value": 150.0},
    {"kind": "direction", "counter": "Y", "sign": -1},
    {"kind": "record", "name": "__proto__", "value": 12.5},
    {"kind": "turn", "control": "no-such-control", "delta": 1},  # refused: the state comes back
    {"kind": "undo"},
    {"kind": "redo"},
    {"kind": "hint", "level": 1},
    {"kind": "lock", "control": "kappa_left"},
]


@pytest.mark.parametrize("exercise", [PRACTICE, EXAM])
def test_applied_patches_give_the_servers_state(client, exercise):
    sid, secret = start(client, exercise, trainee="patch")
    with client.websocket_connect(f"/ws/{sid}") as conn:
        conn.send_text(json.dumps({"auth": secret, "patches": True}))
        hello = json.loads(conn.receive_text())
        held = hello["state"]
        session = client.app.state.registry.live[sid].session
        patched, refused = 0, []
        for seq, action in enumerate([*ACTIONS, {"kind": "claim", "step": held["stage"]}]):
            reply = ask(conn, {"action": action, "seq": seq})
            assert "state" not in reply and reply["seq"] == seq, reply
            if reply["error"]:
                refused.append(action["kind"])
            if "patch" in reply:
                patched += 1
                held = apply_patch(held, reply["patch"])
            # the server's state as a JSON text round trip: what a whole-state frame carries
            assert same(held, json.loads(json.dumps(session.state()))), (action, reply)
        assert patched == len(ACTIONS) + 1 and held["done"] == (exercise == PRACTICE)
        assert held["records"]["__proto__"] == 12.5
        assert refused == (["turn"] if exercise == PRACTICE else ["turn", "undo", "redo", "hint"])
    # a socket that reconnects starts from a whole state; one without patches gets states
    with client.websocket_connect(f"/ws/{sid}") as conn:
        conn.send_text(json.dumps({"auth": secret}))
        again = json.loads(conn.receive_text())["state"]
        assert same(again, held)
        assert "state" in ask(conn, {"action": {"kind": "read", "counter": "X"}})


def test_patches_must_be_asked_for_as_true(client):
    sid, secret = start(client, PRACTICE, trainee="patch-no")
    with client.websocket_connect(f"/ws/{sid}") as conn:
        conn.send_text(json.dumps({"auth": secret, "patches": "yes"}))
        json.loads(conn.receive_text())
        reply = ask(conn, {"action": {"kind": "read", "counter": "X"}})
        assert "patch" not in reply and reply["state"]["counters"]
