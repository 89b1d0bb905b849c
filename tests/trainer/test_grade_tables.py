"""A grade that teaches: per-point tables, the hint cost, the process per stage."""

from __future__ import annotations

import numpy as np
import pytest

from stereoplotter.io.exercise_file import load_exercise
from stereoplotter.trainer.grade_tables import HINT_COST, hint_cost, outcome_points
from stereoplotter.trainer.grading import grade
from stereoplotter.trainer.outcome import standard_q
from stereoplotter.trainer.robot import robot_script
from stereoplotter.trainer.session import Session


@pytest.fixture(scope="module")
def e06():
    s = Session.start(load_exercise("e06-setup-stage3"), trainee="robot")
    for action in robot_script(s):
        s.act(action)
    return s, grade(s, population=0)


def test_the_y_parallax_table_is_the_true_parallax_at_each_standard_point(e06):
    s, g = e06
    rows = g["tables"]["y_parallax"]["rows"]
    q = np.asarray(standard_q(s.at_claim["3"], s.prep), float).reshape(-1) * 1000.0
    assert [r["value"] for r in rows] == pytest.approx(list(q), abs=1e-9)
    worst = max(abs(r["value"]) for r in rows)
    measured = g["stages"]["3"]["measures"][0]
    assert worst == pytest.approx(measured["value"] * 1000.0, rel=1e-12)


def test_the_height_table_holds_the_graded_maximum(e06):
    _, g = e06
    heights = g["tables"]["heights"]
    worst = max(abs(r["error"]) for r in heights["rows"])
    row = next(m for m in g["stages"]["3"]["measures"] if m["unit"] == "m")
    assert worst == pytest.approx(row["value"], rel=1e-12)
    assert heights["tolerance"] == row["tolerance"]
    assert len(g["tables"]["y_parallax_map"]["points"]) > 40  # most of the 9 × 9 grid imaged


def test_per_stage_time_counts_from_the_stages_first_action():
    s = Session(load_exercise("e01-setup-stage1"), "ann", 1, clock=False)
    s.act({"kind": "read", "counter": "X", "t": 600.0})  # a first action long after the start
    s.act({"kind": "claim", "step": "1", "t": 612.5})
    g = grade(s, population=0)
    assert g["process_by_stage"]["1"]["time_s"] == 12.5
    assert g["process"]["skipped_checks"] == []


def test_a_stage_claimed_without_reading_names_its_skipped_checks():
    s = Session(load_exercise("e01-setup-stage1"), "ann", 1, clock=False)
    s.act({"kind": "claim", "step": "1", "t": 1.0})
    assert grade(s, population=0)["process"]["skipped_checks"] == ["stage 1: |L − L′|"]


def test_hint_3_then_claim_no_longer_passes():
    s = Session.start(load_exercise("e01-setup-stage1"), trainee="ann")
    s.act({"kind": "hint", "level": 3})
    s.act({"kind": "claim", "step": "1"})
    o = grade(s, population=0)["overall"]
    assert o["within_tolerance"] and not o["passed"]
    assert o["hint_cost"] == 100.0 * HINT_COST[3]
    assert o["points"] == pytest.approx(o["outcome_points"] - 75.0)


def test_the_hint_rule_counts_the_highest_level_once_per_stage():
    log = [
        {"stage": "1", "action": {"kind": "hint", "level": 1}},
        {"stage": "1", "action": {"kind": "hint", "level": 2}},
        {"stage": "1", "action": {"kind": "hint", "level": 2}},
        {"stage": "2", "action": {"kind": "hint", "level": 3}, "refused": "no"},
    ]
    cost = hint_cost(("1", "2"), log)
    assert cost["stages"]["1"] == {"level": 2, "cost": 50.0 * 0.25}
    assert cost["stages"]["2"] == {"level": None, "cost": 0.0}
    assert cost["total"] == 12.5
    assert [outcome_points(x) for x in (0.3, 1.0, 1.5, 2.0, 3.0, float("inf"))] == [
        100.0,
        100.0,
        50.0,
        0.0,
        0.0,
        0.0,
    ]
