"""Property and behaviour tests of the pure geometry (rotation, collinearity, (3.17), (6.1)/(6.2),
intersection, similarity (6.8), f′). Independent computations serve as references; the book's own
worked examples are in tests/reference/test_reference_resection.py."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import deg, mm, um
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from stereoplotter.errors import GeometryError
from stereoplotter.geometry.collinearity import object_to_photo, photo_to_object
from stereoplotter.geometry.film import corrected_focal_length, fiducial_spans_mm
from stereoplotter.geometry.intersection import space_intersection
from stereoplotter.geometry.rotation import (
    alternative_angles_from_matrix,
    angles_from_matrix,
    rotation_matrix,
    rotation_matrix_from_alternative_angles,
)
from stereoplotter.geometry.similarity import apply_similarity, fit_similarity_with_reflection
from stereoplotter.geometry.transformed import (
    transformed_coordinates,
    transformed_x_single_tilt,
    transformed_y_single_tilt,
)

tilt = st.floats(-10 * deg, 10 * deg)
swing = st.floats(-np.pi + 1e-6, np.pi - 1e-6)
photo_coordinate = st.floats(-100.0, 100.0)


# --- rotation, Eq. (2.50) -------------------------------------------------------------------


@given(tilt, tilt, swing)
def test_rotation_is_orthonormal_with_det_plus_one(alpha, omega, kappa):
    m = rotation_matrix(alpha, omega, kappa)
    assert_allclose(m @ m.T, np.eye(3), atol=1e-15)
    assert np.linalg.det(m) == pytest.approx(1.0, abs=1e-14)


@given(tilt, tilt, swing)
def test_rotation_elements_match_printed_formulas_2_50(alpha, omega, kappa):
    # Independent: the element formulas of (2.50) typed from the book (conventions.md §4).
    sa, ca, so, co, sk, ck = (
        np.sin(alpha),
        np.cos(alpha),
        np.sin(omega),
        np.cos(omega),
        np.sin(kappa),
        np.cos(kappa),
    )
    expected = [
        [ca * ck - sa * so * sk, -ca * sk - sa * so * ck, -sa * co],
        [co * sk, co * ck, -so],
        [sa * ck + ca * so * sk, -sa * sk + ca * so * ck, ca * co],
    ]
    assert_allclose(rotation_matrix(alpha, omega, kappa), expected, atol=1e-15)


@given(tilt, tilt, swing)
def test_angles_round_trip(alpha, omega, kappa):
    assert_allclose(
        angles_from_matrix(rotation_matrix(alpha, omega, kappa)), [alpha, omega, kappa], atol=1e-12
    )


@given(tilt, tilt, swing)
def test_alternative_angles_2_51_2_55_round_trip_and_relations(alpha, omega, kappa):
    m = rotation_matrix(alpha, omega, kappa)
    t, a0, k0 = alternative_angles_from_matrix(m)
    assert_allclose(rotation_matrix_from_alternative_angles(t, a0, k0), m, atol=1e-14)
    # (2.55): tan α = tan α₀ cos t, sin ω = sin α₀ sin t
    assert np.tan(alpha) == pytest.approx(np.tan(a0) * np.cos(t), abs=1e-12)
    assert np.sin(omega) == pytest.approx(np.sin(a0) * np.sin(t), abs=1e-12)


def test_alternative_angles_zero_is_kappa_minus_90():
    assert_allclose(
        rotation_matrix_from_alternative_angles(0, 0, 0),
        rotation_matrix(0, 0, -np.pi / 2),
        atol=1e-16,
    )


def test_rotation_broadcasts_and_scalar_agrees():
    a = np.array([0.01, -0.02, 0.03])
    batch = rotation_matrix(a, 0.02, a[::-1])
    assert batch.shape == (3, 3, 3)
    for i in range(3):
        assert_allclose(batch[i], rotation_matrix(a[i], 0.02, a[::-1][i]), atol=0)


# --- sign meanings (behaviour tests, conventions.md §4) --------------------------------------

F = 100.0 * mm


def test_alpha_positive_tilts_axis_towards_plus_x():
    m = rotation_matrix(3 * deg, 0, 0)
    view = m @ [0, 0, -1]
    assert view[0] > 0 and abs(view[1]) < 1e-16


def test_omega_positive_tilts_axis_towards_plus_y():
    m = rotation_matrix(0, 3 * deg, 0)
    assert (m @ [0, 0, -1])[1] > 0


def test_viewing_direction_formula():
    a, o = 2 * deg, -1.5 * deg
    assert_allclose(
        rotation_matrix(a, o, 0.7) @ [0, 0, -1],
        [np.sin(a) * np.cos(o), np.sin(o), -np.cos(a) * np.cos(o)],
        atol=1e-16,
    )


def test_kappa_positive_turns_photo_axes_counter_clockwise():
    # A point on the +x photo axis of a photo swung by κ > 0 appears at +Y on the ground.
    ground = photo_to_object([50.0, 0.0], 0.0, [0, 0, 1000.0], rotation_matrix(0, 0, 5 * deg), F)
    assert ground[1] > 0
    # First order: x⁰ = x − yκ, y⁰ = y + xκ (3.22)
    k = 1e-6
    xy0 = transformed_coordinates([30.0, 40.0], rotation_matrix(0, 0, k), F)
    assert_allclose(xy0, [30.0 - 40.0 * k, 40.0 + 30.0 * k], atol=1e-10)


def test_principal_point_transformed_position():
    # conventions.md §4: α = ω = 3°, f = 100 → (5.2408, 5.2480); exact (f tan α, f tan ω / cos α)
    a = o = 3 * deg
    xy0 = transformed_coordinates([0.0, 0.0], rotation_matrix(a, o, 0), F)
    assert_allclose(xy0, [F * np.tan(a), F * np.tan(o) / np.cos(a)], atol=1e-12)
    assert_allclose(xy0, [5.2408, 5.2480], atol=0.00005)


# --- collinearity (2.52)/(2.53) --------------------------------------------------------------


@given(tilt, tilt, swing, photo_coordinate, photo_coordinate, st.floats(-300.0, 300.0))
def test_collinearity_round_trip_photo_ground_photo(alpha, omega, kappa, x, y, Z):
    # ground -> photo -> ground: round trip <= 1e-9 mm at photo scale
    centre = np.array([1200.0, -300.0, 1500.0])
    m = rotation_matrix(alpha, omega, kappa)
    ground = photo_to_object([x, y], Z, centre, m, 70.0, (0.01, -0.02))
    back = object_to_photo(ground, centre, m, 70.0, (0.01, -0.02))
    assert_allclose(back, [x, y], atol=1e-9 * mm)


def test_collinearity_arrays_match_scalar_calls():
    rng = np.random.default_rng(7)
    pts = np.column_stack([rng.uniform(-500, 500, (10, 2)), rng.uniform(0, 100, 10)])
    m = rotation_matrix(0.02, -0.03, 0.4)
    batch = object_to_photo(pts, [0, 0, 1000.0], m, 100.0)
    for p, b in zip(pts, batch, strict=True):
        assert_allclose(object_to_photo(p, [0, 0, 1000.0], m, 100.0), b, atol=0)


def test_point_behind_camera_is_nan():
    assert np.all(np.isnan(object_to_photo([0, 0, 2000.0], [0, 0, 1000.0], np.eye(3), 100.0)))


# --- (3.17) and (6.1)/(6.2) -------------------------------------------------------------------


@given(tilt, photo_coordinate)
def test_single_axis_x_equals_3_17_for_alpha_only(alpha, x):
    # (6.1) without n is (3.17) when ω = κ = 0 (conventions.md §6)
    rigorous = transformed_coordinates([x, 0.0], rotation_matrix(alpha, 0, 0), F)
    assert_allclose(transformed_x_single_tilt(x, alpha, F), rigorous[0], atol=1e-9 * mm)
    assert abs(rigorous[1]) < 1e-12


@given(tilt, photo_coordinate)
def test_single_axis_y_equals_3_17_for_omega_only(omega, y):
    rigorous = transformed_coordinates([0.0, y], rotation_matrix(0, omega, 0), F)
    assert_allclose(transformed_y_single_tilt(y, omega, F), rigorous[1], atol=1e-9 * mm)


def test_single_axis_form_is_approximate_with_two_tilts():
    # conventions.md §6 caveat 1: α = ω = 3°, f = 100, mark (90, 0): (3.17) gives 100.092, 5.508,
    # (6.1) gives 99.955; difference 0.136 mm.
    a = o = 3 * deg
    rigorous = transformed_coordinates([90.0, 0.0], rotation_matrix(a, o, 0), F)
    assert_allclose(rigorous, [100.092, 5.508], atol=0.0005)
    assert transformed_x_single_tilt(90.0, a, F) == pytest.approx(99.955, abs=0.0005)
    assert rigorous[0] - transformed_x_single_tilt(90.0, a, F) == pytest.approx(0.136, abs=0.0015)


def test_first_order_3_22():
    # (3.22): x⁰ = x + (f + x²/f)α + (xy/f)ω − yκ, y⁰ = y + (xy/f)α + (f + y²/f)ω + xκ
    x, y, a, o, k = 60.0, -40.0, 1e-6, 2e-6, -1.5e-6
    first = [
        x + (F + x * x / F) * a + x * y / F * o - y * k,
        y + x * y / F * a + (F + y * y / F) * o + x * k,
    ]
    assert_allclose(transformed_coordinates([x, y], rotation_matrix(a, o, k), F), first, atol=1e-9)


# --- intersection --------------------------------------------------------------------------


def test_space_intersection_recovers_points_exactly():
    rng = np.random.default_rng(3)
    pts = np.column_stack([rng.uniform(100, 600, (20, 2)), rng.uniform(-50, 80, 20)])
    s1, s2 = np.array([0, 300, 1400.0]), np.array([720, 312, 1415.0])
    m1, m2 = rotation_matrix(0.02, -0.01, 0.03), rotation_matrix(-0.015, 0.02, -0.01)
    p1 = object_to_photo(pts, s1, m1, 70.0)
    p2 = object_to_photo(pts, s2, m2, 70.0)
    r = space_intersection(p1, p2, s1, m1, s2, m2, 70.0)
    assert_allclose(r.points_m, pts, atol=1e-9)
    assert np.max(r.miss_distance_m) < 1e-9
    # A y-parallax of 10 µm on the right photo produces a miss, in Y, ~ q·H/f = 0.2 m
    r = space_intersection(p1, p2 + [0, 0.010], s1, m1, s2, m2, 70.0)
    assert np.all(np.abs(r.miss_m[:, 1]) > 0.1)


# --- similarity with reflection (6.8) -------------------------------------------------------


def test_similarity_recovers_known_coefficients_exactly():
    rng = np.random.default_rng(11)
    north = rng.uniform(6.14e6, 6.15e6, 6)
    east = rng.uniform(2.35e5, 2.45e5, 6)
    a, b, cx, cy = -9.05e-5, 1.000327, -2.35e5, -6.14e6
    X = a * north + b * east + cx
    Y = -a * east + b * north + cy
    fit = fit_similarity_with_reflection(north, east, X, Y)
    assert_allclose([fit.a, fit.b], [a, b], rtol=0, atol=1e-13)
    assert_allclose([fit.cx_m, fit.cy_m], [cx, cy], atol=1e-6)
    assert fit.rms_m < 1e-6
    assert fit.determinant < 0
    assert fit.redundancy == 8


def test_similarity_axis_swap_and_residuals():
    north = np.array([0.0, 1000.0, 0.0, 1000.0])
    east = np.array([0.0, 0.0, 1000.0, 1000.0])
    fit = fit_similarity_with_reflection(north, east, east, north)
    assert_allclose([fit.a, fit.b, fit.cx_m, fit.cy_m], [0, 1, 0, 0], atol=1e-12)
    # Displace one point by 0.4 m in X_Ф: residuals sum to zero per axis, largest at that point
    X = east.copy()
    X[3] += 0.4
    fit = fit_similarity_with_reflection(north, east, X, north)
    assert_allclose(fit.residuals_m.sum(axis=0), 0, atol=1e-9)
    assert np.argmax(np.linalg.norm(fit.residuals_m, axis=1)) == 3
    assert_allclose(
        apply_similarity(fit, north, east) - np.column_stack([X, north]),
        fit.residuals_m,
        atol=1e-12,
    )


@pytest.mark.parametrize(
    ("north", "east", "message"),
    [
        ([1.0], [2.0], "at least 2 control points"),
        ([5.0, 5.0, 5.0], [7.0, 7.0, 7.0], "coincide"),
        ([1.0, 2.0], [3.0], "equal length"),
        ([1.0, np.nan], [3.0, 4.0], "finite"),
    ],
)
def test_similarity_refuses_bad_input(north, east, message):
    with pytest.raises(GeometryError, match=message):
        fit_similarity_with_reflection(north, east, east[: len(north)], north)


# --- f′ ------------------------------------------------------------------------------------


def test_corrected_focal_length_uniform_shrinkage():
    calibrated = fiducial_spans_mm({"1": [-85, 0], "2": [85, 0], "3": [0, 85], "4": [0, -85]})
    measured = calibrated * (1 - 2e-4)
    # a uniform scale change s equals a change of f by the same s ((1.22)): f′ = f(1 − 2e-4)
    assert float(corrected_focal_length(70.0, measured, calibrated)) == pytest.approx(
        70.0 * (1 - 2e-4), abs=1e-12
    )
    # And it is exactly what keeps (3.17) invariant: scaled photo coordinates with scaled f
    m = rotation_matrix(0.03, 0.02, 0.1)
    xy = np.array([40.0, -60.0])
    s = 1 - 2e-4
    assert_allclose(
        transformed_coordinates(xy * s, m, 70.0 * s),
        s * transformed_coordinates(xy, m, 70.0),
        atol=1e-3 * um,
    )


def test_corrected_focal_length_refuses_non_positive_span():
    with pytest.raises(GeometryError, match="positive finite measured"):
        corrected_focal_length(70.0, [0.0, 170.0], [170.0, 170.0])


# --- fiducial system ---------------------------------------------------------------------------


def test_fiducial_system_recovers_a_rotated_shifted_frame():
    from stereoplotter.geometry.fiducial import to_fiducial_system

    marks = np.array([[-85.0, 0.0], [85.0, 0.0], [0.0, 85.0], [0.0, -85.0]])
    pts = np.array([[10.0, 20.0], [-60.0, 45.0]])
    theta, shift = 0.03, np.array([101.0, 99.0])
    r = np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])
    for origin in ("intersection", "mean_of_marks"):
        back = to_fiducial_system(pts @ r.T + shift, marks @ r.T + shift, origin)
        assert_allclose(back, pts, atol=1e-12)


def test_fiducial_origins_differ_for_asymmetric_marks():
    from stereoplotter.geometry.fiducial import fiducial_frame

    marks = [[-85.0, 0.0], [85.0, 0.0], [1.0, 86.0], [1.0, -80.0]]
    o_int, _ = fiducial_frame(marks, "intersection")
    o_mean, _ = fiducial_frame(marks, "mean_of_marks")
    assert_allclose(o_int, [1.0, 0.0], atol=1e-12)  # lines 1–2 (y = 0) and 3–4 (x = 1)
    assert_allclose(o_mean, [0.5, 1.5], atol=1e-12)


@pytest.mark.parametrize(
    ("marks", "origin", "message"),
    [
        ([[0, 0], [0, 0], [0, 85], [0, -85]], "intersection", "marks 1 and 2 coincide"),
        ([[-85, 0], [85, 0], [-50, 1], [50, 1]], "intersection", "nearly\\) parallel"),
        ([[-85, 0], [85, 0], [0, 85], [0, -85]], "centroid", "expected one of intersection"),
    ],
)
def test_fiducial_frame_errors(marks, origin, message):
    from stereoplotter.geometry.fiducial import fiducial_frame

    with pytest.raises(GeometryError, match=message):
        fiducial_frame(marks, origin)


def test_transformed_and_single_tilt_scalar_and_array_calls_agree():
    xs = np.array([-80.0, -10.0, 35.0, 85.0])
    alphas = np.array([-0.05, 0.0, 0.02, 0.05])
    batch = transformed_x_single_tilt(xs, alphas, F)
    for x, a, b in zip(xs, alphas, batch, strict=True):
        assert transformed_x_single_tilt(x, a, F) == b
    m = rotation_matrix(alphas, -alphas, 0.1)
    pts = np.column_stack([xs, xs[::-1]])
    batch = transformed_coordinates(pts, m, F)
    for i in range(4):
        assert_allclose(transformed_coordinates(pts[i], m[i], F), batch[i], atol=0)
