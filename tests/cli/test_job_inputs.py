"""Job inputs that keep every identifier, messages that point to the cell, a pair refused alone,
output folders that behave, on copies of jobs/strip8."""

from __future__ import annotations

import csv
import io
import json
import re
from pathlib import Path

import pypdf
import pytest
import yaml

from stereoplotter.cli import main
from stereoplotter.commands.setup_job import compute_job, write_job
from stereoplotter.io.job_file import load_job
from stereoplotter.io.job_measured import measured_pair

ROOT = Path(__file__).resolve().parents[2]
STRIP8 = ROOT / "jobs" / "strip8"


def _job(tmp_path: Path, edit=None, control=None, fiducials=None, name="job.yaml") -> Path:
    """A copy of strip8 in ``tmp_path``: ``edit(doc)`` changes the YAML document, ``control``
    and ``fiducials`` the CSV lines (lists of text lines)."""
    doc = yaml.safe_load((STRIP8 / "job.yaml").read_text("utf-8"))
    ctl = (STRIP8 / "control.csv").read_text("utf-8").splitlines()
    fid = (STRIP8 / "fiducials.csv").read_text("utf-8").splitlines()
    if edit:
        edit(doc)
    ctl = control(ctl) if control else ctl
    fid = fiducials(fid) if fiducials else fid
    (tmp_path / "control.csv").write_text("\n".join(ctl) + "\n", "utf-8")
    (tmp_path / "fiducials.csv").write_text("\n".join(fid) + "\n", "utf-8")
    path = tmp_path / name
    path.write_text(yaml.safe_dump(doc, allow_unicode=True), "utf-8")
    return path


def _renumber_101(doc):
    doc["photos"][0]["number"] = "012417"
    doc["pairs"][0]["left"] = "012417"


def _acceptance_control(lines):
    """A comment line after the header, and points 0415 and 415 (two points: the coordinates of
    points 11 and 12, which pair 101-102 images)."""
    rows = lines[1:]
    extra = [rows[0].replace("11,", "0415,", 1), rows[1].replace("12,", "415,", 1)]
    return [lines[0], "# catalogue of 2026-11-20, SK-42 zone 5", *rows, "", *extra]


def _error(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith("error: ") and "Traceback" not in err[0]
    return err[0]


def test_acceptance_ids_stay_distinct_photo_number_prints_as_written(tmp_path, capsys):
    """Ids 0415 and 415, photo number "012417" quoted, a comment line in
    the CSV; then an error on the CSV's line 5 is reported at line 5."""

    def edit(doc):
        _renumber_101(doc)
        doc["pairs"] = doc["pairs"][:2]

    def fiducials(lines):
        return [lines[0], lines[1].replace("101,", "012417,", 1), *lines[2:]]

    path = _job(tmp_path, edit, _acceptance_control, fiducials)
    job = load_job(path)
    ids = [p.id for p in job.points]
    assert "0415" in ids and "415" in ids and len(ids) == len(set(ids)) == 58
    assert next(iter(job.photos)) == "012417" and job.pairs[0].name == "012417-102"
    m = measured_pair(job, job.pairs[0])
    assert {"0415", "415"} <= {p.id for p in m.points}

    out = tmp_path / "out"
    assert main(["setup", str(path), "-o", str(out)]) == 0
    assert "012417-102: M_г = 1:12500" in capsys.readouterr().out
    sheet = yaml.safe_load((out / "012417-102" / "sheet.yaml").read_text("utf-8"))
    assert sheet["job"]["photos"] == {"left": "012417", "right": "102"}
    assert (
        "0415" in sheet["control_heights_model_mm"] and "415" in sheet["control_heights_model_mm"]
    )
    rows = list(csv.DictReader(io.StringIO((out / "block.csv").read_text("utf-8"))))
    assert (rows[0]["pair"], rows[0]["left_photo"]) == ("012417-102", "012417")
    text = re.sub(r"\s+", " ", pypdf.PdfReader(out / "012417-102" / "sheet.pdf").pages[0]
                  .extract_text())  # fmt: skip
    assert "left photo 012417, right photo 102" in text and "5391" not in text

    # line 5 of the file (header, comment, rows 11, 12, 13): a bad north_m of point 13
    lines = (tmp_path / "control.csv").read_text("utf-8").splitlines()
    assert lines[4].startswith("13,")
    lines[4] = lines[4].replace(",6165546.89,", ",6165546.8.9,")
    (tmp_path / "control.csv").write_text("\n".join(lines) + "\n", "utf-8")
    assert main(["setup", str(path), "-o", str(tmp_path / "out2")]) == 1
    column = lines[4].index("6165546.8.9") + 1
    line = _error(capsys)
    assert f"control.csv:5:{column}: north_m: expected a number" in line
    assert "'6165546.8.9'" in line


@pytest.mark.parametrize(
    ("text", "field", "shown"),
    [
        ("number: 012417", "photos[0].number", "012417"),  # octal 5391 to YAML 1.1
        ("number: 0417", "photos[0].number", "0417"),  # octal 271
        ("left: 0101", "pairs[0].left", "0101"),  # octal 65
        ("number: 1_01", "photos[0].number", "1_01"),  # the integer 101
    ],
)
def test_unquoted_number_with_a_leading_zero_is_refused(tmp_path, capsys, text, field, shown):
    path = _job(tmp_path)
    doc = path.read_text("utf-8")
    old = text.split(":")[0] + ": '101'"
    assert old in doc
    path.write_text(doc.replace(old, text, 1), "utf-8")
    assert main(["setup", str(path), "-o", str(tmp_path / "out")]) == 1
    line = _error(capsys)
    assert f'job.yaml: {field}: expected an identifier as text: quote it ("{shown}")' in line
    lineno = next(i for i, t in enumerate(path.read_text("utf-8").splitlines(), 1) if text in t)
    assert f"found {shown} unquoted, read as the " in line
    assert f"(line {lineno}, column" in line
    assert not (tmp_path / "out").exists()


def test_unquoted_plain_numbers_are_their_digits(tmp_path):
    """``number: 101`` unquoted (as older jobs write it) is the photo '101'."""
    path = _job(tmp_path)
    path.write_text(re.sub(r"'(1\d\d)'", r"\1", path.read_text("utf-8")), "utf-8")
    assert "number: 101\n" in path.read_text("utf-8")
    job = load_job(path)
    assert list(job.photos) == [str(n) for n in range(101, 110)]


def test_csv_lines_are_physical_with_comments_and_blank_lines(tmp_path, capsys):
    def control(lines):
        return [lines[0], "", "# comment", *lines[1:3], "", "# another", *lines[3:]]

    path = _job(tmp_path, control=control)
    lines = (tmp_path / "control.csv").read_text("utf-8").splitlines()
    assert lines[7].startswith("13,")  # line 8
    lines[7] = lines[7].replace(",control,", ",contrl,")
    (tmp_path / "control.csv").write_text("\n".join(lines) + "\n", "utf-8")
    assert main(["setup", str(path), "-o", str(tmp_path / "out")]) == 1
    assert "control.csv:8:4: role: expected one of control, check" in _error(capsys)


def test_duplicate_id_names_both_places(tmp_path, capsys):
    path = _job(tmp_path, control=lambda c: [*c, c[1]])
    assert main(["setup", str(path), "-o", str(tmp_path / "out")]) == 1
    line = _error(capsys)
    assert "control.csv:58:1: id: expected a unique point id" in line
    assert "first at " in line and "control.csv:2:1" in line


def test_missing_csv_names_the_job_field(tmp_path, capsys):
    path = _job(tmp_path, lambda d: d.update(points_csv=["control.csv", "more.csv"]))
    assert main(["setup", str(path), "-o", str(tmp_path / "out")]) == 1
    line = _error(capsys)
    assert "job.yaml: points_csv[1]: expected a readable UTF-8 CSV file" in line
    assert "more.csv: No such file" in line


def test_point_in_another_zone_names_the_csv_cell(tmp_path, capsys):
    """Point 23 (line 11) moved to zone 6: named by its CSV file, line and column, not by the
    job's ``points``."""

    def control(lines):
        lines[10] = lines[10].replace(",5349632.34,", ",6349632.34,")
        return lines

    path = _job(tmp_path, control=control)
    assert main(["setup", str(path), "-o", str(tmp_path / "out")]) == 1
    line = _error(capsys)
    column = (tmp_path / "control.csv").read_text("utf-8").splitlines()[10].index("634963") + 1
    assert f"control.csv:11:{column}: east_m: expected a point in zone 5" in line
    assert "found point 23 in zone 6" in line


def _no_control_for_the_last_pair(lines):
    """Without the points of models 7 and 8, pair 108-109 images no control point."""
    return [r for r in lines if not re.match(r"(7|8)\d,|K[78],", r)]


def test_a_pair_without_control_is_refused_alone(tmp_path, capsys):
    path = _job(tmp_path, lambda d: d.update(pairs=d["pairs"][5:]),
                control=_no_control_for_the_last_pair)  # fmt: skip
    out = tmp_path / "out"
    assert main(["setup", str(path), "-o", str(out)]) == 0
    assert "2 of 3 pairs set up" in capsys.readouterr().out
    refused = (out / "refused.md").read_text("utf-8")
    assert "**108-109** (photos 108, 109): no control point imaged on both photos" in refused
    assert (out / "107-108" / "sheet.pdf").is_file() and not (
        out / "108-109" / "sheet.pdf"
    ).exists()
    # --strict: the same files, exit 1
    assert main(["setup", str(path), "-o", str(tmp_path / "strict"), "--strict"]) == 1
    assert "expected every pair set up (--strict), found 1 of 3 refused" in _error(capsys)
    assert (tmp_path / "strict" / "refused.md").read_bytes() == refused.encode("utf-8")
    # none set up: exit 1 without --strict, refused.md written
    only = _job(tmp_path, lambda d: d.update(pairs=d["pairs"][7:]),
                control=_no_control_for_the_last_pair, name="only.yaml")  # fmt: skip
    assert main(["setup", str(only), "-o", str(tmp_path / "none")]) == 1
    assert "expected at least one pair set up, found all 1 refused" in _error(capsys)
    assert "108-109" in (tmp_path / "none" / "refused.md").read_text("utf-8")


def _tree(folder: Path) -> set[str]:
    return {str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file()}


def test_output_folder_refused_unless_force_which_replaces_the_outputs(tmp_path, capsys):
    three = _job(tmp_path, lambda d: d.update(pairs=d["pairs"][:2]))
    out = tmp_path / "out"
    assert main(["setup", str(three), "-o", str(out)]) == 0
    first = _tree(out)
    manifest = json.loads((out / "manifest.json").read_text("utf-8"))
    assert set(manifest["files"]) == first - {"manifest.json"}
    assert manifest["job"] == "strip8" and manifest["job_file"] == "job.yaml"
    for name, entry in manifest["files"].items():
        assert entry["bytes"] == (out / name).stat().st_size
    (out / "notes.txt").write_text("the operator's notes", "utf-8")
    capsys.readouterr()

    two = _job(tmp_path, lambda d: d.update(pairs=d["pairs"][1:2]), name="two.yaml")
    assert main(["setup", str(two), "-o", str(out)]) == 1
    line = _error(capsys)
    assert f"{out}: -o: expected a new or empty output folder, found {len(first) + 1} files" in line
    assert "the outputs of strip8 (job.yaml)" in line and "--force" in line
    assert _tree(out) == first | {"notes.txt"}  # nothing written

    assert main(["setup", str(two), "-o", str(out), "--force"]) == 0
    said = capsys.readouterr().out
    assert "removed 3 stale files of the previous run: 101-102/sheet.md" in said
    assert "left in place: 1 file(s) no job run wrote" in said
    assert not (out / "101-102").exists()
    after = _tree(out)
    assert {"102-103/sheet.pdf", "102-103/sheet.yaml", "notes.txt"} <= after
    listed = set(json.loads((out / "manifest.json").read_text("utf-8"))["files"])
    assert listed == after - {"manifest.json", "notes.txt"}
    assert json.loads((out / "manifest.json").read_text("utf-8"))["job_file"] == "two.yaml"


def test_force_removes_pair_folders_of_a_run_without_manifest(tmp_path, capsys):
    """A folder written before manifests existed: its pair folders (only sheet.* files) are the
    job's outputs and go; anything else stays."""
    out = tmp_path / "out"
    for name in ("099-100/sheet.yaml", "099-100/sheet.md", "keep/sheet.yaml", "keep/x.txt"):
        (out / name).parent.mkdir(parents=True, exist_ok=True)
        (out / name).write_text("old", "utf-8")
    job = load_job(_job(tmp_path, lambda d: d.update(pairs=d["pairs"][:1])))
    report = write_job(compute_job(job), out, force=True)
    assert report.removed == ("099-100/sheet.md", "099-100/sheet.yaml")
    assert report.kept_foreign == 2 and not (out / "099-100").exists()
    assert (out / "keep" / "x.txt").is_file() and (out / "101-102" / "sheet.pdf").is_file()


@pytest.mark.parametrize("number", ["../101", "a/b", ".hidden", "1\\2"])
def test_photo_number_must_be_usable_as_a_folder_name(tmp_path, capsys, number):
    """A photo number is text, and names the pair's output folder: no path out of -o."""

    def edit(doc):
        doc["photos"][0]["number"] = number
        doc["pairs"][0]["left"] = number

    path = _job(tmp_path, edit)
    assert main(["setup", str(path), "-o", str(tmp_path / "out")]) == 1
    assert "photos[0].number: expected a photo number usable in a folder name" in _error(capsys)
    assert not (tmp_path / "out").exists()
