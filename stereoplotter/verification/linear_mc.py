r"""Linear Monte Carlo and deterministic covariance propagation for the accuracy formulas.

Protocol (``accuracy.md``): independent zero-mean normal errors; the statistic is the RMS over
trials *and* over a uniform (midpoint) grid of the integration domain,
sqrt(mean_{t,i} δp²) — never a mean of per-point standard deviations; results "after geodetic
orientation" have the least-squares plane fitted at the four control points removed (the
control observations carry the noise the row states, zero for error-free control).

A :class:`LinearModel` holds the first-order map from standard-normal draws z (J per trial) to
the error field on the grid: e = M z (K sources), field = Gᵀe − P_fit (G_cᵀe + σ_c z_c) + σ_w z_w.
:func:`mc_rms` samples it (all trials at once, in chunks; explicit ``numpy.random.Generator``);
:func:`covariance_rms` propagates the same model exactly on the same grid.

Confidence interval: the per-trial mean square s_t is i.i.d. over trials, so
se(mean s) = sd(s_t)/√T and the half-width of the RMS is z·se/(2·rms) (delta method), z = 3.29
(99.9 %, chosen so that ~40 rows agree jointly). For one dominant source this is
≈ z/√(2T), the ``accuracy.md`` rule.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.accuracy.chapter5 import (
    control_points,
    levelling_design,
    relative_orientation_design,
    standard_points,
)
from stereoplotter.accuracy.setup_accuracy import SETUP_SOURCES

__all__ = [
    "CI_Z",
    "FloatArray",
    "LinearModel",
    "covariance_rms",
    "effective_G",
    "grid_chapter5",
    "grid_setup_unadjusted",
    "least_squares_model",
    "mc_rms",
    "relative_orientation_model",
    "setup_field_basis",
    "setup_model",
]

CI_Z = 3.29  # two-sided 99.9 % normal quantile
#: An array of floats (mm, mm², rad or a coefficient, as each name says).
FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class LinearModel:
    """First-order error model on a grid (see the module docstring).

    Attributes
    ----------
    G : ndarray (K, P)
        Field of each source on the grid.
    M : ndarray (K, J)
        Mixing matrix: source errors e = M z, z ~ N(0, I_J).
    Gc : ndarray (K, 4) or None
        Field of each source at the control points (None: no levelling).
    P_fit : ndarray (P, 4) or None
        Maps control-point values to the fitted plane on the grid.
    sigma_control : float
        Noise of one control observation [mm].
    sigma_white : float
        Independent pointwise noise (measurement error) [mm].
    """

    G: FloatArray
    M: FloatArray
    Gc: FloatArray | None = None
    P_fit: FloatArray | None = None
    sigma_control: float = 0.0
    sigma_white: float = 0.0


def _midpoints(lo: float, hi: float, n: int) -> FloatArray:
    h = (hi - lo) / n
    return np.asarray(lo + h * (np.arange(n) + 0.5), dtype=np.float64)


def grid_setup_unadjusted(c_mm: float, nx: int = 16, ny: int = 32) -> tuple[FloatArray, FloatArray]:
    """Midpoint grid of the (6.27) domain x_л ∈ [0, c], y ∈ [−c, c]; returns (x_л, y) flat.

    Examples
    --------
    >>> x, y = grid_setup_unadjusted(70.0, 4, 8)
    >>> x.shape, float(x.min())
    ((32,), 8.75)
    """
    x, y = np.meshgrid(_midpoints(0.0, c_mm, nx), _midpoints(-c_mm, c_mm, ny), indexing="ij")
    return x.ravel(), y.ravel()


def grid_chapter5(c_mm: float, nx: int = 16, ny: int = 32) -> tuple[FloatArray, FloatArray]:
    """Midpoint grid of the chapter-5 domain x_п ∈ [−c, 0], y ∈ [−c, c]; returns (x_п, y) flat.

    Examples
    --------
    >>> x, y = grid_chapter5(70.0, 4, 8)
    >>> float(x.max())
    -8.75
    """
    x, y = np.meshgrid(_midpoints(-c_mm, 0.0, nx), _midpoints(-c_mm, c_mm, ny), indexing="ij")
    return x.ravel(), y.ravel()


def setup_field_basis(
    x_right_mm: ArrayLike, y_mm: ArrayLike, x_parallax_mm: float, focal_length_mm: float
) -> FloatArray:
    """Field of each setup source (unit error) at points, (6.22) with (3.22) signs; (8, P).

    Order: :data:`SETUP_SOURCES`.

    Examples
    --------
    >>> setup_field_basis(np.array([0.0]), np.array([0.0]), 70.0, 70.0)[:, 0].tolist()
    [1.0, 70.0, -0.0, 0.0, -0.0, -0.0, 0.0, 0.0]
    """
    xr = np.asarray(x_right_mm, float)
    y = np.asarray(y_mm, float)
    xl = xr + x_parallax_mm
    f = focal_length_mm
    return np.stack(
        [np.ones_like(xr), xl**2 / f, -(xr**2) / f, y * xl / f, -y * xr / f, -y, y, xr / f]
    )


def _plane_fit_operator(
    x_grid: FloatArray, y_grid: FloatArray, a_mm: float, c_mm: float
) -> FloatArray:
    Ac = levelling_design(*control_points(a_mm, c_mm))
    Hg = levelling_design(x_grid, y_grid)
    out: FloatArray = Hg @ np.linalg.pinv(Ac)
    return out


def setup_model(
    focal_length_mm: float,
    x_parallax_mm: float,
    a_mm: float,
    c_mm: float,
    sigmas: Mapping[str, float],
    *,
    levelled: bool,
    sigma_control_mm: float = 0.0,
    grid: tuple[int, int] = (16, 32),
) -> LinearModel:
    """Linear model of setup-element errors; unlevelled on the (6.27) domain or levelled on the
    chapter-5 domain.

    Parameters
    ----------
    sigmas : mapping
        σ of each source in :data:`SETUP_SOURCES` (missing: 0).

    Examples
    --------
    >>> m = setup_model(70.0, 70.0, 0.0, 70.0, {"kappa_left": 1e-3}, levelled=False)
    >>> m.G.shape
    (8, 512)
    """
    if levelled:
        xr, y = grid_chapter5(c_mm, *grid)
    else:
        xl, y = grid_setup_unadjusted(c_mm, *grid)
        xr = xl - x_parallax_mm
    G = setup_field_basis(xr, y, x_parallax_mm, focal_length_mm)
    M = np.diag([float(sigmas.get(k, 0.0)) for k in SETUP_SOURCES])
    if not levelled:
        return LinearModel(G, M)
    xc, yc = control_points(a_mm, c_mm)
    Gc = setup_field_basis(xc, yc, x_parallax_mm, focal_length_mm)
    return LinearModel(G, M, Gc, _plane_fit_operator(xr, y, a_mm, c_mm), sigma_control_mm)


def relative_field_basis(xr: FloatArray, y: FloatArray, p: float, f: float) -> FloatArray:
    # (5.13), first order, right-photo elements τ, ν, Δα, Δω, Δκ (sign of (3.22)).
    return np.stack([-p * np.ones_like(xr), -p * xr / f, -(xr**2) / f, -xr * y / f, y])


def relative_orientation_model(
    a_mm: float,
    c_mm: float,
    x_parallax_mm: float,
    focal_length_mm: float,
    sigma_y_parallax_mm: float,
    *,
    sigma_control_mm: float = 0.0,
    sigma_white_mm: float = 0.0,
    grid: tuple[int, int] = (16, 32),
) -> LinearModel:
    """Relative orientation by six standard points (least squares, (5.10)) then levelling on four
    control points, on the chapter-5 domain.

    Examples
    --------
    >>> relative_orientation_model(0.0, 70.0, 70.0, 70.0, 1.0).M.shape
    (5, 6)
    """
    a, c, p, f = a_mm, c_mm, x_parallax_mm, focal_length_mm
    _, xs, ys = standard_points(a, p, c)
    A = relative_orientation_design(xs, ys, p, f)
    M = np.linalg.pinv(A) * sigma_y_parallax_mm
    xr, y = grid_chapter5(c, *grid)
    xc, yc = control_points(a, c)
    return LinearModel(
        relative_field_basis(xr, y, p, f),
        M,
        relative_field_basis(xc, yc, p, f),
        _plane_fit_operator(xr, y, a, c),
        sigma_control_mm,
        sigma_white_mm,
    )


def least_squares_model(design: ArrayLike, sigma_obs: float, select: int) -> LinearModel:
    """Model of one least-squares estimate (a single 'grid point'): element ``select`` of
    pinv(design) @ noise.

    Examples
    --------
    >>> m = least_squares_model(np.array([[1.0], [1.0]]), 1.0, 0)
    >>> round(covariance_rms(m), 6)
    0.707107
    """
    L = np.linalg.pinv(np.asarray(design, float)) * sigma_obs
    G = np.zeros((L.shape[0], 1))
    G[select, 0] = 1.0
    return LinearModel(G, L)


def combine(*models: LinearModel) -> LinearModel:
    """Sum of independent models on the same grid (block-diagonal mixing).

    Examples
    --------
    >>> m = least_squares_model(np.eye(1), 3.0, 0)
    >>> round(covariance_rms(combine(m, least_squares_model(np.eye(1), 4.0, 0))), 6)
    5.0
    """
    G = np.concatenate([m.G for m in models])
    K = G.shape[0]
    J = sum(m.M.shape[1] for m in models)
    M = np.zeros((K, J))
    i = j = 0
    for m in models:
        k, jj = m.M.shape
        M[i : i + k, j : j + jj] = m.M
        i += k
        j += jj
    fits = [m for m in models if m.Gc is not None]
    Gc: FloatArray | None = None
    P_fit: FloatArray | None = None
    if fits:
        Gc = np.concatenate(
            [m.Gc if m.Gc is not None else np.zeros((m.G.shape[0], 4)) for m in models]
        )
        P_fit = fits[0].P_fit
    sc = float(np.sqrt(sum(m.sigma_control**2 for m in models)))
    sw = float(np.sqrt(sum(m.sigma_white**2 for m in models)))
    return LinearModel(G, M, Gc, P_fit, sc, sw)


def effective_G(model: LinearModel) -> FloatArray:
    """The model's sensitivity rows with the control-point fit removed (``G − (P_fit·Gc)ᵀ``
    where the row levels on control points; ``G`` itself otherwise)."""
    G = model.G
    if model.Gc is not None:
        G = G - (_fit(model) @ model.Gc.T).T
    return G


def _fit(model: LinearModel) -> FloatArray:
    """``P_fit`` of a model that levels on control points (``Gc`` set)."""
    if model.P_fit is None:
        raise ValueError("a model with control-point fields (Gc) needs its plane fit (P_fit)")
    return model.P_fit


def covariance_rms(model: LinearModel) -> float:
    """RMS over the grid of the exactly propagated error field (no sampling) [mm].

    Examples
    --------
    >>> round(covariance_rms(least_squares_model(np.eye(2), 2.0, 1)), 6)
    2.0
    """
    Ge = effective_G(model)
    S = model.M @ model.M.T
    var = np.einsum("kp,kl,lp->p", Ge, S, Ge)
    if model.Gc is not None and model.sigma_control:
        var = var + model.sigma_control**2 * np.sum(_fit(model) ** 2, axis=1)
    var = var + model.sigma_white**2
    return float(np.sqrt(var.mean()))


def mc_rms(
    model: LinearModel, trials: int, rng: np.random.Generator, chunk: int = 4000
) -> tuple[float, float, FloatArray]:
    """Monte Carlo RMS over trials and grid points, with its CI half-width.

    Returns
    -------
    rms : float
        sqrt(mean over trials and grid of δp²) [mm].
    half_width : float
        CI_Z standard errors of ``rms`` (delta method on the per-trial mean squares) [mm].
    per_trial : ndarray (trials,)
        Per-trial mean squares (for histograms) [mm²].

    Examples
    --------
    >>> m = least_squares_model(np.eye(1), 1.0, 0)
    >>> r, h, _ = mc_rms(m, 20000, np.random.default_rng(1))
    >>> abs(r - 1.0) < h
    True
    """
    if trials < 2:
        raise ValueError(f"trials = {trials} must be at least 2")
    # The field of a trial is linear in its draws x = (z, control noise): field = x @ B, B of
    # (J + n_c) × P composed once; its mean square over the grid is then the quadratic form
    # x Q xᵀ with Q = B Bᵀ/P, (J + n_c)² work a trial instead of J·P (the same draws, in the
    # same order, as drawing the field; equal to rounding). White noise is drawn on the field.
    J = model.M.shape[1]
    P = model.G.shape[1]
    B = model.M.T @ model.G  # (J, P)
    nc = 0
    if model.Gc is not None:
        B = B - (model.M.T @ model.Gc) @ _fit(model).T
        if model.sigma_control:
            nc = model.Gc.shape[1]
            B = np.vstack([B, -model.sigma_control * _fit(model).T])
    Q = B @ B.T / P
    out = np.empty(trials)
    if model.sigma_white:
        # the chunk's field and white noise in two arrays reused by every chunk (filled in
        # place: the same draws and the same arithmetic as fresh arrays, without allocating
        # and touching t·P new values twice a chunk)
        size = min(chunk, trials)
        field_buffer, noise_buffer = np.empty((size, P)), np.empty((size, P))
    for start in range(0, trials, chunk):
        t = min(chunk, trials - start)
        x = rng.standard_normal((t, J))
        if nc:
            x = np.hstack([x, rng.standard_normal((t, nc))])
        if model.sigma_white:
            field, noise = field_buffer[:t], noise_buffer[:t]
            np.matmul(x, B, out=field)
            rng.standard_normal(out=noise)
            np.multiply(noise, model.sigma_white, out=noise)
            field += noise
            out[start : start + t] = np.einsum("tp,tp->t", field, field) / P
        else:
            out[start : start + t] = np.einsum("ti,ti->t", x @ Q, x)
    ms = out.mean()
    se = out.std(ddof=1) / np.sqrt(trials)
    rms = float(np.sqrt(ms))
    return rms, float(CI_Z * se / (2.0 * rms)), out
