r"""Space intersection of a stereopair: the object point where two homologous rays (nearly) meet.

Reference
---------
.. [1] Kushtin & Lyskov, *Фотограмметрия снимка и стереоскопических моделей*, Nedra, 1984, ch. 5,
   §22, pp. 118–132 (OCR L2836–3100): the pair of collinearity conditions (2.52) of a stereopair.

Each ray is S + λ·d with d = M·(x − x₀, y − y₀, −f)ᵀ (Eq. (2.52)). The point returned is the
midpoint of the shortest segment between the two rays; the segment itself (the *miss*) is the
object-space image of the residual y-parallax and is returned so a caller can judge the pair.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.geometry.collinearity import image_ray_direction

__all__ = ["Intersection", "intersect_rays", "space_intersection"]


@dataclass(frozen=True, slots=True)
class Intersection:
    """Result of a space intersection.

    Attributes
    ----------
    points_m : ndarray, shape (..., 3)
        Midpoints of the shortest segments between the rays. [m]
    miss_m : ndarray, shape (..., 3)
        Vector from the left ray's closest point to the right ray's closest point. [m]
    """

    points_m: NDArray[np.float64]
    miss_m: NDArray[np.float64]

    @property
    def miss_distance_m(self) -> NDArray[np.float64]:
        """Length of the miss vector. [m]"""
        return np.linalg.norm(self.miss_m, axis=-1)


def intersect_rays(
    centre_left_m: ArrayLike,
    direction_left: ArrayLike,
    centre_right_m: ArrayLike,
    direction_right: ArrayLike,
) -> Intersection:
    r"""Closest approach of two rays S_л + λ_л d_л and S_п + λ_п d_п.

    Parameters
    ----------
    centre_left_m, centre_right_m : array_like, shape (..., 3)
        Projection centres S_л, S_п. [m]
    direction_left, direction_right : array_like, shape (..., 3)
        Ray directions (any length). [—]

    Returns
    -------
    Intersection
        Midpoints and miss vectors; NaN where the rays are parallel.

    Notes
    -----
    Solves the 2×2 normal equations of min |S_л + λ_л d_л − S_п − λ_п d_п|² in closed form.

    Examples
    --------
    >>> r = intersect_rays([0, 0, 10], [1, 0, -1], [10, 0, 10], [-1, 0, -1])
    >>> r.points_m
    array([5., 0., 5.])
    """
    s1 = np.asarray(centre_left_m, float)
    s2 = np.asarray(centre_right_m, float)
    d1 = np.asarray(direction_left, float)
    d2 = np.asarray(direction_right, float)
    w = s1 - s2

    def dot(u, v):
        return np.sum(u * v, axis=-1)

    a, b, c = dot(d1, d1), dot(d1, d2), dot(d2, d2)
    d, e = dot(d1, w), dot(d2, w)
    den = a * c - b * b
    with np.errstate(divide="ignore", invalid="ignore"):
        den = np.where(np.abs(den) > 1e-14 * a * c, den, np.nan)
        lam1 = (b * e - c * d) / den
        lam2 = (a * e - b * d) / den
    p1 = s1 + lam1[..., None] * d1
    p2 = s2 + lam2[..., None] * d2
    return Intersection(points_m=0.5 * (p1 + p2), miss_m=p2 - p1)


def space_intersection(
    photo_left_mm: ArrayLike,
    photo_right_mm: ArrayLike,
    centre_left_m: ArrayLike,
    rotation_left: ArrayLike,
    centre_right_m: ArrayLike,
    rotation_right: ArrayLike,
    focal_length_mm: ArrayLike,
    principal_point_mm: ArrayLike = (0.0, 0.0),
) -> Intersection:
    r"""Object points from homologous photo points of a stereopair.

    Parameters
    ----------
    photo_left_mm, photo_right_mm : array_like, shape (..., 2)
        x, y on the left and right photo. [mm]
    centre_left_m, centre_right_m : array_like, shape (3,) or (..., 3)
        Projection centres. [m]
    rotation_left, rotation_right : array_like, shape (3, 3) or (..., 3, 3)
        M of Eq. (2.50) of each photo. [—]
    focal_length_mm : float
        f. [mm]
    principal_point_mm : array_like, shape (2,)
        x₀, y₀. [mm]

    Returns
    -------
    Intersection

    Notes
    -----
    Intersects the two rays of Eq. (2.52) of [1]_; for error-free homologous points the miss is
    zero and the point is exact, whatever the tilts.
    """
    d1 = image_ray_direction(photo_left_mm, rotation_left, focal_length_mm, principal_point_mm)
    d2 = image_ray_direction(photo_right_mm, rotation_right, focal_length_mm, principal_point_mm)
    return intersect_rays(centre_left_m, d1, centre_right_m, d2)
