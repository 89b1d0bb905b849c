"""Issue 11, deliverable 3: documented limits refuse the material like a stop."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.setup.sheet import SetupRefusal, compute_setup_sheet
from stereoplotter.spec.limits import (
    check_material_limits,
    check_model_to_photo_scale,
    check_photo_to_map_ratio,
)
from stereoplotter.spec.range_checks import RangeRefusal, check_in_range

MOUNTAIN = Path(__file__).parents[2] / "stereoplotter" / "data" / "scenarios" / "mountain60.yaml"


def test_relief_limit_sd3_documented_035():
    spec = load_instrument("sd3")
    check_material_limits(spec, relief_m=349.0, flying_height_m=1000.0, camera_f_mm=70.0, what="x")
    with pytest.raises(RangeRefusal, match=r"0\.40 H exceeds .*limit of 0\.35 H \(documented"):
        check_material_limits(
            spec, relief_m=400.0, flying_height_m=1000.0, camera_f_mm=70.0, what="x"
        )
    # the other two instruments document no relief limit
    for name in ("sc1", "spr3"):
        check_material_limits(
            load_instrument(name), relief_m=400.0, flying_height_m=1e3, camera_f_mm=70.0, what="x"
        )


def test_camera_f_range_sd3_documented():
    with pytest.raises(RangeRefusal, match="f_k"):
        check_material_limits(
            load_instrument("sd3"), relief_m=0.0, flying_height_m=1e3, camera_f_mm=50.0, what="x"
        )


def test_scenario_with_relief_04H_refused_on_sd3(tmp_path):
    """mountain60 with hills of +380 m and −290 m: relief 679 m over H ≈ 1700 m (0.40 H)."""
    text = MOUNTAIN.read_text(encoding="utf-8")
    text = text.replace("height_m: 260.0, radius_m: 700.0", "height_m: 380.0, radius_m: 700.0")
    text = text.replace("height_m: -180.0, radius_m: 600.0", "height_m: -290.0, radius_m: 600.0")
    path = tmp_path / "relief40.yaml"
    path.write_text(text, encoding="utf-8")
    scenario = load_scenario(path)
    with pytest.raises(SetupRefusal) as info:
        compute_setup_sheet(scenario, load_instrument("sd3"), rng=np.random.default_rng(1))
    message = str(info.value)
    assert "\n" not in message
    assert "0.40 H" in message and "0.35 H" in message and "documented" in message


def test_spr3_model_scale_range():
    """SPR-3: model 0.5–2 × photo scale (assumed from SPR-2, DRO60); pair60 1:20000 → 1:16000."""
    spec = load_instrument("spr3")
    check_model_to_photo_scale(spec, photo_scale_denominator=20000, model_scale_denominator=16000)
    with pytest.raises(RangeRefusal, match=r"0\.44 × the photo scale .*\[0\.5, 2\]"):
        check_model_to_photo_scale(
            spec, photo_scale_denominator=20000, model_scale_denominator=45000
        )
    # SD-3 and SC-1 state no such range
    check_model_to_photo_scale(
        load_instrument("sd3"), photo_scale_denominator=20000, model_scale_denominator=45000
    )


def test_sc1_projection_distance_stops_at_documented_d_max():
    spec = load_instrument("sc1")
    assert spec.projection_distance_max_mm == 185.0  # SEED6 L3715, documented
    with pytest.raises(RangeRefusal, match="185"):
        check_in_range(spec, "projection_distance_range_mm", 186.0, "D")


def test_sd3_photo_to_map_ratio_documented_05_to_3():
    spec = load_instrument("sd3")
    check_photo_to_map_ratio(spec, photo_scale_denominator=20000, map_scale_denominator=10000)
    with pytest.raises(RangeRefusal, match=r"4\.00 × .*\[0\.5, 3\] \(documented"):
        check_photo_to_map_ratio(spec, photo_scale_denominator=20000, map_scale_denominator=5000)
