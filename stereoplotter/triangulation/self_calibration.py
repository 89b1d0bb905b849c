r"""Self-calibration's result: the camera parameters, their σ and correlations, and their tests.

The parameters (:mod:`~stereoplotter.triangulation.camera_model`) adjusted with the block
(``problem(block, self_calibration=…)``) are tested against the certificate (f certified,
x₀ = y₀ = k₁ = k₂ = p₁ = p₂ = 0):

* each alone: t = (value − certificate)/σ, significant when |t| exceeds the two-sided Student
  quantile t_{1−α/(2u)}(r) (α = 5 % shared by the u parameters, Bonferroni; r the
  redundancy);
* all together: F = Δᵀ·Q_gg⁻¹·Δ/(u·σ₀²) against F_{1−α}(u, r), u the number of parameters —
  the test to read first, since the parameters correlate (f with the heights of the centres,
  x₀, y₀ with the tilts).

σ and correlations from σ₀²·Q_gg, Q_gg the camera's block of N⁻¹ (the Schur complement of the
photos and points, no dense inverse).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import stats

from stereoplotter.triangulation.bundle import Adjusted, BundleProblem
from stereoplotter.triangulation.camera_model import CAMERA_PARAMETERS, CAMERA_UNITS

__all__ = ["CameraCalibration", "camera_calibration"]


@dataclass(frozen=True, slots=True)
class CameraCalibration:
    """``names``, ``units``; ``values`` adjusted, ``certificate`` the a priori values; ``sigma``;
    ``correlation`` (u, u); ``t`` per parameter and its critical value ``t_critical``;
    ``significant`` per parameter; the group test ``f_statistic``, ``f_critical``,
    ``p_value`` and ``group_significant``; ``alpha``."""

    names: tuple[str, ...]
    units: tuple[str, ...]
    values: NDArray[np.float64]
    certificate: NDArray[np.float64]
    sigma: NDArray[np.float64]
    correlation: NDArray[np.float64]
    t: NDArray[np.float64]
    t_critical: float
    significant: NDArray[np.bool_]
    f_statistic: float
    f_critical: float
    p_value: float
    group_significant: bool
    alpha: float


def camera_calibration(p: BundleProblem, adj: Adjusted, alpha: float = 0.05) -> CameraCalibration:
    """:class:`CameraCalibration` of a self-calibrating adjustment (with covariances)."""
    if not p.camera_free or adj.inverse is None or adj.inverse.qgg is None:
        raise ValueError("the adjustment has no free camera parameters with covariances")
    free = p.free
    s0 = adj.solution.sigma0
    qgg = adj.inverse.qgg
    values = adj.camera[free]
    cert = p.camera0()[free]
    sigma = s0 * np.sqrt(np.diag(qgg))
    d = np.sqrt(np.diag(qgg))
    corr = qgg / np.outer(d, d)
    delta = values - cert
    t = delta / sigma
    r = adj.redundancy
    u = free.size
    t_crit = float(stats.t.isf(alpha / (2 * u), r))
    f_stat = float(delta @ np.linalg.solve(qgg, delta)) / (u * s0**2)
    f_crit = float(stats.f.isf(alpha, u, r))
    return CameraCalibration(
        tuple(CAMERA_PARAMETERS[i] for i in free),
        tuple(CAMERA_UNITS[i] for i in free),
        values,
        cert,
        sigma,
        corr,
        t,
        t_crit,
        np.abs(t) > t_crit,
        f_stat,
        f_crit,
        float(stats.f.sf(f_stat, u, r)),
        f_stat > f_crit,
        alpha,
    )
