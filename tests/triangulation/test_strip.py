"""Strip triangulation (dependent and independent models), 7-parameter similarity, polynomials."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import arcsec, m, mm
from synthetic_blocks import block10x4, exact_block

from stereoplotter.errors import GeometryError
from stereoplotter.geometry.rotation import rotation_matrix
from stereoplotter.triangulation.absolute import apply_similarity7, fit_similarity7
from stereoplotter.triangulation.block import interior_orientation
from stereoplotter.triangulation.polynomial import StripAxes, adjust_strip_polynomials
from stereoplotter.triangulation.solution import catalogue_residuals
from stereoplotter.triangulation.strip import (
    common_points,
    measurement_rows,
    strip_block,
    y_parallax,
)


@pytest.mark.parametrize("models", ["independent", "dependent"])
def test_error_free_block_gives_the_true_orientations(models):
    # error-free pairs are exact models: connection, 7-parameter and polynomials change nothing
    block, truth = exact_block()
    s = strip_block(block, models, degree=3)
    err = s.orientations - truth.orientations
    assert np.max(np.abs(err[:, :3])) < 0.01 * arcsec
    assert np.max(np.abs(err[:, 3:])) < 1e-4 * m


def test_true_orientation_clears_the_y_parallax():
    # (5.10): the y-parallax of a pair at its true relative orientation is zero at every point
    block, truth = exact_block()
    xy, rows = interior_orientation(block), measurement_rows(block)
    _, a, b = common_points(xy, rows, 0, 1)
    o = truth.orientations
    q = y_parallax(
        a,
        b,
        rotation_matrix(*o[0, :3]),
        rotation_matrix(*o[1, :3]),
        o[1, 3:] - o[0, 3:],
        block.camera.focal_length_mm,
    )
    assert a.shape[0] >= 6 and np.max(np.abs(q)) < 1e-8 * mm  # measured with σ 10⁻⁹ mm


def test_strip_methods_on_the_noisy_block_are_within_a_metre_at_check_points():
    # σ 5 µm at 1:20 000 is 0.1 m on the ground, the strip methods' check RMS a few times that
    # (docs/triangulation.md); a lost model connection or a wrong sign leaves tens of metres
    block, _ = block10x4()
    for models in ("independent", "dependent"):
        rms = catalogue_residuals(block, strip_block(block, models, 3)).rms(block, "check")
        assert np.all(rms < 1.0 * m), (models, rms)


def test_similarity7_recovers_a_known_transformation_with_height_points():
    rng = np.random.default_rng(0)
    src = rng.normal(0.0, 100.0, (8, 3))
    rot = rotation_matrix(0.1, -0.2, 1.3)
    dst = np.array([5.0, 6.0, 7.0]) + 1.7 * src @ rot.T
    w = np.ones((8, 3))
    w[5:, :2] = 0.0  # height points: their plan is not given ...
    dst[5:, :2] += 50.0  # ... so a wrong plan there must not matter
    t = fit_similarity7(src, dst, w)
    assert abs(t.scale - 1.7) < 1e-12
    assert np.max(np.abs(t.rotation - rot)) < 1e-12
    np.testing.assert_allclose(apply_similarity7(t, src[:5]), dst[:5], atol=1e-9)


def test_similarity7_refuses_collinear_points():
    line = np.outer(np.arange(4.0), [1.0, 2.0, 3.0])
    with pytest.raises(GeometryError, match="on a line"):
        fit_similarity7(line, line)


def test_polynomials_remove_a_known_bend_and_twist():
    # one strip along X, bent (conformal quadratic in plan; bend, tilt, twist in height):
    # the deformations the degree-2 polynomials model are removed
    x = np.linspace(-5000.0, 5000.0, 21)
    y = np.array([-1200.0, 0.0, 1200.0])
    gx, gy = (g.ravel() for g in np.meshgrid(x, y))
    truth = np.column_stack([gx, gy, 100.0 + 0.0 * gx])
    u, v = gx / 5000.0, gy / 5000.0
    bent = truth.copy()
    bent[:, 2] += 3.0 * u**2 - 1.0 * u + 0.5 + 0.8 * v * u  # bend, tilt, shift, twist [m]
    bent[:, 0] += 0.02 * (u**2 - v**2)  # small in plan: the polynomial is evaluated at the
    bent[:, 1] += 0.02 * 2.0 * u * v  # bent u, v, which moves it by (0.02 m)²/5000 m only
    control = np.flatnonzero(np.isin(gx, x[::5]) & (gy != 0.0))
    axes = (StripAxes(np.zeros(2), np.array([1.0, 0.0]), 5000.0),)
    poly = adjust_strip_polynomials(
        np.zeros(gx.size, np.int64), np.arange(gx.size), bent, axes, gx.size, control,
        truth[control], np.full((control.size, 3), 1e4), 0.1, 2,
    )  # fmt: skip
    assert np.max(np.abs(poly.points_m - truth)) < 1e-5 * m


def test_strip_method_point_sigma_matches_the_errors_at_check_points():
    # σ propagated through the polynomial adjustment (a posteriori σ₀): RMS(error/σ) over the
    # check points of 4 blocks of 4 × 10; the blocks' values spread by ≈ 0.17 per axis, so
    # 0.8–1.2 pooled over the axes is ± 4 SE and 0.7–1.3 per axis ± 3.5 SE
    from stereoplotter.triangulation.synth import SynthSpec, synthesize_block

    z = []
    for seed in range(4):
        block, truth = synthesize_block(SynthSpec(), np.random.default_rng([seed, 7]))
        s = strip_block(block)
        se = s.point_standard_errors
        check = {c.id for c in block.catalogue if c.role == "check"}
        idx = [
            i
            for i, pid in enumerate(block.point_ids)
            if pid in check and np.all(np.isfinite(s.points_m[i]))
        ]
        z.append((s.points_m[idx] - truth.points_m[idx]) / se[idx])
    z = np.vstack(z)
    per_axis = np.sqrt(np.mean(z**2, axis=0))
    assert 0.8 < np.sqrt(np.mean(z**2)) < 1.2 and np.all((per_axis > 0.7) & (per_axis < 1.3))
