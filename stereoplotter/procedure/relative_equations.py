r"""The pure equations of relative orientation by the six standard points (ch. 5, §22): the
first-order y-parallax equation (5.10) in the basis system, its solution (5.11) for the six
standard points of Fig. 39, and the over-correction factor of the element-by-element method.

Units: mm in the photo, radians for the elements. Used by the conventional method
(:mod:`~stereoplotter.procedure.conventional`) and the verification.

Reference
---------
.. [1] Kushtin I. F. & Lyskov G. A., *Фотограмметрия снимка и стереоскопических моделей*,
   Moscow: Nedra, 1984, ch. 5, §22, Eqs. (5.10)–(5.11), Fig. 39 (OCR L2928–3010).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "overcorrection_factor",
    "relative_orientation_from_standard_points",
    "y_parallax_first_order",
]


def _a(v: ArrayLike) -> NDArray[np.float64]:
    return np.asarray(v, dtype=float)


def y_parallax_first_order(
    x1: ArrayLike,
    y1: ArrayLike,
    x2: ArrayLike,
    y2: ArrayLike,
    focal_length_mm: ArrayLike,
    alpha1: ArrayLike,
    alpha2: ArrayLike,
    omega2: ArrayLike,
    kappa1: ArrayLike,
    kappa2: ArrayLike,
) -> NDArray[np.float64]:
    r"""The y-parallax q = y₁ − y₂ that relative-orientation elements produce, first order.

    Parameters
    ----------
    x1, y1, x2, y2 : float or ndarray
        Coordinates of the point on the left and right photo. [mm]
    focal_length_mm : float or ndarray
        f (f₁ = f₂ = f). [mm]
    alpha1, alpha2, omega2, kappa1, kappa2 : float or ndarray
        α′₁, α′₂, ω′₂, κ′₁, κ′₂ of the basis system. [rad]

    Returns
    -------
    ndarray
        q solving the first equation of (5.10): the parallax the operator must clear. [mm]

    Notes
    -----
    Eq. (5.10) of [1]_ (first line), solved for q:

    .. math:: q = -\Bigl[\frac{x_1 y_2}{f}\alpha'_1 - \frac{x_2 y_1}{f}\alpha'_2
              - \Bigl(f + \frac{y_1 y_2}{f}\Bigr)\omega'_2 + x_1\kappa'_1 - x_2\kappa'_2\Bigr]

    Examples
    --------
    A point at the left principal point seen at x₂ = −90 mm: only κ′₂ acts.

    >>> float(y_parallax_first_order(0.0, 0.0, -90.0, 0.0, 100.0, 0.0, 0.0, 0.0, 0.0, 1e-3))
    -0.09
    """
    f = _a(focal_length_mm)
    x1, y1, x2, y2 = _a(x1), _a(y1), _a(x2), _a(y2)
    return -(
        x1 * y2 / f * _a(alpha1)
        - x2 * y1 / f * _a(alpha2)
        - (f + y1 * y2 / f) * _a(omega2)
        + x1 * _a(kappa1)
        - x2 * _a(kappa2)
    )


def relative_orientation_from_standard_points(
    q_mm: ArrayLike,
    x11: ArrayLike,
    x12: ArrayLike,
    x21: ArrayLike,
    x22: ArrayLike,
    c_mm: ArrayLike,
    focal_length_mm: ArrayLike,
) -> dict[str, NDArray[np.float64]]:
    r"""Relative-orientation elements from the y-parallaxes at the six standard points.

    Parameters
    ----------
    q_mm : array_like, shape (..., 6)
        q₁ … q₆ measured at points 1–6 of Fig. 39. [mm]
    x11, x12 : float or ndarray
        x of points 1 and 2 on the left photo (x₁₃ = x₁₅ = x₁₁, x₁₄ = x₁₆ = x₁₂). [mm]
    x21, x22 : float or ndarray
        x of points 1 and 2 on the right photo. [mm]
    c_mm : float or ndarray
        y of points 3, 4 (+c) and 5, 6 (−c). [mm]
    focal_length_mm : float or ndarray
        f. [mm]

    Returns
    -------
    dict
        "alpha1", "alpha2", "omega2", "kappa1", "kappa2" [rad].

    Notes
    -----
    Eq. (5.11) of [1]_ in its general form before the substitution of Fig. 39 (the printed
    specialised (5.11) is garbled in the OCR: its κ′₁ line has f where κ′₂ has f²):

    .. math::
        \alpha'_1 = -\frac{f[x_{22}(q_3 - q_5) - x_{21}(q_4 - q_6)]}{2c\,\Delta},\quad
        \alpha'_2 = -\frac{f[x_{12}(q_3 - q_5) - x_{11}(q_4 - q_6)]}{2c\,\Delta},\quad
        \Delta = x_{11}x_{22} - x_{12}x_{21},

        \omega'_2 = \frac{f}{4c^2}[q_3 + q_4 + q_5 + q_6 - 2(q_1 + q_2)],

        \kappa'_1 = \frac{f(x_{22} - x_{21})\omega'_2 - (q_1 x_{22} - q_2 x_{21})}
                         {x_{11}x_{22} - x_{12}x_{21}},\quad
        \kappa'_2 = \frac{f(x_{12} - x_{11})\omega'_2 - (q_1 x_{12} - q_2 x_{11})}
                         {x_{11}x_{22} - x_{21}x_{12}}.

    Examples
    --------
    With a = 0 (points on the photo y axes) and b = 90 mm, a pure κ′₂ = 1 mrad:

    >>> q = [-0.09, 0.0, -0.09, 0.0, -0.09, 0.0]
    >>> r = relative_orientation_from_standard_points(q, 0.0, 90.0, -90.0, 0.0, 80.0, 100.0)
    >>> round(float(r["kappa2"]), 9), round(float(r["omega2"]), 12) + 0.0
    (0.001, 0.0)
    """
    q = _a(q_mm)
    q1, q2, q3, q4, q5, q6 = (q[..., i] for i in range(6))
    f, c = _a(focal_length_mm), _a(c_mm)
    x11, x12, x21, x22 = _a(x11), _a(x12), _a(x21), _a(x22)
    det = x11 * x22 - x12 * x21
    alpha1 = -f * (x22 * (q3 - q5) - x21 * (q4 - q6)) / (2.0 * c * det)
    alpha2 = -f * (x12 * (q3 - q5) - x11 * (q4 - q6)) / (2.0 * c * det)
    omega2 = f / (4.0 * c**2) * (q3 + q4 + q5 + q6 - 2.0 * (q1 + q2))
    kappa1 = (f * (x22 - x21) * omega2 - (q1 * x22 - q2 * x21)) / det
    kappa2 = (f * (x12 - x11) * omega2 - (q1 * x12 - q2 * x11)) / det
    return {
        "alpha1": alpha1,
        "alpha2": alpha2,
        "omega2": omega2,
        "kappa1": kappa1,
        "kappa2": kappa2,
    }


def overcorrection_factor(focal_length_mm: ArrayLike, c_mm: ArrayLike) -> NDArray[np.float64]:
    r"""Over-correction of ω at points 5/6 in element-by-element orientation: ½(f²/c² − 1).

    Examples
    --------
    >>> float(overcorrection_factor(100.0, 80.0))
    0.28125
    """
    return 0.5 * (_a(focal_length_mm) ** 2 / _a(c_mm) ** 2 - 1.0)
