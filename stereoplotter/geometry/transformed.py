r"""Transformed (rectified) photo coordinates: Eq. (3.17) and its single-axis forms (6.1)/(6.2).

Reference
---------
.. [1] Kushtin & Lyskov, *Фотограмметрия снимка и стереоскопических моделей*, Nedra, 1984:
   ch. 3, §18, p. 84 (OCR L2006) for (3.17); ch. 6, §26, p. 153 (OCR L3705–3709) for (6.1)/(6.2).

x⁰, y⁰ are the coordinates of a point on the equivalent *horizontal* photo with the same principal
distance and axes parallel to X, Y. They are computed here **without** the counter coefficient n
(``docs/setup-data.md``): the instrument applies n exactly once.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.geometry.collinearity import image_ray_direction

__all__ = [
    "transformed_coordinates",
    "transformed_x_single_tilt",
    "transformed_y_single_tilt",
]


def transformed_coordinates(
    photo_mm: ArrayLike,
    rotation: ArrayLike,
    focal_length_mm: ArrayLike,
    principal_point_mm: ArrayLike = (0.0, 0.0),
) -> NDArray[np.float64]:
    r"""Rigorous transformed coordinates x⁰, y⁰ of photo points.

    Parameters
    ----------
    photo_mm : array_like, shape (..., 2)
        x, y in the fiducial system. [mm]
    rotation : array_like, shape (..., 3, 3)
        M of Eq. (2.50). [—]
    focal_length_mm : float or array_like
        f (or f′ when the film is deformed). [mm]
    principal_point_mm : array_like, shape (..., 2)
        x₀, y₀. [mm]

    Returns
    -------
    ndarray, shape (..., 2)
        x⁰, y⁰. [mm]

    Notes
    -----
    Implements Eq. (3.17) of [1]_ (OCR L2006), with (X′, Y′, Z′) = M·(x − x₀, y − y₀, −f)ᵀ:

    .. math:: x^0 = -f\frac{X'}{Z'},\quad y^0 = -f\frac{Y'}{Z'}

    Hence X − X_S = (Z_S − Z)·x⁰/f.

    Examples
    --------
    The principal point of a photo with α = ω = 3°, f = 100 mm lands at (f tan α, f tan ω / cos α):

    >>> import numpy as np
    >>> from stereoplotter.geometry.rotation import rotation_matrix
    >>> m = rotation_matrix(np.radians(3), np.radians(3), 0.0)
    >>> np.round(transformed_coordinates([0.0, 0.0], m, 100.0), 4)
    array([5.2408, 5.248 ])
    """
    d = image_ray_direction(photo_mm, rotation, focal_length_mm, principal_point_mm)
    f = np.asarray(focal_length_mm, float)[..., None]
    return -f * d[..., :2] / d[..., 2:3]


def transformed_x_single_tilt(
    x_mm: ArrayLike, alpha: ArrayLike, focal_length_corrected_mm: ArrayLike
) -> NDArray[np.float64]:
    r"""x⁰ of a point on the x axis of a photo tilted by α alone (n-free form of Eq. (6.1)).

    Parameters
    ----------
    x_mm : float or ndarray
        Measured abscissa x of the fiducial mark (signed), x − x₀. [mm]
    alpha : float or ndarray
        Longitudinal tilt α. [rad]
    focal_length_corrected_mm : float or ndarray
        f′, the focal length corrected for film deformation. [mm]

    Returns
    -------
    ndarray
        x⁰. [mm]

    Notes
    -----
    Implements Eq. (6.1) of [1]_ (OCR L3705) without the factor n (applied once, by the counters):

    .. math:: x^0 = f'\frac{f'\sin\alpha + x\cos\alpha}{f'\cos\alpha - x\sin\alpha}

    **Known limit:** exact, i.e. equal to (3.17), only when ω = κ = 0. With both tilts the error is
    second order in ω (0.136 mm for α = ω = 3°, f = 100 mm, x = 90 mm).
    """
    x = np.asarray(x_mm, float)
    a = np.asarray(alpha, float)
    f = np.asarray(focal_length_corrected_mm, float)
    return f * (f * np.sin(a) + x * np.cos(a)) / (f * np.cos(a) - x * np.sin(a))


def transformed_y_single_tilt(
    y_mm: ArrayLike, omega: ArrayLike, focal_length_corrected_mm: ArrayLike
) -> NDArray[np.float64]:
    r"""y⁰ of a point on the y axis of a photo tilted by ω alone (n-free form of Eq. (6.2)).

    Parameters
    ----------
    y_mm : float or ndarray
        Measured ordinate y of the fiducial mark (signed), y − y₀. [mm]
    omega : float or ndarray
        Transverse tilt ω. [rad]
    focal_length_corrected_mm : float or ndarray
        f′. [mm]

    Returns
    -------
    ndarray
        y⁰. [mm]

    Notes
    -----
    Implements Eq. (6.2) of [1]_ (OCR L3707) without the factor n:

    .. math:: y^0 = f'\frac{f'\sin\omega + y\cos\omega}{f'\cos\omega - y\sin\omega}

    **Known limit:** exact only when α = κ = 0.
    """
    return transformed_x_single_tilt(y_mm, omega, focal_length_corrected_mm)
