r"""Collinearity of object point, projection centre and image point: Eqs. (2.52), (2.53), (2.49).

Reference
---------
.. [1] Kushtin & Lyskov, *Фотограмметрия снимка и стереоскопических моделей*, Nedra, 1984, ch. 2,
   §13, pp. 53–62 (OCR L1470–1490).

Conventions
-----------
* Photo coordinates x, y are in the fiducial system [mm]; the principal point is (x₀, y₀) [mm]; the
  image vector in the camera frame is (x − x₀, y − y₀, −f) (positive plane at z = −f).
* Object coordinates X, Y, Z [m], right-handed, Z up.
* ``rotation`` is M of Eq. (2.50), shape (3, 3) or (..., 3, 3).

Shapes: ``points_m`` has shape (..., 3) and ``photo_mm`` (..., 2); the leading dimensions
broadcast against those of ``rotation[..., :, :]`` and ``projection_centre_m[..., :]``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "image_ray_direction",
    "object_to_photo",
    "photo_to_object",
]


def _matvec(m: NDArray, v: NDArray) -> NDArray:
    return np.einsum("...ij,...j->...i", m, v)


def image_ray_direction(
    photo_mm: ArrayLike,
    rotation: ArrayLike,
    focal_length_mm: ArrayLike,
    principal_point_mm: ArrayLike = (0.0, 0.0),
) -> NDArray[np.float64]:
    r"""Object-space direction (X′, Y′, Z′) of the ray through an image point.

    Parameters
    ----------
    photo_mm : array_like, shape (..., 2)
        Photo coordinates x, y. [mm]
    rotation : array_like, shape (..., 3, 3)
        M of Eq. (2.50). [—]
    focal_length_mm : float or array_like
        Principal distance f. [mm]
    principal_point_mm : array_like, shape (..., 2)
        x₀, y₀. [mm]

    Returns
    -------
    ndarray, shape (..., 3)
        (X′, Y′, Z′) = M·(x − x₀, y − y₀, −f)ᵀ. [mm]

    Notes
    -----
    The bracket of Eq. (2.52) of [1]_ (OCR L1476–1481).
    """
    xy = np.asarray(photo_mm, float) - np.asarray(principal_point_mm, float)
    f = np.broadcast_to(np.asarray(focal_length_mm, float), xy.shape[:-1])
    v = np.stack([xy[..., 0], xy[..., 1], -f], axis=-1)
    return _matvec(np.asarray(rotation, float), v)


def photo_to_object(
    photo_mm: ArrayLike,
    Z_m: ArrayLike,
    projection_centre_m: ArrayLike,
    rotation: ArrayLike,
    focal_length_mm: ArrayLike,
    principal_point_mm: ArrayLike = (0.0, 0.0),
) -> NDArray[np.float64]:
    r"""Object point on the plane Z from a photo point (photo → ground).

    Parameters
    ----------
    photo_mm : array_like, shape (..., 2)
        x, y. [mm]
    Z_m : float or array_like
        Height of the object point. [m]
    projection_centre_m : array_like, shape (..., 3)
        X_S, Y_S, Z_S. [m]
    rotation, focal_length_mm, principal_point_mm
        As in :func:`image_ray_direction`.

    Returns
    -------
    ndarray, shape (..., 3)
        X, Y, Z. [m]

    Notes
    -----
    Implements Eq. (2.52) of [1]_ (OCR L1476–1481):

    .. math:: X - X_S = (Z - Z_S)\frac{X'}{Z'},\quad Y - Y_S = (Z - Z_S)\frac{Y'}{Z'}

    Examples
    --------
    >>> import numpy as np
    >>> photo_to_object([10.0, 0.0], 0.0, [0.0, 0.0, 1000.0], np.eye(3), 100.0)
    array([100.,   0.,   0.])
    """
    d = image_ray_direction(photo_mm, rotation, focal_length_mm, principal_point_mm)
    s = np.asarray(projection_centre_m, float)
    Z = np.asarray(Z_m, float)
    dz = Z - s[..., 2]
    X = s[..., 0] + dz * d[..., 0] / d[..., 2]
    Y = s[..., 1] + dz * d[..., 1] / d[..., 2]
    return np.stack(np.broadcast_arrays(X, Y, Z + 0.0 * X), axis=-1)


def object_to_photo(
    points_m: ArrayLike,
    projection_centre_m: ArrayLike,
    rotation: ArrayLike,
    focal_length_mm: ArrayLike,
    principal_point_mm: ArrayLike = (0.0, 0.0),
) -> NDArray[np.float64]:
    r"""Photo coordinates of object points (ground → photo).

    Parameters
    ----------
    points_m : array_like, shape (..., 3)
        X, Y, Z. [m]
    projection_centre_m : array_like, shape (..., 3)
        X_S, Y_S, Z_S. [m]
    rotation : array_like, shape (..., 3, 3)
        M of Eq. (2.50). [—]
    focal_length_mm : float or array_like
        f. [mm]
    principal_point_mm : array_like, shape (..., 2)
        x₀, y₀. [mm]

    Returns
    -------
    ndarray, shape (..., 2)
        x, y. [mm]

    Notes
    -----
    Implements Eq. (2.53) of [1]_ (OCR L1485–1487) with the inverse rotation (2.49):
    u = Mᵀ·(X − X_S, Y − Y_S, Z − Z_S)ᵀ and

    .. math:: x - x_0 = -f\frac{u_1}{u_3},\quad y - y_0 = -f\frac{u_2}{u_3}

    Points behind the camera (u₃ ≥ 0) give NaN.

    Examples
    --------
    >>> import numpy as np
    >>> object_to_photo([100.0, 0.0, 0.0], [0.0, 0.0, 1000.0], np.eye(3), 100.0)
    array([10.,  0.])
    """
    delta = np.asarray(points_m, float) - np.asarray(projection_centre_m, float)
    m = np.asarray(rotation, float)
    u = np.einsum("...ji,...j->...i", m, delta)
    f = np.asarray(focal_length_mm, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        u3 = np.where(u[..., 2] < 0.0, u[..., 2], np.nan)
        x = -f * u[..., 0] / u3
        y = -f * u[..., 1] / u3
    return np.stack([x, y], axis=-1) + np.asarray(principal_point_mm, float)
