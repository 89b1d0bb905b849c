r"""The 7-parameter spatial similarity: absolute orientation of a model or strip, model connection.

X_ground = T + λ·R·X_model with scale λ, rotation R (3 × 3, orthonormal) and shift T: the seven
elements of absolute orientation of a model (the textbook's chapter on analytic
phototriangulation; Kushtin & Lyskov ch. 5 §23 for the model's scale and levelling). The same
transformation connects an independent model to its strip.

The first approximation is the closed-form least-squares solution on the points given in all
three coordinates (centroids, SVD of the cross-covariance: Umeyama 1991); Gauss–Newton on the
weighted coordinates then takes height-only and plan-only points in (weight 0 on a coordinate
not given). Units: whatever the two systems use (model units, m); R and the rotation updates are
dimensionless.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.errors import GeometryError

__all__ = ["Similarity7", "apply_similarity7", "fit_similarity7"]


@dataclass(frozen=True, slots=True)
class Similarity7:
    """X_to = translation + scale·rotation·X_from; ``residuals`` (n, 3) = fitted − given (NaN
    where a coordinate carried no weight); ``rms`` over the weighted coordinates."""

    scale: float
    rotation: NDArray[np.float64]
    translation: NDArray[np.float64]
    residuals: NDArray[np.float64]
    rms: float


def apply_similarity7(t: Similarity7, points: ArrayLike) -> NDArray[np.float64]:
    """X_to of points X_from, shape (..., 3)."""
    return t.translation + t.scale * np.asarray(points, float) @ t.rotation.T


def _skew(v: NDArray) -> NDArray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _closed_form(src: NDArray, dst: NDArray) -> tuple[float, NDArray, NDArray]:
    cs, cd = src.mean(axis=0), dst.mean(axis=0)
    a, b = src - cs, dst - cd
    u, s, vt = np.linalg.svd(b.T @ a)
    d = np.diag([1.0, 1.0, np.sign(np.linalg.det(u @ vt))])
    rot = u @ d @ vt
    scale = float(np.trace(np.diag(s) @ d) / np.sum(a**2))
    return scale, rot, cd - scale * rot @ cs


def fit_similarity7(
    source: ArrayLike, target: ArrayLike, weights: ArrayLike | None = None, iterations: int = 10
) -> Similarity7:
    """Least-squares 7-parameter similarity from ``source`` to ``target`` points (n, 3).

    ``weights`` (n, 3) ≥ 0 per coordinate of ``target`` (default 1); at least three points must
    carry all three coordinates and not lie on a line.

    Raises
    ------
    GeometryError
        Fewer than three full points, or all of them on a line.

    Examples
    --------
    >>> import numpy as np
    >>> src = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    >>> t = fit_similarity7(src, 5.0 + 2.0 * src)
    >>> round(t.scale, 12), np.round(t.translation, 12).tolist()
    (2.0, [5.0, 5.0, 5.0])
    """
    src = np.asarray(source, float).reshape(-1, 3)
    dst = np.asarray(target, float).reshape(-1, 3)
    w = np.ones_like(dst) if weights is None else np.asarray(weights, float).reshape(-1, 3)
    full = np.all(w > 0, axis=1)
    if full.sum() < 3:
        raise GeometryError(
            f"7-parameter similarity: expected at least 3 points with X, Y, Z, found {full.sum()}"
        )
    sv = np.linalg.svd(src[full] - src[full].mean(axis=0), compute_uv=False)
    if sv[1] <= 1e-9 * sv[0]:
        raise GeometryError("7-parameter similarity: the full points lie on a line")
    scale, rot, shift = _closed_form(src[full], dst[full])
    sw = np.sqrt(w).ravel()
    for _ in range(iterations):
        fitted = shift + scale * src @ rot.T
        v = (dst - fitted).ravel() * sw
        rs = src @ rot.T  # the rotated source
        jac = np.zeros((src.shape[0], 3, 7))
        jac[:, :, 0] = rs  # ∂/∂ ln-scale · scale
        for k in range(3):  # ∂/∂ small rotation θ_k: scale·[e_k]×·R·x
            e = np.zeros(3)
            e[k] = 1.0
            jac[:, :, 1 + k] = scale * rs @ _skew(e).T
        jac[:, :, 4:] = np.eye(3)
        a = jac.reshape(-1, 7) * sw[:, None]
        delta, *_ = np.linalg.lstsq(a, v, rcond=None)
        scale = float(scale * (1.0 + delta[0]))
        theta = delta[1:4]
        angle = float(np.linalg.norm(theta))
        if angle > 0.0:
            k = _skew(theta / angle)
            rot = (np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k) @ rot
        shift = shift + delta[4:]
        if np.max(np.abs(delta[:4])) < 1e-13 and np.max(np.abs(delta[4:])) < 1e-9:
            break
    fitted = shift + scale * src @ rot.T
    res = np.where(w > 0, fitted - dst, np.nan)
    rms = float(np.sqrt(np.nanmean(res**2)))
    return Similarity7(scale, rot, shift, res, rms)
