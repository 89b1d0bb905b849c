"""The trainer on the command line: exercise list/show, session run, grade."""

from __future__ import annotations

import json

from stereoplotter.cli import main
from stereoplotter.io.exercise_file import shipped_exercises


def test_exercise_list_names_every_shipped_exercise(capsys):
    assert main(["exercise", "list", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["name"] for r in rows] == sorted(p.stem for p in shipped_exercises())


def test_exercise_show_a_missing_exercise_is_one_error_line(capsys):
    assert main(["exercise", "show", "e99"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1


def test_session_run_then_grade(tmp_path, capsys):
    actions = tmp_path / "actions.jsonl"
    actions.write_text(
        '{"kind": "hint", "level": 3}\n{"kind": "turn", "control": "X", "delta": 0.5}\n'
        '{"kind": "claim", "step": "1"}\n',
        encoding="utf-8",
    )
    log = tmp_path / "s.jsonl"
    assert (
        main(["session", "run", "e01-setup-stage1", "--actions", str(actions), "-o", str(log)]) == 0
    )
    assert "3 actions (0 refused), stage all done" in capsys.readouterr().out
    out = tmp_path / "grade"
    assert main(["grade", str(log), "--json", "--population", "20", "-o", str(out)]) == 0
    g = json.loads(capsys.readouterr().out)
    assert g["process"]["hints"] == 1 and g["process"]["moves"] == 1
    assert g["stages"]["1"]["claimed"]
    assert json.loads((out / "grade.json").read_text(encoding="utf-8")) == g
    assert (out / "grade.md").read_text(encoding="utf-8").startswith("# Grade: ")


def test_a_refused_action_stops_the_run_but_the_log_is_written(tmp_path, capsys):
    actions = tmp_path / "a.json"
    actions.write_text('[{"kind": "turn", "control": "X", "delta": 1e6}]', encoding="utf-8")
    log = tmp_path / "s.jsonl"
    assert (
        main(["session", "run", "e01-setup-stage1", "--actions", str(actions), "-o", str(log)]) == 1
    )
    assert "beyond the range stops" in capsys.readouterr().err
    assert len(log.read_text(encoding="utf-8").splitlines()) == 2
