"""Bundle block adjustment against the truth and against an independent dense solution."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import arcsec, m
from synthetic_blocks import block10x4, exact_block

from stereoplotter.errors import GeometryError
from stereoplotter.geometry.collinearity import object_to_photo
from stereoplotter.geometry.rotation import rotation_matrix
from stereoplotter.triangulation.bundle import bundle_adjust, problem
from stereoplotter.triangulation.synth import SynthSpec, synthesize_block


def test_error_free_block_gives_the_true_orientations():
    block, truth = exact_block()
    s = bundle_adjust(problem(block))
    err = s.orientations - truth.orientations
    assert np.max(np.abs(err[:, :3])) < 1e-4 * arcsec
    assert np.max(np.abs(err[:, 3:])) < 1e-5 * m
    used = np.isfinite(s.points_m[:, 0])
    assert np.max(np.abs(s.points_m[used] - truth.points_m[used])) < 1e-5 * m


def _dense_covariance(p, orient, points):
    """σ-free (JᵀWJ)⁻¹ of the photos from a central-difference Jacobian of Eq. (2.53) over all
    unknowns (photos and points), inverted densely: independent of the analytic Jacobian and
    of the point elimination."""
    used = np.unique(p.obs_point)
    col = {i: 6 * p.n_photos + 3 * k for k, i in enumerate(used)}
    n = 6 * p.n_photos + 3 * used.size
    rows = []
    for o in range(p.obs_photo.size):
        j, i = p.obs_photo[o], p.obs_point[o]
        x0 = np.concatenate([orient[j], points[i]])

        def xy(x):
            return object_to_photo(x[6:], x[3:6], rotation_matrix(*x[:3]), p.f_mm)

        jac = np.zeros((2, n))
        for k in range(9):
            h = 1e-7 if k < 3 else 1e-4
            e = np.zeros(9)
            e[k] = h
            d = (xy(x0 + e) - xy(x0 - e)) / (2 * h)
            jac[:, 6 * j + k if k < 6 else col[i] + k - 6] = d
        rows.append(jac / p.sigma_photo_mm)
    a = np.vstack(rows)
    normal = a.T @ a
    for k, i in enumerate(p.control_point):
        normal[col[i] : col[i] + 3, col[i] : col[i] + 3] += np.diag(p.control_weight[k])
    return np.linalg.inv(normal), col


def test_covariance_equals_the_dense_inverse_of_the_full_normal_matrix():
    block, _ = synthesize_block(
        SynthSpec(strips=2, photos_per_strip=4, control_every_bases=1), np.random.default_rng(11)
    )
    p = problem(block)
    s = bundle_adjust(p)
    full, col = _dense_covariance(p, s.orientations, np.nan_to_num(s.points_m))
    dense = s.sigma0**2 * full
    blocks = np.array([dense[6 * j : 6 * j + 6, 6 * j : 6 * j + 6] for j in range(p.n_photos)])
    after = np.array(
        [dense[6 * j + 6 : 6 * j + 12, 6 * j : 6 * j + 6] for j in range(p.n_photos - 1)]
    )
    np.testing.assert_allclose(s.covariances, blocks, rtol=1e-4, atol=1e-14)
    np.testing.assert_allclose(s.next_covariances[:-1], after, rtol=1e-4, atol=1e-14)
    points = np.array([dense[c : c + 3, c : c + 3] for c in col.values()])
    np.testing.assert_allclose(s.point_covariances[list(col)], points, rtol=1e-4, atol=1e-14)


def test_noisy_block_errors_match_the_propagated_sigma():
    # the orientation errors against the truth, in units of their own σ: RMS 1 if the σ are right
    # (240 correlated values; a factor 1.5 either way would mean a wrong covariance)
    block, truth = block10x4()
    s = bundle_adjust(problem(block))
    z = (s.orientations - truth.orientations) / s.standard_errors
    assert 1 / 1.5 < np.sqrt(np.mean(z**2)) < 1.5
    assert s.iterations <= 10


def test_too_little_control_is_refused():
    block, _ = block10x4()
    no_control = dataclasses.replace(
        block, catalogue=tuple(dataclasses.replace(c, role="check") for c in block.catalogue)
    )
    with pytest.raises(GeometryError, match="plan control points"):
        bundle_adjust(problem(no_control))


def test_selected_inverse_equals_the_dense_inverse_of_the_reduced_matrix():
    # every 6 × 6 block of S⁻¹ the band recursion holds, and the far pairs from the LU factor
    from stereoplotter.triangulation.bundle import measurement_pairs, normals
    from stereoplotter.triangulation.selected_inverse import selected_inverse

    block, _ = block10x4()
    p = problem(block)
    s = bundle_adjust(p, covariance=False)
    n = normals(p, s.orientations, np.nan_to_num(s.points_m), measurement_pairs(p.obs_point))
    sel = selected_inverse(n.reduced)
    dense = np.linalg.inv(n.reduced.toarray())
    a, b = np.meshgrid(np.arange(p.n_photos), np.arange(p.n_photos), indexing="ij")
    got = sel.blocks(a.ravel(), b.ravel())
    want = dense.reshape(p.n_photos, 6, p.n_photos, 6).transpose(0, 2, 1, 3).reshape(-1, 6, 6)
    sd = np.sqrt(np.diag(dense)).reshape(-1, 6)
    norm = sd[a.ravel()][:, :, None] * sd[b.ravel()][:, None, :]  # |correlation| ≤ 1
    assert sel.width < p.n_photos // 2  # the band recursion, not one dense block
    assert np.max(np.abs(got - want) / norm) < 1e-8
