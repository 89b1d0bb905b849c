"""The numbers a photogrammetrist checks first about a scenario: photo scale, overlap, base,
B/H, relief, tilts, control. Pure: returns plain Python values ready for JSON."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from stereoplotter.constants import MM_PER_M
from stereoplotter.scenario.model import Scenario
from stereoplotter.scenario.synthetic import footprint_m, points_in_format, working_area_grid_m

__all__ = ["flying_height_and_relief", "mean_flying_height_m", "summarize_scenario"]


def _r(value: float, digits: int = 3) -> float:
    return round(float(value), digits)


def mean_flying_height_m(scenario: Scenario) -> float:
    """The summary's mean flying height H of the photos above the mean point height, each
    photo's rounded to 0.1 m as printed. [m]"""
    z_mean = float(np.array([p.local_m for p in scenario.points])[:, 2].mean())
    heights = [_r(p.exterior.projection_centre_m[2] - z_mean, 1) for p in scenario.photos]
    return float(np.mean(heights))


def flying_height_and_relief(scenario: Scenario, grid_m: np.ndarray) -> tuple[float, float]:
    """The summary's mean flying height H above the mean point height (each photo's rounded to
    0.1 m, as printed) and the terrain's height range over the working area (rounded to
    0.01 m; the points' range without a working area). [m]

    ``grid_m``: the working-area grid the summary reads the relief on, 15 × 15
    (:func:`~stereoplotter.scenario.synthetic.working_area_grid_m`), computed once by the
    caller.
    """
    pts = np.array([p.local_m for p in scenario.points])
    terrain_z = grid_m[:, 2] if len(grid_m) else pts[:, 2]
    return mean_flying_height_m(scenario), _r(terrain_z.max() - terrain_z.min(), 2)


def summarize_scenario(scenario: Scenario) -> dict[str, Any]:
    """Summary of a scenario.

    Returns
    -------
    dict
        ``photos`` (per photo: flying height above the mean terrain [m], photo scale denominator,
        tilts [deg], film deformation [ppm], points imaged), ``base`` (components [m], length [m],
        B/H, overlap [%]) for a stereopair, ``relief`` (min, max, range of the terrain over the
        working area and of the points [m], range/H), ``points`` (counts by role and kind) and the
        map sheet.

    Notes
    -----
    The photo scale is 1 : (Z_S − Z_mean)·1000/f, with Z_mean the mean height of the scenario's
    points. The overlap is measured on the plane Z_mean along the horizontal base direction:
    the common length of the two footprints' projections on that direction over the left footprint's
    length.
    """
    cam = scenario.camera
    pts = np.array([p.local_m for p in scenario.points])
    z_mean = float(pts[:, 2].mean())
    grid = working_area_grid_m(scenario, (15, 15))
    terrain_z = grid[:, 2] if len(grid) else pts[:, 2]
    photos = [_photo_summary(scenario, photo, pts, z_mean) for photo in scenario.photos]
    flying_height = float(np.mean([p["flying_height_m"] for p in photos]))
    relief = float(terrain_z.max() - terrain_z.min())
    summary: dict[str, Any] = {
        "name": scenario.name,
        "file": scenario.source,
        "description": scenario.description,
        "seed": scenario.seed,
        "camera": {
            "focal_length_mm": cam.focal_length_mm,
            "principal_point_mm": list(cam.principal_point_mm),
            "format_mm": cam.format_mm,
            "fiducials_given_as": cam.fiducials_given_as,
            "fiducials_mm": {k: list(v) for k, v in cam.fiducials_mm.items()},
        },
        "frame": scenario.frame.kind,
        "photos": photos,
        "relief": {
            "working_area_min_m": _r(terrain_z.min(), 2),
            "working_area_max_m": _r(terrain_z.max(), 2),
            "working_area_range_m": _r(relief, 2),
            "points_min_m": _r(pts[:, 2].min(), 2),
            "points_max_m": _r(pts[:, 2].max(), 2),
            "range_over_flying_height": _r(relief / flying_height, 4),
        },
        "points": {
            role: {
                kind: sum(1 for p in scenario.points if p.role == role and p.kind == kind)
                for kind in ("full", "plan", "height")
            }
            for role in ("control", "check")
        },
    }
    if scenario.is_stereopair:
        summary["base"] = _base_summary(scenario, z_mean, flying_height)
    if scenario.map_sheet is not None:
        sheet = scenario.map_sheet
        summary["map_sheet"] = {
            "scale_denominator": sheet.scale_denominator,
            "nomenclature": sheet.nomenclature,
            "corners_sk42_m": [[_r(v) for v in c] for c in sheet.corners_sk42_m],
        }
    return summary


def _photo_summary(scenario: Scenario, photo, pts, z_mean: float) -> dict[str, Any]:
    """One photo's entry of ``photos`` (see :func:`summarize_scenario`)."""
    ext = photo.exterior
    height = ext.projection_centre_m[2] - z_mean
    imaged = points_in_format(scenario, photo, pts)
    return {
        "name": photo.name,
        "projection_centre_m": [_r(v) for v in ext.projection_centre_m],
        "alpha_deg": _r(math.degrees(ext.alpha), 4),
        "omega_deg": _r(math.degrees(ext.omega), 4),
        "kappa_deg": _r(math.degrees(ext.kappa), 4),
        "exterior_source": ext.source,
        "flying_height_m": _r(height, 1),
        "photo_scale_denominator": _r(height * MM_PER_M / scenario.camera.focal_length_mm, 0),
        "film_deformation_ppm": list(photo.film_deformation_ppm),
        "points_imaged": int(imaged.sum()),
    }


def _base_summary(scenario: Scenario, z_mean: float, flying_height: float) -> dict[str, Any]:
    """``base`` of a stereopair: components, B/H and the overlap on the plane Z_mean."""
    left, right = scenario.photos
    b = right.exterior.centre - left.exterior.centre
    horizontal = float(np.hypot(b[0], b[1]))
    direction = b[:2] / horizontal
    spans = []
    for photo in (left, right):
        along = footprint_m(scenario, photo, z_mean)[:, :2] @ direction
        spans.append((along.min(), along.max()))
    common = min(spans[0][1], spans[1][1]) - max(spans[0][0], spans[1][0])
    return {
        "components_m": [_r(v) for v in b],
        "horizontal_m": _r(horizontal),
        "azimuth_from_X_deg": _r(math.degrees(math.atan2(b[1], b[0])), 4),
        "base_to_height": _r(horizontal / flying_height, 4),
        "overlap_percent": _r(100.0 * max(common, 0.0) / (spans[0][1] - spans[0][0]), 1),
    }
