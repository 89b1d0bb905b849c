r"""The plane similarity with reflection of Eq. (6.8), fitted by least squares.

Reference
---------
.. [1] Kushtin & Lyskov, *Фотограмметрия снимка и стереоскопических моделей*, Nedra, 1984, ch. 6,
   §26, pp. 153–158 (OCR L3733–3741).

X_Ф = a·X_г + b·Y_г + c_X,  Y_Ф = −a·Y_г + b·X_г + c_Y

X_г, Y_г are Gauss–Krüger x (north) and y (east) [m], X_Ф, Y_Ф photogrammetric coordinates [m].
The linear part [[a, b], [b, −a]] has determinant −(a² + b²) < 0: the reflection swaps the
left-handed (north, east) pair into the right-handed photogrammetric pair. This is intended; a
proper similarity on the unswapped pair cannot represent it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.errors import GeometryError
from stereoplotter.geometry.grouped import group_sums

__all__ = [
    "SimilarityFit",
    "SimilarityFits",
    "apply_similarity",
    "fit_similarities_with_reflection",
    "fit_similarity_with_reflection",
]


@dataclass(frozen=True, slots=True)
class SimilarityFit:
    """Coefficients and residuals of the fit of Eq. (6.8).

    Attributes
    ----------
    a, b : float
        Similarity coefficients a, b. [—]
    cx_m, cy_m : float
        Shifts c_X, c_Y. [m]
    residuals_m : ndarray, shape (n, 2)
        v_x, v_y = fitted − given X_Ф, Y_Ф per point. [m]
    rms_m : float
        sqrt(mean(v_x² + v_y²)) over the points (per point, both axes). [m]
    redundancy : int
        2n − 4. [—]
    """

    a: float
    b: float
    cx_m: float
    cy_m: float
    residuals_m: NDArray[np.float64]
    rms_m: float
    redundancy: int

    @property
    def scale(self) -> float:
        """√(a² + b²): the scale from Gauss–Krüger to photogrammetric metres. [—]"""
        return float(np.hypot(self.a, self.b))

    @property
    def determinant(self) -> float:
        """det [[a, b], [b, −a]] = −(a² + b²) < 0. [—]"""
        return -(self.a**2 + self.b**2)


def apply_similarity(
    fit: SimilarityFit, gk_north_m: ArrayLike, gk_east_m: ArrayLike
) -> NDArray[np.float64]:
    r"""Photogrammetric X_Ф, Y_Ф of Gauss–Krüger points by Eq. (6.8).

    Parameters
    ----------
    fit : SimilarityFit
    gk_north_m, gk_east_m : float or ndarray
        X_г (north), Y_г (east). [m]

    Returns
    -------
    ndarray, shape (..., 2)
        X_Ф, Y_Ф. [m]

    Notes
    -----
    Implements Eq. (6.8) of [1]_ (OCR L3735, L3739); (6.7) scales the result to the model.
    """
    xg = np.asarray(gk_north_m, float)
    yg = np.asarray(gk_east_m, float)
    X = fit.a * xg + fit.b * yg + fit.cx_m
    Y = -fit.a * yg + fit.b * xg + fit.cy_m
    return np.stack([X, Y], axis=-1)


def fit_similarity_with_reflection(
    gk_north_m: ArrayLike,
    gk_east_m: ArrayLike,
    X_m: ArrayLike,
    Y_m: ArrayLike,
) -> SimilarityFit:
    r"""Least-squares fit of a, b, c_X, c_Y of Eq. (6.8) to control points.

    Parameters
    ----------
    gk_north_m, gk_east_m : array_like, shape (n,)
        X_г (north), Y_г (east) of the control points. [m]
    X_m, Y_m : array_like, shape (n,)
        Their photogrammetric X_Ф, Y_Ф. [m]

    Returns
    -------
    SimilarityFit

    Raises
    ------
    GeometryError
        Fewer than 2 points, mismatched lengths, non-finite values, or all points (nearly)
        coincident so that a, b are undetermined.

    Notes
    -----
    Implements the least-squares solution of Eq. (6.8) of [1]_ with the residual equations

    .. math::
        a X_г + b Y_г + c_X - X_Ф = v_x,\quad -a Y_г + b X_г + c_Y - Y_Ф = v_y

    solved on coordinates reduced to their centroids (Gauss–Krüger values are ~10⁶ m), which
    separates a, b from c_X, c_Y exactly.

    Examples
    --------
    A pure axis swap (X_Ф = Y_г, Y_Ф = X_г) gives a = 0, b = 1:

    >>> fit = fit_similarity_with_reflection([0, 100, 0], [0, 0, 100], [0, 0, 100], [0, 100, 0])
    >>> round(fit.a, 12) + 0.0, round(fit.b, 12)
    (0.0, 1.0)
    """
    arrays = [np.atleast_1d(np.asarray(v, float)) for v in (gk_north_m, gk_east_m, X_m, Y_m)]
    n = arrays[0].size
    if any(v.ndim != 1 or v.size != n for v in arrays):
        raise GeometryError(
            "similarity (6.8): expected four 1-D arrays of equal length, found shapes "
            f"{[v.shape for v in arrays]}"
        )
    fits = fit_similarities_with_reflection(np.zeros(n, np.intp), *arrays, groups=1)
    return fits.fit(0)


@dataclass(frozen=True, slots=True)
class SimilarityFits:
    """The fits of Eq. (6.8) of many groups of points at once.

    Made by :func:`fit_similarities_with_reflection`.
    ``a``, ``b``, ``cx_m``, ``cy_m``, ``rms_m``, ``redundancy`` have shape (G,);
    ``residuals_m`` (n, 2) in the order of the points given, ``group`` (n,) their group;
    ``order`` the points sorted by group (stably), group ``g``'s from ``start[g]`` to
    ``start[g + 1]`` of it.
    """

    a: NDArray[np.float64]
    b: NDArray[np.float64]
    cx_m: NDArray[np.float64]
    cy_m: NDArray[np.float64]
    residuals_m: NDArray[np.float64]
    rms_m: NDArray[np.float64]
    redundancy: NDArray[np.int64]
    group: NDArray[np.intp]
    order: NDArray[np.intp]
    start: NDArray[np.intp]

    def fit(self, g: int) -> SimilarityFit:
        """Group ``g`` as a :class:`SimilarityFit` (its residuals in the order given)."""
        return SimilarityFit(
            float(self.a[g]), float(self.b[g]), float(self.cx_m[g]), float(self.cy_m[g]),
            self.residuals_m[self.order[self.start[g] : self.start[g + 1]]],
            float(self.rms_m[g]), int(self.redundancy[g]),
        )  # fmt: skip


def fit_similarities_with_reflection(
    group: ArrayLike,
    gk_north_m: ArrayLike,
    gk_east_m: ArrayLike,
    X_m: ArrayLike,
    Y_m: ArrayLike,
    *,
    groups: int,
) -> SimilarityFits:
    r"""Least-squares fits of Eq. (6.8), one per group of points, of unequal point counts.

    Parameters
    ----------
    group : array_like of int, shape (n,)
        The group (0 … ``groups`` − 1) of each point.
    gk_north_m, gk_east_m, X_m, Y_m : array_like, shape (n,)
        As for :func:`fit_similarity_with_reflection`. [m]
    groups : int
        The number of groups; each must hold at least 2 points.

    Returns
    -------
    SimilarityFits

    Raises
    ------
    GeometryError
        A group with fewer than 2 points, a non-finite value, or a group whose points coincide.

    Notes
    -----
    The solution of :func:`fit_similarity_with_reflection` (which calls this with one group):
    each group's sums are those of ``numpy.sum`` over the group alone, to the bit.
    """
    idx = np.asarray(group, np.intp)
    xg, yg, X, Y = (np.asarray(v, float) for v in (gk_north_m, gk_east_m, X_m, Y_m))
    count = np.bincount(idx, minlength=groups)
    if groups < 1 or count.min() < 2:
        n = 0 if groups < 1 else int(count.min())
        raise GeometryError(
            f"similarity (6.8): expected at least 2 control points with X_г, Y_г and X_Ф, Y_Ф, "
            f"found {n}"
        )
    if not all(np.all(np.isfinite(v)) for v in (xg, yg, X, Y)):
        raise GeometryError("similarity (6.8): control point coordinates must be finite")

    order = np.argsort(idx, kind="stable")
    start = np.concatenate([[0], np.cumsum(count)])
    in_order = bool(np.all(idx[:-1] <= idx[1:]))  # the groups given one after the other

    def total(v: NDArray) -> NDArray:  # as numpy.sum of each group alone gives it
        return group_sums(v if in_order else v[order], start)

    mxg, myg, mX, mY = (total(v) / count for v in (xg, yg, X, Y))
    dx, dy, dX, dY = xg - mxg[idx], yg - myg[idx], X - mX[idx], Y - mY[idx]
    spread = total(dx**2 + dy**2)
    largest = np.maximum.reduceat(np.maximum(np.abs(xg), np.abs(yg))[order], start[:-1])
    extent = np.maximum(1.0, largest)
    flat = spread <= (1e-9 * extent) ** 2
    if flat.any():
        g = int(np.flatnonzero(flat)[0])
        raise GeometryError(
            f"similarity (6.8): the {count[g]} control points coincide in X_г, Y_г (spread "
            f"{np.sqrt(spread[g]):.3g} m); a and b are undetermined: give points at least "
            "a few hundred metres apart"
        )
    # Normal equations of the centred problem: they are diagonal, N = spread·I.
    a = total(dx * dX - dy * dY) / spread
    b = total(dy * dX + dx * dY) / spread
    cx = mX - a * mxg - b * myg
    cy = mY + a * myg - b * mxg
    # Eq. (6.8) at the points (apply_similarity's expressions, per group) minus X_Ф, Y_Ф
    fitted_x = a[idx] * xg + b[idx] * yg + cx[idx]
    fitted_y = -a[idx] * yg + b[idx] * xg + cy[idx]
    residuals = np.stack([fitted_x - X, fitted_y - Y], axis=-1)
    rms = np.sqrt(total(residuals[:, 0] ** 2 + residuals[:, 1] ** 2) / count)
    return SimilarityFits(a, b, cx, cy, residuals, rms, 2 * count - 4, idx, order, start)
