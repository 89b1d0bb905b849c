"""An exam hides what it hides: from everything an exam session can fetch — its state (marks,
captions' numbers, checklist ticks), the photo overview, the checklist, the sheet panel, go-to,
the words, the photo patches — neither the hidden parallax read-out nor the instrument's true
orientation can be recomputed better than one look through the eyepiece gives it.

The attacker is the strongest there is: the package in hand, so the scene is known exactly
offline (an exercise's photos and points are the same for every trainee; only the instrument's
errors come from the trainee's secret seed). The hidden quantities come from the server's own
session (the oracle): the read-out's x- and y-parallax at a standard point, as the practice
page shows it; the cassettes' true κ; the checklist's judgement of |q| against its tolerance.

The bound is the eye's: a y-parallax judged to σ_q = Δγ₂·d/V = 10″·250 mm/6 = 2.02 µm
(``procedure.eye``, the binocular's 6×). The marks are given to the X, Y counters' least count
(0.01 mm), so a parallax from two of them is off by σ = 0.01/√6 = 4.1 µm. The x-parallax is
held to σ_q too: the fused mark's own σ_p = 6.06 µm is coarser than the marks' 4.1 µm, a limit
of the counters' least count, not of this test.
"""

from __future__ import annotations

import contextlib
import hashlib
import json

import numpy as np
import pytest

from stereoplotter.io.exercise_file import load_exercise
from stereoplotter.io.session_store import SessionStore
from stereoplotter.procedure.eye import Eye, ObservationSystem
from stereoplotter.procedure.operator import Noise, Operator
from stereoplotter.procedure.transcript import Transcript
from stereoplotter.trainer.session import Session
from stereoplotter.web.app import create_app
from stereoplotter.web.registry import SEED_KEY
from tests.web.conftest import EXAM, TOKEN, ask, make_test_client, open_socket, start

#: One look's y-parallax judgement at the instruments' 6× binocular, 250 mm. [µm]
SIGMA_Q_UM = Eye(ObservationSystem(6.0, 250.0)).y_parallax_sigma_mm * 1000.0
READOUT_OFF_PRACTICE = "e08-setup-full"


def _stages_1_and_2(session):
    """The operator's actions of stages 1 and 2 on the trainee's own instrument (the server's
    session: the test is the oracle), stage 1 claimed: the instrument set up as the sheet says
    and the y-parallax cleared as the simulated operator clears it."""
    out, claims = [], 0
    for action in session.operator_script():
        if action["kind"] == "claim":
            claims += 1
            if claims == 2:
                return out
        out.append(action)
    return out


def _run(conn, actions):
    """Send the actions (pipelined) and return the last state; refusals are the instrument's
    (a stop), as a trainee's would be."""
    for n, action in enumerate(actions):
        conn.send_text(json.dumps({"action": action, "seq": n}))
    state = None
    for _ in actions:
        state = json.loads(conn.receive_text()).get("state") or state
    return state


@pytest.fixture(scope="module")
def exam(tmp_path_factory):
    """Two trainees' exams after the same actions (stage 2 in hand), and the scene offline."""
    data = tmp_path_factory.mktemp("hide-data")
    # the server's key kept in the data folder, fixed: the same instruments every run
    SessionStore(data).put_value(SEED_KEY, hashlib.sha256(b"a fixed server key").hexdigest())
    app = create_app(TOKEN, data, hosts=("testserver",), message_limit=(1e4, 10**4))
    offline = Session(load_exercise(EXAM), "anyone", 0).prep.scene.standard
    with make_test_client(app) as c, contextlib.ExitStack() as stack:
        sessions, script = {}, None
        for trainee in ("hider", "twin"):
            sid, secret = start(c, EXAM, trainee=trainee)
            ws, conn, _ = open_socket(c, sid, secret)
            stack.callback(ws.__exit__, None, None, None)
            s = {"sid": sid, "secret": secret, "conn": conn}
            script = script or _stages_1_and_2(_oracle(c, s))
            s["state"] = _run(conn, script)
            sessions[trainee] = s
        for s in sessions.values():
            s["fetched"] = _everything_but_the_state(c, s)
        yield c, sessions, offline


def _get(c, s, what, **params):
    r = c.get(f"/api/sessions/{s['sid']}/{what}", params={"key": s["secret"], **params})
    assert r.status_code == 200, r.text
    return r


def _oracle(c, s):
    return c.app.state.registry.live[s["sid"]].session


def _truth(session, i):
    """The hidden read-out at standard point i (0-based) as the practice page shows it
    (``Session._parallax``): (x, y). [µm]"""
    il, ir = session.prep.scene.standard
    pl, pr = (np.asarray(p, float).reshape(-1) for p in session.inst.marks())
    op = Operator(session.inst, session.prep.operator, Noise(0, None, None, 0),
                  Transcript(enabled=False))
    q = op.y_parallax(session.prep.scene.standard_points_m[i : i + 1],
                      (il[i : i + 1], ir[i : i + 1]))
    x = (pr[0] - ir[i, 0]) - (pl[0] - il[i, 0])
    return float(x) * 1000.0, float(np.asarray(q).reshape(-1)[0]) * 1000.0


def _go_to(c, s, point):
    state = None
    for action in _get(c, s, "goto", point=point).json()["actions"]:
        state = ask(s["conn"], {"action": action})["state"]
    return state


def _estimate(marks, il, ir, i, n_right):
    """The read-out's formulas on the marks and the exact images: x on the photo, y on the
    rods (the right photo's offset times its projection ratio n_п, from the sheet). [µm]"""
    left, right = marks["left"], marks["right"]
    x = (right["x_mm"] - ir[i, 0]) - (left["x_mm"] - il[i, 0])
    y = (right["y_mm"] - ir[i, 1]) - (left["y_mm"] - il[i, 1])
    return x * 1000.0, n_right * y * 1000.0


def test_the_read_out_is_not_recomputed_from_marks_go_to_and_overview(exam):
    """At each standard point, reached by go-to and fused by Z on the x-parallax the marks
    give (secant steps, as a trainee fuses by the view), the read-out's formulas on the marks
    and the exact images are off by at least σ_q, RMS over the six points; the overview's mark
    is no finer than the state's."""
    c, sessions, (il, ir) = exam
    s = sessions["hider"]
    n_right = _get(c, s, "sheet").json()["interior"]["n_right"]
    errors = []
    for i in range(6):
        for _ in range(3):
            x0 = _estimate(_go_to(c, s, str(i + 1))["marks"], il, ir, i, n_right)[0]
            ask(s["conn"], {"action": {"kind": "turn", "control": "Z", "delta": 1.0}})
            x1 = _estimate(_go_to(c, s, str(i + 1))["marks"], il, ir, i, n_right)[0]
            if x1 == x0:
                break
            step = -1.0 - x0 / (x1 - x0)
            ask(s["conn"], {"action": {"kind": "turn", "control": "Z", "delta": round(step, 4)}})
        marks = _go_to(c, s, str(i + 1))["marks"]
        overview = _get(c, s, "overview").json()
        for side in ("left", "right"):
            mark = overview["photos"][side]["mark"]
            assert (mark["x_mm"], mark["y_mm"]) == (marks[side]["x_mm"], marks[side]["y_mm"])
        est_x, est_y = _estimate(marks, il, ir, i, n_right)
        true_x, true_y = _truth(_oracle(c, s), i)
        errors.append((est_x - true_x, est_y - true_y))
    rms_x, rms_y = np.sqrt(np.mean(np.square(errors), axis=0))
    assert rms_x >= SIGMA_Q_UM and rms_y >= SIGMA_Q_UM, (rms_x, rms_y, errors)


def test_the_cassettes_kappa_and_the_counters_errors_are_not_in_the_state(exam):
    """The field's turn the state gives less the κ the trainee set tells less than half of the
    cassette's hidden setting error; the screws' stops as their scales read give the counters'
    hidden errors no finer than the least count (the exact stop readings would give them to
    the last digit)."""
    c, sessions, _ = exam
    s = sessions["hider"]
    state = ask(s["conn"], {"action": {"kind": "read", "counter": "X"}})["state"]
    session = _oracle(c, s)
    for side in ("left", "right"):
        truth = float(session.inst.injected[f"setting.kappa_{side}"])
        guess = state["marks"][side]["kappa_rad"] - state["controls"][f"kappa_{side}"]["value"]
        assert abs(truth) > 1e-6 and abs(guess - truth) >= 0.5 * abs(truth), (side, guess, truth)
    exact = session.full_state()["controls"]
    for screw in ("X", "Y", "Z"):
        for stop in ("min", "max"):
            miss = abs(state["controls"][screw][stop] - exact[screw][stop])
            assert miss > 1e-6, (screw, stop, miss)


def test_the_checklist_does_not_tick_on_the_hidden_parallax(exam):
    """κ_п set where the true y-parallax at standard point 1 vanishes, then 10 mrad off: the
    ticks the state and the checklist give are the same although |q| crosses the tolerance."""
    c, sessions, _ = exam
    s = sessions["hider"]
    session = _oracle(c, s)
    tol_um = float(session.prep.sheet.tolerances["residual_y_parallax_mm"]) * 1000.0
    for action in _get(c, s, "goto", point="1").json()["actions"]:
        ask(s["conn"], {"action": action})

    def at(kappa):
        state = ask(s["conn"], {"action": {"kind": "set", "control": "kappa_right",
                                           "value": kappa}})["state"]
        body = _get(c, s, "checklist").json()
        return state["checklist_ticks"], [(t["done"], t["shown"]) for t in body["steps"]], \
            abs(_truth(session, 0)[1])

    k0 = session.commanded["kappa_right"]
    q0 = _truth(session, 0)[1]
    at(k0 + 1e-3)
    q1 = _truth(session, 0)[1]
    zero = round(k0 - q0 * 1e-3 / (q1 - q0), 6)  # secant on the oracle: q = 0 there
    near = at(zero)
    far = at(zero + 0.01)
    assert near[2] <= tol_um < far[2], (near[2], far[2])
    assert near[:2] == far[:2]


def _everything_but_the_state(c, s):
    overview = _get(c, s, "overview").json()
    for photo in overview["photos"].values():
        photo.pop("mark")
    patch = _get(c, s, "patch.png", side="right", x=10.0, y=-20.0, mag=6.0, size=64)
    return {
        "checklist": _get(c, s, "checklist").json(),
        "overview": overview,
        "sheet": _get(c, s, "sheet").json(),
        "words": _get(c, s, "words").json(),
        "patch": (patch.content, sorted(patch.headers.items())),
    }


def test_two_trainees_fetch_the_same_but_their_marks(exam):
    """After the same actions (before the other tests act), everything but the state's marks
    and readings is the same for two trainees whose instruments differ: it carries nothing of
    the secret instrument."""
    _, sessions, _ = exam
    hider, twin = (s["fetched"] for s in sessions.values())
    for key, value in hider.items():
        assert value == twin[key], key


def test_fiducials_are_the_certificates_and_the_checklist_names_no_controls(exam):
    c, sessions, _ = exam
    s = sessions["hider"]
    overview = _get(c, s, "overview").json()
    fiducials = _get(c, s, "sheet").json()["certificate"]["fiducials_mm"]
    for photo in overview["photos"].values():
        for fid in photo["fiducials"]:
            assert [fid["x_mm"], fid["y_mm"]] == fiducials[fid["id"]]
    steps = _get(c, s, "checklist").json()["steps"]
    names = {"kappa_left", "kappa_right", "k_alpha_left", "k_omega_left", "dx_left", "b_y", "κ_п"}
    assert steps
    for step in steps:
        assert not {"controls", "control_names", "sheet_rows"} & step.keys(), step
        assert step["targets"] == {}, step
        assert not any(name in step["text"] for name in names), step["text"]


def test_practice_with_the_read_out_off_gives_no_check_before_the_claim(exam):
    c, _, _ = exam
    sid, secret = start(c, READOUT_OFF_PRACTICE, trainee="practiser")
    r = c.get(f"/api/sessions/{sid}/feedback", params={"key": secret, "stage": "now"})
    assert r.status_code == 403 and "read-out is off" in r.json()["error"], r.text
