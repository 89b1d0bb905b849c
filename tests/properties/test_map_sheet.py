"""SK-42 map-sheet nomenclature → sheet frame."""

from __future__ import annotations

import pytest

from stereoplotter.errors import StereoplotterError
from stereoplotter.geodesy.map_sheet import sheet_bounds, zone_of_longitude


def minutes(deg):
    return round(deg * 60.0, 6)


def test_moscow_sheets():
    # Moscow (55°45′ N, 37°37′ E) lies on the 1:1 000 000 sheet N-37 (52–56° N, 36–42° E) and on
    # the 1:100 000 sheet N-37-4, the classic textbook example.
    b = sheet_bounds("N-37")
    assert (b.south_deg, b.north_deg, b.west_deg, b.east_deg, b.zone) == (52, 56, 36, 42, 7)
    b = sheet_bounds("N-37-4")
    assert (minutes(b.south_deg), minutes(b.north_deg)) == (55 * 60 + 40, 56 * 60)
    assert (minutes(b.west_deg), minutes(b.east_deg)) == (37 * 60 + 30, 38 * 60)


@pytest.mark.parametrize(
    ("name", "scale", "height_min", "width_min"),
    [
        ("N-37-Б", 500_000, 120, 180),
        ("N-37-XXIV", 200_000, 40, 60),
        ("N-37-4", 100_000, 20, 30),
        ("N-37-4-А", 50_000, 10, 15),
        ("N-37-4-А-б", 25_000, 5, 7.5),
        ("N-37-4-А-б-3", 10_000, 2.5, 3.75),
        ("N-37-4-(256)", 5_000, 1.25, 1.875),
        ("N-37-4-(256-и)", 2_000, 25 / 60, 37.5 / 60),
        ("N-37-4-A-b-3", 10_000, 2.5, 3.75),  # Latin transliteration
    ],
)
def test_sheet_sizes(name, scale, height_min, width_min):
    b = sheet_bounds(name)
    assert b.scale_denominator == scale
    assert minutes(b.north_deg - b.south_deg) == pytest.approx(height_min, abs=1e-6)
    assert minutes(b.east_deg - b.west_deg) == pytest.approx(width_min, abs=1e-6)


def test_quarters_are_nw_ne_sw_se_and_numbers_row_major():
    parent = sheet_bounds("N-37-4")
    a, g = sheet_bounds("N-37-4-А"), sheet_bounds("N-37-4-Г")
    assert (a.north_deg, a.west_deg) == (parent.north_deg, parent.west_deg)
    assert (g.south_deg, g.east_deg) == (parent.south_deg, parent.east_deg)
    last = sheet_bounds("N-37-4-(256-и)")
    assert last.south_deg == pytest.approx(parent.south_deg)
    assert last.east_deg == pytest.approx(parent.east_deg)
    assert sheet_bounds("N-37-13").north_deg == sheet_bounds("N-37-1").south_deg


def test_zones():
    assert zone_of_longitude(37.6) == 7
    assert sheet_bounds("K-38").zone == 8
    assert sheet_bounds("N-30").zone == 60  # 6° W – 0°


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("Z-37", "latitude band 'Z' is not a letter A–V"),
        ("N-61", "column 61 is outside 1–60"),
        ("N-37-145", "1:100 000 part '145' is not a number 1–144"),
        ("N-37-4-Д", "'Д' is not one of"),
        ("N-37-4-(300)", "1:5 000 part must be"),
        ("N-37-4-А-б-5", "1:10 000 part '5' is not one of 1/2/3/4"),
        ("N", "too few parts"),
    ],
)
def test_bad_nomenclature(name, message):
    with pytest.raises(StereoplotterError, match=message):
        sheet_bounds(name)
