"""The command line: info, scenario check, demo; errors without tracebacks."""

from __future__ import annotations

import contextlib
import io
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

import stereoplotter.cli as cli
import stereoplotter.commands.info as info_command
import stereoplotter.io.atomic_write as yamlio
from stereoplotter.cli import main

ROOT = Path(__file__).resolve().parents[2]
PAIR60 = str(ROOT / "scenarios" / "pair60.yaml")


def test_info_lists_versions_and_scenarios(capsys):
    assert main(["info", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert {"stereoplotter", "numpy", "pymunk", "matplotlib", "pyproj"} <= set(info["versions"])
    assert any(s.get("name") == "pair60" for s in info["scenarios"])
    assert main(["info"]) == 0
    assert "scenarios (" in capsys.readouterr().out


def test_scenario_check_text_and_json(capsys):
    assert main(["scenario", "check", PAIR60]) == 0
    text = capsys.readouterr().out
    assert "valid" in text and "overlap" in text and "B/H" in text and "relief" in text
    assert main(["scenario", "check", PAIR60, "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["base"]["horizontal_m"] == pytest.approx(1440.078, abs=0.001)
    assert summary["photos"][0]["photo_scale_denominator"] == pytest.approx(19901, abs=1)


def test_bad_scenario_is_one_error_line_exit_1(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text(
        Path(PAIR60)
        .read_text(encoding="utf-8")
        .replace("focal_length_mm: 70.0", "focal_length_mm: -70.0"),
        encoding="utf-8",
    )
    assert main(["scenario", "check", str(bad)]) == 1
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "camera.focal_length_mm" in err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_missing_file_exit_1(capsys):
    assert main(["scenario", "check", "does-not-exist.yaml"]) == 1
    assert "expected an existing file" in capsys.readouterr().err


def test_usage_error_exits_2(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["scenario"])
    assert exc.value.code == 2


def test_demo_writes_files_reproducibly(tmp_path, capsys):
    out1, out2 = tmp_path / "a", tmp_path / "b"
    assert main(["demo", "-o", str(out1), "--scenario", PAIR60]) == 0
    assert "space intersection" in capsys.readouterr().out
    assert main(["demo", "-o", str(out2), "--scenario", PAIR60]) == 0
    names = {
        "result.json",
        "summary.md",
        "measurements.csv",
        "layout.png",
        "sheet.yaml",
        "sheet.md",
        "sheet.pdf",
        "sheet.png",
    }
    assert {p.name for p in out1.iterdir()} == names | {"simulate"}
    simulated = {
        "transcript.txt",
        "transcript.jsonl",
        "evaluation.yaml",
        "evaluation.md",
        "parallax.png",
    }
    assert {p.name for p in (out1 / "simulate").iterdir()} == simulated
    names |= {f"simulate/{n}" for n in simulated}
    for name in names:  # same seed → byte-identical output files
        assert (out1 / name).read_bytes() == (out2 / name).read_bytes(), name
    result = json.loads((out1 / "result.json").read_text(encoding="utf-8"))
    # 3 µm measurement noise at 1:20 000 gives decimetre errors, not metres
    assert result["intersection"]["statistics"]["check"]["rms_height_m"] < 0.3
    assert result["similarity"]["determinant"] < 0
    assert result["setup_sheet"]["scale_horizontal"] == 12500  # the sheet on the default SC-1


def test_demo_resection_scenario(tmp_path, capsys):
    scenario = str(ROOT / "scenarios" / "book_resection_table7.yaml")
    assert main(["demo", "-o", str(tmp_path), "--scenario", scenario, "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert "not a stereopair" in result["setup_sheet"]["refused"]
    (ext,) = result["exterior"]
    assert ext["source"] == "resection"
    assert max(abs(v) for v in ext["error_angles_arcsec"]) < 0.1
    assert max(abs(v) for v in ext["error_centre_m"]) < 0.001


def test_python_dash_m_runs():
    done = subprocess.run(
        [sys.executable, "-m", "stereoplotter", "--version"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0 and done.stdout.startswith("stereoplotter ")


def test_unexpected_error_is_one_line_exit_3(monkeypatch, capsys):
    def broken():
        raise ZeroDivisionError("boom")

    monkeypatch.delenv("STEREOPLOTTER_DEBUG", raising=False)
    monkeypatch.setattr(info_command, "info", broken)
    assert cli.main(["info"]) == 3
    err = capsys.readouterr().err
    assert err.startswith("error: internal error (ZeroDivisionError: boom)")
    assert "Traceback" not in err


def test_atomic_write_leaves_old_file_when_writing_fails(tmp_path, monkeypatch):
    target = tmp_path / "out.txt"
    yamlio.atomic_write_text(target, "old")

    def failing_replace(src, dst):
        raise OSError("disk full")

    monkeypatch.setattr(yamlio.os, "replace", failing_replace)
    with pytest.raises(OSError, match="disk full"):
        yamlio.atomic_write_text(target, "new")
    assert target.read_text(encoding="utf-8") == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["out.txt"]  # no temporary file left


def test_instrument_test_cli(capsys):
    assert main(["instrument", "test", "sc1", "--tilts", "1", "--variants", "L", "B"]) == 0
    text = capsys.readouterr().out
    assert "§6 Residual y-parallax" in text and "FAIL" in text  # variant B fails mark 4
    assert main(["instrument", "test", "sd3", "--tilts", "0.5", "--variants", "L", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["instrument"] == "sd3" and data["residuals"][0]["unit"] == "canonical"


@pytest.fixture(scope="module")
def verify_run(tmp_path_factory):
    """``verify --trials 2000 -o DIR``: (its printed text, DIR). The procedure MC and the
    as-formula runs take their own trials and seeds, only the linear MC follows --trials (the
    as_formula blocks, mc_procedure and its CI of every row were compared with the default
    run's: identical)."""
    out = tmp_path_factory.mktemp("verify")
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        assert main(["verify", "--trials", "2000", "-o", str(out)]) == 0
    return buf.getvalue(), out


@pytest.fixture(scope="module")
def verify_rows(verify_run):
    """The rows of that run as ``verify --json`` prints them: its ``verification.json`` holds
    the same rows (plain JSON both)."""
    return json.loads((verify_run[1] / "verification.json").read_text(encoding="utf-8"))


def test_verify_cli(verify_run, verify_rows):
    out, folder = verify_run
    assert "(6.43)" in out and "verdict" in out
    names = {p.name for p in folder.iterdir()}
    assert {
        "verification.md",
        "verification.csv",
        "verification.json",
        "closing_comparison.json",
        "error_maps.png",
        "verification_chart.png",
    } <= names
    rows = verify_rows
    keys = {
        "eq",
        "quantity",
        "printed",
        "book",
        "rigorous",
        "mc_linear",
        "mc_linear_ci",
        "mc_procedure",
        "mc_procedure_ci",
        "verdict",
        "note",
    }
    assert all(keys <= set(r) for r in rows)
    assert {r["eq"] for r in rows} >= {f"(6.{i})" for i in range(28, 62)}


def _as_formula_line(label: str, r: dict) -> str:
    a = r["as_formula"]
    vf = a.get("vertical_flat")
    vertical = f"{vf['ratio']:.4f}" if vf else "—"
    depth = f"{vf['ratio_at_depth']:.4f}" if vf and vf.get("ratio_at_depth") else "—"
    return (
        f"| {label} | {a['value']:.4f} ± {a['ci']:.4f} | {a['formula']:.4f} | {a['ratio']:.4f} | "
        f"{vertical} | {depth} | {r['mc_procedure']:.4f} ± {r['mc_procedure_ci']:.4f} |"
    )


def test_accuracy_as_formula_table_is_what_verify_prints(verify_rows):
    """docs/accuracy.md's "As formula" table is the ``as_formula`` block of ``verify --json``:
    each row (labelled by the equations that share one run) prints its first equation's as-formula
    value ± CI, the formula at the simulated geometry, their ratio, the ratio on vertical photos
    over flat terrain and with b_x at the terrain's depth (setup rows), and the default procedure
    MC ± CI, to the 4 decimals printed; the other equations of a label are the same run. A stale
    figure fails."""
    text = (ROOT / "docs" / "accuracy.md").read_text(encoding="utf-8")
    table = text.split("**As formula** (", 1)[1].split("**Decomposition**", 1)[0]
    assert "Generated by `stereoplotter verify --json` (defaults" in table
    lines = [x for x in table.splitlines() if x.startswith("| (")]
    by_eq = {}
    for r in verify_rows:
        by_eq.setdefault(r["eq"], r)
    labels = []
    for line in lines:
        label = line.split(" | ", 1)[0][2:]
        eqs = re.findall(r"\(\d\.\d+\)", label)
        labels += eqs
        assert line == _as_formula_line(label, by_eq[eqs[0]]), label
        for other in eqs[1:]:
            assert by_eq[other]["as_formula"]["value"] == by_eq[eqs[0]]["as_formula"]["value"]
    outcome = {f"(6.{k})" for k in range(39, 62)}
    assert set(labels) == outcome and len(labels) == len(outcome)
