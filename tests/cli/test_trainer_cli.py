"""The trainer on the command line: exercise list/show, session run, grade."""

from __future__ import annotations

import json
import re
import socket
import subprocess
import sys
import time
import urllib.request

from stereoplotter.cli import main
from stereoplotter.io.exercise_file import load_exercise, shipped_exercises


def test_exercise_list_names_every_shipped_exercise(capsys):
    assert main(["exercise", "list", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert sorted(r["name"] for r in rows) == sorted(p.stem for p in shipped_exercises())
    assert [r["level"] for r in rows] == sorted(r["level"] for r in rows)  # easiest first


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


def test_trainer_serves_on_the_printed_free_port(tmp_path):
    # `stereoplotter trainer` with the default port 0: the system picks a free port and the
    # printed address is the one that answers
    with subprocess.Popen(
        [sys.executable, "-m", "stereoplotter", "trainer", "--token", "t0",
         "--data-dir", str(tmp_path)],  # never the user's own data folder
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    ) as proc:
        try:
            first = proc.stdout.readline()
            second = proc.stdout.readline()
            url = re.search(r"http://localhost:(\d+)/$", first.strip())
            assert url and int(url.group(1)) > 0, first
            assert second.strip().endswith(f":{url.group(1)}/instructor?token=t0")
            for _ in range(100):  # the server starts right after printing
                try:
                    with urllib.request.urlopen(url.group(0), timeout=2) as r:
                        assert r.status == 200 and b"<html" in r.read().lower()
                    break
                except OSError:
                    time.sleep(0.05)
            else:
                raise AssertionError("the printed address did not answer")
        finally:
            proc.terminate()
            proc.wait(timeout=10)


def test_trainer_on_a_busy_port_is_one_error_line(capsys, tmp_path):
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen(1)
        port = busy.getsockname()[1]
        assert main(["trainer", "--port", str(port), "--data-dir", str(tmp_path)]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"error: trainer: cannot listen on 127.0.0.1:{port}")
    assert err.count("\n") == 1


def test_exercise_new_writes_a_file_that_loads_back(tmp_path, capsys):
    path = tmp_path / "mine.yaml"
    argv = ["exercise", "new", "mine", "--stages", "2", "--unusable-points", "5", "--seed", "4"]
    assert main([*argv, "--errors", "announced", "-o", str(path)]) == 0
    ex = load_exercise(path)
    assert (ex.name, ex.stages, ex.model, ex.unusable_points, ex.seed) == (
        "mine", ("2",), "incomplete", (5,), 4
    )
    assert main([*argv, "-o", str(path)]) == 1  # exists: no overwrite without --force
    assert "a new file (or --force)" in capsys.readouterr().err


def test_exercise_new_refuses_a_bad_option_in_one_line_and_writes_nothing(tmp_path, capsys):
    path = tmp_path / "bad.yaml"
    assert main(["exercise", "new", "bad", "--stages", "C9", "-o", str(path)]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"error: {path}: stages: expected") and err.count("\n") == 1
    assert not path.exists()


def test_exercise_sheet_gives_a_conventional_exercise_no_orientation_values(capsys):
    assert main(["exercise", "sheet", "e05-conventional-c2", "--json"]) == 0
    sheet = json.loads(capsys.readouterr().out)
    assert sheet["given"] == ["certificate", "interior"]
    assert "readings" not in sheet and "table24" not in sheet
    # f_пр = k·f′ of pair60 on SC-1: 1.5625 × 70 mm (Table 24), to the sheet's 6 digits
    assert abs(sheet["interior"]["f_instrument_mm"] - 1.5625 * 70.0) < 1e-3
    assert main(["exercise", "sheet", "e03-setup-stage2"]) == 0
    assert "## Table 24" in capsys.readouterr().out
