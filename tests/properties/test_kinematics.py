"""Tests of the pure kinematics (``stereoplotter.instrument.kinematics``, kinematics.md §3–§4).

Behaviour and identities only; the §5/§6 reference numbers are in test_reference_kinematics.py.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import deg, mm, um
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from stereoplotter.errors import StereoplotterError
from stereoplotter.geometry.collinearity import object_to_photo
from stereoplotter.geometry.rotation import rotation_matrix
from stereoplotter.geometry.transformed import (
    transformed_coordinates,
    transformed_x_single_tilt,
    transformed_y_single_tilt,
)
from stereoplotter.instrument.decentration_variants import (
    DECENTRATION_VARIANTS,
    decentration_variant,
)
from stereoplotter.instrument.kinematics import (
    CorrectionUnit,
    InstrumentSetting,
    counters_from_homologous_points,
    counters_from_photo,
    depths_of_homologous_points,
    marks_from_counters,
    parallaxes_at_marks,
    photo_from_rod,
    rod_from_counters,
    rod_from_photo,
    rods_intersection,
    x_parallaxes_at_marks,
)
from stereoplotter.instrument.knobs import (
    correction_angle,
    dependent_decentration_change,
    represented_tilt_tangent,
    set_decentrations,
    turn_correction_knob,
    unit_for_orientation,
)
from stereoplotter.procedure.selftest import SyntheticPair, sanity_checks

tilts = st.floats(-5.0, 5.0).map(lambda t: t * deg)
kappas = st.floats(-10.0, 10.0).map(lambda t: t * deg)
coords = st.floats(-100.0, 100.0)
focals = st.floats(50.0, 300.0)


# --- (6.1)/(6.2) on the fiducial axes ----------------------------------------------------------


@settings(max_examples=60)
@given(alpha=tilts, omega=tilts, x=coords, f=focals, strict=st.booleans())
def test_axes_reproduce_6_1_and_6_2(alpha, omega, x, f, strict):
    # kinematics.md §3.3: on the fiducial axes the unit is (6.1)/(6.2) for any α, ω combination.
    unit = unit_for_orientation(alpha, omega, 0.0, f, strict_per_axis=strict)
    xi = rod_from_photo([x, 0.0], unit)[0]
    eta = rod_from_photo([0.0, x], unit)[1]
    assert abs(xi - transformed_x_single_tilt(x, alpha, f)) <= 1e-6 * um
    assert abs(eta - transformed_y_single_tilt(x, omega, f)) <= 1e-6 * um
    # and the forward map brings the rod back onto the axis
    back = photo_from_rod(rod_from_photo([x, 0.0], unit), unit)
    assert_allclose(back, [x, 0.0], atol=1e-6 * um)


def test_axes_vectorised_over_many_points():
    x = np.linspace(-90.0, 90.0, 181)
    alpha, omega = 2.5 * deg, -1.7 * deg
    unit = unit_for_orientation(alpha, omega, 0.0, 100.0)
    pts = np.stack([x, np.zeros_like(x)], axis=-1)
    assert_allclose(
        rod_from_photo(pts, unit)[:, 0], transformed_x_single_tilt(x, alpha, 100.0), atol=1e-9
    )


def test_per_axis_approximation_size():
    # kinematics.md §3.3: against rigorous collinearity the axis formulas (and the unit) differ by
    # 3.3 / 13.3 / 128 µm at the fiducial l = 85 mm for α = ω = 0.5 / 1 / 3°. Read here as the
    # axis coordinate x⁰ at mark 2 (+l, 0), the one (6.1) gives; the other coordinates of the
    # marks differ by up to twice as much (6.5 µm in ξ at mark 3 for 0.5°), which the document
    # does not tabulate.
    for t, printed in ((0.5, 3.3), (1.0, 13.3), (3.0, 128.0)):
        a = t * deg
        unit = unit_for_orientation(a, a, 0.0, 100.0)
        exact = transformed_coordinates([85.0, 0.0], rotation_matrix(a, a, 0.0), 100.0)
        err = abs(rod_from_photo([85.0, 0.0], unit)[0] - exact[0])
        assert err / um == pytest.approx(printed, rel=0.01, abs=0.05)


# --- round trips -------------------------------------------------------------------------------


@settings(max_examples=60)
@given(
    alpha=tilts,
    omega=tilts,
    kappa=kappas,
    x=coords,
    y=coords,
    f=focals,
    strict=st.booleans(),
    ex=st.floats(-10, 10),
    cy=st.floats(-10, 10),
)
def test_photo_rod_photo_round_trip(alpha, omega, kappa, x, y, f, strict, ex, cy):
    unit = CorrectionUnit(
        f,
        np.tan(alpha),
        np.tan(omega),
        ex,
        f * np.tan(omega),
        kappa,
        plane_decentration_y_mm=cy,
        strict_per_axis=strict,
    )
    back = photo_from_rod(rod_from_photo([x, y], unit), unit)
    assert_allclose(back, [x, y], atol=1e-9 * mm)
    again = rod_from_photo(photo_from_rod([x, y], unit), unit)
    assert_allclose(again, [x, y], atol=1e-9 * mm)


@settings(max_examples=60)
@given(
    a=st.lists(tilts, min_size=4, max_size=4),
    k=st.lists(kappas, min_size=2, max_size=2),
    x=st.floats(-50.0, 150.0),
    y=st.floats(-100.0, 100.0),
    d=st.floats(150.0, 220.0),
    b=st.tuples(st.floats(60.0, 120.0), st.floats(-5.0, 5.0), st.floats(-10.0, 10.0)),
    mo=st.tuples(st.floats(-200, 200), st.floats(-200, 200)),
)
def test_counters_marks_counters_round_trip(a, k, x, y, d, b, mo):
    setting = InstrumentSetting(130.0, *b, *mo)
    left = unit_for_orientation(a[0], a[1], k[0], 100.0)
    right = unit_for_orientation(a[2], a[3], k[1], 100.0)
    xm, ym = mo[0] + x, mo[1] + y
    pl, pr = marks_from_counters(xm, ym, d, setting, left, right)
    r = counters_from_homologous_points(pl, pr, setting, left, right)
    assert_allclose([r.x_mm, r.y_mm, r.depth_mm], [xm, ym, d], atol=1e-9 * mm)
    assert abs(r.y_parallax_mm) <= 1e-9 * mm


def test_monocular_counters_agree_with_rods():
    setting = InstrumentSetting(130.0, 100.0, 2.0, 3.0, 10.0, -5.0)
    unit = unit_for_orientation(1.0 * deg, -2.0 * deg, 0.5 * deg, 100.0)
    for side in ("left", "right"):
        xy = counters_from_photo([20.0, -30.0], 185.0, unit, setting, side)
        rod = rod_from_counters(xy[0], xy[1], 185.0, setting, side)
        assert_allclose(photo_from_rod(rod, unit), [20.0, -30.0], atol=1e-12)


def test_fiducial_target_is_the_book_reading():
    # (6.12): O_Y3 = MO_Y + n·y⁰₃ with n = D/f_пр (6.3), κ = 0, unit at the true settings.
    omega = 1.5 * deg
    unit = unit_for_orientation(0.7 * deg, omega, 0.0, 100.0)
    setting = InstrumentSetting(130.0, model_origin_x_mm=50.0, model_origin_y_mm=20.0)
    xy = counters_from_photo([0.0, 85.0], 185.0, unit, setting)
    n = 185.0 / 130.0
    assert xy[1] == pytest.approx(20.0 + n * transformed_y_single_tilt(85.0, omega, 100.0))


# --- exact rectification, conventions ---------------------------------------------------------


def test_exact_rectification_gives_the_affine_model():
    # kinematics.md §2 and §5 sanity: rigorous rectified coordinates in the rods give q ≈ 0 and
    # the model is the affine image of the ground (M_в = M_г/k, base k·b_z).
    s = sanity_checks(SyntheticPair(), tilt_deg=3.0)
    assert s["exact_rectification_max_q_um"] * um <= 1e-9 * mm
    assert s["affine_model_max_error_um"] * um <= 1e-9 * mm


def test_unit_at_zero_is_the_identity():
    unit = CorrectionUnit(100.0)
    pts = np.array([[10.0, -20.0], [0.0, 0.0], [85.0, 85.0]])
    assert_allclose(photo_from_rod(pts, unit), pts)
    assert_allclose(rod_from_photo(pts, unit), pts)


def test_kappa_turns_the_cassette_counter_clockwise():
    # A cassette turned by κ > 0 carries the photo axes counter-clockwise (as κ of Eq. (2.50)), so
    # the photo point under a rod on +ξ has y < 0 in the photo system.
    unit = CorrectionUnit(100.0, kappa=1.0 * deg)
    x, y = photo_from_rod([50.0, 0.0], unit)
    assert x > 0 and y < 0
    assert np.degrees(np.arctan2(-y, x)) == pytest.approx(1.0)


def test_positive_alpha_moves_the_principal_point_to_plus_x():
    # conventions: α > 0 puts the principal point at +f tan α in the rectified frame.
    unit = unit_for_orientation(2.0 * deg, 0.0, 0.0, 100.0)
    assert rod_from_photo([0.0, 0.0], unit)[0] == pytest.approx(100.0 * np.tan(2.0 * deg))


def test_unit_matches_collinearity_for_a_single_tilt():
    # With one tilt and κ the unit is exact everywhere along that axis, also with κ ≠ 0 (κ is
    # innermost, R = R_α R_ω R_κ).
    kappa = 1.2 * deg
    m = rotation_matrix(0.0, 2.0 * deg, kappa)
    unit = unit_for_orientation(0.0, 2.0 * deg, kappa, 100.0)
    # photo points whose rotated coordinates (u, v) lie on the v axis
    v = np.linspace(-80, 80, 9)
    c, s = np.cos(kappa), np.sin(kappa)
    pts = np.stack([s * v, c * v], axis=-1)  # R₂(κ)ᵀ(0, v)
    assert_allclose(rod_from_photo(pts, unit), transformed_coordinates(pts, m, 100.0), atol=1e-9)


# --- broadcasting ----------------------------------------------------------------------------


def test_scalar_and_array_calls_agree():
    rng = np.random.default_rng(7)
    a = rng.uniform(-3, 3, (5, 4)) * deg
    k = rng.uniform(-2, 2, (5, 2)) * deg
    pts = rng.uniform(-80, 80, (11, 2))
    left = unit_for_orientation(a[:, 0:1], a[:, 1:2], k[:, 0:1], 100.0)
    rods = rod_from_photo(pts, left)  # (5, 11, 2)
    photos = photo_from_rod(pts, left)
    assert rods.shape == photos.shape == (5, 11, 2)
    for i in range(5):
        one = unit_for_orientation(float(a[i, 0]), float(a[i, 1]), float(k[i, 0]), 100.0)
        for j in range(11):
            assert_allclose(rod_from_photo(pts[j], one), rods[i, j], rtol=0, atol=1e-12)
            assert_allclose(photo_from_rod(pts[j], one), photos[i, j], rtol=0, atol=1e-12)
    setting = InstrumentSetting(130.0, 100.0, 1.0, 2.0)
    right = unit_for_orientation(a[:, 2:3], a[:, 3:4], k[:, 1:2], 100.0)
    xs, ys, ds = pts[:, 0] + 50.0, pts[:, 1], np.full(11, 185.0)
    pl, pr = marks_from_counters(xs, ys, ds, setting, left, right)
    assert pl.shape == pr.shape == (5, 11, 2)
    r = counters_from_homologous_points(pl, pr, setting, left, right)
    assert r.x_mm.shape == (5, 11)
    one_r = unit_for_orientation(float(a[3, 2]), float(a[3, 3]), float(k[3, 1]), 100.0)
    one_l = unit_for_orientation(float(a[3, 0]), float(a[3, 1]), float(k[3, 0]), 100.0)
    s = counters_from_homologous_points(pl[3, 4], pr[3, 4], setting, one_l, one_r)
    assert_allclose(list(s), [r.x_mm[3, 4], r.y_mm[3, 4], r.depth_mm[3, 4], 0.0], atol=1e-9)


def test_stereo_against_rigorous_photos():
    # Homologous points from rigorous collinearity, units at the true settings: q is the small
    # per-axis residual (≤ 1 µm at 0.5° for these points; kinematics.md §6 gives 0.5 µm max).
    pair = SyntheticPair()
    t = np.array([0.5, -0.5, 0.5, 0.5]) * deg
    pl, pr = pair.photos(t)
    left = unit_for_orientation(t[0], t[1], pair.kappa_left, 100.0)
    right = unit_for_orientation(t[2], t[3], pair.kappa_right, 100.0)
    r = counters_from_homologous_points(pl, pr, pair.setting(), left, right)
    assert np.max(np.abs(r.y_parallax_mm)) < 1.0 * um
    assert np.max(np.abs(r.depth_mm - pair.true_depth_mm())) < 0.05 * mm


def test_rods_intersection_clears_x_parallax():
    setting = InstrumentSetting(130.0, 90.0, 1.0, 3.0)
    rl, rr = np.array([40.0, 10.0]), np.array([-20.0, 9.0])
    r = rods_intersection(rl, rr, setting)
    n_l = r.depth_mm / 130.0
    n_r = (r.depth_mm + 3.0) / 130.0
    assert n_l * rl[0] == pytest.approx(90.0 + n_r * rr[0])
    assert r.y_parallax_mm == pytest.approx((n_l * 10.0 - 1.0 - n_r * 9.0) / n_l)


# --- knob semantics (D1) and variants ----------------------------------------------------------


@settings(max_examples=40)
@given(t0=st.floats(-0.05, 0.05), t1=st.floats(-0.05, 0.05), k=st.floats(0.5, 3.0))
def test_knob_drag_is_f_times_delta_tan_theta_over_k(t0, t1, k):
    f = 100.0
    unit = turn_correction_knob(CorrectionUnit(f), "alpha", t0)
    after = turn_correction_knob(unit, "alpha", t1)
    expected = dependent_decentration_change(f, correction_angle(t0, k), correction_angle(t1, k), k)
    assert float(after.decentration_x_mm - unit.decentration_x_mm) == pytest.approx(
        float(expected), abs=1e-12
    )
    assert float(represented_tilt_tangent(correction_angle(t1, k), k)) == pytest.approx(t1)


def test_linkages():
    u = CorrectionUnit(100.0)
    lo = turn_correction_knob(u, "omega", 0.01, "L")
    assert (float(lo.decentration_y_mm), lo.plane_decentration_mm[1].item()) == (1.0, 1.0)
    ao = turn_correction_knob(u, "omega", 0.01, "A")
    assert (float(ao.decentration_y_mm), ao.plane_decentration_mm[1].item()) == (1.0, 0.0)
    bo = turn_correction_knob(u, "omega", 0.01, "B")
    assert (float(bo.decentration_y_mm), bo.plane_decentration_mm[1].item()) == (0.0, 0.0)
    s = set_decentrations(ao, 0.5, 2.0)
    assert [c.item() for c in s.plane_decentration_mm] == [0.5, 2.0]


def test_dependent_decentration_keeps_the_true_unit():
    # Turning both knobs from zero in linkage L gives exactly the unit at the true settings.
    alpha, omega = 1.3 * deg, -0.8 * deg
    u = turn_correction_knob(CorrectionUnit(100.0), "omega", np.tan(omega))
    u = turn_correction_knob(u, "alpha", np.tan(alpha))
    true = unit_for_orientation(alpha, omega, 0.0, 100.0)
    pts = np.array([[30.0, -60.0], [85.0, 85.0]])
    assert_allclose(rod_from_photo(pts, u), rod_from_photo(pts, true), atol=1e-12)


def test_variants_table():
    assert set(DECENTRATION_VARIANTS) == {"L", "A", "B", "B2", "S"}
    assert decentration_variant("S").strict_per_axis
    assert decentration_variant("S").linkage == "L"
    assert decentration_variant("B2").decentrations_first


def test_errors_name_the_valid_choices():
    with pytest.raises(StereoplotterError, match=r"unknown decentration variant 'C'.*L, A, B"):
        decentration_variant("C")
    with pytest.raises(StereoplotterError, match=r"linkage must be one of .*found 'X'"):
        turn_correction_knob(CorrectionUnit(100.0), "alpha", 0.0, "X")
    with pytest.raises(StereoplotterError, match=r"axis must be 'alpha' or 'omega', found 'k'"):
        turn_correction_knob(CorrectionUnit(100.0), "k", 0.0)
    with pytest.raises(StereoplotterError, match=r"side must be 'left' or 'right'"):
        rod_from_counters(0.0, 0.0, 185.0, InstrumentSetting(130.0), "middle")


def test_synthetic_photos_are_collinearity():
    pair = SyntheticPair()
    t = np.array([1.0, -1.0, -1.0, 1.0]) * deg
    pl, _ = pair.photos(t)
    m = rotation_matrix(t[0], t[1], pair.kappa_left)
    assert_allclose(pl, object_to_photo(pair.ground_points_m(), pair.station_left_m, m, 100.0))


def test_parallaxes_at_marks_are_the_marks_minus_the_photo_points_on_a_trial_grid():
    """On a (trials × points) grid large enough to be evaluated a block of rows at a time, the
    parallaxes equal :func:`marks_from_counters`' marks minus the given photo points, to the
    bit (the same arithmetic)."""
    rng = np.random.default_rng(3)
    trials, points = 700, 90
    setting = InstrumentSetting(
        130.0, base_x_mm=90.0 + rng.normal(0, 0.01, (trials, 1)), base_y_mm=0.5, base_z_mm=-1.0
    )
    left = CorrectionUnit(100.0, tan_alpha=rng.normal(0, 0.01, (trials, 1)), decentration_x_mm=0.2)
    right = CorrectionUnit(100.0, tan_omega=rng.normal(0, 0.01, (trials, 1)))
    x, y = rng.uniform(-50, 50, points), rng.uniform(-50, 50, points)
    depth = rng.uniform(120, 140, points)
    p0l, p0r = rng.uniform(-80, 80, (points, 2)), rng.uniform(-80, 80, (points, 2))
    pl, pr = marks_from_counters(x, y, depth, setting, left, right)
    dp, q = parallaxes_at_marks(x, y, depth, setting, left, right, p0l, p0r)
    assert dp.shape == q.shape == (trials, points)
    assert np.array_equal(dp, (pl - p0l)[..., 0] - (pr - p0r)[..., 0])
    assert np.array_equal(q, (pl - p0l)[..., 1] - (pr - p0r)[..., 1])


def test_x_parallaxes_and_depths_alone_are_those_of_the_full_maps_on_a_trial_grid():
    """δp alone (:func:`x_parallaxes_at_marks`) and D alone
    (:func:`depths_of_homologous_points`) on a (trials × points) grid evaluated a block of rows
    at a time equal, to the bit, the full maps' (the same arithmetic), strict per axis or not."""
    rng = np.random.default_rng(5)
    trials, points = 600, 80
    setting = InstrumentSetting(
        130.0, base_x_mm=90.0 + rng.normal(0, 0.01, (trials, 1)), base_y_mm=0.5, base_z_mm=-1.0
    )
    for strict in (False, True):
        left = CorrectionUnit(
            100.0,
            tan_alpha=rng.normal(0, 0.01, (trials, 1)),
            decentration_x_mm=0.2,
            plane_decentration_x_mm=0.3,
            plane_decentration_y_mm=-0.1,
            strict_per_axis=strict,
        )
        right = CorrectionUnit(100.0, tan_omega=rng.normal(0, 0.01, (trials, 1)), kappa=0.01)
        x, y = rng.uniform(-50, 50, points), rng.uniform(-50, 50, points)
        depth = rng.uniform(120, 140, points)
        p0l, p0r = rng.uniform(-80, 80, (points, 2)), rng.uniform(-80, 80, (points, 2))
        dp, _ = parallaxes_at_marks(x, y, depth, setting, left, right, p0l, p0r)
        alone = x_parallaxes_at_marks(x, y, depth, setting, left, right, p0l[:, 0], p0r[:, 0])
        assert alone.shape == (trials, points)
        assert np.array_equal(alone, dp)
        full = counters_from_homologous_points(p0l, p0r, setting, left, right)
        d = depths_of_homologous_points(p0l, p0r, setting, left, right)
        assert d.shape == full.depth_mm.shape == (trials, points)
        assert np.array_equal(d, full.depth_mm)
