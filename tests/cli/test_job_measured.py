"""The measured inputs of a job's pairs computed together (``measured_pairs``: the geodesy of
every pair's frame in one call) are each pair's own (``measured_pair``), to the bit."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
import yaml

from stereoplotter.io.job_file import load_job, measured_pair, measured_pairs
from stereoplotter.setup.records import SetupRefusal

ROOT = Path(__file__).resolve().parents[2]
STRIP8 = ROOT / "jobs" / "strip8" / "job.yaml"
TRUTH = ROOT / "jobs" / "block3x6" / "truth" / "job.yaml"


def _strip8_with(tmp_path: Path, edit) -> Path:
    doc = yaml.safe_load(STRIP8.read_text("utf-8"))
    for name in ("fiducials.csv", "control.csv"):
        (tmp_path / name).write_text((STRIP8.parent / name).read_text("utf-8"), "utf-8")
    edit(doc)
    path = tmp_path / "job.yaml"
    path.write_text(yaml.safe_dump(doc, allow_unicode=True), "utf-8")
    return path


def _same(a, b) -> None:
    """Equal field by field, arrays and floats to the bit."""
    assert type(a) is type(b)
    if isinstance(a, SetupRefusal):
        assert str(a) == str(b)
        return
    for field in dataclasses.fields(a):
        x, y = getattr(a, field.name), getattr(b, field.name)
        if isinstance(x, np.ndarray):
            assert x.dtype == y.dtype and x.shape == y.shape
            assert x.tobytes() == y.tobytes(), field.name
        else:
            assert x == y, field.name


def _alone(job, pair):
    try:
        return measured_pair(job, pair)
    except SetupRefusal as exc:
        return exc


def _far_photo(doc):
    """Photo 109 far north of its neighbour: pair 108-109 has no control on both photos."""
    doc["photos"][-1]["north_m"] += 30000.0


@pytest.mark.parametrize(
    "job_path",
    [lambda tmp: STRIP8, lambda tmp: TRUTH, lambda tmp: _strip8_with(tmp, _far_photo)],
    ids=["strip8 (SK-42)", "block3x6 truth (local)", "strip8 with a refused pair"],
)
def test_pairs_together_equal_each_pair_alone(tmp_path, job_path):
    job = load_job(job_path(tmp_path))
    together = measured_pairs(job)
    assert len(together) == len(job.pairs)
    for pair, got in zip(job.pairs, together, strict=True):
        _same(got, _alone(job, pair))


def test_a_pair_beyond_its_zone_gives_the_error_of_that_pair(tmp_path):
    job = load_job(_strip8_with(tmp_path, lambda d: d["photos"][2].update(east_m=5884000.0)))
    with pytest.raises(Exception) as alone:
        measured_pair(job, job.pairs[1])
    with pytest.raises(Exception) as together:
        measured_pairs(job)
    assert "pair 102-103" in str(alone.value)
    assert str(together.value) == str(alone.value)
