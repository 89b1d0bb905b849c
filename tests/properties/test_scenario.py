"""Scenario files: loading, validation messages, summary numbers and synthetic measurements."""

from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from conftest import deg, node_paths, um
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from stereoplotter.errors import ConfigError, StereoplotterError
from stereoplotter.geometry.collinearity import object_to_photo
from stereoplotter.io.scenario_file import load_scenario, scenario_from_mapping
from stereoplotter.scenario import summarize_scenario, synthesize_measurements

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
SHIPPED = sorted(SCENARIOS.glob("*.yaml"))


def pair60() -> dict:
    return yaml.safe_load((SCENARIOS / "pair60.yaml").read_text(encoding="utf-8"))


def test_the_required_scenarios_are_shipped():
    names = {p.stem for p in SHIPPED}
    assert {"pair60", "pair80", "mountain60", "book_resection_table7"} <= names


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.stem)
def test_shipped_scenarios_load_and_summarise(path):
    scenario = load_scenario(path)
    summary = summarize_scenario(scenario)
    assert summary["name"] == scenario.name
    for photo in summary["photos"]:
        assert photo["points_imaged"] >= 4


def test_pair_scenarios_match_the_book_setting():
    # §27 (OCR L3956): f = 70 mm, l = 85 mm; 60 % and 80 % overlap
    for name, overlap in (("pair60", 60.0), ("pair80", 80.0)):
        s = load_scenario(SCENARIOS / f"{name}.yaml")
        summary = summarize_scenario(s)
        assert s.camera.focal_length_mm == 70.0
        assert s.camera.fiducials_mm["2"] == (85.0, 0.0)
        # tilts and swings of < 1.1° move the rigorous overlap by a few per cent
        assert summary["base"]["overlap_percent"] == pytest.approx(overlap, abs=3.5)


def test_mountainous_scenario_has_tilts_up_to_3_degrees_and_real_relief():
    s = load_scenario(SCENARIOS / "mountain60.yaml")
    tilts = [abs(v) for p in s.photos for v in (p.exterior.alpha, p.exterior.omega)]
    # up to 3°, but inside the ±3° of the correction mechanisms after the frame rotation
    assert 2.8 * deg < max(tilts) < 3 * deg
    assert summarize_scenario(s)["relief"]["range_over_flying_height"] > 0.25


def test_summary_overlap_and_scale_for_vertical_photos():
    # Independent: for vertical photos over flat ground overlap = 1 − B/(format·M),
    # M = H·1000/f.
    d = pair60()
    for p in d["photos"]:
        p["exterior"].update(alpha_deg=0.0, omega_deg=0.0, kappa_deg=0.0, Y_m=0.0, Z_m=1550.0)
    d["terrain"] = {"base_height_m": 150.0}
    summary = summarize_scenario(scenario_from_mapping(d, "vertical.yaml"))
    scale = 1400.0 * 1000.0 / 70.0
    assert summary["photos"][0]["photo_scale_denominator"] == pytest.approx(scale)
    assert summary["base"]["overlap_percent"] == pytest.approx(
        100 * (1 - 1440.0 / (0.180 * scale)), abs=0.05
    )
    assert summary["base"]["base_to_height"] == pytest.approx(1440.0 / 1400.0, abs=1e-4)


def test_sk42_points_and_local_points_agree():
    # mountain60 gives points 1 and 3 in SK-42; they were computed from local (±1150, ±1900)
    s = load_scenario(SCENARIOS / "mountain60.yaml")
    by_id = {p.id: p for p in s.points}
    assert_allclose(by_id["1"].local_m[:2], [1150.0, 1900.0], atol=0.002)
    assert_allclose(by_id["3"].local_m[:2], [-1150.0, -1900.0], atol=0.002)
    assert_allclose(by_id["1"].local_m[2], s.terrain.height_m(1150.0, 1900.0), atol=0.002)


def test_map_sheet_from_nomenclature_contains_the_model():
    s = load_scenario(SCENARIOS / "pair60.yaml")
    corners = s.map_sheet.corners_sk42_m
    pts = np.array([p.sk42_m[:2] for p in s.points])
    assert np.all((pts[:, 0] > corners[:, 0].min()) & (pts[:, 0] < corners[:, 0].max()))
    assert np.all((pts[:, 1] > corners[:, 1].min()) & (pts[:, 1] < corners[:, 1].max()))


# --- synthetic measurements -------------------------------------------------------------------


def test_noise_free_measurements_are_rigorous_collinearity():
    s = load_scenario(SCENARIOS / "pair60.yaml")
    m = synthesize_measurements(s, np.random.default_rng(0), noise=False)
    pts = np.array([p.local_m for p in s.points])
    for photo in s.photos:
        expected = object_to_photo(pts, photo.exterior.centre, photo.exterior.rotation, 70.0)
        assert_allclose(m.photo(photo.name).points_mm, expected, atol=1e-12)
    assert m.focal_length_corrected_mm == 70.0


def test_measurements_are_reproducible_from_the_seed():
    s = load_scenario(SCENARIOS / "mountain60.yaml")
    a = synthesize_measurements(s, np.random.default_rng(5))
    b = synthesize_measurements(s, np.random.default_rng(5))
    c = synthesize_measurements(s, np.random.default_rng(6))
    assert np.array_equal(a.photos[1].points_mm, b.photos[1].points_mm)
    assert not np.array_equal(a.photos[1].points_mm, c.photos[1].points_mm)


def test_measurement_noise_has_the_configured_sigma():
    # 2n draws of N(0, σ²): the sample σ is within 4/sqrt(2(N−1)) relative (style.md §10)
    d = pair60()
    d["errors"] = {"photo_point_sigma_um": 5.0, "fiducial_sigma_um": 0.0}
    s = scenario_from_mapping(d, "noise.yaml")
    m = synthesize_measurements(s, np.random.default_rng(1), grid_shape=(60, 60))
    residual = np.concatenate([(p.grid_mm - p.grid_true_mm).ravel() for p in m.photos])
    n = residual.size
    assert abs(residual.std() / (5 * um) - 1) < 4 / math.sqrt(2 * (n - 1))


def test_film_deformation_gives_f_prime():
    # Uniform shrinkage of 150 ppm on both photos and axes: f′ = f (1 − 150e-6) (conventions §7)
    d = pair60()
    for p in d["photos"]:
        p["film_deformation_ppm"] = [-150.0, -150.0]
    s = scenario_from_mapping(d, "film.yaml")
    m = synthesize_measurements(s, np.random.default_rng(0), noise=False)
    assert m.focal_length_corrected_mm == pytest.approx(70.0 * (1 - 150e-6), abs=1e-12)
    assert_allclose(m.photos[0].fiducials_mm[1], [85.0 * (1 - 150e-6), 0.0], atol=1e-12)


# --- bad files -----------------------------------------------------------------------------


def _mutate(path: str, value):
    d = pair60()
    node = d
    keys = path.split(".")
    for k in keys[:-1]:
        node = node[int(k)] if isinstance(node, list) else node[k]
    last = keys[-1]
    if value is KeyError:
        del node[last]
    elif isinstance(node, list):
        node[int(last)] = value
    else:
        node[last] = value
    return d


@pytest.mark.parametrize(
    ("path", "value", "message"),
    [
        (
            "camera.focal_length_mm",
            KeyError,
            r"bad\.yaml: camera\.focal_length_mm: expected a value \(the field is required\)",
        ),
        (
            "camera.focal_length_mm",
            "seventy",
            r"camera\.focal_length_mm: expected a number in \(0, 1000\] mm, found the text "
            r"'seventy'",
        ),
        (
            "camera.focal_lenght_mm",
            70.0,
            r"camera\.focal_lenght_mm: expected no such field, found focal_lenght_mm \(allowed "
            r"here: focal_length_mm",
        ),
        (
            "photos.0.exterior.alpha_deg",
            25.0,
            r"photos\[0\]\.exterior\.alpha_deg: expected a number in \[-15, 15\] °, found 25\.0 "
            r"\(near-vertical",
        ),
        (
            "photos.1.exterior.kappa_deg",
            270,
            r"photos\[1\]\.exterior\.kappa_deg: expected a number in \[-180, 180\] °, found 270",
        ),
        (
            "photos.1.name",
            "second",
            r"photos: expected two photos named left and right, in that order, found "
            r"\['left', 'second'\]",
        ),
        (
            "photos.0.exterior.Z_m",
            100.0,
            r"photos\[0\]\.exterior\.Z_m: expected a projection centre above every point",
        ),
        (
            "photos.1.exterior",
            pair60()["photos"][0]["exterior"],
            r"photos\[1\]\.exterior: expected a horizontal base of at least 1 m",
        ),
        (
            "camera.fiducials.coordinates_mm.1",
            [85.0, 0.0],
            r"coordinates_mm\.1: expected mark 1 on the −x side",
        ),
        (
            "frame.origin.east_m",
            352300.0,
            r"frame\.origin\.east_m: expected a number in \[1e\+06, 6\.1e\+07\] m \(conventional",
        ),
        (
            "map_sheet.nomenclature",
            "N-35-145",
            r"map_sheet\.nomenclature: expected a valid SK-42 nomenclature, found N-35-145 "
            r"\(map sheet nomenclature 'N-35-145': 1:100 000 part '145'",
        ),
        (
            "map_sheet.scale",
            25000,
            r"map_sheet\.scale: expected 10000 \(the scale of sheet N-35-14-А-б-3\), found 25000",
        ),
        (
            "errors.photo_point_sigma_um",
            -1.0,
            r"errors\.photo_point_sigma_um: expected a number in \[0, 1000\] µm, found -1\.0",
        ),
        (
            "points.0.role",
            "maybe",
            r"points\[0\]\.role: expected one of control, check, found the text 'maybe'",
        ),
        ("points.1.id", "1", r"points\[1\]\.id: expected a unique point id, found 1"),
        ("seed", -3, r"seed: expected an integer in \[0, 9223372036854775807\], found -3"),
    ],
)
def test_bad_scenario_gives_one_clear_message(path, value, message):
    with pytest.raises(ConfigError, match=message):
        scenario_from_mapping(_mutate(path, value), "bad.yaml")


def test_too_few_control_points_for_the_sheet_fit():
    d = pair60()
    for p in d["points"]:
        if p["id"] in ("2", "3", "4"):
            p["role"] = "check"
    message = (
        r"points: expected at least 2 control points of kind full or plan for the sheet "
        r"fit \(6\.8\), found 1 \(1\)"
    )
    with pytest.raises(ConfigError, match=message):
        scenario_from_mapping(d, "few.yaml")


def test_too_few_control_points_for_a_resection():
    d = yaml.safe_load((SCENARIOS / "book_resection_table7.yaml").read_text(encoding="utf-8"))
    d["points"] = d["points"][:2]
    with pytest.raises(
        ConfigError,
        match=r"photos\[0\]\.exterior\.source: expected at least 3 "
        r"full control points imaged on photo 'single'",
    ):
        scenario_from_mapping(d, "t7.yaml")


def test_sk42_point_in_a_local_frame_is_refused():
    d = yaml.safe_load((SCENARIOS / "book_resection_table7.yaml").read_text(encoding="utf-8"))
    d["points"][0] = {"id": "1", "sk42": {"north_m": 1.0, "east_m": 4.5e6, "height_m": 0.0}}
    with pytest.raises(ConfigError, match=r"points\[0\]\.sk42: expected local coordinates"):
        scenario_from_mapping(d, "t7.yaml")


def test_file_errors(tmp_path):
    with pytest.raises(ConfigError, match=r"nope\.yaml: \(file\): expected an existing file"):
        load_scenario(tmp_path / "nope.yaml")
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: [unclosed\n", encoding="utf-8")
    with pytest.raises(
        ConfigError,
        match=r"bad\.yaml: \(file\): expected valid YAML, found .*"
        r"line 2",
    ):
        load_scenario(bad)
    bad.write_text("- a list\n", encoding="utf-8")
    with pytest.raises(
        ConfigError,
        match=r"\(top level\): expected a mapping of fields, found "
        r"list",
    ):
        load_scenario(bad)


# --- fuzzing: a mutated file never produces anything but a ConfigError -------------------------

_LEAVES = node_paths(pair60())
_JUNK = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(10**7), 10**7),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
    st.lists(st.floats(-1e3, 1e3), max_size=4),
    st.dictionaries(st.text(max_size=4), st.integers(), max_size=2),
)


@given(st.sampled_from(_LEAVES), _JUNK)
def test_fuzzed_scenarios_fail_cleanly(path, junk):
    d = copy.deepcopy(pair60())
    node = d
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = junk
    try:
        scenario_from_mapping(d, "fuzz.yaml")
    except StereoplotterError as exc:
        assert str(exc).startswith("fuzz.yaml: ")
