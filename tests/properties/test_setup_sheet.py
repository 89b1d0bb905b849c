"""The setup sheet (Table 24) and the `stereoplotter setup` command."""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from conftest import node_paths, value_at
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from stereoplotter.cli import main
from stereoplotter.errors import StereoplotterError
from stereoplotter.geometry.rotation import rotation_z
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario, scenario_from_mapping
from stereoplotter.report.sheet import sheet_markdown, sheet_to_dict
from stereoplotter.scenario.frame import local_from_sk42
from stereoplotter.setup.sheet import SetupOptions, SetupRefusal, compute_setup_sheet

ROOT = Path(__file__).resolve().parents[2]
SCENARIOS = ROOT / "scenarios"
PAIRS = ("pair60", "pair80", "mountain60")
INSTRUMENTS = ("sc1", "spr3", "sd3")


def _doc(name: str) -> dict:
    return yaml.safe_load((SCENARIOS / f"{name}.yaml").read_text(encoding="utf-8"))


def _noise_free(name: str) -> dict:
    d = _doc(name)
    d["errors"] = {"photo_point_sigma_um": 0.0, "fiducial_sigma_um": 0.0}
    return d


@pytest.mark.parametrize("instrument", INSTRUMENTS)
@pytest.mark.parametrize("name", PAIRS)
def test_every_shipped_pair_gets_a_sheet_on_every_instrument(name, instrument):
    # docs/setup-data.md lists the outcome; today every pair fits every instrument.
    sheet = compute_setup_sheet(
        load_scenario(SCENARIOS / f"{name}.yaml"), load_instrument(instrument)
    )
    spec = load_instrument(instrument)
    lo, hi = spec.projection_distance_range_mm
    assert lo <= sheet.depth_range_used_mm[0] <= sheet.depth_range_used_mm[1] <= hi
    assert sheet.n_left == pytest.approx(spec.projection_distance_max_mm / sheet.f_instrument_mm)
    d = sheet_to_dict(sheet)
    for key in (
        "n_left",
        "n_right",
        "f_instrument_mm",
        "scale_horizontal",
        "scale_vertical",
        "base_mm",
        "fiducials_transformed_mm",
        "L_mm",
        "control_heights_model_mm",
        "sheet_corners_mm",
        "similarity",
    ):
        assert key in d
    assert set(d["fiducials_transformed_mm"]["left"]) == {"x2", "y3", "y4"}
    assert set(d["fiducials_transformed_mm"]["right"]) == {"x1", "y3", "y4"}


def test_noise_free_sheet_matches_the_truth():
    s = scenario_from_mapping(_noise_free("pair60"), "pair60.yaml")
    sheet = compute_setup_sheet(s, load_instrument("sc1"))
    mg, mv = sheet.horizontal_scale_denominator, sheet.vertical_scale_denominator
    left, right = (p.exterior for p in s.photos)
    b = right.centre - left.centre
    horizontal = math.hypot(b[0], b[1])
    assert sheet.focal_length_corrected_mm == 70.0
    assert_allclose(sheet.base_mm, [horizontal * 1000 / mg, 0.0, b[2] * 1000 / mv], atol=1e-12)
    assert sheet.f_instrument_mm == pytest.approx(70.0 * mg / mv, abs=1e-12)
    # n_п = (D_max + b_z′)/f_пр: the right rod is b_z′ deeper (kinematics.md §3.5)
    assert sheet.n_right == pytest.approx((185.0 + sheet.base_mm[2]) / sheet.f_instrument_mm)
    # The frame turns the base onto +X: the turned EO angles, rebuilt, equal R_Z(−θ)·M
    theta = math.atan2(b[1], b[0])
    assert sheet.frame_rotation == pytest.approx(theta)
    from stereoplotter.geometry.rotation import rotation_matrix

    p = sheet.photos[0]
    assert_allclose(
        rotation_matrix(p.alpha, p.omega, p.kappa), rotation_z(-theta) @ left.rotation, atol=1e-14
    )


def test_sheet_corners_agree_with_the_rigorous_geodesy():
    # Independent: each corner, taken through the rigorous SK-42 → local transform (pyproj and
    # the §9 chain) and the same frame turn, scaled 1:M_г, lands on the sheet's x′, y′ to within
    # the similarity's residual (~7 mm on the ground = 0.0006 mm in the model).
    s = scenario_from_mapping(_noise_free("pair60"), "pair60.yaml")
    sheet = compute_setup_sheet(s, load_instrument("sc1"))
    origin = np.array(sheet.frame_origin_m)
    turn = rotation_z(-sheet.frame_rotation)
    for corner in sheet.corners:
        height = float(np.mean([p.local_m[2] for p in s.points]))
        local = np.array(
            local_from_sk42(s.frame, (corner["gk_north_m"], corner["gk_east_m"], height))
        )
        model = (turn @ (local - origin))[:2] * 1000 / sheet.horizontal_scale_denominator
        assert_allclose([corner["x_mm"], corner["y_mm"]], model, atol=0.002)
        assert_allclose(
            [corner["x_book_form_mm"], corner["y_book_form_mm"]],
            [corner["x_mm"], corner["y_mm"]],
            atol=1e-9,
        )


def test_book_sign_option_of_6_4():
    s = load_scenario(SCENARIOS / "pair60.yaml")  # right station 10 m higher
    default = compute_setup_sheet(s, load_instrument("sc1"))
    book = compute_setup_sheet(s, load_instrument("sc1"), SetupOptions(book_sign_n_right=True))
    assert default.n_right > default.n_left > book.n_right
    assert default.n_right - default.n_left == pytest.approx(default.n_left - book.n_right)


def test_readings_are_zero_reading_plus_signed_value():
    sheet = compute_setup_sheet(load_scenario(SCENARIOS / "pair60.yaml"), load_instrument("sc1"))
    rows = {r["reading"]: r for r in sheet.readings}
    left, right = sheet.photos
    assert rows["O_Y3,л"]["value"] == pytest.approx(sheet.n_left * left.transformed_book_mm["y3"])
    assert rows["O_Y4,л"]["value"] < 0  # mark 4 is on −y: the book's MO_Y − |…|
    assert rows["O_X1,п"]["zero_reading"] == "MO_X,п"
    assert rows["O_X1,п"]["value"] == pytest.approx(sheet.n_right * right.transformed_book_mm["x1"])
    assert rows["O_bz"]["value"] == pytest.approx(sheet.base_mm[2])
    assert rows["L_л"]["tolerance"] == pytest.approx(0.03 / sheet.n_left)
    assert rows["O_Y4,л"]["tolerance"] == pytest.approx(0.02 * sheet.n_left)
    assert rows["corner 4: O_X"]["tolerance"] == 0.3
    assert [r["stage"] for r in sheet.readings] == sorted(r["stage"] for r in sheet.readings)


def test_assumed_flags():
    sheet = compute_setup_sheet(load_scenario(SCENARIOS / "pair60.yaml"), load_instrument("sc1"))
    assert "gears.vertical_scale_denominators" in sheet.assumed["scale_vertical"]
    # D_max of SC-1 is documented (OCR L3715): n_л rests only on the assumed gears/ranges
    assert "projection.distance_max_mm" not in sheet.assumed["n_left"]
    text = sheet_markdown(sheet)
    assert "**(assumed)**" in text and "gears.coordinatograph_ratios" in text


def test_forced_scale_outside_a_range_is_refused_with_the_way_out():
    s = load_scenario(SCENARIOS / "pair60.yaml")
    with pytest.raises(
        SetupRefusal,
        match=r"cannot take this stereopair: none of the 1 scale "
        r"pairs .* Way out: another instrument",
    ):
        compute_setup_sheet(
            s,
            load_instrument("sc1"),
            SetupOptions(horizontal_scale_denominator=5000, vertical_scale_denominator=8000),
        )


def test_tilt_beyond_the_correction_range_is_refused():
    d = _doc("pair60")
    d["photos"][0]["exterior"]["omega_deg"] = -4.0
    s = scenario_from_mapping(d, "tilted.yaml")
    with pytest.raises(
        StereoplotterError,
        match=r"ω_left = -4\.0\d+° is beyond the assumed "
        r"correction range ±3° of .*sc1\.yaml",
    ):
        compute_setup_sheet(s, load_instrument("sc1"))


def test_single_photo_is_refused():
    s = load_scenario(SCENARIOS / "book_resection_table7.yaml")
    with pytest.raises(SetupRefusal, match="is not a stereopair"):
        compute_setup_sheet(s, load_instrument("sc1"))


def test_cli_setup_writes_four_files_reproducibly(tmp_path, capsys):
    a, b = tmp_path / "a", tmp_path / "b"
    for out in (a, b):
        assert (
            main(["setup", str(SCENARIOS / "pair60.yaml"), "--instrument", "sc1", "-o", str(out)])
            == 0
        )
    assert "written: sheet.yaml" in capsys.readouterr().out
    for name in ("sheet.yaml", "sheet.md", "sheet.pdf", "sheet.png"):
        assert (a / name).read_bytes() == (b / name).read_bytes(), name
    data = yaml.safe_load((a / "sheet.yaml").read_text(encoding="utf-8"))
    assert data["scale_horizontal"] == 12500
    assert data["annotations"]["n_left"]["equation"] == "(6.3)"


def test_cli_setup_json_and_refusal(tmp_path, capsys):
    assert main(["setup", str(SCENARIOS / "pair80.yaml"), "--instrument", "sd3", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert set(data["base_mm"]) == {"bx", "by", "bz"}
    assert not list(tmp_path.iterdir())
    assert (
        main(
            [
                "setup",
                str(SCENARIOS / "pair60.yaml"),
                "--instrument",
                "sc1",
                "--horizontal-scale",
                "5000",
                "-o",
                str(tmp_path / "x"),
            ]
        )
        == 1
    )
    err = capsys.readouterr().err
    assert err.startswith("error: instrument sc1 cannot take this stereopair")
    assert not (tmp_path / "x").exists()  # nothing written on refusal
    assert main(["setup", str(SCENARIOS / "pair60.yaml"), "--instrument", "nope"]) == 1
    assert "error:" in capsys.readouterr().err


def test_cli_instrument_show(capsys):
    assert main(["instrument", "show", "sc1"]) == 0
    text = capsys.readouterr().out
    assert "185" in text and "ASSUMED" in text
    assert main(["instrument", "show", "spr3", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)


# --- fuzz: odd but valid scenarios never give anything but a StereoplotterError ----------------

_BASE = _noise_free("pair60")
_NUMERIC = [
    p
    for p in node_paths(_BASE)
    if isinstance(value_at(_BASE, p), int | float) and not isinstance(value_at(_BASE, p), bool)
]


@settings(max_examples=40, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.sampled_from(_NUMERIC), st.sampled_from([-1.0, 0.0, 0.5, 0.9, 1.1, 2.0, 10.0])
        ),
        min_size=1,
        max_size=3,
    )
)
def test_fuzzed_scenarios_give_a_sheet_or_a_clear_refusal(mutations):
    d = copy.deepcopy(_BASE)
    for path, factor in mutations:
        node = d
        for k in path[:-1]:
            node = node[k]
        node[path[-1]] = node[path[-1]] * factor
    try:
        sheet = compute_setup_sheet(scenario_from_mapping(d, "fuzz.yaml"), load_instrument("sc1"))
    except StereoplotterError as exc:
        assert str(exc)
    else:
        assert np.isfinite(sheet.n_left) and np.isfinite(sheet.n_right)


def test_cli_setup_block_mode(tmp_path, capsys):
    block = str(SCENARIOS / "blocks" / "strip60.yaml")
    assert main(["setup", block, "--instrument", "sc1", "-o", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert out.startswith("block strip60 on") and "8 of 8 models set up" in out
    assert (tmp_path / "block.csv").exists() and (tmp_path / "101-102" / "sheet.yaml").exists()
    assert main(["setup", block, "--instrument", "sd3", "--json"]) == 0
    models = json.loads(capsys.readouterr().out)["models"]
    assert len(models) == 8 and all(m["status"] == "ok" for m in models)
    assert main(["setup", block, "--instrument", "sc1", "--horizontal-scale", "12500"]) == 1
    assert "apply to single pairs only" in capsys.readouterr().err


def test_corner_readings_6_16_to_6_18_and_zero_reading_of_bz():
    s = load_scenario(SCENARIOS / "pair60.yaml")
    sheet = compute_setup_sheet(s, load_instrument("sc1"))
    rows = {r["reading"]: r for r in sheet.readings}
    for corner, equation in (("1", "(6.16)"), ("3", "(6.17)"), ("4", "(6.18)")):
        c = next(c for c in sheet.corners if c["corner"] == corner)
        assert rows[f"corner {corner}: O_X"]["value"] == pytest.approx(c["x_mm"])
        assert rows[f"corner {corner}: O_Y"]["value"] == pytest.approx(c["y_mm"])
        assert rows[f"corner {corner}: O_X"]["equation"] == equation
        assert rows[f"corner {corner}: O_X"]["zero_reading"] == "MO_X"  # the left plumb
    # D7: MO_bz = stage-1 reading − b_z′, and (6.14) re-sets MO_bz + b_z′: the same b_z reading
    assert rows["MO_bz"]["value"] + rows["O_bz"]["value"] == pytest.approx(0.0)
    other = compute_setup_sheet(s, load_instrument("sc1"), SetupOptions(bz_scale_sense=-1))
    rows_other = {r["reading"]: r for r in other.readings}
    assert rows_other["O_bz"]["value"] == pytest.approx(-rows["O_bz"]["value"])
    with pytest.raises(StereoplotterError, match="bz_scale_sense: expected"):
        SetupOptions(bz_scale_sense=0)


def test_scale_choice_reports_why_larger_scales_fail():
    sheet = compute_setup_sheet(load_scenario(SCENARIOS / "pair60.yaml"), load_instrument("sc1"))
    refused = sheet_to_dict(sheet)["scale_choice"]["refused_larger_scales"]
    assert [r["horizontal"] for r in refused] == [5000, 6300, 8000, 10000]
    assert all(r["fails"] for r in refused)
    # 1:10 000 fails on depth: D_max = 185 mm needs M_в ≥ 1425 m·1000/185 = 7703, and then
    # f_пр = 70·10000/M_в < 100 mm; its closest pair is limited by the projection distance
    assert refused[-1]["fails"] == ["projection_distance"]
