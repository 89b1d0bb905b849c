"""The block measurements file: round trip, text identifiers, one-line errors."""

from __future__ import annotations

import numpy as np
import pytest
from synthetic_blocks import exact_block

from stereoplotter.errors import ConfigError
from stereoplotter.io.block_measurements_file import (
    load_block_measurements,
    write_block_measurements,
)


@pytest.fixture
def folder(tmp_path):
    block, _ = exact_block()
    write_block_measurements(tmp_path, block)
    return tmp_path


def test_round_trip_keeps_the_block(folder):
    block, _ = exact_block()
    loaded, production = load_block_measurements(folder / "block.yaml")
    assert production is None
    assert loaded.strips == block.strips
    assert [loaded.point_ids[i] for i in loaded.obs_point] == [
        block.point_ids[i] for i in block.obs_point[np.lexsort((block.obs_point, block.obs_photo))]
    ]
    np.testing.assert_allclose(loaded.fiducials_mm, block.fiducials_mm, atol=5e-5)  # 0.1 µm
    assert [c.id for c in loaded.catalogue] == [c.id for c in block.catalogue]


def _edit(path, old, new):
    text = path.read_text(encoding="utf-8")
    assert old in text
    path.write_text(text.replace(old, new, 1), encoding="utf-8")


def test_photo_numbers_are_text(folder):
    # "0101" and "101" are two photos: rename photo 101 everywhere to 0101
    _edit(folder / "block.yaml", '["101",', '["0101",')
    text = (folder / "measurements.csv").read_text(encoding="utf-8")
    (folder / "measurements.csv").write_text(text.replace("\n101,", "\n0101,"), encoding="utf-8")
    block, _ = load_block_measurements(folder / "block.yaml")
    assert block.photos[0] == "0101" and "101" not in block.photos


@pytest.mark.parametrize(
    ("file", "old", "new", "message"),
    [
        ("block.yaml", '["101",', "[101,", r"block\.yaml: strips.*quoted text"),
        (
            "measurements.csv",
            ",fiducial,",
            ",fiducal,",
            r"measurements\.csv:2: kind: expected one of",
        ),
        (
            "measurements.csv",
            "101,1,fiducial,",
            "101,1,fiducial,x",
            r"measurements\.csv:2: x_mm: expected a number",
        ),
        (
            "measurements.csv",
            "101,1,fiducial,",
            "999,1,fiducial,",
            r"measurements\.csv:2: photo: expected a photo number",
        ),
        ("control.csv", ",control,", ",kontrol,", r"control\.csv:\d+: role: expected one of"),
        (
            "block.yaml",
            "photo_mm: 1.0e-09",
            "photo_mm: -1",
            r"block\.yaml: sigma\.photo_mm: expected",
        ),
    ],
)
def test_bad_input_is_one_line_naming_file_and_field(folder, file, old, new, message):
    _edit(folder / file, old, new)
    with pytest.raises(ConfigError, match=message) as info:
        load_block_measurements(folder / "block.yaml")
    assert "\n" not in str(info.value)


def test_a_missing_fiducial_mark_is_named(folder):
    lines = (folder / "measurements.csv").read_text(encoding="utf-8").splitlines()
    (folder / "measurements.csv").write_text(
        "\n".join(line for line in lines if not line.startswith("102,3,fiducial")) + "\n",
        encoding="utf-8",
    )
    with pytest.raises(ConfigError, match=r"fiducial marks of photo 102.*no mark 3"):
        load_block_measurements(folder / "block.yaml")
