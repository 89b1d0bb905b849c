"""Control spacing for removing a strip's deformation by a polynomial (Burshtynskaya).

Source: Kh. V. Burshtynskaya, *О выборе расстояния между опорными точками при пространственном
фототриангулировании* ("On the choice of the distance between control points in spatial
phototriangulation"), Tables 1 and 2 and the recommended link lengths.
``docs/triangulation-papers.md`` reproduces them; ``python -m
stereoplotter.triangulation.spacing_report`` prints the comparison.

Model (the paper's first display). A strip of n bases has n + 1 points, base index b = 0 … n
(the paper numbers them 1 … n + 1: paper point = b + 1). Random errors ε_j of the bases
(independent, equal variance σ_ε²) accumulate by double summation::

    η(b) = Σ_{j=1}^{b} (b − j + 1) ε_j,      η(0) = 0,  η(1) = ε_1,  η(n) = n ε_1 + … + ε_n

so cov(η) = T Tᵀ σ_ε² with T[b, j] = max(b − j, 0) (j = 0 … n − 1). The paper's numbering
η_1 = ε_1 at point 1 adds the term (b + 1)·ε_0, linear in b, which every fitted polynomial of
degree ≥ 1 absorbs: both numberings give the same residuals (tested).

A polynomial of degree k, p(b) = a_0 + a_1 b + … + a_k b^k, is fitted (least squares; with
k + 1 control points it interpolates) to η at the control points; P is the linear operator η → p
at every point. Two "residual variances":

- :func:`residual_variance` — the variance of the actual residual Δ = η − p,
  diag((I − P) C (I − P)ᵀ). A Monte Carlo of simulated strips reproduces it
  (``tests/triangulation/test_spacing_monte_carlo.py``).
- :func:`paper_residual_variance` — the paper's Eq. (1): σ_Δ² = σ_η² − σ_p², i.e. diag(C) −
  diag(P C Pᵀ). Eq. (1) treats the fitted polynomial and Δ as uncorrelated, which they are not
  (p is a function of the same η). The printed Tables 1 and 2 are the magnitudes of this
  difference; it is negative in part of every strip (the fitted value there varies more than η).

Units: variances in units of the per-base variance σ_ε² (the paper's tables use σ_ε² = 0.01;
multiply, as its last paragraph says). Criterion of the paper for the spacing: the mean square of
the series of residual variances over the non-control points, m² = Σ (σ_Δ²)² / (N − N_control)
(its Table 1 last column, computed there from the rounded table entries).
"""

from __future__ import annotations

import itertools
from typing import Literal

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "PAPER_PER_BASE_VARIANCE",
    "accumulation_matrix",
    "choose_control_spacing",
    "eta_covariance",
    "fit_operator",
    "link_lengths",
    "mean_square",
    "paper_residual_variance",
    "residual_variance",
    "simulate_residual_variance",
]

#: σ_ε² the paper assumes for its tables ("для расчета принято σ² = 0,01").
PAPER_PER_BASE_VARIANCE = 0.01

Criterion = Literal["residual", "paper"]


def _check_strip(n_bases: int, degree: int) -> None:
    if int(n_bases) != n_bases or n_bases < 1:
        raise ValueError(f"n_bases: expected an integer ≥ 1, found {n_bases!r}")
    if int(degree) != degree or degree < 0:
        raise ValueError(f"degree: expected an integer ≥ 0, found {degree!r}")


def accumulation_matrix(n_bases: int) -> NDArray[np.float64]:
    """T of η = T ε for double summation, shape (n_bases + 1, n_bases): T[b, j] = max(b − j, 0)."""
    _check_strip(n_bases, 0)
    b = np.arange(n_bases + 1)[:, None]
    j = np.arange(n_bases)[None, :]
    return np.maximum(b - j, 0).astype(float)


def eta_covariance(n_bases: int) -> NDArray[np.float64]:
    """cov(η) = T Tᵀ in units of σ_ε², shape (n_bases + 1, n_bases + 1).

    var η(b) = Σ_{m=1}^{b} m² = b(b + 1)(2b + 1)/6.

    >>> float(eta_covariance(3)[3, 3]), float(eta_covariance(3)[2, 3])
    (14.0, 8.0)
    """
    t = accumulation_matrix(n_bases)
    return t @ t.T


def _control_array(n_bases: int, control_indices, degree: int) -> NDArray[np.int64]:
    c = np.asarray(control_indices)
    if c.ndim != 1 or c.size == 0 or not np.issubdtype(c.dtype, np.integer):
        raise ValueError(
            f"control_indices: expected base indices (integers), found {control_indices!r}"
        )
    if c.min() < 0 or c.max() > n_bases:
        raise ValueError(f"control_indices: expected values in 0 … {n_bases}, found {c.tolist()}")
    if np.unique(c).size != c.size:
        raise ValueError(f"control_indices: expected distinct points, found {c.tolist()}")
    if c.size < degree + 1:
        raise ValueError(
            f"control_indices: a degree-{degree} polynomial needs ≥ {degree + 1} control points, "
            f"found {c.size}"
        )
    return c.astype(np.int64)


def fit_operator(n_bases: int, control_indices, degree: int) -> NDArray[np.float64]:
    """P, (n_bases + 1)²: the fitted polynomial at every point from η (only control columns ≠ 0).

    Least squares in the scaled abscissa u = b/n_bases (conditioning only; the fit is the same);
    with degree + 1 control points it interpolates.
    """
    _check_strip(n_bases, degree)
    c = _control_array(n_bases, control_indices, degree)
    u = np.arange(n_bases + 1) / n_bases
    v = np.vander(u, degree + 1, increasing=True)
    p = np.zeros((n_bases + 1, n_bases + 1))
    p[:, c] = v @ np.linalg.pinv(v[c])
    return p


def residual_variance(n_bases: int, control_indices, degree: int) -> NDArray[np.float64]:
    """Variance of the residual η − p at each point b = 0 … n_bases, in units of σ_ε².

    The variance of the deformation left after the polynomial through the control is removed
    (zero at interpolated control points).
    """
    r = np.eye(n_bases + 1) - fit_operator(n_bases, control_indices, degree)
    c = eta_covariance(n_bases)
    return np.einsum("ij,jk,ik->i", r, c, r)


def paper_residual_variance(n_bases: int, control_indices, degree: int) -> NDArray[np.float64]:
    """The paper's Eq. (1) solved for σ_Δ²: var η − var p (signed), units σ_ε².

    The printed Tables 1 and 2 are |this| × 0.01 (see the module docstring for why it is not the
    variance of the residual).
    """
    p = fit_operator(n_bases, control_indices, degree)
    c = eta_covariance(n_bases)
    return np.diag(c) - np.einsum("ij,jk,ik->i", p, c, p)


def mean_square(variances, control_indices) -> float:
    """The paper's m²: Σ (σ_Δ²)² / (number of non-control points) (Table 1, last column)."""
    v = np.asarray(variances, float)
    free = np.ones(v.size, bool)
    free[np.asarray(control_indices)] = False
    return float(np.sum(v[free] ** 2) / max(int(free.sum()), 1))


def link_lengths(control_indices) -> tuple[int, ...]:
    """Bases between consecutive control points (the paper's "длины звеньев")."""
    return tuple(int(d) for d in np.diff(np.sort(np.asarray(control_indices))))


def choose_control_spacing(
    n_bases: int, degree: int, criterion: Criterion = "residual"
) -> tuple[int, ...]:
    """Base indices of degree + 1 control points for a strip of n_bases bases.

    The ends 0 and n_bases are control; the degree − 1 inner points are chosen by exhaustive
    search to minimise the paper's criterion m² (:func:`mean_square`) of the residual
    variances — of :func:`residual_variance` (``criterion="residual"``, the default: the
    variance of the deformation actually left, as the Monte Carlo confirms) or of the paper's
    |:func:`paper_residual_variance`| (``criterion="paper"``, reproducing its recommendations).
    Ties go to the longer first link (the paper's recommendations put the longer link first).

    >>> choose_control_spacing(7, 2, criterion="paper")
    (0, 4, 7)
    """
    _check_strip(n_bases, degree)
    if degree < 1 or n_bases < degree:
        raise ValueError(
            f"n_bases: a degree-{degree} fit needs degree ≥ 1 and ≥ {degree} bases, found {n_bases}"
        )
    if criterion not in ("residual", "paper"):
        raise ValueError(f"criterion: expected 'residual' or 'paper', found {criterion!r}")
    variance = residual_variance if criterion == "residual" else paper_residual_variance
    best: tuple[float, tuple[int, ...]] | None = None
    for inner in itertools.combinations(range(1, n_bases), degree - 1):
        control = (0, *inner, n_bases)
        m2 = mean_square(np.abs(variance(n_bases, np.array(control), degree)), control)
        # strictly better (by more than rounding noise), or equal with a longer first link
        if (
            best is None
            or m2 < best[0] * (1 - 1e-9)
            or (m2 <= best[0] * (1 + 1e-9) and control[1] > best[1][1])
        ):
            best = (m2, control)
    assert best is not None  # at least one combination: n_bases ≥ degree
    return best[1]


def simulate_residual_variance(
    n_bases: int,
    control_indices,
    degree: int,
    n_trials: int,
    rng: np.random.Generator,
    chunk: int = 20_000,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Monte Carlo of actual strips: mean of (η − p)² per point and its standard error.

    Each trial draws ε ~ N(0, 1) for the n_bases bases, accumulates η by double summation
    (``cumsum`` twice), fits the polynomial through the control by least squares and keeps the
    residual. Trials run in chunks of ``chunk`` (memory ≈ 8·chunk·(n_bases + 1) bytes).
    """
    p = fit_operator(n_bases, control_indices, degree)
    r = np.eye(n_bases + 1) - p
    total = np.zeros(n_bases + 1)
    total_sq = np.zeros(n_bases + 1)
    done = 0
    while done < n_trials:
        m = min(chunk, n_trials - done)
        eps = rng.standard_normal((m, n_bases))
        eta = np.zeros((m, n_bases + 1))
        eta[:, 1:] = np.cumsum(np.cumsum(eps, axis=1), axis=1)
        res2 = (eta @ r.T) ** 2
        total += res2.sum(axis=0)
        total_sq += (res2**2).sum(axis=0)
        done += m
    mean = total / n_trials
    var = np.maximum(total_sq / n_trials - mean**2, 0.0)
    return mean, np.sqrt(var / n_trials)
