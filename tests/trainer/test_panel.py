"""What the page shows beside the eyepieces: the action catalogue, the overview, the
checklist, coupled motions explained, readable hints, no numeric read-out in an exam."""

from __future__ import annotations

import json

import numpy as np
import pytest

from stereoplotter.errors import TrainerError
from stereoplotter.io.exercise_file import exercise_from_mapping, load_exercise
from stereoplotter.trainer.actions import ACTION_CATALOGUE, ACTION_FIELDS
from stereoplotter.trainer.panel import checklist, overview, sheet_parts, show_me_actions
from stereoplotter.trainer.session import Session
from stereoplotter.trainer.texts import announced_row


@pytest.fixture(scope="module")
def e07():
    return Session.start(load_exercise("e07-setup-stage2-incomplete"), trainee="ann")


def test_the_catalogue_lists_every_action_kind_with_its_required_fields():
    assert sorted(a["kind"] for a in ACTION_CATALOGUE) == sorted(ACTION_FIELDS)
    for entry in ACTION_CATALOGUE:
        required = [f["name"] for f in entry["fields"] if not f["optional"]]
        assert required == list(ACTION_FIELDS[entry["kind"]]), entry["kind"]
    json.dumps(ACTION_CATALOGUE, allow_nan=False)


def test_a_knob_moves_its_decentration_by_f_prime_times_the_tangent_and_says_why(e07):
    s = Session.start(e07.exercise, trainee="ann")
    state = s.act({"kind": "turn", "control": "k_alpha_right", "delta": 0.01})
    (event,) = state["events"]
    before, after = event["moved"]["dx_right"]
    # the linked decentration follows by f′·ΔT (decision D1); f′ from the sheet's Table 24
    f_prime = float(s.prep.sheet.focal_length_corrected_mm)
    assert after - before == pytest.approx(f_prime * 0.01, abs=s.inst.spec.xy_least_count_mm)
    assert "D1" in event["text"] and "k_alpha_right" in event["text"]
    assert s.act({"kind": "read", "counter": "X"})["events"] == []


def test_the_overview_places_the_points_and_the_mark_on_the_photos(e07):
    o = overview(e07)
    json.dumps(o, allow_nan=False)
    left = o["photos"]["left"]
    std = np.array([[p["x_mm"], p["y_mm"]] for p in left["standard_points"]])
    np.testing.assert_allclose(std, e07.prep.scene.standard[0], atol=1e-4)
    assert [p["usable"] for p in left["standard_points"]] == [True] * 4 + [False] * 2
    cam = e07.exercise.scenario.camera.fiducials_mm
    for f in left["fiducials"]:  # the true marks: the certificate's, film deformation aside
        assert np.hypot(f["x_mm"] - cam[f["id"]][0], f["y_mm"] - cam[f["id"]][1]) < 0.05
    ids = {p["id"] for p in left["control_points"]}
    assert ids == {p.id for p in e07.exercise.scenario.points if p.role == "control"}
    mark = left["mark"]
    xy = np.asarray(e07.inst.marks()[0], float).reshape(-1)
    half = e07.exercise.spec.xy_least_count_mm / 2  # read-out off: to the counters' least count
    assert (mark["x_mm"], mark["y_mm"]) == pytest.approx(tuple(xy), abs=half + 1e-9)
    assert mark["diameter_mm"] == e07.exercise.spec.mark_diameter_mm


def test_the_checklist_ticks_a_step_when_its_target_is_met():
    s = Session.start(load_exercise("e01-setup-stage1"), trainee="ann")
    first = checklist(s)["steps"][0]
    assert first["rule"] == "target" and not first["done"]
    for action in show_me_actions(s)[:2]:  # the operator's own first two: f_пр and the gear
        s.act(action)
    c = checklist(s)
    assert c["steps"][0]["done"] and c["done"] >= 1
    assert s.state()["checklist_ticks"]["done"][0] is True


def test_a_hint_names_the_controls_as_the_page_does(e07):
    s = Session.start(e07.exercise, trainee="ann")
    s.act({"kind": "hint", "level": 2})
    result = s.log[-1]["result"]
    lines = result["text"].split("\n")
    assert lines[0].startswith("Stage 2:")
    assert "Steps:" not in lines  # the checklist beside the hint holds them: not repeated
    controls = next(line for line in lines if line.startswith("Controls, in order: "))
    assert "k_α left (wheel)" in controls and "kappa_left" not in controls


def test_announced_errors_are_listed_in_readable_units(e07):
    rows = e07.state()["injected_errors_list"]
    assert rows and all(r["text"] for r in rows)
    assert announced_row("setting.kappa_left", 2e-4)["value"] == pytest.approx(0.2)  # mrad
    assert announced_row("counter_scale.X", 1e-5)["unit"] == "ppm"


def test_an_exam_carries_no_parallax_numbers_whatever_the_file_says():
    data = dict(load_exercise("e03-setup-stage2").source)
    data.update(name="exam-readout", mode="exam", assists={"parallax_readout": True})
    s = Session.start(exercise_from_mapping(data), trainee="ann")
    s.act({"kind": "read", "counter": "X"})
    assert s.state()["parallax"] is None and not s.state()["assists"]["parallax_readout"]


def test_the_conventional_method_withholds_the_orientation_values():
    assert sheet_parts(load_exercise("e05-conventional-c2"))["given"] == ["certificate", "interior"]
    assert "readings" in sheet_parts(load_exercise("e03-setup-stage2"))["given"]


def test_a_refusal_names_the_instrument_never_a_server_path():
    s = Session.start(load_exercise("e10-setup-mountain"), trainee="ann")
    for action in (
        {"kind": "turn", "control": "Z", "delta": 1e5},
        {"kind": "set", "control": "kappa_left", "value": 2.0},
    ):
        with pytest.raises(TrainerError) as exc:
            s.act(action)
        message = str(exc.value)
        assert "instrument sd3" in message, message
        assert ".yaml" not in message and "/" not in message and "YAML" not in message


@pytest.mark.parametrize(
    ("name", "stage"), [("e02-conventional-c1", "C1"), ("e04-setup-stage4", "4")]
)
def test_every_stage_lists_its_checks_with_tolerances(name, stage):
    state = Session.start(load_exercise(name), trainee="ann").state()
    assert state["stage"] == stage
    assert state["checks"] and all(c["tolerance"] > 0 for c in state["checks"])
