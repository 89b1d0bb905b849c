"""Behaviour tests of the space resection (rigorous and the book's method) on synthetic geometry.

The reference values of the book (Tables 7–13) are in ``tests/test_reference_resection.py``.
Synthetic photos are generated with the independent forward model (2.52)/(2.53)
(:mod:`stereoplotter.geometry.collinearity`) from seeded random exterior orientations.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from stereoplotter.constants import ARCSEC_PER_RAD
from stereoplotter.errors import GeometryError
from stereoplotter.geometry.collinearity import object_to_photo, photo_to_object
from stereoplotter.geometry.resection import initial_exterior_orientation, space_resection
from stereoplotter.geometry.resection_book import book_space_resection, line_coefficients
from stereoplotter.geometry.rotation import rotation_matrix

mm = 1.0
um = 1e-3 * mm
m = 1.0
arcsec = 1.0 / ARCSEC_PER_RAD


def _random_photo(
    rng: np.random.Generator,
    n_points: int,
    max_tilt_deg: float = 5.0,
    max_swing_deg: float = 180.0,
):
    """A near-vertical aerial photo: tilts up to ``max_tilt_deg``, swing up to
    ``max_swing_deg``, hilly terrain (relief up to 15 % of the flying height)."""
    f = rng.choice([70.0, 100.0, 150.0, 200.0])
    angles = np.radians(
        [
            rng.uniform(-max_tilt_deg, max_tilt_deg),
            rng.uniform(-max_tilt_deg, max_tilt_deg),
            rng.uniform(-max_swing_deg, max_swing_deg),
        ]
    )
    centre = np.array([rng.uniform(-5e3, 5e3), rng.uniform(-5e3, 5e3), rng.uniform(800, 4000)])
    photo = rng.uniform(-90.0, 90.0, size=(n_points, 2))
    heights = rng.uniform(0.0, 0.15 * centre[2], size=n_points)
    points = photo_to_object(photo, heights, centre, rotation_matrix(*angles), f)  # (2.52)
    return f, angles, centre, photo, points


@pytest.mark.parametrize("seed", range(12))
def test_noise_free_random_geometries_recover_orientation(seed):
    rng = np.random.default_rng(seed)
    f, angles, centre, photo, points = _random_photo(rng, n_points=int(rng.integers(4, 12)))
    result = space_resection(photo, points, f)
    assert result.converged
    assert result.iterations <= 10
    assert_allclose(result.angles, angles, rtol=0, atol=1e-6 * arcsec)
    assert_allclose(result.projection_centre_m, centre, rtol=0, atol=1e-6 * mm * 1e-3)
    assert result.rms_residual_mm < 1e-9 * um


def test_three_points_are_an_exact_solution_without_precision():
    rng = np.random.default_rng(7)
    f, angles, centre, photo, points = _random_photo(rng, n_points=3)
    result = space_resection(photo, points, f)
    assert result.redundancy == 0
    assert result.sigma0_mm is None and result.covariance is None
    assert result.standard_errors is None
    assert_allclose(result.angles, angles, rtol=0, atol=1e-6 * arcsec)
    assert_allclose(result.projection_centre_m, centre, rtol=0, atol=1e-6)


def test_residuals_are_measured_minus_computed_by_collinearity():
    rng = np.random.default_rng(3)
    f, _, _, photo, points = _random_photo(rng, n_points=8)
    noisy = photo + rng.normal(0.0, 5 * um, size=photo.shape)
    result = space_resection(noisy, points, f, principal_point_mm=(0.0, 0.0))
    computed = object_to_photo(points, result.projection_centre_m, result.rotation, f)
    assert_allclose(result.residuals_mm, noisy - computed, rtol=0, atol=1e-12)
    assert result.rms_residual_mm == pytest.approx(np.sqrt(np.mean(result.residuals_mm**2)))
    assert result.sigma0_mm == pytest.approx(np.sqrt(np.sum(result.residuals_mm**2) / (2 * 8 - 6)))


def test_principal_point_offset():
    rng = np.random.default_rng(11)
    f, angles, _centre, photo, points = _random_photo(rng, n_points=6)
    pp = np.array([0.012, -0.021])
    result = space_resection(photo + pp, points, f, principal_point_mm=pp)
    assert_allclose(result.angles, angles, rtol=0, atol=1e-6 * arcsec)


def test_explicit_initial_approximation_is_used():
    rng = np.random.default_rng(5)
    f, angles, centre, photo, points = _random_photo(rng, n_points=5)
    start = np.concatenate([angles + 0.01, centre + np.array([30.0, -20.0, 50.0])])
    result = space_resection(photo, points, f, initial=start)
    assert_allclose(result.angles, angles, rtol=0, atol=1e-6 * arcsec)


def test_automatic_initial_approximation_is_close_for_a_vertical_photo():
    rng = np.random.default_rng(2)
    f, angles, centre, photo, points = _random_photo(rng, n_points=6, max_tilt_deg=0.0)
    start = initial_exterior_orientation(photo, points, f)
    # Vertical photo: alpha = omega = 0 assumed; swing and position are off only by the relief
    # displacement, which the plane similarity ignores (terrain up to 15 % of the height).
    assert start[0] == 0.0 and start[1] == 0.0
    assert abs(np.angle(np.exp(1j * (start[2] - angles[2])))) < np.radians(2.0)
    assert np.hypot(*(start[3:5] - centre[:2])) < 0.05 * centre[2]
    assert abs(start[5] - centre[2]) < 0.15 * centre[2]


# Monte Carlo check of the a-posteriori precision (style.md §10; derived tolerance): with
# sigma = 5 um on each coordinate, sigma0^2 averages sigma^2, and the errors of the elements
# normalised by the covariance of (3.11) (rescaled to the a-priori sigma) have unit variance.
def test_noisy_resection_covariance_is_consistent():
    rng = np.random.default_rng(2024)
    f, angles, centre, photo, points = _random_photo(rng, n_points=8)
    sigma = 5 * um
    n_trials = 200
    z = np.empty((n_trials, 6))
    s0 = np.empty(n_trials)
    truth = np.concatenate([angles, centre])
    for t in range(n_trials):
        noisy = photo + rng.normal(0.0, sigma, size=photo.shape)
        r = space_resection(noisy, points, f)
        estimate = np.concatenate([r.angles, r.projection_centre_m])
        s0[t] = r.sigma0_mm
        cov = r.covariance * (sigma / r.sigma0_mm) ** 2
        z[t] = (estimate - truth) / np.sqrt(np.diag(cov))
    # E[sigma0^2] = sigma^2; sigma0^2 ~ sigma^2 chi2_10/10 has relative s.d. sqrt(2/10)/sqrt(N).
    assert np.mean(s0**2) / sigma**2 == pytest.approx(1.0, abs=4 * math.sqrt(0.2 / n_trials))
    tol = 4 / math.sqrt(2 * (n_trials - 1))
    assert_allclose(z.std(axis=0, ddof=1), 1.0, rtol=0, atol=tol)
    assert_allclose(z.mean(axis=0), 0.0, rtol=0, atol=4 / math.sqrt(n_trials))


# The book's method linearises in the angles from zero: it is meant for plan photos (angles of a
# few degrees, §18 of [1]); a sweep of 300 seeded geometries with all three angles up to 5°
# converged in at most 9 approximations.
@pytest.mark.parametrize("seed", range(3))
def test_book_method_agrees_with_rigorous_resection_on_noise_free_data(seed):
    rng = np.random.default_rng(seed)
    f, _angles, _centre, photo, points = _random_photo(
        rng, n_points=6, max_tilt_deg=5.0, max_swing_deg=5.0
    )
    book = book_space_resection(photo, points, f, tolerance=1e-6 * arcsec)
    rigorous = space_resection(photo, points, f)
    a = book.angular
    assert a.converged
    assert_allclose([a.alpha, a.omega, a.kappa], rigorous.angles, rtol=0, atol=1e-4 * arcsec)
    assert_allclose(book.projection_centre_m, rigorous.projection_centre_m, rtol=0, atol=1e-6)


# --- Error messages (style.md §11) ---------------------------------------------------------------


def test_too_few_points():
    with pytest.raises(GeometryError, match=r"at least 3 control points .* got 2"):
        space_resection([[0.0, 0.0], [10.0, 0.0]], [[0, 0, 0], [100, 0, 0]], 100.0)


def test_mismatched_point_counts():
    with pytest.raises(GeometryError, match=r"photo_mm has 3 points but points_m has 4"):
        space_resection(np.zeros((3, 2)), np.zeros((4, 3)), 100.0)


def test_coincident_points():
    photo = [[0.0, 0.0], [10.0, 0.0], [0.0, 10.0], [0.0, 10.0]]
    points = [[0, 0, 0], [100, 0, 0], [0, 100, 0], [0, 100, 0]]
    with pytest.raises(GeometryError, match=r"points_m: points 2 and 3 coincide"):
        space_resection(photo, points, 100.0)


def test_collinear_points():
    photo = [[0.0, 0.0], [10.0, 1.0], [20.0, 2.0], [30.0, 3.0]]
    points = [[0, 0, 0], [100, 10, 0], [200, 20, 0], [300, 30, 0]]
    with pytest.raises(GeometryError, match=r"points_m: the 4 control points are collinear"):
        space_resection(photo, points, 100.0)


def test_non_convergence_is_reported():
    rng = np.random.default_rng(1)
    f, _angles, _centre, photo, points = _random_photo(rng, n_points=6)
    with pytest.raises(GeometryError, match=r"did not converge in 1 iterations"):
        space_resection(photo, points, f, max_iterations=1)
    result = space_resection(photo, points, f, max_iterations=1, raise_on_failure=False)
    assert not result.converged and result.iterations == 1


def test_points_behind_the_camera():
    rng = np.random.default_rng(4)
    f, angles, centre, photo, points = _random_photo(rng, n_points=5)
    start = np.concatenate([angles, centre * [1, 1, -1]])
    with pytest.raises(GeometryError, match=r"behind the camera"):
        space_resection(photo, points, f, initial=start)


def test_bad_initial_shape():
    rng = np.random.default_rng(4)
    f, _, _, photo, points = _random_photo(rng, n_points=5)
    with pytest.raises(GeometryError, match=r"initial must be \(alpha, omega, kappa"):
        space_resection(photo, points, f, initial=[0.0, 0.0, 0.0])


def test_book_method_needs_three_points():
    with pytest.raises(GeometryError, match=r"line method of §18 needs at least 3"):
        book_space_resection([[0.0, 0.0], [1.0, 1.0]], [[0, 0, 0], [10, 10, 0]], 100.0)


def test_book_method_rejects_degenerate_line():
    # Photo direction of line 1-2 perpendicular to its ground direction: Q = 0.
    with pytest.raises(GeometryError, match=r"Q = 0 for lines \[\[1, 2\]\]"):
        line_coefficients([[0.0, 0.0], [10.0, 0.0]], [[0, 0, 0], [0, 100, 0]], 100.0)
