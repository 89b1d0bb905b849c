"""The page's own endpoints: glossary, hint costs, go-to, feedback, the class's acuities."""

from __future__ import annotations

import pytest

from tests.web.conftest import EXAM, TOKEN, ask, make_client, open_socket, start


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    with make_client(tmp_path_factory.mktemp("page-data")) as c:
        yield c


def test_the_glossary_is_public_and_bilingual(client):
    body = client.get("/api/glossary").json()
    symbols = {s["symbol"]: s for s in body["symbols"]}
    assert {"MO", "M_в", "n_л", "L-check", "decision", "(6."} <= set(symbols)
    assert all(s["en"] and s["ru"] for s in body["symbols"])
    assert body["controls"]["f_instrument"] == "f_пр"


def test_hint_costs_are_said_in_points_of_this_exercise(client):
    sid, key = start(client, trainee="costs")
    words = client.get(f"/api/sessions/{sid}/words", params={"key": key}).json()
    # e01 has one stage worth 100 points: hint 3 costs 0.75 of it (grade_tables.HINT_COST)
    assert words["hint_points"] == {"1": 10.0, "2": 25.0, "3": 75.0}
    assert words["show_me_actions"] > 100


def test_go_to_a_standard_point_puts_the_left_mark_on_it(client):
    sid, key = start(client, exercise="e05-conventional-c2", trainee="walker")
    r = client.get(f"/api/sessions/{sid}/goto", params={"key": key, "point": "3"})
    actions = r.json()["actions"]
    assert [a["control"] for a in actions] == ["X", "Y"]
    overview = client.get(f"/api/sessions/{sid}/overview", params={"key": key}).json()
    target = overview["photos"]["left"]["standard_points"][2]
    ws, conn, _ = open_socket(client, sid, key)
    try:
        for n, a in enumerate(actions, 1):
            state = ask(conn, {"action": a, "seq": n})["state"]
    finally:
        ws.__exit__(None, None, None)
    mark = state["marks"]["left"]
    # within the counter's least count (the settings are sent to the µm)
    assert abs(mark["x_mm"] - target["x_mm"]) < 0.01 and abs(mark["y_mm"] - target["y_mm"]) < 0.01
    bad = client.get(f"/api/sessions/{sid}/goto", params={"key": key, "x": "1e400", "y": "0"})
    assert bad.status_code == 400 and set(bad.json()) == {"error"}
    far = client.get(f"/api/sessions/{sid}/goto", params={"key": key, "x": "500", "y": "0"})
    assert far.status_code == 400


def test_feedback_names_the_check_and_the_setting_in_practice_only(client):
    sid, key = start(client, trainee="wrong-gear")
    ws, conn, _ = open_socket(client, sid, key)
    try:
        f = {"kind": "set", "control": "f_instrument", "value": 109.3748}
        ask(conn, {"action": f, "seq": 1})
        ask(conn, {"action": {"kind": "gear", "value": 12500}, "seq": 2})
    finally:
        ws.__exit__(None, None, None)
    body = client.get(f"/api/sessions/{sid}/feedback", params={"key": key, "stage": "now"}).json()
    assert any("not geared" in f["name"] for f in body["failed"])
    gear = next(s for s in body["settings"] if s["control"].startswith("gear"))
    assert gear["value"] == 12500 and gear["target"] == 8000
    assert gear["mistake"] == "M_г in place of M_в"
    exam, ekey = start(client, exercise=EXAM, trainee="examinee")
    r = client.get(f"/api/sessions/{exam}/feedback", params={"key": ekey, "stage": "now"})
    assert r.status_code == 403


def test_the_instructor_sees_the_class_acuities(client):
    sid, key = start(client, trainee="eyes")
    ws, conn, _ = open_socket(client, sid, key)
    try:
        for n, (name, v) in enumerate(
            (("stereo acuity x (arcsec)", 24.5), ("stereo acuity y (arcsec)", 9.0)), 1
        ):
            ask(conn, {"action": {"kind": "record", "name": name, "value": v}, "seq": n})
    finally:
        ws.__exit__(None, None, None)
    assert client.get("/api/instructor/acuity").status_code == 403
    rows = client.get("/api/instructor/acuity", params={"token": TOKEN}).json()
    mine = next(r for r in rows if r["id"] == sid)
    assert mine["trainee"] == "eyes" and mine["x_arcsec"] == 24.5 and mine["y_arcsec"] == 9.0
