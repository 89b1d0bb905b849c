"""The trainee's session: actions, undo/redo, refusals, hints, and the byte-for-byte replay."""

from __future__ import annotations

import pytest

from stereoplotter.errors import TrainerError
from stereoplotter.io.exercise_file import load_exercise
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
        Session.replay(records)
