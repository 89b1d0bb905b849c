"""`block synth` → `triangulate` → setup: the chain from comparator to forms, against the truth.

The forms themselves (PDF) are `stereoplotter setup`'s, tested with jobs/strip8 in
tests/cli/test_job.py; here the sheets of the triangulated job are computed in process.
"""

from __future__ import annotations

import csv
import dataclasses
import shutil

import numpy as np
import pytest

from stereoplotter.cli import main
from stereoplotter.commands.triangulation_chain import chain_comparison
from stereoplotter.io.block_measurements_file import (
    load_block_measurements,
    write_block_measurements,
)
from stereoplotter.io.job_file import load_job
from stereoplotter.triangulation.bundle import bundle_block
from stereoplotter.triangulation.synth import SynthSpec, synthesize_block


@pytest.fixture(scope="module")
def chain(tmp_path_factory):
    root = tmp_path_factory.mktemp("chain")
    argv = [
        "block",
        "synth",
        "-o",
        str(root / "block"),
        "--strips",
        "2",
        "--photos",
        "5",
        "--control-every",
        "2",
        "--seed",
        "5",
    ]
    assert main(argv) == 0
    assert main(["triangulate", str(root / "block" / "block.yaml"), "-o", str(root / "tri")]) == 0
    return root


def test_triangulate_writes_orientations_residuals_report_and_job(chain):
    names = {p.name for p in (chain / "tri").iterdir()}
    assert {
        "orientations.csv",
        "residuals.csv",
        "report.md",
        "residuals.png",
        "job.yaml",
        "fiducials.csv",
        "control_points.csv",
        "points.csv",
        "flagged.csv",
        "observations.csv",
        "catalogue_observations.csv",
        "photo_residuals.png",
        "precision.png",
    } <= names
    with open(chain / "tri" / "orientations.csv", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert [r["photo"] for r in rows[:2]] == ["101", "102"] and len(rows) == 10
    assert all(float(r["s_X_m"]) > 0 for r in rows)


def test_forms_agree_with_forms_of_the_true_orientations_within_the_propagated_sigma(chain):
    # 12 sheet values × 8 pairs: |Δ| ≤ 4σ for all (Bonferroni over ~100 comparisons at 1 %)
    block, _ = load_block_measurements(chain / "block" / "block.yaml")
    rows = chain_comparison(
        chain / "tri" / "job.yaml",
        chain / "block" / "truth" / "job.yaml",
        block,
        bundle_block(block),
    )
    compared = [r for r in rows if r.sigma > 1e-9]
    assert len({r.pair for r in rows}) == 8 and len(compared) >= 8 * 10
    worst = max(compared, key=lambda r: r.ratio)
    assert worst.ratio <= 4.0, worst


def test_strip_method_runs_from_the_command_line(chain, tmp_path):
    argv = [
        "triangulate",
        str(chain / "block" / "block.yaml"),
        "--method",
        "strip",
        "--degree",
        "2",
        "-o",
        str(tmp_path),
    ]
    assert main(argv) == 0
    assert "strip" in (tmp_path / "report.md").read_text(encoding="utf-8")


def test_a_degree_the_control_cannot_fix_is_refused(chain, tmp_path, capsys):
    # control at bases 0, 2, 4 of each strip: three stations fix a quadratic, not a cubic
    argv = [
        "triangulate",
        str(chain / "block" / "block.yaml"),
        "--method",
        "strip",
        "--degree",
        "3",
        "-o",
        str(tmp_path),
    ]
    assert main(argv) == 1
    assert "height control at 3 stations" in capsys.readouterr().err


def test_bad_block_file_is_one_error_line(tmp_path, capsys):
    bad = tmp_path / "block.yaml"
    bad.write_text("format: stereoplotter-block-measurements/1\nname: x\n", encoding="utf-8")
    assert main(["triangulate", str(bad), "-o", str(tmp_path / "out")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"error: {bad}: ")


def test_leading_zero_photo_numbers_pass_through_to_the_job(chain, tmp_path):
    """Photo numbers are text in the job: a block whose photo 101 is numbered 0101
    gives a job whose photo and pair keep 0101 (the job format took integers and the writer
    refused it)."""

    block = tmp_path / "block"
    shutil.copytree(chain / "block", block)
    text = (block / "block.yaml").read_text(encoding="utf-8")
    assert '["101",' in text
    (block / "block.yaml").write_text(text.replace('["101",', '["0101",', 1), encoding="utf-8")
    rows = (block / "measurements.csv").read_text(encoding="utf-8")
    (block / "measurements.csv").write_text(rows.replace("\n101,", "\n0101,"), encoding="utf-8")
    assert main(["triangulate", str(block / "block.yaml"), "-o", str(tmp_path / "tri")]) == 0
    job = load_job(tmp_path / "tri" / "job.yaml")
    assert next(iter(job.photos)) == "0101" and "101" not in job.photos
    assert job.pairs[0].name == "0101-102"


def test_outputs_hold_no_nan_and_name_a_point_of_one_photo_not_intersected(chain, tmp_path):
    # the polygon report's σ₀ is a number; a check point on one photo is "not intersected"
    for method in ("bundle", "polygon"):
        out = tmp_path / method
        argv = ["triangulate", str(chain / "block" / "block.yaml"), "--method", method]
        assert main([*argv, "-o", str(out)]) == 0
        for name in ("report.md", "residuals.csv", "points.csv", "orientations.csv"):
            assert "nan" not in (out / name).read_text(encoding="utf-8").lower(), (method, name)
        with open(out / "residuals.csv", encoding="utf-8") as f:
            rows = list(csv.DictReader(f))
        single = [r for r in rows if r["rays"] == "1"]
        assert single and all(r["note"].startswith("not intersected") for r in single)
    assert "σ₀ = 1." in (tmp_path / "polygon" / "report.md").read_text(encoding="utf-8")


def test_points_csv_gives_every_point_with_its_sigma(chain):
    with open(chain / "tri" / "points.csv", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    roles = {r["role"] for r in rows}
    assert roles == {"tie", "control", "check"} or roles == {"control", "check"}
    fixed = [r for r in rows if r["X_m"]]
    assert fixed and all(float(r["s_Z_m"]) > 0 for r in fixed)


def test_self_calibration_from_the_command_line(chain, tmp_path, capsys):
    argv = ["triangulate", str(chain / "block" / "block.yaml"), "-o", str(tmp_path)]
    assert main([*argv, "--self-calibrate", "f,x0,y0,k1"]) == 0
    text = (tmp_path / "report.md").read_text(encoding="utf-8")
    assert "## Self-calibration of the camera" in text and "| k1 [mm⁻²] |" in text
    f_row = next(line for line in text.splitlines() if line.startswith("| f [mm] |"))
    adjusted = float(f_row.split("|")[3])
    job = load_job(tmp_path / "job.yaml")  # the job carries the adjusted f
    assert job.camera.focal_length_mm == pytest.approx(adjusted, abs=5e-6 * adjusted)
    assert job.camera.focal_length_mm != 70.0
    assert main([*argv, "--self-calibrate", "f,z9"]) == 1
    assert "--self-calibrate" in capsys.readouterr().err


def test_reject_from_the_command_line_names_the_blunders_in_flagged_csv(tmp_path):
    block, _ = synthesize_block(SynthSpec(strips=3, photos_per_strip=6), np.random.default_rng(4))
    rays = np.bincount(block.obs_point)
    o = int(np.flatnonzero(rays[block.obs_point] == 3)[4])
    comparator = block.comparator_mm.copy()
    comparator[o, 1] += 0.5
    cat = list(block.catalogue)
    k = next(i for i, c in enumerate(cat) if c.role == "control" and c.kind == "height")
    north, east, h = cat[k].sk42_m
    cat[k] = dataclasses.replace(cat[k], sk42_m=(north, east, h + 2.0))
    bad = dataclasses.replace(block, comparator_mm=comparator, catalogue=tuple(cat))
    write_block_measurements(tmp_path / "b", bad)
    assert main(["triangulate", str(tmp_path / "b" / "block.yaml"), "-o", str(tmp_path / "t"),
                 "--reject"]) == 0  # fmt: skip
    with open(tmp_path / "t" / "flagged.csv", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    got = {(r["photo"], r["point"], r["observation"]) for r in rows}
    photo, point = block.photos[block.obs_photo[o]], block.point_ids[block.obs_point[o]]
    assert got == {(photo, point, "y_mm"), ("", cat[k].id, "height_m")}
    assert all(abs(float(r["w"])) > 4 and float(r["mdb"]) > 0 for r in rows)
    assert "removed and the block readjusted" in (tmp_path / "t" / "report.md").read_text("utf-8")
