"""The scenario of a study cell: a normal case built on the base scenario's camera and frame.

A cell that varies no geometry axis runs the base scenario unchanged. Otherwise
:func:`normal_case` builds the pair from the base's geometry (:func:`base_geometry`) with the
cell's values:

* photo-scale number m = H/f; half-width of the ground footprint W = m·format/2; air base
  B = (1 − overlap)·format·m (the normal case: vertical photos at one height);
* the projection centres at the base's model centre ± B/2 along the base direction β, at the
  height H above the mean terrain height z₀; α, ω opposed on the two photos (left +α, −ω;
  right −α, +ω); κ = β plus the base photo's κ (the photo x axis along the base);
* the terrain flat at z₀ with, for ``relief`` r > 0, one Gaussian hill of height r·H and
  radius 0.45 W at (0.2 W, 0.25 W) from the model centre — not symmetric about the base, so it
  does not cancel between the two halves of the model;
* the points laid out on the overlap like the book's pair (``pair60``): full control at
  (±0.75 (W − B/2), ±0.78 W), height control at the nadirs, six check points inside; Z on the
  terrain; SK-42 coordinates from the base's frame when it has one;
* the camera (fiducials, format), the film deformations, the map sheet, the errors and the
  seed are the base's.

Without ``flying_height_m`` the height follows f at the base's photo scale (H = f·m_base):
varying f then varies the bundle's angle at one photo scale, which is what (6.39)–(6.46) depend
on through p/f.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from stereoplotter.scenario.frame import sk42_from_local
from stereoplotter.scenario.model import ExteriorOrientation, Hill, Photo, Point, Scenario, Terrain
from stereoplotter.study.design import GEOMETRY_AXES

__all__ = ["base_geometry", "cell_scenario", "normal_case"]

#: Point layout on the overlap, in units of (W − B/2 along the base, W across): id, role, kind,
#: u, v (nadirs: the height control points at ∓B/2, marked by None).
_LAYOUT = (
    ("1", "control", "full", -0.75, 0.78),
    ("2", "control", "full", 0.75, 0.78),
    ("3", "control", "full", 0.75, -0.78),
    ("4", "control", "full", -0.75, -0.78),
    ("5", "control", "height", None, 0.0),
    ("6", "control", "height", None, 0.0),
    ("K1", "check", "full", 0.0, 0.0),
    ("K2", "check", "full", -0.4, 0.45),
    ("K3", "check", "full", 0.4, -0.45),
    ("K4", "check", "full", 0.0, 0.75),
    ("K5", "check", "full", 0.0, -0.75),
    ("K6", "check", "full", 0.47, 0.3),
)


def _mean_terrain_height(scenario: Scenario) -> float:
    if scenario.points:
        return float(np.mean([p.local_m[2] for p in scenario.points]))
    return float(scenario.terrain.base_height_m)


def base_geometry(scenario: Scenario) -> dict[str, float]:
    """f, overlap, H, base direction of a stereopair scenario (tilts and relief 0: the normal
    case's defaults). H is above the mean height of the scenario's points."""
    left = np.asarray(scenario.photo("left").exterior.centre, float)
    right = np.asarray(scenario.photo("right").exterior.centre, float)
    f = float(scenario.camera.focal_length_mm)
    height = 0.5 * (left[2] + right[2]) - _mean_terrain_height(scenario)
    base = float(np.hypot(*(right - left)[:2]))
    return {
        "f_mm": f,
        "overlap": 1.0 - base * f / (height * float(scenario.camera.format_mm)),
        "flying_height_m": height,
        "alpha_deg": 0.0,
        "omega_deg": 0.0,
        "relief": 0.0,
        "base_direction_deg": math.degrees(math.atan2(*(right - left)[1::-1])),
    }


def normal_case(base: Scenario, values: dict[str, Any], name: str | None = None) -> Scenario:
    """The normal-case scenario of ``values`` (geometry axes; missing ones from the base)."""
    g = base_geometry(base)
    scale = g["flying_height_m"] / g["f_mm"]
    g.update({k: float(v) for k, v in values.items() if k in GEOMETRY_AXES})
    f, height = g["f_mm"], g.get("flying_height_m")
    if "flying_height_m" not in values:
        height = f * scale
    fmt = float(base.camera.format_mm)
    m = height / f
    w = 0.5 * fmt * m
    b = (1.0 - g["overlap"]) * fmt * m
    beta = math.radians(g["base_direction_deg"])
    u = np.array([math.cos(beta), math.sin(beta)])
    v = np.array([-math.sin(beta), math.cos(beta)])
    left0 = np.asarray(base.photo("left").exterior.centre, float)
    right0 = np.asarray(base.photo("right").exterior.centre, float)
    centre = 0.5 * (left0[:2] + right0[:2])
    z0 = _mean_terrain_height(base)
    hills = ()
    if g["relief"] > 0:
        peak = centre + 0.2 * w * u + 0.25 * w * v
        hills = (Hill(float(peak[0]), float(peak[1]), g["relief"] * height, 0.45 * w),)
    terrain = Terrain(z0, (0.0, 0.0), hills)
    a, o = math.radians(g["alpha_deg"]), math.radians(g["omega_deg"])
    photos = []
    for photo, sign in ((base.photo("left"), -1.0), (base.photo("right"), 1.0)):
        xy = centre + sign * 0.5 * b * u
        ext = ExteriorOrientation(
            (float(xy[0]), float(xy[1]), z0 + height),
            -sign * a,
            sign * o,
            beta + photo.exterior.kappa,
            photo.exterior.source,
        )
        photos.append(Photo(photo.name, ext, photo.film_deformation_ppm))
    points = []
    half = w - 0.5 * b
    for pid, role, kind, pu, pv in _LAYOUT:
        du = (0.5 * b if pid == "6" else -0.5 * b) if pu is None else pu * half
        xy = centre + du * u + pv * w * v
        z = float(terrain.height_m(xy[0], xy[1]))
        local = (float(xy[0]), float(xy[1]), z)
        sk42 = sk42_from_local(base.frame, local) if base.frame.kind == "sk42" else None
        points.append(Point(pid, role, kind, local, sk42))
    camera = replace(base.camera, focal_length_mm=f)
    return replace(
        base,
        name=name or f"{base.name} (normal case)",
        description=f"normal case on {base.name}: " + ", ".join(f"{k}={g[k]:g}" for k in sorted(g)),
        camera=camera,
        photos=tuple(photos),
        terrain=terrain,
        points=tuple(points),
    )


def cell_scenario(base: Scenario, config: dict[str, Any], name: str | None = None) -> Scenario:
    """The base scenario when ``config`` sets no geometry axis, else its :func:`normal_case`."""
    if not any(k in config for k in GEOMETRY_AXES):
        return base
    return normal_case(base, config, name)
