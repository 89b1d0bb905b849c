"""An exam hides what it hides: from everything an exam session can fetch (its state, the photo
overview, the checklist, the sheet panel) the hidden parallax read-out cannot be recomputed,
the fiducials are the certificate's, and the checklist names no controls (that is hint 2).

The hidden quantities are computed from the server's own session (the oracle); the attacker's
estimate is the read-out's formula applied to what was fetched: x-parallax = (right mark −
right image) − (left mark − left image), y likewise."""

from __future__ import annotations

import json

import numpy as np
import pytest

from stereoplotter.io.exercise_file import load_exercise
from stereoplotter.procedure.operator import Noise, Operator
from stereoplotter.procedure.transcript import Transcript
from stereoplotter.trainer.session import Session
from stereoplotter.web.app import create_app
from tests.web.conftest import EXAM, TOKEN, ask, make_test_client, open_socket, start

#: The read-out's resolution an attacker would need: a quarter of the mark's 0.05 mm, the
#: sheet's residual y-parallax tolerance. [µm]
NEEDED_UM = 12.5


@pytest.fixture(scope="module")
def exam(tmp_path_factory):
    app = create_app(TOKEN, tmp_path_factory.mktemp("hide-data"), hosts=("testserver",),
                     message_limit=(1e4, 10**4))
    with make_test_client(app) as c:
        sid, secret = start(c, EXAM, trainee="hider")
        ws, conn, hello = open_socket(c, sid, secret)
        try:
            yield c, sid, secret, conn, hello
        finally:
            ws.__exit__(None, None, None)


def _truth(session, i):
    """The hidden read-out at standard point i (0-based) as the practice page shows it. [µm]"""
    il, ir = session.prep.scene.standard
    pl, pr = (np.asarray(p, float).reshape(-1) for p in session.inst.marks())
    op = Operator(session.inst, session.prep.operator, Noise(0, None, None, 0),
                  Transcript(enabled=False))
    q = op.y_parallax(session.prep.scene.standard_points_m[i : i + 1],
                      (il[i : i + 1], ir[i : i + 1]))
    x = (pr[0] - ir[i, 0]) - (pl[0] - il[i, 0])
    return float(x) * 1000.0, float(np.asarray(q).reshape(-1)[0]) * 1000.0


def _end_of_stage(script, k):
    """The number of non-claim actions before the k-th claim."""
    n = claims = 0
    for a in script:
        if a["kind"] == "claim":
            claims += 1
            if claims == k:
                return n
        else:
            n += 1
    return n


def _estimate(state, overview, i):
    marks = state["marks"]
    left = overview["photos"]["left"]["standard_points"][i]
    right = overview["photos"]["right"]["standard_points"][i]
    x = (marks["right"]["x_mm"] - right["x_mm"]) - (marks["left"]["x_mm"] - left["x_mm"])
    y = (marks["right"]["y_mm"] - right["y_mm"]) - (marks["left"]["y_mm"] - left["y_mm"])
    return x * 1000.0, y * 1000.0


def _drive_left_mark(conn, state, target):
    """Turn X and Y until the left mark is within 2 µm of ``target`` (Newton steps)."""
    def mark(s):
        return np.array([s["marks"]["left"]["x_mm"], s["marks"]["left"]["y_mm"]])

    jac = np.zeros((2, 2))
    for k, screw in enumerate(("X", "Y")):
        before = mark(state)
        state = ask(conn, {"action": {"kind": "turn", "control": screw, "delta": 1.0}})["state"]
        jac[:, k] = mark(state) - before
    for _ in range(8):
        miss = np.asarray(target) - mark(state)
        if np.hypot(*miss) < 0.002:
            break
        step = np.linalg.solve(jac, miss)
        for screw, delta in zip(("X", "Y"), step, strict=True):
            reply = ask(conn, {"action": {"kind": "turn", "control": screw,
                                          "delta": round(float(delta), 4)}})
            assert reply["error"] is None, reply
            state = reply["state"]
    return state


def test_the_hidden_parallax_cannot_be_recomputed(exam):
    c, sid, secret, conn, hello = exam
    state = hello["state"]
    assert state["parallax"] is None and state["injected_errors"] is None
    f = state["controls"]["f_instrument"]
    sheet = c.get(f"/api/sessions/{sid}/sheet", params={"key": secret}).json()
    f_value = sheet.get("interior", {}).get("f_instrument_mm", (f["min"] + f["max"]) / 2)
    state = ask(conn, {"action": {"kind": "set", "control": "f_instrument",
                                  "value": round(f_value, 2)}})["state"]
    overview = c.get(f"/api/sessions/{sid}/overview", params={"key": secret}).json()
    session = c.app.state.registry.live[sid].session
    il, ir = session.prep.scene.standard
    errors = []
    for i in range(6):  # the estimate's error at each point: what the overview withholds
        fx = overview["photos"]["left"]["standard_points"][i]
        gx = overview["photos"]["right"]["standard_points"][i]
        ex = (ir[i, 0] - gx["x_mm"]) - (il[i, 0] - fx["x_mm"])
        ey = (ir[i, 1] - gx["y_mm"]) - (il[i, 1] - fx["y_mm"])
        errors += [abs(ex) * 1000.0, abs(ey) * 1000.0]
    assert np.median(errors) > 2 * NEEDED_UM, errors
    # end to end: the instrument set up as the sheet says (the operator's script of stages 1
    # and 2 on the public seed, claims left out), the left mark on point 2's image, then the
    # read-out recomputed
    script = Session.start(load_exercise(EXAM), trainee="hider").operator_script()
    stages = [a for a in script if a["kind"] != "claim"][: _end_of_stage(script, 2)]
    for n, action in enumerate(stages):
        conn.send_text(json.dumps({"action": action, "seq": n}))
    for _ in stages:
        state = json.loads(conn.receive_text()).get("state") or state
    i = 1
    state = _drive_left_mark(conn, state, il[i])
    overview = c.get(f"/api/sessions/{sid}/overview", params={"key": secret}).json()
    true_x, true_y = _truth(session, i)
    est_x, est_y = _estimate(state, overview, i)
    assert abs(est_x - true_x) > NEEDED_UM or abs(est_y - true_y) > NEEDED_UM, (
        (est_x, true_x), (est_y, true_y))


def test_fiducials_are_the_certificates_and_the_checklist_names_no_controls(exam):
    c, sid, secret, _, _ = exam
    overview = c.get(f"/api/sessions/{sid}/overview", params={"key": secret}).json()
    certificate = c.get(f"/api/sessions/{sid}/sheet", params={"key": secret}).json()
    fiducials = certificate["certificate"]["fiducials_mm"]
    for photo in overview["photos"].values():
        for fid in photo["fiducials"]:
            assert [fid["x_mm"], fid["y_mm"]] == fiducials[fid["id"]]
    checklist = c.get(f"/api/sessions/{sid}/checklist", params={"key": secret}).json()
    assert checklist["steps"] and all("controls" not in s for s in checklist["steps"])
