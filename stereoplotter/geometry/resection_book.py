r"""The book's separate determination of the elements of exterior orientation (§18).

Reference
---------
.. [1] Kushtin & Lyskov, *Фотограмметрия снимка и стереоскопических моделей*, Moscow: Nedra,
   1984, ch. 3, §18 "Separate determination of the elements of exterior orientation and of the
   corrections to photo coordinates from control points", pp. 80–93 (OCR L1983–2300); worked
   example in Tables 7–13 (OCR L2097–2276).

The method works on *lines* i–j between pairs of control points:

1. Angular elements. Each line gives one working equation (3.23), A′α + B′ω + κ + l′ = 0,
   whose coefficients (3.24) use only photo differences, ground differences and the height
   difference h = Z_j − Z_i: the linear elements X_S, Y_S, Z_S drop out. The equations of all
   lines are solved by least squares (approximation I, Table 8). The photo is then transformed
   with the angles found, Eq. (3.17) (Table 9), and the same equations written with the
   transformed coordinates give corrections δα, δω, δκ (approximation II, Table 10), and so on.
2. Z_S from the ratio of the ground and transformed-photo lengths of each line, Eq. (3.26)
   (Table 12), with the weighted mean (3.27).
3. X_S, Y_S from each point by Eq. (3.28) and the mean (3.29) (Table 13).

Corrections to the printed equations (``docs/conventions.md`` §12, items 26 and 28), verified on
Tables 8, 10 and 12:

* (3.24): A′ = [K(X_j − X_i) + h(**y_j − y_i**)]/Q and
  l′ = (ρ″/Q)[(**y_j − y_i**)(X_j − X_i) − (x_j − x_i)(Y_j − Y_i) − K·h]. The OCR prints
  h(Y₂ − Y₁) in A′ and (Y₂ − Y₁)(X₂ − X₁) in l′.
* (3.26): ΔY_ij uses **y_j⁰** (printed x_j⁰), and h = Z_j − Z_i (printed h_i).

Updates of the angles are *added* to the previous approximation, as the book does
(α^II = α^I + δα₁). The correct composition is M = R(δα, δω, δκ)·M^I; the difference is of second
order and the iteration converges to the same fixed point.

Conventions: photo coordinates [mm] relative to the principal point, object coordinates [m],
angles [rad] (the book's free terms l′ are in arc-seconds; here they are in radians).
Lines are ordered as in the book: (1-2, 1-3, 1-4, 2-3, 2-4, 3-4) for four points, i.e.
:func:`itertools.combinations` of the point indices.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.constants import ARCSEC_PER_RAD
from stereoplotter.errors import GeometryError
from stereoplotter.geometry.rotation import rotation_matrix
from stereoplotter.geometry.transformed import transformed_coordinates

__all__ = [
    "AngularApproximations",
    "BookResection",
    "FlyingHeightLines",
    "LineCoefficients",
    "angular_elements_by_lines",
    "angular_normal_equations",
    "book_space_resection",
    "flying_height_by_lines",
    "line_coefficients",
    "line_pairs",
    "projection_centre_height",
    "projection_centre_plan_by_points",
    "solve_angular_normal_equations",
]


def line_pairs(n_points: int) -> NDArray[np.intp]:
    """Index pairs (i, j), i < j, of all lines between n points, in the book's order.

    Parameters
    ----------
    n_points : int
        Number of control points. [—]

    Returns
    -------
    ndarray, shape (n(n − 1)/2, 2)
        Zero-based point indices; for 4 points the lines 1-2, 1-3, 1-4, 2-3, 2-4, 3-4 of
        Tables 8, 10 and 12 of [1]_.

    Examples
    --------
    >>> line_pairs(3).tolist()
    [[0, 1], [0, 2], [1, 2]]
    """
    return np.array(list(itertools.combinations(range(n_points), 2)), dtype=np.intp).reshape(-1, 2)


def _check_inputs(photo_mm: ArrayLike, points_m: ArrayLike, pairs: ArrayLike | None):
    photo = np.asarray(photo_mm, dtype=float)
    points = np.asarray(points_m, dtype=float)
    if photo.ndim != 2 or photo.shape[1] != 2 or points.shape != (photo.shape[0], 3):
        raise GeometryError(
            f"need photo_mm of shape (n, 2) and points_m of shape (n, 3), got {photo.shape} "
            f"and {points.shape}"
        )
    if photo.shape[0] < 3:
        raise GeometryError(
            f"the line method of §18 needs at least 3 control points, got {photo.shape[0]}"
        )
    pairs = line_pairs(photo.shape[0]) if pairs is None else np.asarray(pairs, dtype=np.intp)
    return photo, points, pairs


@dataclass(frozen=True, slots=True)
class LineCoefficients:
    """Coefficients of the working equations (3.23) of one approximation (Tables 8 and 10).

    Attributes
    ----------
    pairs : ndarray, shape (m, 2)
        Point indices i, j of each line. [—]
    photo_difference_mm : ndarray, shape (m, 2)
        x_j − x_i, y_j − y_i (transformed coordinates after approximation I). [mm]
    ground_difference_m : ndarray, shape (m, 3)
        X_j − X_i, Y_j − Y_i, h = Z_j − Z_i. [m]
    K_mm : ndarray, shape (m,)
        K = (x_j y_i − x_i y_j)/f, twice the area of the triangle o-i-j over f. [mm]
    Q : ndarray, shape (m,)
        Q = (x_j − x_i)(X_j − X_i) + (y_j − y_i)(Y_j − Y_i). [mm·m]
    A, B : ndarray, shape (m,)
        Coefficients A′ of α and B′ of ω. [—] (The coefficient of κ is C′ = 1.)
    free_term : ndarray, shape (m,)
        l′. [rad] (the book prints l′ in arc-seconds)
    """

    pairs: NDArray[np.intp]
    photo_difference_mm: NDArray[np.float64]
    ground_difference_m: NDArray[np.float64]
    K_mm: NDArray[np.float64]
    Q: NDArray[np.float64]
    A: NDArray[np.float64]
    B: NDArray[np.float64]
    free_term: NDArray[np.float64]


# long: the docstring (Eqs. (3.23)–(3.24) and a Table 8 example) is 65 lines; code ~28
def line_coefficients(
    photo_mm: ArrayLike,
    points_m: ArrayLike,
    focal_length_mm: float,
    principal_point_mm: ArrayLike = (0.0, 0.0),
    pairs: ArrayLike | None = None,
) -> LineCoefficients:
    r"""Coefficients of the working equation A′α + B′ω + κ + l′ = 0 for each line i–j.

    Parameters
    ----------
    photo_mm : array_like, shape (n, 2)
        Photo coordinates x, y of the control points: measured ones for approximation I,
        transformed ones x⁰, y⁰ (Eq. (3.17), with x₀ = y₀ = 0) for the later approximations. [mm]
    points_m : array_like, shape (n, 3)
        X, Y, Z of the control points. [m]
    focal_length_mm : float
        f. [mm]
    principal_point_mm : array_like, shape (2,)
        x₀, y₀ [mm]; subtracted from ``photo_mm``.
    pairs : array_like, shape (m, 2), optional
        Zero-based point indices of the lines; default :func:`line_pairs`.

    Returns
    -------
    LineCoefficients

    Raises
    ------
    GeometryError
        If Q = 0 for a line (coincident points, or a line whose photo and ground directions are
        perpendicular).

    Notes
    -----
    Implements Eqs. (3.23)–(3.24) of [1]_ (OCR L2061–2065), with the correction of
    ``conventions.md`` §12 item 26 (verified on every entry of Tables 8 and 10):

    .. math::
        A' = \frac{K(X_j - X_i) + h(y_j - y_i)}{Q},\quad
        B' = \frac{K(Y_j - Y_i) - h(x_j - x_i)}{Q},\quad C' = 1,

        l' = \frac{(y_j - y_i)(X_j - X_i) - (x_j - x_i)(Y_j - Y_i) - K h}{Q},

        Q = (x_j - x_i)(X_j - X_i) + (y_j - y_i)(Y_j - Y_i),\quad
        K = \frac{x_j y_i - x_i y_j}{f},\quad h = Z_j - Z_i.

    The equation follows from (3.20)–(3.21) (the rigorous coplanarity (3.16) linearised in
    α, ω, κ) with x_j⁰, y_j⁰ replaced by their first-order form (3.22) and divided by C ≈ Q.

    Examples
    --------
    Line 1-2 of Table 8 of [1]_ (K = 133.39807, Q = 201 440.82, A = 0.930606,
    B = −0.059286, l = 834.38″):

    >>> import numpy as np
    >>> c = line_coefficients([[-78.8969, 64.8774], [64.9894, 73.36805]],
    ...                       [[2100, 1400, 2], [3500, 1400, 85]], 75.0, pairs=[[0, 1]])
    >>> float(np.round(c.A[0], 6)), float(np.round(c.B[0], 6))
    (0.930606, -0.059286)
    >>> float(np.round(c.free_term[0] * 648000 / np.pi, 2))
    834.38
    """
    xy = np.asarray(photo_mm, dtype=float) - np.asarray(principal_point_mm, dtype=float)
    points = np.asarray(points_m, dtype=float)
    pairs = line_pairs(xy.shape[0]) if pairs is None else np.asarray(pairs, dtype=np.intp)
    i, j = pairs[:, 0], pairs[:, 1]
    f = float(focal_length_mm)
    dxy = xy[j] - xy[i]
    dXYh = points[j] - points[i]
    dx, dy = dxy[:, 0], dxy[:, 1]
    dX, dY, h = dXYh[:, 0], dXYh[:, 1], dXYh[:, 2]
    K = (xy[j, 0] * xy[i, 1] - xy[i, 0] * xy[j, 1]) / f  # (3.24), K = 2S_oij / f
    Q = dx * dX + dy * dY  # (3.24)
    _refuse_zero_q(pairs, Q, np.hypot(dx, dy) * np.hypot(dX, dY))
    A = (K * dX + h * dy) / Q  # (3.24), corrected: h(y_j − y_i)
    B = (K * dY - h * dx) / Q  # (3.24)
    free_term = (dy * dX - dx * dY - K * h) / Q  # (3.24), corrected: (y_j − y_i)(X_j − X_i)
    return LineCoefficients(pairs, dxy, dXYh, K, Q, A, B, free_term)


def _refuse_zero_q(pairs: NDArray[np.intp], Q: NDArray[np.float64], lengths) -> None:
    """Raise :class:`GeometryError` for the lines whose Q of (3.24) vanishes (relative to the
    product ``lengths`` of their photo and ground lengths)."""
    zero = np.abs(Q) <= 1e-12 * (lengths + 1e-300)
    if np.any(zero):
        raise GeometryError(
            f"Q = 0 for lines {(pairs[zero] + 1).tolist()} (1-based): coincident points, or photo "
            "and ground directions at 90°; the working equation (3.23) cannot be divided by Q"
        )


def angular_normal_equations(
    coefficients: LineCoefficients,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    r"""Normal equations N·(α, ω, κ) + n = 0 of the working equations (3.23).

    Parameters
    ----------
    coefficients : LineCoefficients
        From :func:`line_coefficients`.

    Returns
    -------
    N : ndarray, shape (3, 3)
        [[AA], [AB], [A]; [AB], [BB], [B]; [A], [B], m] (Gauss brackets). [—]
    n : ndarray, shape (3,)
        [Al′], [Bl′], [l′]. [rad]

    Notes
    -----
    Least squares on Eq. (3.23) of [1]_ with equal weights, as in the example after Table 8
    (OCR L2119) and before Table 10 (OCR L2162).
    """
    design = np.column_stack([coefficients.A, coefficients.B, np.ones_like(coefficients.A)])
    return design.T @ design, design.T @ coefficients.free_term


def solve_angular_normal_equations(
    normal_matrix: ArrayLike, normal_constants: ArrayLike
) -> NDArray[np.float64]:
    r"""Solve N·(α, ω, κ) + n = 0.

    Parameters
    ----------
    normal_matrix : array_like, shape (3, 3)
        N from :func:`angular_normal_equations`. [—]
    normal_constants : array_like, shape (3,)
        n. [rad]

    Returns
    -------
    ndarray, shape (3,)
        α, ω, κ (approximation I) or δα, δω, δκ (later approximations). [rad]

    Raises
    ------
    GeometryError
        If N is singular (fewer than three independent lines).

    Notes
    -----
    The solution of the normal equations of Eq. (3.23) of [1]_ (OCR L2119–2127).
    """
    N = np.asarray(normal_matrix, dtype=float)
    n = np.asarray(normal_constants, dtype=float)
    if np.linalg.cond(N) > 1e12:
        raise GeometryError(
            f"the normal equations of (3.23) are singular (condition {np.linalg.cond(N):.3g}): "
            "the lines do not determine alpha, omega and kappa"
        )
    return -np.linalg.solve(N, n)


@dataclass(frozen=True, slots=True)
class AngularApproximations:
    """Successive approximations of α, ω, κ by the line method of §18.

    Attributes
    ----------
    alpha, omega, kappa : float
        The last approximation. [rad]
    approximations : ndarray, shape (k, 3)
        Row r is approximation r + 1 (I, II, III, ...) of (α, ω, κ). [rad]
    corrections : ndarray, shape (k, 3)
        Row 0 is approximation I itself; row r ≥ 1 is (δα, δω, δκ) added to get
        approximation r + 1. [rad]
    converged : bool
        Whether the last correction was below the tolerance.
    """

    alpha: float
    omega: float
    kappa: float
    approximations: NDArray[np.float64]
    corrections: NDArray[np.float64]
    converged: bool


def angular_elements_by_lines(
    photo_mm: ArrayLike,
    points_m: ArrayLike,
    focal_length_mm: float,
    principal_point_mm: ArrayLike = (0.0, 0.0),
    *,
    initial: ArrayLike = (0.0, 0.0, 0.0),
    tolerance: float = 1e-4 / ARCSEC_PER_RAD,
    max_approximations: int = 20,
    pairs: ArrayLike | None = None,
) -> AngularApproximations:
    r"""Angular elements α, ω, κ by successive approximations on the lines (Tables 8–11).

    Parameters
    ----------
    photo_mm : array_like, shape (n, 2)
        Measured photo coordinates x, y, n ≥ 3. [mm]
    points_m : array_like, shape (n, 3)
        X, Y, Z of the control points. [m]
    focal_length_mm : float
        f. [mm]
    principal_point_mm : array_like, shape (2,)
        x₀, y₀. [mm]
    initial : array_like, shape (3,)
        Starting (α, ω, κ) [rad]; the book starts plan photos from 0.
    tolerance : float
        Stop when every correction is at most this. [rad] (default 1e-4″)
    max_approximations : int
        Upper limit on the number of approximations. [—]
    pairs : array_like, shape (m, 2), optional
        Lines to use; default all pairs (:func:`line_pairs`).

    Returns
    -------
    AngularApproximations

    Raises
    ------
    GeometryError
        Fewer than 3 points, a degenerate line (Q = 0) or singular normal equations.

    Notes
    -----
    The book's "second method" of §18 of [1]_ (OCR L2036): in each approximation the photo is
    transformed with the current angles by Eq. (3.17) (with x₀ = y₀ = 0 on the transformed
    photo), the working equations (3.23)–(3.24) are formed from the transformed coordinates
    (:func:`line_coefficients`) and solved by least squares
    (:func:`angular_normal_equations`); the corrections are added to the angles. Approximation
    I, from α = ω = κ = 0, uses the measured coordinates directly (Table 8). The book stops after
    approximation III (0.4″ error in its example); here the iteration runs to ``tolerance``.

    **Known limit:** the working equation is linear in the angles about the current
    approximation, so the iteration needs a start within a few degrees (plan photos; the default
    zero start converged for all three angles up to 5° in a sweep of 300 random geometries).
    With error-free data the fixed point is the exact orientation.
    """
    photo, points, pairs = _check_inputs(photo_mm, points_m, pairs)
    f = float(focal_length_mm)
    pp = np.asarray(principal_point_mm, dtype=float)
    angles = np.asarray(initial, dtype=float).copy()
    approximations, corrections = [], []
    converged = False
    for _ in range(max_approximations):
        transformed = transformed_coordinates(photo, rotation_matrix(*angles), f, pp)  # (3.17)
        coefficients = line_coefficients(transformed, points, f, pairs=pairs)  # (3.24)
        delta = solve_angular_normal_equations(*angular_normal_equations(coefficients))
        angles = angles + delta
        approximations.append(angles.copy())
        corrections.append(delta)
        if np.all(np.abs(delta) <= tolerance):
            converged = True
            break
    return AngularApproximations(
        alpha=float(angles[0]),
        omega=float(angles[1]),
        kappa=float(angles[2]),
        approximations=np.array(approximations),
        corrections=np.array(corrections),
        converged=converged,
    )


@dataclass(frozen=True, slots=True)
class FlyingHeightLines:
    """Z_S from each line i–j by Eq. (3.26) (Table 12).

    Attributes
    ----------
    pairs : ndarray, shape (m, 2)
        Point indices i, j. [—]
    photo_difference_mm : ndarray, shape (m, 2)
        Δx⁰_ij = x⁰_j − x⁰_i, Δy⁰_ij = y⁰_j − y⁰_i. [mm]
    ground_difference_m : ndarray, shape (m, 2)
        ΔX_ij, ΔY_ij, the ground differences reduced to the height of point i. [m]
    ground_distance_m : ndarray, shape (m,)
        D⁰_ij = √(ΔX_ij² + ΔY_ij²). [m]
    height_above_point_m : ndarray, shape (m,)
        Z_S − Z_i. [m]
    projection_centre_height_m : ndarray, shape (m,)
        Z_S of each line. [m]
    weight : ndarray, shape (m,)
        p = D⁰²_ij / D⁰²_first line, the weights of Eq. (3.27) normalised as in Table 12. [—]
    """

    pairs: NDArray[np.intp]
    photo_difference_mm: NDArray[np.float64]
    ground_difference_m: NDArray[np.float64]
    ground_distance_m: NDArray[np.float64]
    height_above_point_m: NDArray[np.float64]
    projection_centre_height_m: NDArray[np.float64]
    weight: NDArray[np.float64]


def flying_height_by_lines(
    transformed_mm: ArrayLike,
    points_m: ArrayLike,
    focal_length_mm: float,
    pairs: ArrayLike | None = None,
) -> FlyingHeightLines:
    r"""Height Z_S of the projection centre from each line i–j of the transformed photo.

    Parameters
    ----------
    transformed_mm : array_like, shape (n, 2)
        Transformed coordinates x⁰, y⁰ of Eq. (3.17), with the final angles. [mm]
    points_m : array_like, shape (n, 3)
        X, Y, Z of the control points. [m]
    focal_length_mm : float
        f. [mm]
    pairs : array_like, shape (m, 2), optional
        Lines; default :func:`line_pairs`.

    Returns
    -------
    FlyingHeightLines

    Notes
    -----
    Implements Eq. (3.26) of [1]_ (OCR L2210–2218), with the correction of ``conventions.md``
    §12 item 28 (verified on every entry of Table 12: the printed ΔY_ij uses x⁰_j and h_i):

    .. math::
        Z_S - Z_i = f\frac{D^0_{ij}}{d^0_{ij}}
                  = f\sqrt{\frac{\Delta X_{ij}^2 + \Delta Y_{ij}^2}
                               {\Delta x_{ij}^{0\,2} + \Delta y_{ij}^{0\,2}}},\quad
        \Delta X_{ij} = X_j - X_i + \frac{h}{f}x_j^0,\quad
        \Delta Y_{ij} = Y_j - Y_i + \frac{h}{f}y_j^0,

    with h = Z_j − Z_i. ΔX_ij, ΔY_ij are the ground differences reduced to the horizontal plane of
    point i. The weights p = c·D⁰²_ij of (3.27) are returned with c = 1/D⁰²_first.
    """
    xy = np.asarray(transformed_mm, dtype=float)
    points = np.asarray(points_m, dtype=float)
    pairs = line_pairs(xy.shape[0]) if pairs is None else np.asarray(pairs, dtype=np.intp)
    i, j = pairs[:, 0], pairs[:, 1]
    f = float(focal_length_mm)
    dxy = xy[j] - xy[i]
    h = points[j, 2] - points[i, 2]
    dXY = points[j, :2] - points[i, :2] + (h / f)[:, None] * xy[j]  # (3.26), corrected
    D = np.hypot(dXY[:, 0], dXY[:, 1])
    d = np.hypot(dxy[:, 0], dxy[:, 1])
    if np.any(d == 0.0):
        raise GeometryError(
            f"lines {(pairs[d == 0.0] + 1).tolist()} (1-based) have zero length on the photo; "
            "Eq. (3.26) needs distinct image points"
        )
    above = f * D / d  # (3.26)
    return FlyingHeightLines(
        pairs=pairs,
        photo_difference_mm=dxy,
        ground_difference_m=dXY,
        ground_distance_m=D,
        height_above_point_m=above,
        projection_centre_height_m=above + points[i, 2],
        weight=D**2 / D[0] ** 2,
    )


def projection_centre_height(lines: FlyingHeightLines) -> float:
    r"""Weighted mean Z_S of the per-line heights.

    Parameters
    ----------
    lines : FlyingHeightLines
        From :func:`flying_height_by_lines`.

    Returns
    -------
    float
        Z_S = Σ p Z_S / Σ p. [m]

    Notes
    -----
    Implements Eq. (3.27) of [1]_ (OCR L2220–2226) with p proportional to D⁰²_ij, the square of
    the (reduced) ground distance (Table 12; the weights 1, 1.79, 0.94, ... are ground-distance
    ratios, not photo-distance ratios).
    """
    return float(np.sum(lines.weight * lines.projection_centre_height_m) / np.sum(lines.weight))


def projection_centre_plan_by_points(
    transformed_mm: ArrayLike,
    points_m: ArrayLike,
    projection_centre_height_m: float,
    focal_length_mm: float,
) -> NDArray[np.float64]:
    r"""X_S, Y_S of the projection centre from each control point.

    Parameters
    ----------
    transformed_mm : array_like, shape (n, 2)
        x⁰, y⁰ of Eq. (3.17). [mm]
    points_m : array_like, shape (n, 3)
        X, Y, Z of the control points. [m]
    projection_centre_height_m : float
        Z_S from :func:`projection_centre_height`. [m]
    focal_length_mm : float
        f. [mm]

    Returns
    -------
    ndarray, shape (n, 2)
        X_Si, Y_Si. [m] Their mean is X_S, Y_S of Eq. (3.29).

    Notes
    -----
    Implements Eq. (3.28) of [1]_ (OCR L2228–2230):

    .. math:: X_{S_i} = X_i - \frac{Z_S - Z_i}{f}x_i^0,\quad
              Y_{S_i} = Y_i - \frac{Z_S - Z_i}{f}y_i^0
    """
    xy = np.asarray(transformed_mm, dtype=float)
    points = np.asarray(points_m, dtype=float)
    scale = (projection_centre_height_m - points[:, 2]) / float(focal_length_mm)
    return points[:, :2] - scale[:, None] * xy  # (3.28)


@dataclass(frozen=True, slots=True)
class BookResection:
    """Exterior orientation by the separate method of §18.

    Attributes
    ----------
    angular : AngularApproximations
        α, ω, κ and their approximations. [rad]
    transformed_mm : ndarray, shape (n, 2)
        x⁰, y⁰ with the final angles (Table 11). [mm]
    lines : FlyingHeightLines
        Per-line Z_S (Table 12).
    plan_by_points_m : ndarray, shape (n, 2)
        X_Si, Y_Si (Table 13). [m]
    projection_centre_m : ndarray, shape (3,)
        X_S, Y_S by (3.29) and Z_S by (3.27). [m]
    """

    angular: AngularApproximations
    transformed_mm: NDArray[np.float64]
    lines: FlyingHeightLines
    plan_by_points_m: NDArray[np.float64]
    projection_centre_m: NDArray[np.float64]


def book_space_resection(
    photo_mm: ArrayLike,
    points_m: ArrayLike,
    focal_length_mm: float,
    principal_point_mm: ArrayLike = (0.0, 0.0),
    *,
    initial: ArrayLike = (0.0, 0.0, 0.0),
    tolerance: float = 1e-4 / ARCSEC_PER_RAD,
    max_approximations: int = 20,
) -> BookResection:
    r"""Exterior orientation by the book's separate method (angles, then Z_S, then X_S, Y_S).

    Parameters
    ----------
    photo_mm : array_like, shape (n, 2)
        Measured photo coordinates, n ≥ 3. [mm]
    points_m : array_like, shape (n, 3)
        X, Y, Z of the control points. [m]
    focal_length_mm : float
        f. [mm]
    principal_point_mm : array_like, shape (2,)
        x₀, y₀. [mm]
    initial, tolerance, max_approximations
        As in :func:`angular_elements_by_lines`.

    Returns
    -------
    BookResection
        Check ``result.angular.converged``: the method linearises in the angles and is meant
        for plan photos (angles of a few degrees); for a large swing pass an approximate
        ``initial``, as the book does for oblique photos.

    Notes
    -----
    Chains §18 of [1]_: :func:`angular_elements_by_lines` (Eqs. (3.23)–(3.24), Tables 8–10),
    the transformation (3.17) (Table 11), :func:`flying_height_by_lines` (3.26) and
    :func:`projection_centre_height` (3.27) (Table 12), and
    :func:`projection_centre_plan_by_points` (3.28) with the arithmetic mean (3.29) (Table 13).
    For a rigorous least-squares adjustment use
    :func:`stereoplotter.geometry.resection.space_resection`.

    Examples
    --------
    >>> import numpy as np
    >>> photo = [[-78.8969, 64.8774], [64.9894, 73.36805], [70.4375, -68.28268],
    ...          [-82.09999, -89.19385]]
    >>> points = [[2100, 1400, 2], [3500, 1400, 85], [3500, 15, 19], [2100, 3, 51]]
    >>> r = book_space_resection(photo, points, 75.0)
    >>> np.round(r.projection_centre_m, 2)
    array([2800.,  700.,  750.])
    """
    photo, points, pairs = _check_inputs(photo_mm, points_m, None)
    f = float(focal_length_mm)
    pp = np.asarray(principal_point_mm, dtype=float)
    angular = angular_elements_by_lines(
        photo,
        points,
        f,
        pp,
        initial=initial,
        tolerance=tolerance,
        max_approximations=max_approximations,
    )
    m = rotation_matrix(angular.alpha, angular.omega, angular.kappa)
    transformed = transformed_coordinates(photo, m, f, pp)  # (3.17)
    lines = flying_height_by_lines(transformed, points, f, pairs)  # (3.26)
    z_s = projection_centre_height(lines)  # (3.27)
    plan = projection_centre_plan_by_points(transformed, points, z_s, f)  # (3.28)
    centre = np.array([*plan.mean(axis=0), z_s])  # (3.29)
    return BookResection(
        angular=angular,
        transformed_mm=transformed,
        lines=lines,
        plan_by_points_m=plan,
        projection_centre_m=centre,
    )
