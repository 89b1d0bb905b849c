"""block.yaml and the triangulated job.yaml through the safe YAML emitter: a name with
YAML syntax and a photo number with a leading zero read back as the same text."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from stereoplotter.io.block_measurements_file import (
    load_block_measurements,
    production_data,
    write_block_measurements,
)
from stereoplotter.io.job_file import load_job
from stereoplotter.io.triangulated_job import write_triangulated_job

ROOT = Path(__file__).resolve().parents[2]
BLOCK = ROOT / "jobs" / "block3x6"
NAME = "a: b #c"


def _renamed_block():
    """jobs/block3x6 named ``a: b #c`` with photo 101 renumbered ``012417`` (its readings too)."""
    block, production = load_block_measurements(BLOCK / "block.yaml")
    strips = tuple(tuple("012417" if p == "101" else p for p in s) for s in block.strips)
    return replace(block, name=NAME, strips=strips), production


def test_block_file_keeps_a_name_with_yaml_syntax_and_a_leading_zero(tmp_path: Path) -> None:
    block, production = _renamed_block()
    sheets = [m.nomenclature for m in production.map_sheets]
    write_block_measurements(
        tmp_path, block, description="x: y # not a comment",
        production=production_data("sc1", production.date, sheets),
    )  # fmt: skip
    back, back_production = load_block_measurements(tmp_path / "block.yaml")
    assert back.name == NAME
    assert back.strips == block.strips and back.strips[0][0] == "012417"
    assert [m.nomenclature for m in back_production.map_sheets] == sheets
    assert back_production.date == production.date
    np.testing.assert_array_equal(back.fiducials_mm, block.fiducials_mm)


def test_triangulated_job_keeps_the_name_and_the_photo_number(tmp_path: Path) -> None:
    block, production = _renamed_block()
    truth = np.loadtxt(BLOCK / "truth.csv", delimiter=",", skiprows=1, usecols=range(1, 7))
    orientations = np.column_stack([np.radians(truth[:, :3]), truth[:, 3:]])
    write_triangulated_job(
        tmp_path, block, production, orientations, source="b: c.yaml", description="d: e #f"
    )
    job = load_job(tmp_path / "job.yaml")
    assert job.name == NAME
    assert "012417" in job.photos and "101" not in job.photos
    assert (job.pairs[0].left, job.pairs[0].right) == ("012417", "102")
    assert job.photos["012417"].number == "012417"
    # centres written to 1 mm, as before
    np.testing.assert_allclose(job.photos["102"].centre, truth[1, 3:], atol=5e-4)
