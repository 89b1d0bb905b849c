"""The foundation job: from a scenario's ground truth to measured photos and back.

This is what ``stereoplotter demo`` runs until the setup sheet and the simulated operator exist:
synthetic measurements by rigorous collinearity, f′ from the fiducials, the exterior orientation
(as given, or by space resection from the measured control), space intersection of every control
and check point, the similarity (6.8) between Gauss–Krüger and the photogrammetric system, and the
errors of all of it against the truth. Orchestration only: every formula lives in ``geometry``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from stereoplotter.constants import ARCSEC_PER_RAD, MM_PER_M, UM_PER_MM
from stereoplotter.errors import GeometryError
from stereoplotter.geometry.intersection import space_intersection
from stereoplotter.geometry.rotation import angles_from_matrix, rotation_matrix
from stereoplotter.geometry.similarity import apply_similarity, fit_similarity_with_reflection
from stereoplotter.scenario.exterior import known_exterior_orientation
from stereoplotter.scenario.model import Scenario
from stereoplotter.scenario.summary import summarize_scenario
from stereoplotter.scenario.synthetic import Measurements, synthesize_measurements

__all__ = ["run_foundation"]


def _rounded(values, digits: int) -> list[float]:
    return [round(float(v), digits) for v in np.ravel(values)]


def _exterior(scenario: Scenario, measurements: Measurements) -> list[dict[str, Any]]:
    """EO used downstream, per photo (given, or by resection), with its error against the truth."""
    out = []
    for known, photo in zip(
        known_exterior_orientation(scenario, measurements), scenario.photos, strict=True
    ):
        truth = photo.exterior
        angles = np.array(angles_from_matrix(known.rotation))
        record: dict[str, Any] = {"photo": photo.name, "source": known.source}
        if known.resection is not None:
            record.update(
                points_used=list(known.point_ids),
                iterations=known.resection.iterations,
                rms_residual_um=round(known.resection.rms_residual_mm * UM_PER_MM, 4),
            )
        d_angles = (angles - [truth.alpha, truth.omega, truth.kappa]) * ARCSEC_PER_RAD
        record.update(
            alpha_deg=round(math.degrees(angles[0]), 7),
            omega_deg=round(math.degrees(angles[1]), 7),
            kappa_deg=round(math.degrees(angles[2]), 7),
            projection_centre_m=_rounded(known.centre_m, 4),
            error_angles_arcsec=_rounded(d_angles, 3),
            error_centre_m=_rounded(np.asarray(known.centre_m) - truth.centre, 4),
            _angles=angles,
            _centre=np.asarray(known.centre_m, float),
        )
        out.append(record)
    return out


def _intersection(
    scenario: Scenario, measurements: Measurements, exterior: list[dict[str, Any]]
) -> dict[str, Any]:
    left, right = (measurements.photo(n) for n in ("left", "right"))
    el, er = exterior
    both = left.points_imaged & right.points_imaged
    pts = np.array([p.local_m for p in scenario.points])
    result = space_intersection(
        left.points_mm[both],
        right.points_mm[both],
        el["_centre"],
        rotation_matrix(*el["_angles"]),
        er["_centre"],
        rotation_matrix(*er["_angles"]),
        measurements.focal_length_corrected_mm,
        scenario.camera.principal_point_mm,
    )
    errors = result.points_m - pts[both]
    height = scenario.photos[0].exterior.projection_centre_m[2] - float(pts[:, 2].mean())
    sheet = scenario.map_sheet.scale_denominator if scenario.map_sheet else None
    rows = []
    ids = [p for p, b in zip(scenario.points, both, strict=True) if b]
    for p, e, miss in zip(ids, errors, result.miss_distance_m, strict=True):
        row = {
            "id": p.id,
            "role": p.role,
            "error_m": _rounded(e, 4),
            "error_height_permille_H": round(float(e[2]) / height * 1000.0, 4),
            "ray_miss_m": round(float(miss), 4),
        }
        if sheet:
            row["plan_error_mm_at_map_scale"] = round(
                float(np.hypot(e[0], e[1])) * MM_PER_M / sheet, 4
            )
        rows.append(row)
    stats = {}
    for role in ("control", "check"):
        sel = np.array([p.role == role for p in ids], bool)
        if sel.any():
            e = errors[sel]
            stats[role] = {
                "count": int(sel.sum()),
                "rms_plan_m": round(float(np.sqrt(np.mean(e[:, 0] ** 2 + e[:, 1] ** 2))), 4),
                "rms_height_m": round(float(np.sqrt(np.mean(e[:, 2] ** 2))), 4),
                "max_abs_height_m": round(float(np.max(np.abs(e[:, 2]))), 4),
            }
    return {
        "points": rows,
        "statistics": stats,
        "flying_height_m": round(height, 2),
        "not_in_overlap": [p.id for p, b in zip(scenario.points, both, strict=True) if not b],
    }


def _similarity(scenario: Scenario) -> dict[str, Any] | None:
    plan = [
        p
        for p in scenario.points
        if p.role == "control" and p.kind in ("full", "plan") and p.sk42_m is not None
    ]
    if scenario.map_sheet is None or len(plan) < 2:
        return None
    north = np.array([p.sk42_m[0] for p in plan])
    east = np.array([p.sk42_m[1] for p in plan])
    X = np.array([p.local_m[0] for p in plan])
    Y = np.array([p.local_m[1] for p in plan])
    try:
        fit = fit_similarity_with_reflection(north, east, X, Y)
    except GeometryError as exc:  # pragma: no cover - the loader already refuses this
        return {"error": str(exc)}
    corners = apply_similarity(fit, *scenario.map_sheet.corners_sk42_m.T)
    return {
        "equation": "(6.8)",
        "a": fit.a,
        "b": fit.b,
        "cx_m": fit.cx_m,
        "cy_m": fit.cy_m,
        "scale": fit.scale,
        "determinant": fit.determinant,
        "residuals_m": {p.id: _rounded(r, 4) for p, r in zip(plan, fit.residuals_m, strict=True)},
        "rms_m": round(fit.rms_m, 4),
        "sheet_corners_photogrammetric_m": [_rounded(c, 3) for c in corners],
    }


def run_foundation(scenario: Scenario, rng: np.random.Generator) -> dict[str, Any]:
    """Run the foundation job on a scenario.

    Parameters
    ----------
    scenario : Scenario
    rng : numpy.random.Generator
        Source of the measurement noise.

    Returns
    -------
    dict
        ``summary``, ``focal_length_corrected_mm``, ``exterior`` (per photo, with its error
        against the truth), ``intersection`` (stereopairs: per-point errors and statistics) and
        ``similarity`` (the fit of (6.8), where the scenario has a map sheet); plus
        ``measurements`` (the :class:`Measurements` object) for writers.
    """
    measurements = synthesize_measurements(scenario, rng)
    exterior = _exterior(scenario, measurements)
    result: dict[str, Any] = {
        "summary": summarize_scenario(scenario),
        "focal_length_corrected_mm": round(measurements.focal_length_corrected_mm, 6),
        "focal_length_corrected_per_photo_mm": _rounded(
            measurements.focal_length_corrected_per_photo_mm, 6
        ),
        "exterior": [{k: v for k, v in e.items() if not k.startswith("_")} for e in exterior],
    }
    if scenario.is_stereopair:
        result["intersection"] = _intersection(scenario, measurements, exterior)
    result["similarity"] = _similarity(scenario)
    result["measurements"] = measurements
    return result
