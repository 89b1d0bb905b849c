"""Exact inverse collinearity over the terrain: where the ray of a photo point meets the ground.

For a photo point the ray of Eq. (2.52) (:func:`~stereoplotter.geometry.collinearity.
photo_to_object`) is X(Z), Y(Z); the ground point is the highest root of
g(Z) = Z_terrain(X(Z), Y(Z)) − Z (the first surface the ray meets coming down from the
projection centre). Units: photo mm, ground m.

Robustness in steep terrain: no fixed-point iteration (it diverges where the terrain is steeper
than the ray); instead the ray is marched down from above the highest terrain in equal Z steps
until g changes sign, and the bracket is closed by bisection. The result never leaves the
bracket, so there is no NaN at the frame edges.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from stereoplotter.geometry.collinearity import image_ray_direction
from stereoplotter.scenario.model import Scenario

__all__ = ["ground_heights_m", "terrain_bounds_m"]

MARCH_STEPS = 32
BISECTIONS = 30


def terrain_bounds_m(scenario: Scenario, half_extent_m: float) -> tuple[float, float]:
    """Lowest and highest terrain height over a square of half side ``half_extent_m`` around the
    mean projection centre, sampled on a 401² grid, widened by 1 % of the range + 1 m. [m]"""
    c = np.mean([p.exterior.centre for p in scenario.photos], axis=0)
    t = np.linspace(-half_extent_m, half_extent_m, 401)
    X, Y = np.meshgrid(c[0] + t, c[1] + t)
    Z = scenario.terrain.height_m(X, Y)
    pad = 0.01 * float(Z.max() - Z.min()) + 1.0
    return float(Z.min()) - pad, float(Z.max()) + pad


def ground_heights_m(
    scenario: Scenario,
    side: str,
    photo_mm: NDArray[np.float64],
    z_bounds_m: tuple[float, float],
) -> NDArray[np.float64]:
    """Height Z of the visible ground point on the ray of each ideal photo point. [m]

    ``photo_mm`` has shape (..., 2) (ideal fiducial-system coordinates, film deformation
    removed). Highest root of g(Z) in ``z_bounds_m`` by a march of :data:`MARCH_STEPS` steps and
    :data:`BISECTIONS` bisections (bracket / 2³⁰ ≈ 10⁻⁶ m per 1000 m of relief).
    """
    ext = scenario.photo(side).exterior
    cam = scenario.camera
    d = image_ray_direction(photo_mm, ext.rotation, cam.focal_length_mm, cam.principal_point_mm)
    s = ext.centre
    kx = d[..., 0] / d[..., 2]
    ky = d[..., 1] / d[..., 2]

    def g(Z: NDArray) -> NDArray:
        dz = Z - s[2]
        return scenario.terrain.height_m(s[0] + dz * kx, s[1] + dz * ky) - Z

    z_lo, z_hi = z_bounds_m
    shape = photo_mm.shape[:-1]
    upper = np.full(shape, z_hi)
    lower = np.full(shape, z_lo)
    found = np.zeros(shape, bool)
    prev = upper.copy()
    for z in np.linspace(z_hi, z_lo, MARCH_STEPS + 1)[1:]:
        hit = (~found) & (g(np.full(shape, z)) >= 0.0)
        upper = np.where(hit, prev, upper)
        lower = np.where(hit, z, lower)
        found |= hit
        prev = np.full(shape, z)
    for _ in range(BISECTIONS):
        mid = 0.5 * (upper + lower)
        above = g(mid) < 0.0
        upper = np.where(above, mid, upper)
        lower = np.where(above, lower, mid)
    return 0.5 * (upper + lower)
