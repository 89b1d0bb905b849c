"""Mechanics back-ends: pymunk lead-screw axes against the closed-form play operator.

Reference numbers are the measurements of ``docs/design/mechanics.md`` (pymunk 7.3.1, dt = 1 ms,
10 iterations). Derived tolerances:

* quasi-static oracle: |pymunk − play| ≤ 0.5 µm for slow (0.2 mm/s creep) approaches (§9);
* rigid reversal: b − 2·v_final·dt ≤ reversal ≤ b, the carriage loses ≤ v_final·dt per approach
  (the SlideJoint bias lags one step);
* compliant reversal: the quasi-static b + 2F/k less 2·v_final·dt (as rigid) less the spring's
  relaxation inside the friction band, ≤ 0.35 µm (§8): deficit in [0, 2·v_final·dt + 0.35 µm];
* Z sag: b/2 + (m + m_f)·g/k within ±F/k (§7, §9);
* unidirectional index error: spread over the targets < 0.01 µm (§9);
* sheet, ideal drives and zero acuity: every residual < 0.01 µm (§9).
"""

from __future__ import annotations

import math
import re
from dataclasses import replace

import numpy as np
import pytest

from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.mechanics import (
    BRIDGE,
    G_MM_S2,
    N_PER_UM,
    AxisParams,
    Coordinatograph,
    CoordinatographParams,
    LinearAxis,
    OperatorParams,
    PlayAxis,
    PymunkAxis,
    SheetOnTable,
    TravelRefusal,
    half_play_mm,
    orient_sheet,
    pin_radial_residual,
    play,
    velocity_plan,
)
from stereoplotter.io.instrument_file import load_instrument
from tests.conftest import arcsec, um

REF = AxisParams(name="X")  # §8 defaults: b = 20 µm, μ = 0.1, 2 kg, k = 1 N/µm, dt = 1 ms
RIGID = replace(REF, stiffness_kg_s2=math.inf)
Z_COLUMN = AxisParams(
    name="Z", mass_kg=3.0, friction=0.02, vertical=True, range_mm=(100.0, 400.0)
)  # §7
CORNERS = np.array([[100.0, 100.0], [600.0, 100.0], [600.0, 600.0], [100.0, 600.0]])
CREEP_STEP = REF.creep_mm_s * REF.dt_s  # v_final·dt = 0.2 µm


def both_sides(params: AxisParams, target: float = 500.0, run: float = 20.0) -> tuple[float, float]:
    """Carriage after a long move to ``target`` from below and from above (§8 protocol)."""
    axis = PymunkAxis(params, start_mm=target)
    axis.place(target - run, "below")
    below = axis.approach(target)
    axis.place(target + run, "above")
    above = axis.approach(target)
    return below, above


# --- the play operator ----------------------------------------------------------------------


def test_half_play_reference_numbers():
    # §8: oracle reversal 2h = 23.924 µm (k = 1 N/µm), 20.000 µm (rigid); §5 dead bands.
    assert 2 * REF.half_play_mm == pytest.approx(23.924 * um, abs=0.001 * um)
    assert 2 * RIGID.half_play_mm == pytest.approx(20.0 * um, abs=1e-12)
    assert BRIDGE.half_play_mm == pytest.approx(19.66 * um, abs=0.005 * um)
    assert CoordinatographParams().y.half_play_mm == pytest.approx(11.47 * um, abs=0.005 * um)
    assert Z_COLUMN.offset_mm == pytest.approx(-44.34 * um, abs=0.01 * um)  # 44.335 exactly


def test_play_operator_is_a_clip():
    x = play([0.0, 5.0, 10.0], 5.0, 0.01)
    np.testing.assert_array_equal(x, [4.99, 5.0, 5.01])


def test_vectorised_play_equals_loop_of_scalar_calls():
    rng = np.random.default_rng(7)
    T = 64
    b = rng.uniform(0.0, 0.04, T)
    mu = rng.uniform(0.02, 0.3, T)
    m = rng.uniform(0.5, 10.0, T)
    k = rng.choice([0.5e6, 1e6, 2e6, np.inf], T)
    h = half_play_mm(b, mu, m, k)
    many = PlayAxis(REF, half_play_mm=h)
    single = [PlayAxis(REF, half_play_mm=h[i : i + 1]) for i in range(T)]
    many.place(0.0, "below")
    for axis in single:
        axis.place(0.0, "below")
    for _ in range(12):
        targets = rng.uniform(-50.0, 50.0, T)
        side = [None, "below", "above"][rng.integers(3)]
        got = many.approach(targets, side)
        want = np.concatenate([a.approach(t, side) for a, t in zip(single, targets, strict=True)])
        np.testing.assert_array_equal(got, want)
        assert got.shape == (T,)
    np.testing.assert_array_equal(many.nut, np.concatenate([a.nut for a in single]))


def test_half_play_broadcasts_like_scalar_calls():
    b = np.array([0.005, 0.02, 0.03])
    k = np.array([np.inf, 1e6, 2e6])
    vec = half_play_mm(b, 0.1, 2.0, k)
    loop = [float(half_play_mm(bi, 0.1, 2.0, ki)) for bi, ki in zip(b, k, strict=True)]
    np.testing.assert_array_equal(vec, loop)


# --- pymunk axis against the oracle ---------------------------------------------------------


def test_both_backends_implement_the_interface():
    assert isinstance(PymunkAxis(REF), LinearAxis)
    assert isinstance(PlayAxis(REF), LinearAxis)


@pytest.mark.parametrize("params", [REF, RIGID, replace(REF, backlash_mm=0.005)], ids=str)
def test_pymunk_agrees_with_play_operator(params):
    """A scripted session (direct moves, reversals, both unidirectional sides): ≤ 0.5 µm."""
    script = [
        (501.0, None),
        (500.3, None),  # reversal
        (500.31, None),  # 10 µm: inside the dead band, the carriage must not move
        (503.0, "below"),
        (502.0, "below"),  # needs a pre-position below
        (502.5, "above"),
        (499.0, None),
    ]
    sim = PymunkAxis(params, start_mm=500.0)
    oracle = PlayAxis(params)
    sim.place(498.0, "below")
    oracle.place(498.0, "below")
    for target, side in script:
        x_sim = sim.approach(target, side)
        x_play = float(oracle.approach(target, side)[0])
        assert abs(x_sim - x_play) <= 0.5 * um, (target, side, x_sim - x_play)
        assert sim.nut == pytest.approx(target, abs=1e-9)


def test_rigid_reversal_is_backlash_within_two_creep_steps():
    below, above = both_sides(RIGID)
    reversal = above - below
    b = RIGID.backlash_mm
    assert b - 2 * CREEP_STEP <= reversal <= b
    assert reversal == pytest.approx(19.601 * um, abs=0.005 * um)  # §8
    assert below - 500.0 == pytest.approx(-9.800 * um, abs=0.005 * um)


def test_compliant_reversal_is_dead_band_less_relaxation():
    below, above = both_sides(REF)
    deficit = 2 * REF.half_play_mm - (above - below)
    assert 0.0 <= deficit <= 2 * CREEP_STEP + 0.35 * um
    assert above - below == pytest.approx(23.442 * um, abs=0.005 * um)  # §8
    assert above - 500.0 == pytest.approx(-(below - 500.0), abs=0.005 * um)  # symmetric


def test_small_backlash_reference():
    below, above = both_sides(replace(REF, backlash_mm=0.005))
    assert above - below == pytest.approx(8.442 * um, abs=0.005 * um)  # §8


@pytest.mark.slow
@pytest.mark.parametrize(
    ("params", "reference_um"),
    [(replace(REF, dt_s=0.25e-3), 23.567), (replace(RIGID, dt_s=0.25e-3), 19.900)],
)
def test_reference_runs_at_quarter_millisecond(params, reference_um):
    below, above = both_sides(params)
    assert above - below == pytest.approx(reference_um * um, abs=0.005 * um)
    deficit = 2 * params.half_play_mm - (above - below)
    assert 0.0 <= deficit <= 2 * params.creep_mm_s * params.dt_s + 0.35 * um


def test_place_shortcut_matches_full_simulation():
    """§4: placing 2 mm before the end differs from simulating all 20 mm by ≈ 0.012 µm."""
    full = PymunkAxis(replace(REF, simulate_last_mm=math.inf), start_mm=480.0)
    full.place(480.0, "below")
    short = PymunkAxis(REF, start_mm=480.0)
    short.place(480.0, "below")
    x_full, x_short = full.approach(500.0), short.approach(500.0)
    assert abs(x_full - x_short) <= 0.05 * um
    assert short.steps < full.steps


def test_targets_one_micrometre_apart():
    """§8: long approaches to targets 1 µm apart put the carriage 1.000 ± 0.004 µm apart."""
    axis = PymunkAxis(REF)
    x = []
    for i in range(3):
        axis.place(9.0, "below")
        x.append(axis.approach(10.0 + i * um) - i * um)
    np.testing.assert_allclose(np.diff(x), 0.0, atol=0.004 * um)


def test_velocity_plan_respects_acceleration_and_creep():
    plan = velocity_plan(5.0, REF)
    speeds = np.array([v for v, _ in plan])
    n_stair = round(REF.stair_s / REF.dt_s)
    assert np.all(
        np.abs(np.diff(np.concatenate([[0.0], speeds]))) <= REF.accel_mm_s2 * REF.stair_s + 1e-12
    )
    assert all(n >= n_stair for v, n in plan if v > REF.creep_mm_s)  # levels held ≥ one stair
    assert plan[-1][0] == REF.creep_mm_s
    assert plan[-1][1] * CREEP_STEP >= REF.creep_distance_mm - 1e-12
    covered = sum(v * n for v, n in plan) * REF.dt_s
    assert 0.0 <= 5.0 - covered < CREEP_STEP + 1e-12
    assert max(speeds) == REF.slew_mm_s


# --- refusals -------------------------------------------------------------------------------


@pytest.mark.parametrize("backend", [PymunkAxis, PlayAxis])
def test_range_stops_refuse_and_nothing_moves(backend):
    params = replace(REF, name="Y", range_mm=(-100.0, 100.0))
    axis = backend(params)
    axis.place(0.0, "below")
    before = np.copy(axis.position)
    with pytest.raises(
        TravelRefusal,
        match=re.escape("axis Y: target 100.500000 mm is beyond the range stops [-100, 100] mm"),
    ) as info:
        axis.approach(100.5)
    assert (info.value.axis, info.value.value, info.value.low, info.value.high) == (
        "Y",
        100.5,
        -100.0,
        100.0,
    )
    with pytest.raises(TravelRefusal, match=r"axis Y: pre-position -100\.300000 mm is beyond"):
        axis.approach(-99.8, side="below")  # the final stroke would start beyond the stop
    with pytest.raises(TravelRefusal, match=r"axis Y: setting -250\.000000 mm"):
        axis.place(-250.0)
    np.testing.assert_array_equal(axis.position, before)
    assert isinstance(info.value, StereoplotterError)


def test_refusal_names_the_instrument_file():
    params = AxisParams.from_instrument(load_instrument("sc1"), "X")
    with pytest.raises(
        TravelRefusal,
        match=r"axis sc1 X: target 500\.000000 mm .*\[-250, 450\] mm of "
        r".*sc1\.yaml: model\.x_offset_mm \(assumed\)",
    ):
        PlayAxis(params).approach(500.0)


def test_bad_side_and_bad_parameters_are_refused():
    with pytest.raises(StereoplotterError, match="a PymunkAxis simulates one trial, found 2"):
        PymunkAxis(REF).approach([1.0, 2.0])
    assert PymunkAxis(REF).approach(np.array([0.5])) == pytest.approx(0.5, abs=0.02)
    with pytest.raises(
        StereoplotterError, match="side must be None, 'below' or 'above', found 'left'"
    ):
        PlayAxis(REF).approach(1.0, side="left")  # type: ignore[arg-type]
    with pytest.raises(StereoplotterError, match=r"axis Z: friction μ < 1 on a vertical axis"):
        replace(Z_COLUMN, friction=1.5)
    with pytest.raises(StereoplotterError, match="overtravel_mm > the dead band 2h"):
        replace(REF, backlash_mm=0.9)


# --- determinism ----------------------------------------------------------------------------


def _session(seed: int) -> list[str]:
    axis = PymunkAxis(REF, start_mm=10.0)
    out = [axis.approach(t, s) for t, s in [(12.0, None), (11.5, None), (11.0, "above")]]
    pen = Coordinatograph()
    out += list(pen.move_pen((123.4, 567.8), "below"))
    sheet = orient_sheet(
        CORNERS,
        np.random.default_rng(seed),
        operator=OperatorParams(acuity_mm=0.02, pointing_sigma_mm=0.015, pin_sigma_mm=0.03),
    )
    out += list(sheet.marks_mm.ravel()) + [sheet.rotation_error_rad]
    return [float(v).hex() for v in out]


def test_same_seed_same_bits():
    assert _session(11) == _session(11)
    assert _session(11)[-9:] != _session(12)[-9:]  # the seed does reach the sheet


# --- strategies on the coordinatograph ------------------------------------------------------


def test_unidirectional_strategy_gives_a_constant_index_error():
    rng = np.random.default_rng(3)
    targets = rng.uniform(50.0, 750.0, (12, 2))
    direct, unidirectional = Coordinatograph(), Coordinatograph()
    e_direct = np.array([direct.move_pen(t) - t for t in targets])
    e_uni = np.array([unidirectional.move_pen(t, "below") - t for t in targets])
    h = direct.dead_band_mm
    assert np.all(np.ptp(e_uni, axis=0) < 0.01 * um)
    assert np.all(np.abs(e_uni.mean(axis=0) + h) <= 0.5 * um)  # index ≈ −h
    assert np.all(np.ptp(e_direct, axis=0) > 1.9 * h - 1 * um)  # direct: spread ≈ 2h
    # §5 reference: X −19.32 (constant), Y −11.25 (constant) at 10 iterations
    np.testing.assert_allclose(e_uni.mean(axis=0), [-19.32 * um, -11.25 * um], atol=0.02 * um)


def test_fast_coordinatograph_is_the_oracle():
    fast, sim = Coordinatograph(fast=True), Coordinatograph()
    for target in ([200.0, 300.0], [199.0, 310.0], [205.0, 305.0]):
        np.testing.assert_allclose(fast.move_pen(target), sim.move_pen(target), atol=0.5 * um)


def test_coordinatograph_refuses_beyond_the_table():
    params = CoordinatographParams.from_instrument(load_instrument("sc1"))
    c = Coordinatograph(params, fast=True)
    with pytest.raises(
        TravelRefusal,
        match=r"axis coordinatograph Y: target 900\.000000 mm .*\[0, 800\] mm of .*table_mm",
    ):
        c.move_pen((100.0, 900.0))
    np.testing.assert_array_equal(c.counters, [400.0, 400.0])  # X did not move either


# --- Z column under gravity -----------------------------------------------------------------


def test_z_column_sags_by_half_backlash_plus_load():
    axis = PymunkAxis(Z_COLUMN, start_mm=200.0)
    axis.place(190.0, "below")
    from_below = axis.approach(200.0) - 200.0
    axis.place(210.0, "above")
    from_above = axis.approach(200.0) - 200.0
    p = Z_COLUMN
    sag = p.backlash_mm / 2 + (p.mass_kg + p.follower_mass_kg) * G_MM_S2 / p.stiffness_kg_s2
    f_over_k = p.friction_force / p.stiffness_kg_s2
    assert abs(from_below + sag) <= f_over_k
    assert abs(from_above + sag) <= f_over_k
    assert from_below < from_above  # friction adds to the load going up
    assert from_below == pytest.approx(-44.66 * um, abs=0.01 * um)  # §7
    assert from_above == pytest.approx(-44.01 * um, abs=0.01 * um)
    oracle = PlayAxis(p)
    oracle.place(190.0, "below")
    assert abs(float(oracle.approach(200.0)[0]) - 200.0 - from_below) <= 0.5 * um


def test_horizontal_axis_ignores_gravity_in_a_shared_space():
    z = PymunkAxis(Z_COLUMN, start_mm=200.0)
    x = PymunkAxis(REF, z.space, offset_mm=-500.0, start_mm=50.0)
    x.place(50.0)
    for _ in range(300):
        z.space.step(REF.dt_s)
    assert abs(x.position - 50.0) < 1e-9


# --- sheet on the table ---------------------------------------------------------------------


def test_handwheel_direction():
    """mechanics.md §10.7: a positive rate turns the sheet counter-clockwise about the pin."""
    sheet = SheetOnTable(CORNERS)
    sheet.pin(CORNERS[0])
    before = sheet.marks()[2]
    sheet.turn(0.01, 200)
    after = sheet.marks()[2]
    radius = before - CORNERS[0]
    tangent = np.array([-radius[1], radius[0]]) / np.hypot(*radius)
    assert sheet.angle_rad == pytest.approx(0.01 * 0.2, rel=0.05)
    assert (after - before) @ tangent > 0
    np.testing.assert_allclose(sheet.marks()[0], CORNERS[0], atol=1e-9)  # the pin holds


def test_sheet_ideal_drives_zero_acuity_leave_nothing():
    r = orient_sheet(CORNERS, np.random.default_rng(0))
    assert r.converged and r.passed
    assert np.abs(r.residuals_mm).max() < 0.01 * um
    assert r.misclosure_norm_mm < 0.01 * um
    assert abs(r.rotation_error_rad) < 0.01 * arcsec


def test_pin_error_leaves_the_radial_residual():
    e = np.array([0.05, -0.03])  # §6
    r = orient_sheet(CORNERS, np.random.default_rng(0), pin_error_mm=e)
    expected = pin_radial_residual(e, CORNERS[0], CORNERS[2])
    np.testing.assert_allclose(r.residuals_mm[2], expected, atol=0.01 * um)
    radial = (CORNERS[2] - CORNERS[0]) / np.hypot(*(CORNERS[2] - CORNERS[0]))
    tangential = r.residuals_mm[2] - (r.residuals_mm[2] @ radial) * radial
    assert np.hypot(*tangential) < 0.01 * um
    assert np.hypot(*r.residuals_mm[0]) == pytest.approx(np.hypot(*e), abs=0.01 * um)


def test_finite_acuity_and_real_drives_stay_within_the_corner_tolerance():
    spec = load_instrument("sc1")
    operator = OperatorParams(acuity_mm=0.02)
    r = orient_sheet(
        CORNERS,
        np.random.default_rng(5),
        operator=operator,
        coordinatograph=Coordinatograph(),
        side="below",
        tolerance_mm=spec.corner_tolerance_mm,
    )
    assert r.converged and r.passed
    tangential_left = r.residuals_mm[2]
    assert 0.0 < np.hypot(*tangential_left) < 0.1  # acuity + drives: tens of µm, not mm


@pytest.mark.slow
def test_play_monte_carlo_agrees_with_pymunk_on_a_sample():
    """The bulk path: sampled axes under the play operator vs pymunk on 8 of the trials."""
    rng = np.random.default_rng(2024)
    T = 10_000
    b = rng.uniform(0.005, 0.03, T)
    mu = rng.uniform(0.05, 0.2, T)
    m = rng.uniform(1.0, 10.0, T)
    k = rng.uniform(0.5, 3.0, T) * N_PER_UM
    bulk = PlayAxis(REF, half_play_mm=half_play_mm(b, mu, m, k))
    bulk.place(0.0, "below")
    x_bulk = bulk.approach(1.0)
    bulk_reversal = bulk.approach(0.5) - x_bulk
    for i in rng.choice(T, 8, replace=False):
        p = replace(REF, backlash_mm=b[i], friction=mu[i], mass_kg=m[i], stiffness_kg_s2=k[i])
        axis = PymunkAxis(p)
        axis.place(0.0, "below")
        x = axis.approach(1.0)
        assert abs(x - x_bulk[i]) <= 0.5 * um
        assert abs(axis.approach(0.5) - x - bulk_reversal[i]) <= 1.0 * um
