"""Self-calibration: the camera's f, principal point and distortion adjusted with the block."""

from __future__ import annotations

import numpy as np
import pytest

from stereoplotter.geometry.collinearity import object_to_photo
from stereoplotter.geometry.rotation import rotation_matrix
from stereoplotter.triangulation.bundle import bundle_adjusted, problem
from stereoplotter.triangulation.camera_model import CAMERA_PARAMETERS, camera_image
from stereoplotter.triangulation.self_calibration import camera_calibration
from stereoplotter.triangulation.synth import SynthSpec, synthesize_block

#: Δf 0.5 mm, x₀ 0.1 mm, y₀ −0.08 mm, k₁ 5·10⁻⁸ mm⁻² (50 µm at r = 100 mm)
PLANTED = (0.5, 0.1, -0.08, 5e-8, 0.0, 0.0, 0.0)


def _calibrate(error):
    block, _ = synthesize_block(
        SynthSpec(camera_error=error), np.random.default_rng([0, 5])
    )  # 4 strips × 10 photos
    p = problem(block, CAMERA_PARAMETERS)
    return camera_calibration(p, bundle_adjusted(p))


def test_camera_jacobian_equals_central_differences():
    rng = np.random.default_rng(1)
    ideal = rng.uniform(-80, 80, (20, 2))
    cam = np.array([70.3, 0.02, -0.01, 3e-8, 2e-12, 1e-6, -2e-6])
    _, d, jac = camera_image(ideal, cam)
    steps = (1e-4, 1e-4, 1e-4, 1e-10, 1e-14, 1e-8, 1e-8)
    for k, h in enumerate(steps):
        e = np.zeros(7)
        e[k] = h
        num = (camera_image(ideal, cam + e)[0] - camera_image(ideal, cam - e)[0]) / (2 * h)
        if k == 0:  # f acts through the ideal image x̄ = f·(…): scale it with f
            num = (
                camera_image(ideal * (cam[0] + h) / cam[0], cam + e)[0]
                - camera_image(ideal * (cam[0] - h) / cam[0], cam - e)[0]
            ) / (2 * h)
        np.testing.assert_allclose(jac[:, :, k], num, rtol=1e-6, atol=1e-9)
    h = 1e-5
    for k in range(2):
        e = np.zeros(2)
        e[k] = h
        num = (camera_image(ideal + e, cam)[0] - camera_image(ideal - e, cam)[0]) / (2 * h)
        np.testing.assert_allclose(d[:, :, k], num, rtol=1e-7, atol=1e-9)


def test_covariance_equals_the_dense_inverse_with_the_camera():
    # every unknown (photos, points, 7 camera parameters) in one dense numerical Jacobian
    block, _ = synthesize_block(
        SynthSpec(strips=3, photos_per_strip=5, control_every_bases=2, camera_error=PLANTED),
        np.random.default_rng(11),
    )
    p = problem(block, CAMERA_PARAMETERS)
    a = bundle_adjusted(p)
    s = a.solution
    used = np.unique(p.obs_point)
    n6, n3 = 6 * p.n_photos, 3 * used.size

    def residuals(x):
        o = x[:n6].reshape(-1, 6)[p.obs_photo]
        pts = np.zeros((p.n_points, 3))
        pts[used] = x[n6 : n6 + n3].reshape(-1, 3)
        cam = x[n6 + n3 :]
        m = rotation_matrix(o[:, 0], o[:, 1], o[:, 2])
        xy = camera_image(object_to_photo(pts[p.obs_point], o[:, 3:], m, cam[0]), cam)[0]
        ctl = np.sqrt(p.control_weight) * (p.control_m - pts[p.control_point])
        return np.concatenate([((p.xy_mm - xy) / p.sigma_photo_mm).ravel(), ctl.ravel()])

    x0 = np.concatenate([s.orientations.ravel(), s.points_m[used].ravel(), a.camera])
    steps = np.concatenate(
        [np.tile([1e-7] * 3 + [1e-5] * 3, p.n_photos), np.full(n3, 1e-5),
         [1e-5, 1e-5, 1e-5, 1e-11, 1e-15, 1e-9, 1e-9]]
    )  # fmt: skip
    jac = np.empty((x0.size, residuals(x0).size))
    for k, h in enumerate(steps):
        e = np.zeros(x0.size)
        e[k] = h
        jac[k] = (residuals(x0 - e) - residuals(x0 + e)) / (2 * h)
    q = np.linalg.inv(jac @ jac.T)
    qgg = q[-7:, -7:]
    sd = np.sqrt(np.diag(qgg))
    assert np.max(np.abs(qgg - a.inverse.qgg) / np.outer(sd, sd)) < 1e-5
    qc = np.array([q[6 * j : 6 * j + 6, 6 * j : 6 * j + 6] for j in range(p.n_photos)])
    got = a.inverse.blocks(np.arange(p.n_photos), np.arange(p.n_photos))
    sc = np.sqrt(np.einsum("nii->ni", qc))
    assert np.max(np.abs(got - qc) / (sc[:, :, None] * sc[:, None, :])) < 1e-5
    qp = np.array(
        [q[n6 + 3 * k : n6 + 3 * k + 3, n6 + 3 * k : n6 + 3 * k + 3] for k in range(used.size)]
    )
    mine = s.point_covariances[used] / s.sigma0**2
    sp_ = np.sqrt(np.einsum("nii->ni", qp))
    assert np.max(np.abs(mine - qp) / (sp_[:, :, None] * sp_[:, None, :])) < 1e-5


def test_planted_camera_errors_are_recovered_within_two_sigma_and_significant():
    c = _calibrate(PLANTED)
    truth = np.array([70.0 + PLANTED[0], *PLANTED[1:]])
    z = (c.values - truth) / c.sigma
    named = {n: float(v) for n, v in zip(c.names, z, strict=True)}
    assert all(abs(named[n]) < 2.0 for n in ("f", "x0", "y0", "k1")), named
    assert c.group_significant and c.p_value < 1e-6
    assert c.significant[c.names.index("x0")] and c.significant[c.names.index("k1")]
    assert np.allclose(np.diag(c.correlation), 1.0) and np.all(np.abs(c.correlation) <= 1 + 1e-9)


def test_a_camera_as_certified_is_not_significant():
    c = _calibrate((0.0,) * 7)
    assert not c.group_significant and c.f_statistic < c.f_critical
    assert not np.any(c.significant)
    assert c.f_critical == pytest.approx(2.03, abs=0.01)  # F_0.95(7, r ≈ 400)


def test_planted_camera_errors_are_recovered_with_measured_centres():
    # the projection centres measured (σ 5 cm) as well: their normals enter the photo blocks,
    # the camera's border comes from the photo measurements alone
    block, _ = synthesize_block(
        SynthSpec(camera_error=PLANTED, centre_sigma_m=0.05), np.random.default_rng([0, 5])
    )
    p = problem(block, CAMERA_PARAMETERS)
    c = camera_calibration(p, bundle_adjusted(p))
    truth = np.array([70.0 + PLANTED[0], *PLANTED[1:]])
    z = (c.values - truth) / c.sigma
    named = {n: float(v) for n, v in zip(c.names, z, strict=True)}
    # 3σ: the chance that any of the four normal z exceeds it is about 1 %
    assert all(abs(named[n]) < 3.0 for n in ("f", "x0", "y0", "k1")), named
    assert c.group_significant
