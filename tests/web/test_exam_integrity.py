"""Exams nobody passes without doing them: the seed is the server's own, one name (however it is
spelt in look-alike letters) has one attempt, and "show me" is charged as the hint it is."""

from __future__ import annotations

import json

import pytest

from stereoplotter.io.exercise_file import load_exercise
from stereoplotter.trainer.exercise import trainee_seed
from stereoplotter.trainer.session import Session
from stereoplotter.web.app import create_app
from stereoplotter.web.guard import trainee_key
from tests.web.conftest import EXAM, PRACTICE, TOKEN, ask, make_test_client, open_socket, start


@pytest.fixture(scope="module")
def fast(tmp_path_factory):
    """A server whose sockets take a robot's pace (the limits are tried elsewhere)."""
    app = create_app(
        TOKEN,
        tmp_path_factory.mktemp("exam-data"),
        hosts=("testserver",),
        start_limit=(1e3, 10**4),
        message_limit=(1e5, 10**5),
        address_limit=(1e5, 10**5),
    )
    with make_test_client(app) as c:
        yield c


def _grade(client, sid, secret):
    r = client.get(f"/api/sessions/{sid}/grade", params={"key": secret})
    assert r.status_code == 200, r.text
    return r.json()["grade"]


def test_an_exam_answered_offline_is_failed(fast):
    """The robot's script built from public facts only (the package, the exercise's and the
    trainee's names) for the seed anyone can compute; sent over the socket it fails: the
    server's seed comes from its own key."""
    robot = Session.start(load_exercise(EXAM), trainee="Mallory")
    assert robot.seed == trainee_seed(EXAM, "Mallory")
    script = robot.operator_script()  # on its own seed it passes: 0.43, 100 points
    sid, secret = start(fast, EXAM, trainee="Mallory")
    ws, conn, _ = open_socket(fast, sid, secret)
    try:
        for i, action in enumerate(script):
            conn.send_text(json.dumps({"action": action, "seq": i}))
        replies = [json.loads(conn.receive_text()) for _ in script]
    finally:
        ws.__exit__(None, None, None)
    assert replies[-1]["state"]["done"], replies[-1].get("error")
    head = json.loads(
        fast.get(f"/api/sessions/{sid}/log.jsonl", params={"token": TOKEN}).text.splitlines()[0]
    )
    assert head["seed"] != robot.seed
    grade = _grade(fast, sid, secret)
    assert grade["overall"]["passed"] is False, grade["overall"]


LOOK_ALIKES = [
    "M\u0430llory",  # Cyrillic а
    "Mallor\u0443",  # Cyrillic у
    "Mallory\u034f",  # combining grapheme joiner
    "Mallory\ufe0f",  # variation selector 16
    "Mallory\u2800",  # braille blank
    "Mallory\u3164",  # Hangul filler
    "Mallory\u115f",  # Hangul choseong filler
    "Mallory\u200b",  # zero width space
    "MALLORY",
    "\uff2d\uff41\uff4c\uff4c\uff4f\uff52\uff59",  # fullwidth
    "Mallory\u00a0",
    " mallory ",
]


def test_a_look_alike_name_gets_no_second_attempt(fast):
    exam = "e12-conventional-exam"
    sid, _ = start(fast, exam, trainee="Mallory")
    keys = {trainee_key(name) for name in LOOK_ALIKES}
    assert keys == {trainee_key("Mallory")}
    for name in LOOK_ALIKES:
        r = fast.post("/api/sessions", json={"exercise": exam, "trainee": name})
        refused = (403, "attempt") if name.isprintable() or "\u200b" not in name else (400, "")
        assert r.status_code == refused[0] and refused[1] in r.json()["error"], ascii(name)
    # a different name is a different trainee; the stored name is what was typed
    other, _ = start(fast, exam, trainee="Malorie")
    table = fast.get("/api/instructor/sessions", params={"token": TOKEN}).json()
    rows = {r["id"]: r for r in table}
    assert rows[sid]["trainee"] == "Mallory" and rows[other]["trainee"] == "Malorie"
    for invisible in ("\u200b", "\u3164\u115f", "\ufe0f"):  # a name of nothing visible
        r = fast.post("/api/sessions", json={"exercise": PRACTICE, "trainee": invisible})
        assert r.status_code == 400, ascii(invisible)


def test_show_me_is_charged_as_a_level_3_hint(fast):
    sid, secret = start(fast, PRACTICE, trainee="shown")
    r = fast.get(f"/api/sessions/{sid}/showme", params={"key": secret})
    assert r.status_code == 200 and r.json()["actions"], r.text
    ws, conn, hello = open_socket(fast, sid, secret)
    try:  # the charge is in the log before the actions are given; playing them is free
        assert hello["n"] == 1
        stage = hello["state"]["stage"]
        reply = ask(conn, {"action": {"kind": "claim", "step": stage}})
        assert reply["state"]["done"], reply
    finally:
        ws.__exit__(None, None, None)
    grade = _grade(fast, sid, secret)
    hints = grade["hints"]
    assert hints["stages"][stage]["level"] == 3 and hints["total"] > 0, hints
    assert grade["overall"]["hint_cost"] == hints["total"]
    # the cost is what a hint of level 3 asked on the socket costs
    sid2, secret2 = start(fast, PRACTICE, trainee="hinted")
    ws, conn, hello = open_socket(fast, sid2, secret2)
    try:
        assert ask(conn, {"action": {"kind": "hint", "level": 3}})["error"] is None
        assert ask(conn, {"action": {"kind": "claim", "step": stage}})["state"]["done"]
    finally:
        ws.__exit__(None, None, None)
    assert _grade(fast, sid2, secret2)["hints"]["total"] == hints["total"]
