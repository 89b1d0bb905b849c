"""Messages that point at the input: a pair refused for want of imaged control names the photo
or point that looks wrong and why; the advice to quote an identifier only where YAML read it as
another number; ``-q`` prints warnings and errors only."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from stereoplotter.cli import main

STRIP8 = Path(__file__).resolve().parents[2] / "jobs" / "strip8"


def _job(tmp_path: Path, old: str, new: str) -> Path:
    folder = tmp_path / "job"
    shutil.copytree(STRIP8, folder)
    path = folder / "job.yaml"
    text = path.read_text("utf-8")
    assert old in text
    path.write_text(text.replace(old, new, 1), "utf-8")
    return path


@pytest.mark.parametrize(
    ("value", "advice", "found"),
    [
        ("-5", False, "found the number -5 (line"),
        ("1.5", False, "found the number 1.5 (line"),
        ("0101", True, "found 0101 unquoted, read as the octal number 65 (line"),
        ("1:30", True, "found 1:30 unquoted, read as the sexagesimal number 90 (line"),
    ],
)
def test_quoting_advice_only_where_yaml_read_another_number(tmp_path, capsys, value, advice,
                                                            found):  # fmt: skip
    path = _job(tmp_path, '{number: "101"', f"{{number: {value}")
    assert main(["setup", str(path), "-o", str(tmp_path / "out")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "photos[0].number: expected an identifier" in err[0]
    assert ("quote it" in err[0]) is advice and found in err[0], err[0]


def test_a_photo_far_from_its_pair_is_named(tmp_path, capsys):
    """Photo 102's north halved (6 167 100 → 3 083 550 m): pairs 101-102 and 102-103 are
    refused, each naming photo 102 as the one 3 051.5 km from the control, and the control point
    nearest to being imaged with how far it falls outside the format; -q prints only these
    warnings, the other six pairs' forms are written."""
    path = _job(tmp_path, '{number: "102", north_m: 6167100.000',
                '{number: "102", north_m: 3083550.000')  # fmt: skip
    assert main(["setup", str(path), "-o", str(tmp_path / "out"), "-q"]) == 0
    out, err = capsys.readouterr()
    assert out == ""
    lines = err.strip().splitlines()
    assert [line.split(":")[1].strip() for line in lines] == ["101-102", "102-103"]
    for line in lines:
        assert line.startswith("warning: ") and "suspicious: photos 10" in line
        assert "photo 102 is 3051.5 km" in line and "km from the nearest control point" in line
        assert "mm outside the format on photo 102" in line
    assert (tmp_path / "out" / "103-104" / "sheet.pdf").is_file()


def test_a_photo_below_the_ground_is_named(tmp_path, capsys):
    path = _job(tmp_path, "east_m: 5347962.056, height_m: 1548.671",
                "east_m: 5347962.056, height_m: 0")  # fmt: skip
    assert main(["setup", str(path), "-o", str(tmp_path / "out"), "-q"]) == 0
    err = capsys.readouterr().err
    assert err.count("photo 102 at 0.0 m is not above the control's median height") == 2


def test_quiet_job_to_scenario_prints_nothing(tmp_path, capsys):
    out = tmp_path / "pair.yaml"
    assert main(["job", "to-scenario", str(STRIP8 / "job.yaml"), "101-102", "-o", str(out),
                 "-q"]) == 0  # fmt: skip
    assert capsys.readouterr() == ("", "") and out.is_file()
