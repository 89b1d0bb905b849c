"""The virtual instrument: controls, scales, stops, and a setup sheet set on it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.error_model import error_model_from_spec
from stereoplotter.instrument.kinematics import counters_from_photo
from stereoplotter.instrument.mechanics.base import TravelRefusal
from stereoplotter.instrument.virtual import Instrument
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import scenario_from_mapping
from stereoplotter.setup.sheet import compute_setup_sheet
from stereoplotter.spec.range_checks import RangeRefusal

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def sheet():
    d = yaml.safe_load((ROOT / "scenarios" / "pair60.yaml").read_text(encoding="utf-8"))
    d["errors"] = {"photo_point_sigma_um": 0.0, "fiducial_sigma_um": 0.0}
    return compute_setup_sheet(scenario_from_mapping(d, "pair60.yaml"), load_instrument("sc1"))


def _set_up(inst: Instrument, sheet) -> dict[str, float]:
    """Stage 1–2 settings of the sheet, set on the instrument from its (known) zero readings."""
    zero = inst.state()["zero_readings"]
    inst.set("f_instrument", sheet.f_instrument_mm)
    for name, value in zip(("bx", "by", "bz"), sheet.base_mm, strict=True):
        inst.set(name, zero[name] + value)
    inst.set("Z", zero["Z"] + sheet.n_left * sheet.f_instrument_mm)
    for photo in sheet.photos:
        inst.turn_knob(f"k_omega_{photo.name}", np.tan(photo.omega))
        inst.turn_knob(f"k_alpha_{photo.name}", np.tan(photo.alpha))
    return zero


def _gimbal_scale(photo, f_mm: float, h_mm: float) -> float:
    """The SC-1 carrier tilted by θ about gimbal axes h below the emulsion (docs/instruments.md):
    the emulsion rises by h(1 − cos θ), so the projected photo is scaled by f/(f − h(1 − cos θ)).
    θ from α, ω by the tilt of the carrier's normal (independent of the package's closed form,
    which writes cos θ = 1/√(1 + tan²α + tan²ω))."""
    normal = np.array([np.tan(photo.alpha), np.tan(photo.omega), 1.0])
    cos_theta = normal[2] / np.linalg.norm(normal)
    return f_mm / (f_mm - h_mm * (1.0 - cos_theta))


def test_sheet_readings_put_the_marks_on_the_fiducials(sheet):
    # The sheet's (6.12)/(6.13) targets, computed with the book's single-axis (6.1)/(6.2), are
    # where the instrument shows the fiducials: exactly for the canonical unit (kinematics.md
    # §3.3: the unit reproduces (6.1)/(6.2) on the axes), and scaled by the SC-1 gimbal's
    # second-order lift for the SC-1's own mechanism (gimbal offset 20 mm, assumed).
    # Independent paths: setup_data vs kinematics.
    spec = load_instrument("sc1")
    h_mm = spec.parameters["correction.gimbal_offset_mm"].value
    inst = Instrument.error_free(spec, sheet.focal_length_corrected_mm)
    zero = _set_up(inst, sheet)
    for photo, n, (mo_x, mo_y) in (
        (sheet.photos[0], sheet.n_left, (0.0, 0.0)),
        (sheet.photos[1], sheet.n_right, (sheet.base_mm[0], sheet.base_mm[1])),
    ):
        unit = inst.state()["units"][photo.name]
        s = _gimbal_scale(photo, sheet.focal_length_corrected_mm, h_mm)
        assert 1e-5 < s - 1.0 < 5e-5  # pair60 tilts of 0.6°–0.9°: a few µm at 140 mm
        for mark in ("3", "4"):
            point = photo.marks_measured_mm[mark]
            xy = counters_from_photo(point, 185.0, unit, inst.setting, photo.name)
            assert xy[1] - mo_y == pytest.approx(
                n * photo.transformed_book_mm[f"y{mark}"] / s, abs=1e-4
            )  # 0.1 µm: 1/30 of the 3 µm gimbal effect checked (27 nm found on pair60)
            inst.set("X", zero["X"] + xy[0])
            inst.set("Y", zero["Y"] + xy[1])
            offsets = inst.mark_offsets(**{f"{photo.name}_point_mm": point})
            np.testing.assert_allclose(offsets[photo.name], 0.0, atol=1e-9)
        x_mark = "2" if photo.name == "left" else "1"
        point = photo.marks_measured_mm[x_mark]
        xy = counters_from_photo(point, 185.0, unit, inst.setting, photo.name)
        assert xy[0] - mo_x == pytest.approx(
            n * photo.transformed_book_mm[f"x{x_mark}"] / s, abs=1e-4
        )


def test_readings_are_zero_plus_scale_and_rounded_to_the_least_count():
    spec = load_instrument("sc1")
    inst = Instrument(spec, 70.0, rng=np.random.default_rng(2))
    zero_x = inst.state()["zero_readings"]["X"]
    inst.set("X", zero_x + 12.3456)
    assert inst.read("X", exact=True) == pytest.approx(zero_x + 12.3456, abs=1e-12)
    assert inst.read("X") == pytest.approx(round((zero_x + 12.3456) / 0.01) * 0.01)
    # the carriage follows the nut through the backlash and the friction dead band
    carriage = inst.state()["carriages_mm"]["X"]
    nut = (12.3456) / (1 + inst.injected["counter_scale.X"])
    assert abs(carriage - nut) < 0.005 / 2 + 0.003


def test_stops_refuse_settings():
    inst = Instrument.error_free(load_instrument("sc1"), 70.0)
    zero = inst.state()["zero_readings"]
    with pytest.raises(TravelRefusal, match=r"sc1 X: .* beyond the range stops \[-250, 450\]"):
        inst.set("X", zero["X"] + 500.0)
    with pytest.raises(RangeRefusal, match=r"f_пр = 90\.000 mm is .*\[100, 185\]"):
        inst.set("f_instrument", 90.0)
    with pytest.raises(RangeRefusal, match=r"k_alpha,left"):
        inst.turn_knob("k_alpha_left", np.tan(np.radians(4.0)))
    with pytest.raises(StereoplotterError, match="no control 'W'"):
        inst.set("W", 1.0)


def test_same_seed_same_instrument_and_trials_vectorise():
    spec = load_instrument("spr3")
    a = Instrument(spec, 70.0, rng=np.random.default_rng(9))
    b = Instrument(spec, 70.0, rng=np.random.default_rng(9))
    assert a.injected == b.injected
    many = Instrument(spec, 70.0, rng=np.random.default_rng(9), trials=50)
    assert many.state()["zero_readings"]["X"].shape == (50,)
    many.set("Z", many.state()["zero_readings"]["Z"] + 150.0)
    assert many.state()["carriages_mm"]["Z"].shape == (50,)
    with pytest.raises(StereoplotterError, match=r"needs an explicit numpy\.random\.Generator"):
        Instrument(spec, 70.0)


def test_variant_b_keeps_decentrations_independent():
    spec = load_instrument("sc1")
    inst_l = Instrument.error_free(spec, 70.0, variant="L")
    inst_b = Instrument.error_free(spec, 70.0, variant="B")
    for inst in (inst_l, inst_b):
        inst.turn_knob("k_alpha_left", 0.02)
    assert float(inst_l.state()["units"]["left"].decentration_x_mm) == pytest.approx(1.4)
    assert float(inst_b.state()["units"]["left"].decentration_x_mm) == 0.0


def test_error_free_model_zero_terms():
    spec = load_instrument("sd3")
    model = error_model_from_spec(spec).zero()
    inst = Instrument(spec, 70.0, errors=model)  # no rng needed: nothing random
    assert all(v == 0 for v in inst.injected.values())


def test_coordinatograph_follows_the_carriages_through_the_gears():
    spec = load_instrument("sc1")
    inst = Instrument.error_free(spec, 70.0)
    inst.connect_coordinatograph(1.25, origin_table_mm=(400.0, 400.0))
    zero = inst.state()["zero_readings"]
    inst.set("X", zero["X"] + 100.0)
    inst.set("Y", zero["Y"] - 50.0)
    np.testing.assert_allclose(inst.needle(), [400.0 + 125.0, 400.0 - 62.5], atol=1e-9)
    with pytest.raises(
        RangeRefusal, match=r"coordinatograph ratio = 1\.3 is not in the assumed gear"
    ):
        inst.connect_coordinatograph(1.3)


def test_back_ends_agree_within_half_a_micrometre():
    # mechanics.md: pymunk and the play operator agree within 0.5 µm for slow approaches; here
    # through the instrument, for a script of moves with reversals and one-sided finishes.
    spec = load_instrument("sc1")
    carriages = {}
    for backend in ("pymunk", "closed-form"):
        inst = Instrument(spec, 70.0, rng=np.random.default_rng(1), backend=backend)
        zero = inst.state()["zero_readings"]
        for target, side in ((100.0, "below"), (99.5, None), (100.0, "above"), (20.0, "below")):
            inst.set("X", zero["X"] + target, side=side)
            inst.set("Z", zero["Z"] + 170.0 + target / 100.0, side=side)
        carriages[backend] = inst.state()["carriages_mm"]
    for axis in ("X", "Z"):
        assert abs(carriages["pymunk"][axis] - carriages["closed-form"][axis]) < 0.5e-3
    with pytest.raises(StereoplotterError, match="pymunk back-end runs single instruments"):
        Instrument(spec, 70.0, rng=np.random.default_rng(1), backend="pymunk", trials=3)
