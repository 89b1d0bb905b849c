r"""Strip deformation removed by polynomials of degree 2 or 3, all strips of a block at once.

After the 7-parameter absolute orientation of each strip (:mod:`~stereoplotter.triangulation.
absolute`) its points still carry the systematic deformation that the sequential connection of
models accumulates (bending and twisting growing with the square and cube of the distance along
the strip). Each strip s gets a correction polynomial in its own axes (u along the strip from
its first to its last photo, v across, both divided by half the strip's length):

* plan, conformal (keeps the plan shape of a model): ΔX + iΔY = Σ_{k=0}^{n} (a_k + i b_k)(u + iv)^k;
* height: ΔZ = Σ_{k=0}^{n} c_k u^k + v·Σ_{k=0}^{n−1} d_k u^k (bending and twist along the strip).

The polynomials of all strips and the ground coordinates of all points are one linear least
squares problem (the polynomial block adjustment): every point of a strip gives corrected strip
coordinate = ground point (σ of a model coordinate), every control point ground point =
catalogue (σ of the catalogue); points shared by neighbouring strips tie the strips together, so
a strip without plan control along its length is held by its neighbours. Solved sparse
(:func:`~stereoplotter.triangulation.solution.sparse_least_squares`). Units: m.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from stereoplotter.errors import GeometryError
from stereoplotter.triangulation.solution import sparse_least_squares

__all__ = [
    "StripAxes",
    "StripPolynomials",
    "adjust_strip_polynomials",
    "height_terms",
    "plan_terms",
    "point_sigmas",
]


@dataclass(frozen=True, slots=True)
class StripAxes:
    """A strip's axes: ``origin`` (2,) [m], unit ``direction`` (2,) along the strip, ``half``
    half its length [m]."""

    origin: NDArray[np.float64]
    direction: NDArray[np.float64]
    half: float

    def uv(self, xy: NDArray) -> tuple[NDArray, NDArray]:
        """Normalised u (along), v (across) of plan points (..., 2). [—]"""
        d = (np.asarray(xy, float) - self.origin) / self.half
        e = self.direction
        return d[..., 0] * e[0] + d[..., 1] * e[1], -d[..., 0] * e[1] + d[..., 1] * e[0]


def plan_terms(u: NDArray, v: NDArray, degree: int) -> NDArray[np.float64]:
    """Design of ΔX, ΔY in (a_0, b_0, …, a_n, b_n), shape (n, 2, 2·(degree + 1))."""
    w = (np.asarray(u) + 1j * np.asarray(v))[:, None] ** np.arange(degree + 1)
    out = np.empty((w.shape[0], 2, 2 * (degree + 1)))
    out[:, 0, 0::2], out[:, 0, 1::2] = w.real, -w.imag
    out[:, 1, 0::2], out[:, 1, 1::2] = w.imag, w.real
    return out


def height_terms(u: NDArray, v: NDArray, degree: int) -> NDArray[np.float64]:
    """Design of ΔZ in (c_0 … c_n, d_0 … d_{n−1}), shape (n, 2·degree + 1)."""
    p = np.asarray(u)[:, None] ** np.arange(degree + 1)
    return np.concatenate([p, np.asarray(v)[:, None] * p[:, :degree]], axis=1)


@dataclass(frozen=True, slots=True)
class StripPolynomials:
    """Adjusted polynomials: ``plan`` (n_strips, 2(n+1)), ``height`` (n_strips, 2n+1); the
    ground ``points_m`` (n_points, 3) (NaN where no strip measured the point) and their σ
    ``sigma_m`` (n_points, 3) propagated through the polynomial adjustment
    (:func:`point_sigmas`)."""

    degree: int
    axes: tuple[StripAxes, ...]
    plan: NDArray[np.float64]
    height: NDArray[np.float64]
    points_m: NDArray[np.float64]
    sigma_m: NDArray[np.float64] | None = None

    def correct(self, strip: int, xyz: NDArray) -> NDArray[np.float64]:
        """Strip coordinates (n, 3) with the strip's polynomial corrections added. [m]"""
        xyz = np.asarray(xyz, float).reshape(-1, 3)
        u, v = self.axes[strip].uv(xyz[:, :2])
        out = xyz.copy()
        out[:, :2] += plan_terms(u, v, self.degree) @ self.plan[strip]
        out[:, 2] += height_terms(u, v, self.degree) @ self.height[strip]
        return out


def adjust_strip_polynomials(
    obs_strip: NDArray[np.int64],
    obs_point: NDArray[np.int64],
    strip_xyz: NDArray[np.float64],
    axes: tuple[StripAxes, ...],
    n_points: int,
    control_point: NDArray[np.int64],
    control_m: NDArray[np.float64],
    control_weight: NDArray[np.float64],
    sigma_model_m: float,
    degree: int,
) -> StripPolynomials:
    """Polynomials of every strip and ground points from strip coordinates and control.

    ``obs_strip``, ``obs_point``, ``strip_xyz`` (n, 3): each point's coordinates in each strip
    (after the strip's absolute orientation) [m]; ``control_*`` as in the bundle problem
    (weights 1/σ² per coordinate, 0 where not given); ``sigma_model_m`` the σ of a strip
    coordinate.

    Raises
    ------
    GeometryError
        Too little control for the polynomials (a singular system).
    """
    if degree not in (1, 2, 3):
        raise GeometryError(f"strip polynomials: expected degree 1, 2 or 3, found {degree}")
    u, v = _strip_uv(obs_strip, strip_xyz, axes)
    control = (control_point, control_m, control_weight)
    results = [
        _adjust_dimensions(
            terms, dims, obs_strip, obs_point, strip_xyz, len(axes), n_points, control,
            sigma_model_m, degree,
        )
        for terms, dims in (
            (plan_terms(u, v, degree), (0, 1)),
            (height_terms(u, v, degree)[:, None], (2,)),
        )
    ]  # fmt: skip
    (plan, plan_pts, plan_sig), (height, height_pts, height_sig) = results
    points = np.column_stack([plan_pts, height_pts])
    return StripPolynomials(
        degree, axes, plan, height, points, np.column_stack([plan_sig, height_sig])
    )


def _strip_uv(
    obs_strip: NDArray[np.int64], strip_xyz: NDArray[np.float64], axes: tuple[StripAxes, ...]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Each observation's coordinates along and across its strip's axis (:meth:`StripAxes.uv`)."""
    u = np.empty(obs_strip.size)
    v = np.empty(obs_strip.size)
    for s, ax in enumerate(axes):
        m = obs_strip == s
        u[m], v[m] = ax.uv(strip_xyz[m, :2])
    return u, v


def _adjust_dimensions(
    terms: NDArray[np.float64],
    dims: tuple[int, ...],
    obs_strip: NDArray[np.int64],
    obs_point: NDArray[np.int64],
    strip_xyz: NDArray[np.float64],
    ns: int,
    n_points: int,
    control: tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.float64]],
    sigma_model_m: float,
    degree: int,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """One of the two systems (plan: ``dims`` (0, 1); height: (2,)) solved: the strips'
    coefficients (strips × terms), the points' coordinates and their σ (points × dims) [m]."""
    nt = terms.shape[2]
    nd = len(dims)
    a, b, cols = _observation_rows(
        terms, dims, obs_strip, obs_point, strip_xyz, ns, n_points, control, sigma_model_m
    )
    used = np.zeros(a.shape[1], bool)
    used[cols] = True
    x = np.full(a.shape[1], np.nan)
    try:
        au = a[:, used]
        x[used] = sparse_least_squares(au, b)
        sig = np.full(a.shape[1], np.nan)
        sig[used] = point_sigmas(au, b, x[used], int(np.count_nonzero(used[: ns * nt])))
    except RuntimeError:
        raise GeometryError(
            f"strip polynomials of degree {degree}: the control does not fix them (a "
            "singular system): give more control or a lower degree"
        ) from None
    return (
        x[: ns * nt].reshape(ns, nt),
        x[ns * nt :].reshape(n_points, nd),
        sig[ns * nt :].reshape(n_points, nd),
    )


def _observation_rows(
    terms: NDArray[np.float64],
    dims: tuple[int, ...],
    obs_strip: NDArray[np.int64],
    obs_point: NDArray[np.int64],
    strip_xyz: NDArray[np.float64],
    ns: int,
    n_points: int,
    control: tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.float64]],
    sigma_model_m: float,
) -> tuple[sp.csr_matrix, NDArray[np.float64], NDArray[np.int64]]:
    """The weighted design matrix, right-hand side and the columns used: a row per strip
    coordinate (polynomial of the strip − point = −coordinate, weight 1/σ of the model) and per
    given control coordinate (point = control, weight 1/σ)."""
    control_point, control_m, control_weight = control
    n_obs = obs_strip.size
    nt = terms.shape[2]
    nd = len(dims)
    wm = 1.0 / sigma_model_m
    rows, cols, vals, rhs = [], [], [], []
    for k, dim in enumerate(dims):
        r = np.arange(n_obs) + k * n_obs
        rows += [np.repeat(r, nt), r]
        cols += [
            (obs_strip[:, None] * nt + np.arange(nt)).ravel(),
            ns * nt + nd * obs_point + k,
        ]
        vals += [wm * terms[:, k, :].ravel(), np.full(n_obs, -wm)]
        rhs.append(-wm * strip_xyz[:, dim])
    base = nd * n_obs
    for k, dim in enumerate(dims):
        wc = np.sqrt(control_weight[:, dim])
        use = wc > 0
        r = base + np.arange(int(use.sum()))
        base += r.size
        rows.append(r)
        cols.append(ns * nt + nd * control_point[use] + k)
        vals.append(wc[use])
        rhs.append(wc[use] * control_m[use, dim])
    rows_a, cols_a = np.concatenate(rows), np.concatenate(cols)
    a = sp.csr_matrix(
        (np.concatenate(vals), (rows_a, cols_a)), shape=(base, ns * nt + nd * n_points)
    )
    return a, np.concatenate(rhs), cols_a


def point_sigmas(a: sp.spmatrix, b: NDArray, x: NDArray, n_coefficients: int) -> NDArray:
    """σ of every unknown of a weighted linear least squares whose first ``n_coefficients``
    unknowns are the polynomials' and the rest points' coordinates (each point coordinate's
    normal block is one number: N_pp diagonal): σ₀·√diag(N⁻¹) by block elimination of the
    points, σ₀ = √([vv]/r) a posteriori (the model coordinates' σ is a rule of thumb; the
    residuals say what it is). The coefficients' σ are returned as NaN.

    Raises RuntimeError when the polynomials' reduced matrix is singular."""
    n = (a.T @ a).tocsr()
    k = n_coefficients
    d = n.diagonal()[k:]
    bcp = n[:k, k:].toarray()
    m = bcp / d  # N_cp·N_pp⁻¹
    s = n[:k, :k].toarray() - m @ bcp.T
    try:
        qcc = np.linalg.inv(s)
    except np.linalg.LinAlgError as exc:
        raise RuntimeError(str(exc)) from None
    q_points = 1.0 / d + np.einsum("ij,ij->j", m, qcc @ m)
    v = a @ x - b
    r = a.shape[0] - a.shape[1]
    sigma0 = float(np.sqrt(v @ v / r)) if r > 0 else float("nan")
    return np.concatenate([np.full(k, np.nan), sigma0 * np.sqrt(q_points)])
