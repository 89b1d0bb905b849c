"""The stage checklist ticks a step when its target is met, and says where its values come from."""

from __future__ import annotations

import re

import numpy as np
import pytest

from stereoplotter.io.exercise_file import load_exercise
from stereoplotter.report.exercise_sheet import exercise_sheet
from stereoplotter.trainer.panel import checklist
from stereoplotter.trainer.session import Session
from stereoplotter.trainer.step_words import SYMBOL_PATTERNS, glossary


def _steps(s):
    return {st["text"]: st for st in checklist(s)["steps"]}


def _find(s, start):
    return next(st for t, st in _steps(s).items() if t.startswith(start))


@pytest.fixture
def e01():
    return Session.start(load_exercise("e01-setup-stage1"), trainee="ann")


def test_setting_f_ticks_the_f_step_and_only_within_the_least_count(e01):
    lc = e01.exercise.spec.xy_least_count_mm
    f = float(e01.prep.sheet.f_instrument_mm)
    e01.act({"kind": "set", "control": "f_instrument", "value": round(f + 2 * lc, 4)})
    assert not _find(e01, "set the instrument principal distance")["done"]
    e01.act({"kind": "set", "control": "f_instrument", "value": round(f, 4)})
    assert _find(e01, "set the instrument principal distance")["done"]
    assert not _find(e01, "gear the height counter")["done"]  # the gear is a step of its own
    e01.act({"kind": "gear", "value": int(e01.prep.sheet.vertical_scale_denominator)})
    assert _find(e01, "gear the height counter")["done"]


def test_the_carriage_step_ticks_at_z_equal_n_times_f(e01):
    sheet = e01.prep.sheet
    e01.act({"kind": "set", "control": "f_instrument", "value": round(sheet.f_instrument_mm, 4)})
    e01.act({"kind": "set", "control": "bz", "value": 50.0})  # b_z = 0 at stage 1: its MO
    assert not _find(e01, "lower the carriage")["done"]
    z = sheet.photos[0].n * sheet.f_instrument_mm  # n_л·f_пр (185.00 mm on pair60)
    assert z == pytest.approx(185.0, abs=0.01)
    e01.act({"kind": "set", "control": "Z", "value": round(z, 2)})
    assert _find(e01, "lower the carriage")["done"]


def test_the_corrections_show_only_when_the_l_check_fails(e01):
    c = checklist(e01)
    hidden = [st for st in c["steps"] if not st["shown"]]
    assert hidden and all(st["conditional"] for st in hidden)
    assert all(re.match(r"ΔZ|Δb_z", st["text"]) or "bottom stop" in st["text"] for st in hidden)
    assert c["total"] == len(c["steps"]) - len(hidden)
    e01.act({"kind": "set", "control": "f_instrument", "value": 109.3748})
    e01.act({"kind": "set", "control": "Z", "value": 183.0})  # 2 mm too high: L′ ≠ L
    shown = [st for st in checklist(e01)["steps"] if st["conditional"]]
    assert shown and all(st["shown"] for st in shown)
    assert "L-check fails" in shown[0]["condition"]


def test_hint_3_ticks_every_step_it_did(e01):
    e01.act({"kind": "hint", "level": 3})
    c = checklist(e01)
    assert c["done"] == c["total"] == sum(st["shown"] for st in c["steps"])
    assert e01.state()["checklist_ticks"]["done"].count(True) == c["total"]


def test_the_l_step_and_the_sheet_l_are_both_shown_with_the_reason(e01):
    step = _find(e01, "measure L′_л")
    sheet_l = exercise_sheet(e01.exercise)["table24"]["L_mm"]["left"]
    shown = float(re.search(r"L_л = ([\d.]+) mm", step["text"]).group(1))
    assert abs(sheet_l - shown) > 0.01  # the book's (6.5) against the units-at-zero span
    assert f"{sheet_l:.3f}" in step["note"] and f"{shown:.3f}" in step["note"]
    assert "decision D5" in step["note"]


def test_each_setting_step_names_its_control_and_sheet_row(e01):
    step = _find(e01, "set the instrument principal distance")
    assert step["control_names"] == ["f_пр"]
    assert step["sheet_rows"][0]["key"] == "f_instrument_mm"
    sheet = exercise_sheet(e01.exercise)
    for st in checklist(e01)["steps"]:
        for row in st["sheet_rows"]:
            value = sheet[row["part"]]
            for k in row["key"].split("."):
                value = value[k]
            assert isinstance(value, float | int), row


def test_the_conventional_sheet_rows_name_only_given_parts():
    s = Session.start(load_exercise("e02-conventional-c1"), trainee="ann")
    parts = {r["part"] for st in checklist(s)["steps"] for r in st["sheet_rows"]}
    assert parts <= {"certificate", "interior"}


@pytest.mark.parametrize(
    "text",
    ["MO_bx", "M_в", "n_л", "L-check", "decision D9", "(6.10)", "f_пр", "MO_Y,п", "O′_Z", "κ_п"],
)
def test_every_book_symbol_on_the_page_has_an_explanation(text):
    hits = [g for g in glossary() if re.search(g["pattern"], text)]
    assert hits and all(g["en"] and g["ru"] for g in hits), text


def test_a_symbol_is_not_found_inside_a_longer_word():
    assert not re.search(SYMBOL_PATTERNS["D"], "D_max and DEM")
    assert not re.search(SYMBOL_PATTERNS["C2"], "C24")
    assert re.search(SYMBOL_PATTERNS["D"], "D = n·f_пр")


def test_nothing_is_ticked_for_a_control_never_set(e01):
    ticks = dict(zip((st["text"] for st in checklist(e01)["steps"]),
                     e01.state()["checklist_ticks"]["done"], strict=True))
    assert not ticks["set the instrument principal distance f_пр"]
    assert not next(v for t, v in ticks.items() if t.startswith("lower the carriage"))


def test_the_cached_checks_follow_z_and_the_orientation():
    from stereoplotter.trainer.outcome import stage_measures, standard_q
    from stereoplotter.trainer.panel import span_fails, standard_q_now

    s = Session.start(load_exercise("e01-setup-stage1"), trainee="ann")
    s.act({"kind": "set", "control": "f_instrument", "value": 109.3748})
    tol = s.prep.sheet.tolerances["mark_span_mm"]
    for z in (185.0, 184.0, 185.0):  # Z is the projection distance: the span follows it
        s.act({"kind": "set", "control": "Z", "value": z})
        span = float(stage_measures(s.inst, s.prep, "1")[0].value)
        assert span_fails(s) == (span > tol)
    c2 = Session.start(load_exercise("e05-conventional-c2"), trainee="ann")
    for action in (
        {"kind": "set", "control": "X", "value": 250.0},  # a pointing: q stays
        {"kind": "set", "control": "kappa_right", "value": 0.002},  # an element: q changes
    ):
        c2.act(action)
        np.testing.assert_array_equal(standard_q_now(c2), np.abs(standard_q(c2.inst, c2.prep)))
