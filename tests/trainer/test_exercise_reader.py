"""Replaying a session log needs no registration done by importing io: the reader of the
header's exercise is passed explicitly; without one the replay is refused in one line."""

from __future__ import annotations

import pytest

from stereoplotter.errors import TrainerError
from stereoplotter.io.exercise_file import exercise_from_mapping, load_exercise
from stereoplotter.io.session_log import log_bytes, read_log, replay_log, write_log
from stereoplotter.trainer.session import Session


def test_replay_with_an_explicit_reader_needs_no_registry(tmp_path):
    s = Session.start(load_exercise("e01-setup-stage1"), trainee="cy")
    s.act({"kind": "turn", "control": "X", "delta": 0.75})
    s.act({"kind": "read", "counter": "X"})
    path = tmp_path / "a.jsonl"
    write_log(path, s)
    with pytest.raises(TrainerError, match="no exercise reader"):
        Session.replay(read_log(path))
    again = Session.replay(read_log(path), read_exercise=exercise_from_mapping)
    assert log_bytes([again.header(), *again.log]) == path.read_bytes()
    by_io = replay_log(path)  # the io layer passes its reader: no registry needed either
    assert log_bytes([by_io.header(), *by_io.log]) == path.read_bytes()
