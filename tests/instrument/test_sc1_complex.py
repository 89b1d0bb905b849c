"""Issue 11, deliverable 4: the SC complex options (off by default), Monte Carlo within CI."""

from __future__ import annotations

import numpy as np
import pytest

from stereoplotter.instrument.sc1_complex import (
    AutomaticCoordinatograph,
    ErrorCorrectionUnit,
    SC1Options,
)
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.spec.range_checks import RangeRefusal


def test_options_off_by_default():
    assert SC1Options() == SC1Options(False, False)


def test_correction_unit_rms_3um_and_range_100um():
    unit = ErrorCorrectionUnit.from_spec(load_instrument("sc1"))
    assert (unit.range_um, unit.rms_um) == (100.0, 3.0)  # SCX, documented
    rng = np.random.default_rng(11)
    res = unit.residual_um(np.full((20000, 2), 60.0), rng)
    rms = float(np.sqrt(np.mean(np.sum(res**2, axis=-1))))
    # vector RMS 3 µm; the MC standard error of the RMS is ≈ 3/√(2n) = 0.015 µm: 4 of them
    assert rms == pytest.approx(3.0, abs=4 * 3.0 / np.sqrt(2 * 20000))
    with pytest.raises(RangeRefusal, match=r"±100 µm"):
        unit.residual_um([[101.0, 0.0]], rng)


def test_no_correction_unit_on_sd3():
    with pytest.raises(RangeRefusal):
        ErrorCorrectionUnit.from_spec(load_instrument("sd3"))


def test_automatic_coordinatograph_lag_and_enlargement():
    coord = AutomaticCoordinatograph.from_spec(load_instrument("sc1"))
    coord.check_enlargement(10.0)
    with pytest.raises(RangeRefusal, match=r"10 ×"):
        coord.check_enlargement(10.5)
    # straight track at 2 mm/s: the pen lags by v·τ = 0.1 mm on average (closed form)
    t = np.arange(0, 10, 0.01)
    track = np.column_stack([2.0 * t, np.zeros_like(t)])
    pen = coord.pen_mm(track, 0.01, np.random.default_rng(3))
    lag = float(np.mean(track[:, 0] - pen[:, 0]))
    assert lag == pytest.approx(2.0 * 0.05, abs=4 * 0.02 / np.sqrt(len(t)))


# --- the options as switches of the instrument and of simulate ---------------------------------

from dataclasses import replace  # noqa: E402

from stereoplotter.cli import main  # noqa: E402
from stereoplotter.errors import StereoplotterError  # noqa: E402
from stereoplotter.instrument.virtual import Instrument  # noqa: E402
from stereoplotter.io.scenario_file import load_scenario  # noqa: E402
from stereoplotter.procedure.operator import OperatorModel  # noqa: E402
from stereoplotter.procedure.simulate import apply_correction_unit, simulate  # noqa: E402
from stereoplotter.setup.records import SetupRefusal  # noqa: E402


def test_options_by_name_only_on_the_sc1():
    sc1 = load_instrument("sc1")
    assert SC1Options.from_names(sc1, ["correction_unit"]) == SC1Options(True, False)
    assert SC1Options.from_names(sc1, ["automatic_coordinatograph"]).names == (
        "automatic_coordinatograph",
    )
    for name in ("spr3", "sd3"):
        with pytest.raises(StereoplotterError, match="has no such unit"):
            SC1Options.from_names(load_instrument(name), ["correction_unit"])
    with pytest.raises(StereoplotterError, match="expected one of"):
        SC1Options.from_names(sc1, ["autofocus"])


def test_option_on_another_instrument_is_one_line(capsys):
    code = main(["simulate", "scenarios/pair60.yaml", "--instrument", "spr3",
                 "--option", "correction_unit", "-q"])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 1 and err.count("\n") == 1 and "has no such unit" in err


def test_correction_unit_adds_its_residual_to_the_operator_in_quadrature():
    sc, spec = load_scenario("scenarios/pair60.yaml"), load_instrument("sc1")
    # the free-σ operator (10 µm, eye="sigma") keeps the figures below round
    corrected, op = apply_correction_unit(sc, spec, OperatorModel(eye="sigma"))
    assert all(p.film_deformation_ppm == (0.0, 0.0) for p in corrected.photos)
    # σ_c = 3/√2 µm per coordinate (vector RMS 3 µm, SCX): √(10² + 4.5) and √(10² + 9) µm
    assert op.monocular_sigma_mm == pytest.approx(np.sqrt(100.0 + 4.5) / 1000.0, rel=1e-12)
    assert op.stereo_sigma_mm == pytest.approx(np.sqrt(109.0) / 1000.0, rel=1e-12)
    assert op.y_parallax_sigma_mm == pytest.approx(np.sqrt(109.0) / 1000.0, rel=1e-12)


def _film(sc, left_ppm):
    photos = (replace(sc.photos[0], film_deformation_ppm=left_ppm), sc.photos[1])
    return replace(sc, photos=photos)


def test_correction_unit_takes_a_deformed_film_the_plain_sc1_refuses():
    """±900 ppm on the left film (81 µm at the format corner, inside ±100 µm): without the unit
    the sheet's settings leave more than the ¼-mark 12.5 µm (§26) and the setup method is
    refused; with it the error-free run leaves a floor under that tolerance. 1 200 ppm
    (108 µm) is beyond the unit's range and refused like a stop."""
    sc, spec = load_scenario("scenarios/pair60.yaml"), load_instrument("sc1")
    film = _film(sc, (-900.0, 900.0))
    kw = dict(errors="zero", operator=OperatorModel().zero(), ideal_mechanics=True, seed=1)
    with pytest.raises(
        SetupRefusal, match=r"film_deformation_ppm = \[-900, 900\].*correction_unit"
    ):
        simulate(film, spec, **kw)
    r = simulate(film, spec, trials=20, options=SC1Options(error_correction_unit=True), **kw)
    q_rms = np.sqrt(np.mean(np.asarray(r.q_grid_mm) ** 2, axis=1))
    assert float(q_rms.max()) < 0.0125
    with pytest.raises(RangeRefusal, match=r"±100 µm"):
        simulate(_film(sc, (-1200.0, 0.0)), spec, options=SC1Options(True, False), **kw)


def test_automatic_coordinatograph_needle_is_the_gear_target_at_rest():
    """Servo at rest: no screw backlash, no pen play — the needle is origin + r·(X, Y) plus
    the caller's servo noise; the geared coordinatograph with backlash is not."""
    spec = load_instrument("sc1")
    rng = np.random.default_rng(3)
    inst = Instrument(spec, 100.0, rng=rng, options=SC1Options(automatic_coordinatograph=True))
    inst.connect_coordinatograph(2.0)
    inst.set("X", 40.0)
    inst.set("Y", -25.0)
    eps = float(inst.injected["coordinatograph.nonorthogonality"])
    x, y = (np.asarray(inst.position(a), float) for a in "XY")
    target = inst.table_position_mm([x, y])
    noise = np.array([0.013, -0.007])
    got = inst.needle("+", noise)
    expected_y = target[1] + noise[1]
    expected_x = target[0] + noise[0] + (expected_y - target[1] + 2.0 * y) * np.sin(eps)
    np.testing.assert_allclose(got, [expected_x, expected_y], atol=1e-12)
    assert inst.servo_sigma_mm == 0.02  # assumed (sc1_complex)
    with pytest.raises(RangeRefusal, match=r"10 ×"):
        inst.connect_coordinatograph(2.0, enlargement=10.5)


def test_instrument_refuses_options_its_file_does_not_document():
    with pytest.raises(StereoplotterError, match="has no such unit"):
        Instrument(
            load_instrument("sd3"), 100.0, rng=np.random.default_rng(0),
            options=SC1Options(automatic_coordinatograph=True),
        )  # fmt: skip
