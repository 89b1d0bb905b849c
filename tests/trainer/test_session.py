"""The trainee's session: actions, undo/redo, refusals, hints, and the byte-for-byte replay."""

from __future__ import annotations

import pytest

from stereoplotter.errors import TrainerError
from stereoplotter.io.exercise_file import exercise_from_mapping, load_exercise
from stereoplotter.io.session_log import read_log, replay_log, write_log
from stereoplotter.trainer.session import Session


@pytest.fixture(scope="module")
def stage1():
    return load_exercise("e01-setup-stage1")


def test_turn_moves_the_counter_by_the_delta_and_undo_restores_it(stage1):
    s = Session.start(stage1, trainee="ann")
    x0 = s.state()["counters"]["X"]["value"]
    s.act({"kind": "turn", "control": "X", "delta": 1.5})
    # the counter reads zero + (1 + e)·nut: without injected errors (errors: off) e = 0, so a
    # turn by 1.5 mm of reading shows 1.5 mm more, to the least count
    assert s.state()["counters"]["X"]["value"] == pytest.approx(x0 + 1.5, abs=0.01)
    s.act({"kind": "undo"})
    assert s.state()["counters"]["X"]["value"] == x0
    s.act({"kind": "redo"})
    assert s.state()["counters"]["X"]["value"] == pytest.approx(x0 + 1.5, abs=0.01)


def test_a_setting_beyond_the_stop_is_refused_in_one_line_and_logged(stage1):
    s = Session.start(stage1)
    with pytest.raises(TrainerError, match=r"beyond the range stops") as exc:
        s.act({"kind": "turn", "control": "X", "delta": 1e6})
    assert "\n" not in str(exc.value)
    assert s.log[-1]["refused"] == str(exc.value)
    assert s.log[-1]["state_before"] == s.log[-1]["state_after"]


def test_the_log_replays_byte_for_byte(stage1, tmp_path):
    s = Session.start(stage1, trainee="bob")
    s.act({"kind": "set", "control": "f_instrument", "value": 120.0})
    s.act({"kind": "turn", "control": "Z", "delta": -2.0})
    s.act({"kind": "read", "counter": "Z"})
    s.act({"kind": "undo"})
    s.act({"kind": "hint", "level": 2})
    with pytest.raises(TrainerError):
        s.act({"kind": "claim", "step": "2"})
    s.act({"kind": "hint", "level": 3})
    s.act({"kind": "claim", "step": "1"})
    first, second = tmp_path / "a.jsonl", tmp_path / "b.jsonl"
    write_log(first, s)
    write_log(second, replay_log(first))
    assert first.read_bytes() == second.read_bytes()
    assert len(read_log(first)) == len(s.log) + 1


def test_replay_refuses_a_tampered_log(stage1, tmp_path):
    s = Session.start(stage1)
    s.act({"kind": "turn", "control": "Y", "delta": 2.0})
    path = tmp_path / "a.jsonl"
    write_log(path, s)
    records = read_log(path)
    records[1]["action"]["delta"] = 3.0
    with pytest.raises(TrainerError, match="does not replay"):
        Session.replay(records, read_exercise=exercise_from_mapping)


def test_exam_mode_refuses_undo_and_hints():
    s = Session.start(load_exercise("e11-setup-exam"), trainee="ann")
    s.act({"kind": "turn", "control": "X", "delta": 1.0})
    for action in ({"kind": "undo"}, {"kind": "hint", "level": 1}):
        with pytest.raises(TrainerError, match="not allowed now"):
            s.act(action)
    assert s.state()["parallax"] is None  # no read-out in this exam


def test_switching_a_counter_keeps_its_reading_and_reverses_it(stage1):
    s = Session.start(stage1)
    y0 = s.state()["counters"]["Y"]["value"]
    s.act({"kind": "direction", "counter": "Y", "sign": -1})
    assert s.state()["counters"]["Y"]["value"] == y0
    assert s.state()["counters"]["Y"]["direction"] == -1
    # the reversed counter shows 2 mm less where the normal one shows 2 mm more: the carriage
    # stands where it stands after the normal counter is set to y0 + 2 (a second session)
    s.act({"kind": "set", "control": "Y", "value": y0 - 2.0})
    t = Session.start(stage1)
    t.act({"kind": "set", "control": "Y", "value": y0 + 2.0})
    assert float(s.inst.position("Y")) == float(t.inst.position("Y"))
    assert float(s.inst.position("Y")) == pytest.approx(2.0, abs=0.01)  # from the plumb (0)


def test_a_locked_control_refuses_to_turn(stage1):
    s = Session.start(stage1)
    s.act({"kind": "lock", "control": "bx"})
    with pytest.raises(TrainerError, match="locked"):
        s.act({"kind": "turn", "control": "bx", "delta": 0.1})


def test_show_me_does_the_stage_as_the_operator(stage1):
    """Hint level 3 replays the simulated operator's stage on the trainee's instrument: the
    instrument ends where the operator's ended (its own instrument, driven by the procedure)."""
    s = Session.start(stage1)
    result = s.act({"kind": "hint", "level": 3})
    assert s.log[-1]["result"]["applied"] == len(s.par.stage_actions("1")) > 0
    assert result["counters"]["Z"]["value"] == pytest.approx(
        float(s.par.instrument.read("Z")), abs=0
    )


def test_parallax_read_out_after_stage_2_is_within_the_tolerance():
    """With no injected errors, after the operator's stage 2 the true y-parallax at the six
    standard points is the residual the operator left: below the 12.5 µm tolerance (sheet)."""
    s = Session.start(load_exercise("e03-setup-stage2"))
    s.act({"kind": "hint", "level": 3})
    y = s.state()["parallax"]["y_um"]
    assert abs(y) < 1000.0 * s.prep.sheet.tolerances["residual_y_parallax_mm"]


def test_an_incomplete_model_needs_its_substitutes_before_the_claim():
    s = Session.start(load_exercise("e07-setup-stage2-incomplete"))
    with pytest.raises(TrainerError, match="substitute 5"):
        s.act({"kind": "claim", "step": "2"})
    s.act({"kind": "record", "name": "substitute 5", "value": [1.0, 60.0]})
    s.act({"kind": "record", "name": "substitute 6", "value": [1.0, -60.0]})
    assert s.act({"kind": "claim", "step": "2"})["done"]


def test_announced_errors_are_shown_and_hidden_ones_are_not():
    announced = Session.start(load_exercise("e04-setup-stage4")).state()["injected_errors"]
    # the SPR-3's default error model draws zero-reading errors of every counter
    assert set(announced) >= {f"zero_reading.{c}" for c in ("X", "Y", "Z", "bx", "by", "bz")}
    assert Session.start(load_exercise("e08-setup-full")).state()["injected_errors"] is None


def test_a_practice_claim_tells_the_stages_true_outcome(stage1, tmp_path):
    s = Session.start(stage1)
    s.act({"kind": "claim", "step": "1"})  # nothing done: f_пр not set, counter not geared
    result = s.log[-1]["result"]
    assert result["claimed"] == "1"
    assert [(m["name"], m["passed"]) for m in result["measures"]] == [
        ("f_пр not set", False),
        ("height counter not geared for M_в", False),
    ]
    write_log(tmp_path / "a.jsonl", s)  # the log stays JSON (no inf, no nan)
    exam = Session.start(load_exercise("e11-setup-exam"))
    exam.act({"kind": "claim", "step": "1"})
    assert "measures" not in exam.log[-1]["result"]


def test_a_hint_lists_the_operators_steps_of_the_stage(stage1):
    s = Session.start(stage1)
    s.act({"kind": "hint", "level": 1})
    steps = s.log[-1]["result"]["steps"]
    # the steps are the operator's transcript records of stage 1, each once
    transcript = [r.step for r in s.par.run.op.log.records if r.stage == "1"]
    assert steps == list(dict.fromkeys(s for s in transcript if s in steps))
    assert set(steps) <= set(transcript)
    assert steps  # (the texts are the procedure's labels: not pinned here)


def test_undo_and_redo_walk_back_and_forth_through_the_states_each_action_left():
    """Every kind of state an action changes (screws with play, κ, decentrations, knobs, f_пр,
    a lock, a record, a claim with its copy of the instrument) comes back exactly on undo, and
    again on redo: each state compared with the one the session showed when it got there."""
    s = Session.start(load_exercise("e08-setup-full"), trainee="ann")
    s.act({"kind": "hint", "level": 3})  # the operator's stage 1 applied: not undoable itself
    actions = [
        {"kind": "set", "control": "f_instrument", "value": 120.0},
        {"kind": "turn", "control": "X", "delta": 3.0},
        {"kind": "turn", "control": "X", "delta": -1.0},  # reversal: the nut takes up its play
        {"kind": "set", "control": "kappa_left", "value": 0.002},
        {"kind": "turn", "control": "dx_right", "delta": 0.5},
        {"kind": "set", "control": "k_omega_left", "value": 0.001},
        {"kind": "turn", "control": "bz", "delta": -0.4},
        {"kind": "record", "name": "note", "value": [1.0, 2.0]},
        {"kind": "lock", "control": "by"},
        {"kind": "claim", "step": "1"},
        {"kind": "turn", "control": "Y", "delta": 2.0},
    ]
    seen = [s.full_state()]
    for action in actions:
        s.act(action)
        seen.append(s.full_state())
    checked = len(seen) - 1
    for k in range(checked):
        s.act({"kind": "undo"})
        assert _undoable_part(s.full_state()) == _undoable_part(seen[-2 - k])
    assert "undo" not in s.allowed()
    for k in range(checked):
        s.act({"kind": "redo"})
        assert _undoable_part(s.full_state()) == _undoable_part(seen[1 + k])
    assert s.at_claim["1"] is not s.inst


def _undoable_part(state):
    """A state without what undo leaves as it is (the checklist's ticks, the last action's
    coupled motions) and what follows from the stacks (the actions allowed)."""
    return {k: v for k, v in state.items() if k not in ("checklist_ticks", "events", "allowed")}
