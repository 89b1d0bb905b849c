"""Tests of the evaluation of a built model against the ground truth
(``stereoplotter.procedure.evaluation``).

References for the tolerances: ``kinematics.md`` §3.3 (per-axis approximation at the fiducials)
and §6 (residual y-parallax and height deformation of the canonical unit at the true settings).
"""

from __future__ import annotations

import dataclasses
import functools
import json
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from conftest import m, mm, um
from numpy.testing import assert_allclose, assert_array_equal

from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.kinematics import InstrumentSetting
from stereoplotter.instrument.knobs import unit_for_orientation
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.procedure.evaluation import (
    evaluate_instrument,
    evaluate_model,
    film_points_mm,
    instrument_frame_m,
    parallax_map_data,
)
from stereoplotter.scenario.synthetic import synthesize_measurements
from stereoplotter.setup.equations import instrument_principal_distance
from stereoplotter.setup.sheet import compute_setup_sheet

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"

# kinematics.md §6, canonical unit, worst case over the tilt signs, f′ = 100 mm, §5 grid
# (photo coordinates up to 80 mm, tan of the half field ≈ 0.8): tilt [deg] ->
# (max|q| [mm], height deformation after levelling [‰ H]).
SECTION6 = {0.5: (0.5 * um, 0.014), 1.0: (2.2 * um, 0.057), 3.0: (22.6 * um, 0.54)}
# kinematics.md §3.3: unit vs rigorous collinearity at the fiducial l = 85 mm, f′ = 100 mm, with
# α = ω = tilt: the per-axis approximation in photo mm.
SECTION33 = {0.5: 3.3 * um, 1.0: 13.3 * um, 3.0: 128.0 * um}


@functools.cache
def _case(name: str):
    """Scenario, its SC-1 sheet and the error-free instrument at the exact settings."""
    scenario = load_scenario(SCENARIOS / f"{name}.yaml")
    sheet = compute_setup_sheet(scenario, load_instrument("sc1"))
    # The sheet's f′ comes from noisy fiducials; the exact instrument uses the noise-free f′ of
    # the films and f_пр = k·f′ with the sheet's scales (setup-data.md, item 1).
    f = synthesize_measurements(scenario, np.random.default_rng(0), noise=False)
    f_prime = f.focal_length_corrected_mm
    f_pr = float(
        instrument_principal_distance(
            f_prime, sheet.horizontal_scale_denominator, sheet.vertical_scale_denominator
        )
    )
    setting = InstrumentSetting(f_pr, *sheet.base_mm)
    units = tuple(unit_for_orientation(p.alpha, p.omega, p.kappa, f_prime) for p in sheet.photos)
    return scenario, sheet, setting, units


def _tolerances(name: str):
    """Bounds from kinematics.md §6/§3.3 for the scenario's largest tilt and field angle.

    The per-axis residuals are second order in the tilt and grow with the square of the field
    angle: take the tabulated value at the next tilt step at or above the largest |α|, |ω| of the
    pair, and scale it by (tan φ / 0.8)², tan φ = (format/2)/f the half-field of the scenario's
    camera against the ≈ 0.8 of the §5 grid (f′ = 100 mm, ±80 mm).
    """
    scenario, sheet, _, _ = _case(name)
    tilt = max(np.degrees(abs(v)) for p in sheet.photos for v in (p.alpha, p.omega))
    step = min(t for t in SECTION6 if t >= tilt)
    field = ((scenario.camera.format_mm / 2 / scenario.camera.focal_length_mm) / 0.8) ** 2
    q_max, dh_permille = SECTION6[step]
    return q_max * field, dh_permille * field, SECTION33[step] * field


# --- (a) error-free instrument at the exact settings -------------------------------------------


@pytest.mark.parametrize(
    ("name", "measured"),
    [
        # measured (grid 9 × 9): max|q|, max|δp| after plane, max|ΔH| after plane [‰ H],
        # max plan error [m], max|ΔH| raw [‰ H]
        ("pair60", (1.38 * um, 0.22 * um, 0.0016, 0.23 * m, 0.13)),
        ("mountain60", (41.7 * um, 18.2 * um, 0.24, 4.7 * m, 1.86)),
    ],
)
def test_error_free_instrument_at_the_level_of_the_per_axis_approximation(name, measured):
    scenario, sheet, setting, (left, right) = _case(name)
    ev = evaluate_model(scenario, sheet, setting, left, right)
    s = ev.summary()
    q_bound, dh_bound_permille, axis_bound = _tolerances(name)
    # pair60: tilts ≤ 0.71° → §6 at 1°: 2.2 µm × 2.58 = 5.7 µm; 0.057 ‰ × 2.58 = 0.15 ‰.
    # mountain60: tilts ≤ 2.9° → §6 at 3°: 22.6 µm × 2.58 = 58 µm; 0.54 ‰ × 2.58 = 1.4 ‰.
    for part in ("grid", "standard_points", "control", "check"):
        assert s[part]["y_parallax_max_mm"] <= q_bound
        assert s[part]["height_error_after_plane_max_permille"] <= dh_bound_permille
        # δp after levelling is the same height deformation seen as a parallax:
        # δp ≈ (ΔH/H)·b_photo, b_photo = b_x·M_г/M_photo ≈ B·f/H̄.
        b_photo = (
            (sheet.base_mm[0] * sheet.horizontal_scale_denominator / 1000.0)
            * scenario.camera.focal_length_mm
            / ev.flying_height_m
        )
        assert s[part]["x_parallax_error_after_plane_max_mm"] <= dh_bound_permille * 1e-3 * b_photo
        # plan: the per-axis discrepancy at the photo (§3.3) taken to the ground at photo scale
        photo_scale = ev.flying_height_m / (scenario.camera.focal_length_mm * mm)
        assert s[part]["plan_error_max_m"] <= axis_bound * photo_scale
    # the measured values, stated (10 % + rounding of the comment)
    q, dp_plane, dh_plane, plan, dh_raw = measured
    assert s["grid"]["y_parallax_max_mm"] == pytest.approx(q, rel=0.1)
    assert s["grid"]["x_parallax_error_after_plane_max_mm"] == pytest.approx(dp_plane, rel=0.1)
    assert s["grid"]["height_error_after_plane_max_permille"] == pytest.approx(dh_plane, rel=0.1)
    assert s["grid"]["plan_error_max_m"] == pytest.approx(plan, rel=0.1)
    assert s["grid"]["height_error_max_permille"] == pytest.approx(dh_raw, rel=0.1)


def test_without_tilts_the_instrument_is_exact():
    # α = ω = 0: the correction units are the identity apart from κ (τ = 1, kinematics.md §3.3),
    # so the instrument is the rigorous transformed bundle: every error is rounding.
    scenario, _, _, _ = _case("pair60")
    photos = tuple(
        dataclasses.replace(p, exterior=dataclasses.replace(p.exterior, alpha=0.0, omega=0.0))
        for p in scenario.photos
    )
    flat = dataclasses.replace(scenario, photos=photos)
    sheet = compute_setup_sheet(flat, load_instrument("sc1"))
    f_pr = float(
        instrument_principal_distance(
            70.0, sheet.horizontal_scale_denominator, sheet.vertical_scale_denominator
        )
    )
    units = [unit_for_orientation(p.alpha, p.omega, p.kappa, 70.0) for p in sheet.photos]
    ev = evaluate_model(flat, sheet, InstrumentSetting(f_pr, *sheet.base_mm), *units)
    for part in ev.summary().values():
        for key, value in part.items():
            if key.endswith("_mm"):
                assert value < 1e-9 * mm, key
            elif key.endswith("_m"):
                assert value < 1e-9 * m, key


def test_film_points_match_the_synthetic_measurements():
    scenario, sheet, _, _ = _case("mountain60")  # with film deformation
    meas = synthesize_measurements(
        scenario, np.random.default_rng(1), noise=False, grid_shape=(9, 9)
    )
    for pm in meas.photos:
        assert_allclose(film_points_mm(scenario, pm.photo, meas.grid_m), pm.grid_true_mm, 0, 1e-12)
    # the frame round trip
    p = instrument_frame_m(meas.grid_m, sheet.frame_origin_m, sheet.frame_rotation)
    back = instrument_frame_m(p, sheet.frame_origin_m, sheet.frame_rotation, inverse=True)
    assert_allclose(back, meas.grid_m, 0, 1e-9 * m)


def test_standard_points_lie_at_the_nadirs_and_at_plus_minus_c():
    scenario, sheet, setting, units = _case("pair60")
    ev = evaluate_model(scenario, sheet, setting, *units)
    st = ev.standard_points.ground_m
    right = instrument_frame_m(
        scenario.photo("right").exterior.centre, sheet.frame_origin_m, sheet.frame_rotation
    )
    assert_allclose(st[0, :2], [0.0, 0.0], atol=1e-9)  # plumb of S_л
    assert_allclose(st[1, :2], right[:2], atol=1e-9)  # plumb of S_п
    c_m = 80.0 * ev.flying_height_m / scenario.camera.focal_length_mm
    assert_allclose(st[2:, 1] - st[[0, 1, 0, 1], 1], [c_m, c_m, -c_m, -c_m], rtol=1e-12)
    assert ev.standard_points.ids == ("1", "2", "3", "4", "5", "6")


# --- (b) known perturbations -------------------------------------------------------------------


def test_base_x_scale_error_changes_heights_by_minus_epsilon_h():
    # b_x·(1 + ε) scales the model along the base: t_л = (b_x + ξ_п b_z′/f_пр)/(ξ_л − ξ_п)
    # (kinematics.md §3.4) grows by ε·b_x/(b_x + ξ_п b_z′/f_пр), so D → D(1 + ε) and
    # ΔH/H ≈ −ε at every point, H = Z_Sл − Z of the point. Deviation from −ε: the b_z′ term,
    # |ξ_п|·|b_z′|/(f_пр·b_x) ≤ 127 mm · 1.25 mm / (109 mm · 115 mm) = 1.3 % here (ξ ≤ 90√2).
    scenario, sheet, setting, units = _case("pair60")
    eps = 1e-3
    base = evaluate_model(scenario, sheet, setting, *units)
    scaled = dataclasses.replace(setting, base_x_mm=setting.base_x_mm * (1 + eps))
    ev = evaluate_model(scenario, sheet, scaled, *units)
    rel = abs(setting.base_z_mm) * 90 * np.sqrt(2) / (setting.f_instrument_mm * setting.base_x_mm)
    for part in ("grid", "control", "check", "standard_points"):
        a, b = getattr(base, part), getattr(ev, part)
        h = -b.ground_m[:, 2]  # flying height above each point
        ratio = (b.height_error_m - a.height_error_m) / h
        assert_allclose(ratio, -eps, rtol=rel + eps)
        # and the plan scales about S_л: ΔX ≈ ε·X
        assert_allclose(b.x_error_m - a.x_error_m, eps * b.ground_m[:, 0], atol=eps * rel * 2e3)


def test_base_z_offset_tilts_the_model_about_the_right_nadir():
    # b_z′ + δ: Δt_л = ξ_п δ/(f_пр(ξ_л − ξ_п)) (kinematics.md §3.4), i.e. ΔD ≈ (X − b_x)·δ/b_x in
    # model mm: a tilt of the model about the Y axis through the right nadir;
    # ΔH = −ΔD·M_в/1000. Neglected: b_z′/D and ξ_п b_z′/(f_пр b_x), ≤ 2 % here.
    scenario, sheet, setting, units = _case("pair60")
    delta = 0.2 * mm
    base = evaluate_model(scenario, sheet, setting, *units)
    ev = evaluate_model(
        scenario, sheet, dataclasses.replace(setting, base_z_mm=setting.base_z_mm + delta), *units
    )
    bx = float(setting.base_x_mm)
    mv = sheet.vertical_scale_denominator
    for part in ("grid", "control", "check"):
        a, b = getattr(base, part), getattr(ev, part)
        predicted = -(b.model_mm[:, 0] - bx) * delta / bx * mv / 1000.0
        change = b.height_error_m - a.height_error_m
        assert_allclose(change, predicted, atol=0.02 * np.max(np.abs(predicted)))
        # the tilt is removed by the levelling plane; what stays is second order in δ
        # ((δ/D)·ΔH ≈ 0.1 % of the tilt) and the variation of the neglected factors over the relief
        assert_allclose(
            b.height_error_after_plane_m,
            a.height_error_after_plane_m,
            atol=0.005 * np.max(np.abs(predicted)),
        )
    assert np.max(np.abs(ev.grid.height_error_m)) > 1.0 * m  # the raw tilt is large


def test_height_zero_reads_the_heights_on_the_slipped_scale():
    scenario, sheet, setting, units = _case("pair60")
    base = evaluate_model(scenario, sheet, setting, *units)
    ev = evaluate_model(scenario, sheet, setting, *units, height_zero=sheet.frame_origin_m[2] + 0.5)
    assert_allclose(ev.check.height_error_m - base.check.height_error_m, 0.5, rtol=1e-9)
    # a constant offset is removed with the plane
    assert_allclose(
        ev.check.height_error_after_plane_m, base.check.height_error_after_plane_m, atol=1e-9
    )


# --- (c) vectorised over trials == loop of single evaluations ---------------------------------


def _perturbed(rng: np.random.Generator, trials: int):
    scenario, sheet, setting, (left, right) = _case("pair60")
    vec_setting = dataclasses.replace(
        setting,
        base_x_mm=setting.base_x_mm * (1 + 1e-3 * rng.normal(size=trials)),
        base_y_mm=setting.base_y_mm + 0.05 * rng.normal(size=trials),
        base_z_mm=setting.base_z_mm + 0.05 * rng.normal(size=trials),
    )
    vec_units = tuple(
        dataclasses.replace(
            u,
            tan_alpha=u.tan_alpha + 1e-4 * rng.normal(size=trials),
            kappa=u.kappa + 1e-4 * rng.normal(size=trials),
            decentration_y_mm=u.decentration_y_mm + 0.01 * rng.normal(size=trials),
        )
        for u in (left, right)
    )
    return scenario, sheet, vec_setting, vec_units


def _trial(obj, i):
    changes = {
        f.name: np.asarray(getattr(obj, f.name))[i]
        for f in dataclasses.fields(obj)
        if np.ndim(getattr(obj, f.name)) == 1
    }
    return dataclasses.replace(obj, **changes)


def test_vectorised_equals_loop():
    # bit-identical: the trial axis only broadcasts element-wise operations (no BLAS reductions)
    trials = 5
    rng = np.random.default_rng(20240605)
    scenario, sheet, setting, units = _perturbed(rng, trials)
    h0 = sheet.frame_origin_m[2] + rng.normal(size=trials)
    c4 = np.abs(rng.normal(0.0, 0.1, size=trials))
    vec = evaluate_model(scenario, sheet, setting, *units, height_zero=h0, corner4_misclosure_mm=c4)
    assert vec.trials == trials
    assert vec.grid.x_parallax_error_mm.shape == (trials, len(vec.grid.ids))
    vec_d = vec.to_dict()
    for i in range(trials):
        one = evaluate_model(
            scenario,
            sheet,
            _trial(setting, i),
            *(_trial(u, i) for u in units),
            height_zero=h0[i],
            corner4_misclosure_mm=c4[i],
        )
        assert one.trials is None
        for name, part in one.sets().items():
            vpart = vec.sets()[name]
            for f in dataclasses.fields(part):
                a, b = getattr(part, f.name), getattr(vpart, f.name)
                if f.name in ("ids", "ground_m", "model_mm"):
                    assert_array_equal(np.asarray(a), np.asarray(b))
                else:
                    assert_array_equal(a, b[i], err_msg=f"{name}.{f.name}")
        for name, summary in one.summary().items():
            for key, value in summary.items():
                got = vec_d["summary"][name][key]
                assert value == (got if key == "n_points" else got[i])
        assert one.corner4_misclosure_mm == c4[i]


def test_to_dict_is_json_ready_and_keys_carry_units():
    scenario, sheet, setting, units = _case("pair60")
    d = evaluate_model(scenario, sheet, setting, *units, corner4_misclosure_mm=0.12).to_dict()
    text = json.dumps(d, allow_nan=False)
    assert json.loads(text)["corner4_misclosure_mm"] == 0.12
    assert set(d["summary"]) == {"grid", "standard_points", "control", "check"}
    assert d["plane_point_ids"] == ["1", "2", "3", "4"]
    assert d["points"]["check"]["ids"] == ["K1", "K2", "K3", "K4", "K5", "K6"]
    for key in ("plan_error_max_map_mm", "height_error_rms_permille", "y_parallax_max_mm"):
        assert key in d["summary"]["check"]


def test_evaluate_instrument_reads_the_physical_state():
    scenario, sheet, setting, (left, right) = _case("pair60")
    fake = SimpleNamespace(setting=setting, state=lambda: {"units": {"left": left, "right": right}})
    a = evaluate_instrument(scenario, sheet, fake).to_dict()
    b = evaluate_model(scenario, sheet, setting, left, right).to_dict()
    assert a == b


def test_evaluate_instrument_on_a_vectorised_virtual_instrument():
    from stereoplotter.instrument.virtual import Instrument

    scenario, sheet, setting, _ = _case("pair60")
    inst = Instrument.error_free(load_instrument("sc1"), 70.0, trials=3)
    inst.set("f_instrument", float(setting.f_instrument_mm))
    ev = evaluate_instrument(scenario, sheet, inst)  # an unoriented instrument: large errors
    assert ev.trials == 3
    assert ev.grid.y_parallax_mm.shape == (3, len(ev.grid.ids))
    assert np.all(ev.summary()["grid"]["y_parallax_max_mm"] > 1.0 * mm)


def test_mixed_trial_counts_are_refused():
    scenario, sheet, setting, (left, right) = _case("pair60")
    bad = dataclasses.replace(setting, base_x_mm=np.full(3, setting.base_x_mm))
    left4 = dataclasses.replace(left, kappa=np.zeros(4))
    with pytest.raises(StereoplotterError, match=r"mixes trial counts \[3, 4\]"):
        evaluate_model(scenario, sheet, bad, left4, right)
    with pytest.raises(StereoplotterError, match=r"height_zero: expected .* \(None,\)"):
        evaluate_model(scenario, sheet, setting, left, right, height_zero=[1.0, 2.0])
    with pytest.raises(StereoplotterError, match="not points of scenario"):
        evaluate_model(scenario, sheet, setting, left, right, plane_point_ids=["1", "X9"])


# --- (d) the figure ------------------------------------------------------------------------------


@pytest.mark.parametrize("trials", [None, 3])
def test_parallax_error_map_has_the_expected_artists(trials):
    import matplotlib.pyplot as plt
    from matplotlib.collections import PathCollection
    from matplotlib.contour import ContourSet

    from stereoplotter.plotting.evaluation import plot_parallax_error_map

    if trials is None:
        scenario, sheet, setting, units = _case("pair60")
    else:
        scenario, sheet, setting, units = _perturbed(np.random.default_rng(7), trials)
    ev = evaluate_model(scenario, sheet, setting, *units)
    fig = plot_parallax_error_map(ev)
    ax = fig.axes[0]
    assert len(fig.axes) == 2  # the map and its colour bar
    assert sum(isinstance(c, ContourSet) for c in ax.collections) == 1
    scatters = [c for c in ax.collections if isinstance(c, PathCollection)]
    assert [len(c.get_offsets()) for c in scatters] == [6, 6, 6]  # standard, control, check
    assert [t.get_text() for t in ax.texts] == ["1", "2", "3", "4", "5", "6"]
    data = parallax_map_data(ev)
    assert data["x_parallax_error_um"].shape == (len(ev.grid.ids),)
    assert ("RMS over trials" in ax.get_title()) == (trials is not None)
    plt.close(fig)
