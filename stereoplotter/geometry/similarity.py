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

__all__ = ["SimilarityFit", "apply_similarity", "fit_similarity_with_reflection"]


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
    if n < 2:
        raise GeometryError(
            f"similarity (6.8): expected at least 2 control points with X_г, Y_г and X_Ф, Y_Ф, "
            f"found {n}"
        )
    if not all(np.all(np.isfinite(v)) for v in arrays):
        raise GeometryError("similarity (6.8): control point coordinates must be finite")
    xg, yg, X, Y = arrays
    mxg, myg, mX, mY = (float(v.mean()) for v in arrays)
    dx, dy, dX, dY = xg - mxg, yg - myg, X - mX, Y - mY
    spread = float(np.sum(dx**2 + dy**2))
    extent = max(1.0, float(np.max(np.abs(np.concatenate([xg, yg])))))
    if spread <= (1e-9 * extent) ** 2:
        raise GeometryError(
            f"similarity (6.8): the {n} control points coincide in X_г, Y_г (spread "
            f"{np.sqrt(spread):.3g} m); a and b are undetermined: give points at least "
            "a few hundred metres apart"
        )
    # Normal equations of the centred problem: they are diagonal, N = spread·I.
    a = float(np.sum(dx * dX - dy * dY)) / spread
    b = float(np.sum(dy * dX + dx * dY)) / spread
    cx = mX - a * mxg - b * myg
    cy = mY + a * myg - b * mxg
    fit = SimilarityFit(a, b, cx, cy, np.zeros((n, 2)), 0.0, 2 * n - 4)
    residuals = apply_similarity(fit, xg, yg) - np.stack([X, Y], axis=-1)
    rms = float(np.sqrt(np.mean(np.sum(residuals**2, axis=-1))))
    return SimilarityFit(a, b, cx, cy, residuals, rms, 2 * n - 4)
