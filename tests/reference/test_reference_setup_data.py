"""Reference tests of the setup-data equations (6.1)–(6.15), Kushtin & Lyskov 1984, §26
(OCR L3682–3826). The book prints few numbers here; where it prints none the reference is an
independent computation (rigorous collinearity through the affine model of ``kinematics.md`` §2).
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import deg, mm, um
from numpy.testing import assert_allclose

from stereoplotter.geometry.collinearity import photo_to_object
from stereoplotter.geometry.rotation import rotation_matrix
from stereoplotter.geometry.similarity import fit_similarity_with_reflection
from stereoplotter.geometry.transformed import (
    transformed_coordinates,
    transformed_x_single_tilt,
    transformed_y_single_tilt,
)
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.setup.equations import (
    base_components,
    base_z_correction,
    counter_scale_left,
    counter_scale_right,
    decentration,
    height_correction,
    height_scale_reading,
    instrument_principal_distance,
    mark_span,
    model_height,
    sheet_corner_instrument_coordinates,
    sheet_corner_instrument_coordinates_book_form,
)
from stereoplotter.setup.sheet import compute_setup_sheet

F = 70.0 * mm  # §27 setting: f = 70 mm, marks at l = 85 mm (OCR L3950–3956)
L_MARK = 85.0 * mm


# --- (6.1)/(6.2) ---------------------------------------------------------------------------


@pytest.mark.parametrize("tilt_deg", [-3.0, -0.5, 0.7, 3.0])
def test_6_1_6_2_equal_3_17_for_a_single_tilt(tilt_deg):
    # Independent: the rigorous (3.17) with one tilt reproduces the book's single-axis forms.
    t = tilt_deg * deg
    for x in (-L_MARK, L_MARK):
        rigorous = transformed_coordinates([x, 0.0], rotation_matrix(t, 0, 0), F)[0]
        assert transformed_x_single_tilt(x, t, F) == pytest.approx(rigorous, abs=1e-9 * um)
    for y in (-L_MARK, L_MARK):
        rigorous = transformed_coordinates([0.0, y], rotation_matrix(0, t, 0), F)[1]
        assert transformed_y_single_tilt(y, t, F) == pytest.approx(rigorous, abs=1e-9 * um)


@pytest.fixture(scope="module")
def pair60_sheet():
    sc = load_scenario("pair60")
    return compute_setup_sheet(sc, load_instrument("sc1"), rng=np.random.default_rng(sc.seed))


def _rigorous_y(photo, mark, f):
    # (3.17) rigorous with the single tilt ω, on the measured mark's y (the book's (6.2) frame)
    y = photo.marks_measured_mm[mark][1]
    return transformed_coordinates([0.0, y], rotation_matrix(0.0, photo.omega, 0.0), f)[1]


def test_6_5_sheet_mark_span_applies_n_once(pair60_sheet):
    # (6.5) L = n·(y⁰₃ − y⁰₄) on the pair60/SC-1 sheet against an independent computation: y⁰ of
    # the measured marks 3, 4 through the rigorous (3.17) with the photo's ω, times n once.
    # ERRATA: the printed (6.1)/(6.2) carry n and (6.5) multiplies again; n² would put L off by
    # the factor n ≈ 1.69 (≈ 200 mm), far beyond the 0.018 mm tolerance of the L check.
    f = pair60_sheet.focal_length_corrected_mm
    for photo in pair60_sheet.photos:
        span = photo.n * (_rigorous_y(photo, "3", f) - _rigorous_y(photo, "4", f))
        assert photo.mark_span_mm == pytest.approx(span, abs=1e-9)
        assert float(mark_span(photo.n, span / photo.n, 0.0)) == pytest.approx(span, abs=1e-9)
        assert abs(photo.n * photo.mark_span_mm - span) > 100.0  # the n² reading is refused


# --- (6.3), (6.4) ---------------------------------------------------------------------------


def test_6_3_sc1_book_example():
    # OCR L3715: D_max = 185 mm for SC-1; §27 (L3956) works with n = 1.42 → f_пр ≈ 130 mm.
    assert float(counter_scale_left(185.0, 130.0)) == pytest.approx(1.42, abs=0.005)


def test_6_4_geometric_sign_and_book_sign():
    # setup-data.md acceptance: right station 20 m higher at M_в = 5000 (f_пр = 130 mm).
    n_l = float(counter_scale_left(185.0, 130.0))
    n_r = float(counter_scale_right(n_l, 1000.0, 1020.0, 130.0, 5000))
    n_r_book = float(counter_scale_right(n_l, 1000.0, 1020.0, 130.0, 5000, book_sign=True))
    assert n_r > n_l and n_r_book < n_l
    # Independent: n_п = D_п/f_пр with D_п = D_max + b_z′, b_z′ = 20 m·1000/5000 = 4 mm
    assert n_r == pytest.approx((185.0 + 4.0) / 130.0, abs=1e-15)
    assert n_r_book == pytest.approx((185.0 - 4.0) / 130.0, abs=1e-15)


# --- scales, base, (6.5), (6.6) through the affine model -----------------------------------


def _affine_model_point(ground_m, mg, mv):
    """Ground → model mm: X/M_г, Y/M_г, Z/M_в (kinematics.md §2.1)."""
    g = np.asarray(ground_m, float)
    return np.column_stack([g[..., 0] * 1000 / mg, g[..., 1] * 1000 / mg, g[..., 2] * 1000 / mv])


def test_6_5_mark_span_is_the_model_distance_of_the_mark_rays():
    # Independent: intersect the rays through marks 3 and 4 (single tilt ω) with the ground plane
    # at depth H, scale with the affine model, and compare the Y distance with (6.5).
    omega, mg, mv = 1.5 * deg, 12500, 8000
    f_pr = float(instrument_principal_distance(F, mg, mv))
    n = float(counter_scale_left(185.0, f_pr))
    depth_m = 185.0 * mv / 1000.0  # the plane of n_л: D = D_max
    centre = np.array([0.0, 0.0, depth_m])
    m = rotation_matrix(0.0, omega, 0.0)
    ground = photo_to_object([[0.0, L_MARK], [0.0, -L_MARK]], 0.0, centre, m, F)
    model = _affine_model_point(ground, mg, mv)
    y3 = transformed_y_single_tilt(L_MARK, omega, F)
    y4 = transformed_y_single_tilt(-L_MARK, omega, F)
    assert float(mark_span(n, y3, y4)) == pytest.approx(model[0, 1] - model[1, 1], abs=1e-9)


def test_6_6_model_height_is_the_counter_coefficient_of_the_point():
    # Independent: a ground point at height Z below S_л; its counter offset divided by its
    # rectified coordinate is n_i = Z_i/f_пр with Z_i from (6.6).
    mg, mv = 12500, 8000
    f_pr = float(instrument_principal_distance(F, mg, mv))
    centre = np.array([0.0, 0.0, 1550.0])
    m = rotation_matrix(0.6 * deg, -0.4 * deg, 0.8 * deg)
    point = photo_to_object([40.0, -25.0], 180.0, centre, m, F)
    x0 = transformed_coordinates([40.0, -25.0], m, F)
    offset_mm = (point[:2] - centre[:2]) * 1000 / mg
    z_i = float(model_height(1550.0 - 180.0, mv))
    assert_allclose(offset_mm / x0, z_i / f_pr, rtol=1e-12)


def test_base_components_and_scale_chain():
    mg, mv = 12500, 8000
    b = base_components([0, 0, 1550.0], [1440.0, 15.0, 1560.0], mg, mv)
    assert_allclose(b, [1440 * 1000 / mg, 15 * 1000 / mg, 10 * 1000 / mv], atol=1e-12)
    # b_z′ = k·b_z with k = f_пр/f′ = M_г/M_в (DRO60 "k·b_z")
    k = float(instrument_principal_distance(F, mg, mv)) / F
    assert b[2] == pytest.approx(k * 10 * 1000 / mg, abs=1e-12)


def test_decentration_is_the_principal_point_offset_from_the_plumb():
    # The plumb point of a photo with α alone lies at x = −f tan α: the decentration f′·tan α is
    # the distance of the principal point from it (kinematics.md §2.4).
    a = 2.0 * deg
    nadir_x = transformed_x_single_tilt(-F * np.tan(a), a, F)
    assert nadir_x == pytest.approx(0.0, abs=1e-12)
    assert float(decentration(F, a)) == pytest.approx(F * np.tan(a), abs=1e-15)


# --- (6.9)–(6.11), (6.15) ------------------------------------------------------------------


def test_6_9_6_10_first_order_span_corrections():
    # L ∝ D at fixed f_пр: at a depth D′ off the target D the measured span is L′ = L·D′/D.
    # (6.9)/(6.10), evaluated with the target D, give back D − D′ exactly; with the reading D′
    # (as the book does) the error is second order, (D − D′)²/D.
    d_target, d_actual, span, mv = 185.0, 184.2, 172.4, 8000
    measured = span * d_actual / d_target
    dz_m = float(height_correction(d_target, span - measured, span, mv))
    assert dz_m * 1000 / mv == pytest.approx(d_target - d_actual, abs=1e-12)
    step = float(base_z_correction(d_actual, span - measured, span))
    assert abs(step - (d_target - d_actual)) <= (d_target - d_actual) ** 2 / d_target + 1e-12


def test_6_15_height_scale_reading():
    # The height scale reads const − D·M_в/1000; MO_Z is read at D = n_л·f_пр. A point with
    # Z_i = D_max − 10 mm (80 m higher at M_в = 8000) reads MO_Z + 80 m.
    n_l, f_pr, mv = 185.0 / 109.375, 109.375, 8000
    assert float(height_scale_reading(500.0, 175.0, n_l, f_pr, mv)) == pytest.approx(580.0)


def test_6_12_6_13_sheet_readings_against_rigorous_transform(pair60_sheet):
    # The pair60/SC-1 sheet's O_Y4,л (6.12) and O_X1,п (6.13) against an independent computation:
    # n times the rigorous (3.17) coordinate of the measured mark with the single tilt (ω for y,
    # α for x); the book form prints MO − |n·y⁰| to the 0.001 mm it shows.
    rows = {r["reading"]: r for r in pair60_sheet.readings}
    left, right = pair60_sheet.photos
    f = pair60_sheet.focal_length_corrected_mm
    y4 = left.n * _rigorous_y(left, "4", f)
    x1 = right.n * transformed_coordinates(
        [right.marks_measured_mm["1"][0], 0.0], rotation_matrix(right.alpha, 0.0, 0.0), f
    )[0]
    for name, zero, expected in (("O_Y4,л", "MO_Y", y4), ("O_X1,п", "MO_X,п", x1)):
        row = rows[name]
        assert row["zero_reading"] == zero
        assert row["value"] == pytest.approx(expected, abs=1e-9)
        assert expected < 0
        printed = float(row["book_form"].split("−")[1])
        assert printed == pytest.approx(abs(expected), abs=0.0005)


# --- (6.7), (6.8) --------------------------------------------------------------------------


def test_6_7_model_scale_form_equals_book_form_with_photo_scale():
    # setup-data.md: the printed (6.7) with n_л and M_photo = n_л·M_г gives the same x′.
    rng = np.random.default_rng(4)
    north = 6.167e6 + rng.uniform(-2000, 2000, 5)
    east = 5.352e6 + rng.uniform(-2000, 2000, 5)
    X, Y = east - 5.352e6 + 3.0, north - 6.167e6 - 2.0  # axis swap + shift (reflection)
    fit = fit_similarity_with_reflection(north, east, X, Y)
    corners_n, corners_e = north[:4], east[:4]
    n_l, mg = 1.6914, 12500
    model = sheet_corner_instrument_coordinates(fit, corners_n, corners_e, mg, (-720.0, 0.0))
    book = sheet_corner_instrument_coordinates_book_form(
        fit, corners_n, corners_e, n_l, n_l * mg, (-720.0, 0.0)
    )
    assert_allclose(model, book, atol=1e-12)
    # and the model coordinate is the ground offset from S_л at 1:M_г
    assert_allclose(model[:, 0], (X[:4] + 720.0) * 1000 / mg, atol=1e-6)
