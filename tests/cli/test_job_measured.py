"""The measured inputs of a job's pairs computed together (``measured_pairs``: the geodesy of
every pair's frame in one call) are each pair's own (``measured_pair``), to the bit; the records
a job builds when they are read are the sheets computed at once, and its refusals theirs."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
import yaml

from stereoplotter.commands.setup_job import compute_job
from stereoplotter.io.job_file import load_job
from stereoplotter.io.job_measured import measured_pair, measured_pairs
from stereoplotter.setup.records import SetupOptions, SetupRefusal
from stereoplotter.setup.sheet import compute_sheets_from_measurements

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


def _same_record(a, b, where="sheet") -> None:
    """Equal as records: dataclasses field by field, mappings and sequences item by item,
    arrays and floats to the bit (Table 24's block object aside: its columns are the block's)."""
    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        assert type(a) is type(b), where
        for field in dataclasses.fields(a):
            if field.name != "table24":
                x, y = getattr(a, field.name), getattr(b, field.name)
                _same_record(x, y, f"{where}.{field.name}")
    elif isinstance(a, dict):
        assert list(a) == list(b), where
        for key in a:
            _same_record(a[key], b[key], f"{where}[{key!r}]")
    elif isinstance(a, list | tuple):
        assert type(a) is type(b) and len(a) == len(b), where
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            _same_record(x, y, f"{where}[{k}]")
    elif isinstance(a, np.ndarray):
        assert a.shape == b.shape and a.tobytes() == b.tobytes(), where
    else:
        assert type(a) is type(b) and (a == b or (a != a and b != b)), where


def _tilted_and_off_scale(doc):
    """Photo 105 tilted 4° (a pair beyond the instrument's tilt), photo 109 far north (a pair
    without control)."""
    doc["photos"][4]["alpha_deg"] = 4.0
    doc["photos"][-1]["north_m"] += 30000.0


def test_job_records_built_when_read_equal_the_sheets_computed_at_once(tmp_path):
    job = load_job(_strip8_with(tmp_path, _tilted_and_off_scale))
    result = compute_job(job)
    measured = measured_pairs(job)
    ready = [m for m in measured if not isinstance(m, SetupRefusal)]
    options = SetupOptions(
        book_sign_n_right=job.book_sign,
        horizontal_scale_denominator=job.horizontal_scale,
        vertical_scale_denominator=job.vertical_scale,
        bz_scale_sense=job.bz_scale_sense,
    )
    at_once = iter(compute_sheets_from_measurements(
        [m.sheet_arguments() for m in ready], spec=result.spec, options=options,
        source=job.source, name=job.name,
    ))  # fmt: skip
    reasons = []
    for p, m in zip(result.pairs, measured, strict=True):
        if isinstance(m, SetupRefusal):
            assert not p.accepted and p.sheet is None and p.reason == str(m)
            continue
        expected = next(at_once)
        if isinstance(expected, SetupRefusal):
            assert not p.accepted and p.sheet is None and p.reason == str(expected)
            reasons.append(p.pair.name)
            continue
        assert p.accepted and p.reason == ""
        _same_record(p.sheet, expected)
        assert p.sheet is p.sheet  # built once
    assert reasons  # the tilted photo's pairs are refused by the block's checks
