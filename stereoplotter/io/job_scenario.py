"""A job's pair as a scenario: production data for the simulator.

A job has no ground truth; a scenario is one. :func:`job_pair_scenario` writes the scenario
(``docs/scenarios.md``) that the simulator can treat as the truth of one pair of a job:

* the camera of the certificate (its marks as the certificate gives them);
* the two photos' exterior orientation in the pair's own frame, as the job computes it
  (:func:`stereoplotter.io.job_measured.measured_pair`: the §10 local system of the pair, angles
  turned by M_local = R·M_grid), the angles recovered from M by the inverse of (2.50);
* the film deformation of each photo from its measured fiducial distances (l′/l − 1 per axis,
  the uniform deformation the job assumes), so the scenario's f′ is the job's;
* the pair's control and check points (those imaged on both photos) at their catalogue
  coordinates in the pair's frame;
* the pair's map sheet (where the frame is tied to SK-42);
* a terrain *fitted* to the control heights, which the job does not have: a plane by least
  squares, or with at least 6 height-bearing control points a plane plus one Gaussian hill of
  fixed centre and radius (the scenario format's curved term; it has no quadratic kind). The
  YAML says which, with the residuals, in a comment above ``terrain:`` so the user sees it and
  can change it.
"""

from __future__ import annotations

import math
import os
import textwrap
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from stereoplotter.errors import ConfigError
from stereoplotter.geometry.film import fiducial_spans_mm
from stereoplotter.geometry.rotation import angles_from_matrix
from stereoplotter.io.atomic_write import atomic_write_bytes
from stereoplotter.io.job_file import Job, JobPair
from stereoplotter.io.job_measured import MeasuredPair, measured_pair
from stereoplotter.scenario.model import Point

__all__ = ["TerrainFit", "fit_terrain", "job_pair_scenario", "write_job_scenario"]

#: Height-bearing control points from which the curved surface is fitted instead of a plane.
CURVED_MIN_POINTS = 6
#: The hill's radius as a multiple of the largest distance of a control point from the centroid:
#: inside the control the Gaussian then bends like an isotropic quadratic.
HILL_RADIUS_FACTOR = 1.5
#: The loader's ranges (io/scenario_file.py): a fit outside them falls back to the plane.
_SLOPE_MAX, _HILL_MAX, _BASE_RANGE = 1.0, 3000.0, (-500.0, 9000.0)


@dataclass(frozen=True, slots=True)
class TerrainFit:
    """A terrain fitted to heights: the scenario's ``terrain`` section and what it is.

    ``kind`` is ``flat``, ``plane`` or ``plane+hill``; ``rms_m`` and ``max_m`` are the residuals
    of the fitted heights [m]; ``note`` says in words how it was chosen.
    """

    kind: str
    section: dict[str, Any]
    points: int
    rms_m: float
    max_m: float
    note: str


def _plane_section(base: float, slope: tuple[float, float]) -> dict[str, Any]:
    return {"base_height_m": round(base, 4), "slope": [round(slope[0], 8), round(slope[1], 8)]}


def fit_terrain(xyz: np.ndarray) -> TerrainFit:
    """Fit Z(X, Y) to points (n, 3) [m] with the terrain kinds a scenario supports.

    0 points: flat at 0; 1–2 (or collinear) points: flat at their mean height; 3–5: a plane by
    least squares; ≥ 6: a plane plus one Gaussian hill centred at the points' centroid with the
    radius ``HILL_RADIUS_FACTOR`` × the largest distance from it, its height fitted with the plane
    by linear least squares (falls back to the plane when a value leaves the loader's ranges).
    """
    xyz = np.asarray(xyz, float).reshape(-1, 3)
    n = len(xyz)
    if n == 0:
        return TerrainFit("flat", {"base_height_m": 0.0}, 0, 0.0, 0.0, "no height: flat at 0")
    z = xyz[:, 2]
    mean = float(z.mean())
    flat = TerrainFit("flat", {"base_height_m": round(mean, 4)}, n, float(np.std(z)),
                      float(np.max(np.abs(z - mean))), "flat at the mean height")  # fmt: skip
    if n < 3:
        return flat
    centre = xyz[:, :2].mean(axis=0)
    d = xyz[:, :2] - centre
    plane_a = np.column_stack([np.ones(n), d])
    coef, _, rank, _ = np.linalg.lstsq(plane_a, z, rcond=None)
    if rank < 3:
        return TerrainFit("flat", flat.section, n, flat.rms_m, flat.max_m,
                          "flat at the mean height (the points are collinear: no plane)")
    res = z - plane_a @ coef
    base = float(coef[0] - coef[1:] @ centre)
    plane = TerrainFit(
        "plane", _plane_section(base, (float(coef[1]), float(coef[2]))), n,
        float(np.sqrt(np.mean(res**2))), float(np.max(np.abs(res))),
        f"a plane by least squares ({n} heights; a curved surface needs {CURVED_MIN_POINTS})",
    )  # fmt: skip
    if n < CURVED_MIN_POINTS or abs(coef[1]) > _SLOPE_MAX or abs(coef[2]) > _SLOPE_MAX:
        return plane
    radius = HILL_RADIUS_FACTOR * float(np.max(np.hypot(d[:, 0], d[:, 1])))
    hill = np.exp(-0.5 * np.sum(d**2, axis=1) / radius**2)
    a = np.column_stack([plane_a, hill])
    coef, _, rank, _ = np.linalg.lstsq(a, z, rcond=None)
    base = float(coef[0] - coef[1:3] @ centre)
    if (rank < 4 or np.any(np.abs(coef[1:3]) > _SLOPE_MAX) or abs(coef[3]) > _HILL_MAX
            or not _BASE_RANGE[0] <= base <= _BASE_RANGE[1]):  # fmt: skip
        return TerrainFit(plane.kind, plane.section, n, plane.rms_m, plane.max_m,
                          plane.note.split(" (")[0] + " (the curved fit left the loader's ranges)")
    res = z - a @ coef
    section = _plane_section(base, (float(coef[1]), float(coef[2])))
    section["hills"] = [{"X_m": round(float(centre[0]), 4), "Y_m": round(float(centre[1]), 4),
                         "height_m": round(float(coef[3]), 4), "radius_m": round(radius, 4)}]
    return TerrainFit(
        "plane+hill", section, n, float(np.sqrt(np.mean(res**2))), float(np.max(np.abs(res))),
        f"a plane plus one Gaussian hill by least squares ({n} heights ≥ {CURVED_MIN_POINTS}; "
        f"the hill's centre is the centroid, its radius {HILL_RADIUS_FACTOR:g} × the farthest "
        "point: inside the control it bends like an isotropic quadratic; the scenario format "
        f"has no quadratic term); the plane alone leaves rms {plane.rms_m:.3f} m",
    )  # fmt: skip


def _find_pair(job: Job, name: str) -> JobPair:
    for pair in job.pairs:
        if pair.name == name:
            return pair
    raise ConfigError(job.source, "pairs", "a pair of the job, LEFT-RIGHT ("
                      + ", ".join(p.name for p in job.pairs) + ")", name)  # fmt: skip


def _m(v: float) -> float:
    return round(float(v), 4) + 0.0  # 0.1 mm; no -0.0


def _fiducials(job: Job) -> dict[str, Any]:
    marks = job.camera.fiducials_mm
    if job.camera.fiducials_given_as == "distances":
        return {"distances_mm": {"1-2": round(marks["2"][0] - marks["1"][0], 6),
                                 "3-4": round(marks["3"][1] - marks["4"][1], 6)}}  # fmt: skip
    return {"coordinates_mm": {k: [float(v[0]), float(v[1])] for k, v in marks.items()}}


def _frame(origin: tuple[float, float, float] | None) -> dict[str, Any]:
    if origin is None:
        return {"kind": "local"}
    return {"kind": "sk42", "origin": dict(zip(("north_m", "east_m", "height_m"), origin,
                                               strict=True))}  # fmt: skip


def _point(p: Point) -> dict[str, Any]:
    x, y, z = p.local_m
    return {"id": p.id, "role": p.role, "kind": p.kind,
            "local": {"X_m": _m(x), "Y_m": _m(y), "Z_m": _m(z)}}  # fmt: skip


def job_pair_scenario(job: Job, pair_name: str) -> tuple[dict[str, Any], TerrainFit, MeasuredPair]:
    """The scenario document of one pair of a job, the terrain fit and the pair's inputs.

    Raises
    ------
    ConfigError
        The pair is not in the job.
    StereoplotterError
        The pair cannot be computed (no points imaged on both photos and no working area).
    """
    pair = _find_pair(job, pair_name)
    m = measured_pair(job, pair)
    cam = job.camera
    spans = fiducial_spans_mm(cam.fiducials_mm)
    photos = []
    for side, number, centre, rotation in zip(("left", "right"), (pair.left, pair.right),
                                              m.centres_m, m.rotations, strict=True):  # fmt: skip
        alpha, omega, kappa = (math.degrees(float(a)) for a in angles_from_matrix(rotation))
        measured = job.photos[number].fiducial_distances_mm
        photos.append({
            "name": side,
            "exterior": {"X_m": _m(centre[0]), "Y_m": _m(centre[1]), "Z_m": _m(centre[2]),
                         "alpha_deg": round(alpha, 8) + 0.0, "omega_deg": round(omega, 8) + 0.0,
                         "kappa_deg": round(kappa, 8) + 0.0, "source": "given"},
            "film_deformation_ppm": [round((measured[i] / float(spans[i]) - 1.0) * 1e6, 4) + 0.0
                                     for i in range(2)],
        })  # fmt: skip
    heights = np.array([p.local_m for p in m.points
                        if p.role == "control" and p.kind != "plan"], float)  # fmt: skip
    fit = fit_terrain(heights)
    doc: dict[str, Any] = {
        "name": f"{job.name}-{pair.name}",
        "description": (f"Pair {pair.name} (photos {pair.left}, {pair.right}) of job {job.name} "
                        f"({Path(job.source).name}), made by stereoplotter job to-scenario."),
        "seed": 0,
        "camera": {
            "focal_length_mm": cam.focal_length_mm,
            "principal_point_mm": [float(v) for v in cam.principal_point_mm],
            "format_mm": cam.format_mm,
            "fiducials": _fiducials(job),
        },
        "frame": _frame(m.origin_sk42_m),
        "terrain": fit.section,
        "photos": photos,
        "points": [_point(p) for p in m.points],
    }
    sheet = m.map_sheet
    if sheet is not None and m.origin_sk42_m is not None:
        doc["map_sheet"] = ({"scale": sheet.scale_denominator, "nomenclature": sheet.nomenclature}
                            if sheet.nomenclature else {
            "scale": sheet.scale_denominator,
            "corners": [{"north_m": float(c[0]), "east_m": float(c[1])}
                        for c in sheet.corners_sk42_m],
        })  # fmt: skip
    doc["errors"] = {"photo_point_sigma_um": 3.0, "fiducial_sigma_um": 2.0}
    return doc, fit, m


_SECTION_NOTES = {
    "photos": ["exterior orientation in the pair's frame as the job computes it (from the",
               "aerotriangulation); film deformation from the measured fiducial distances"],
    "points": ["the pair's control and check points (imaged on both photos), catalogue",
               "coordinates in the pair's frame"],
    "errors": ["σ of the synthetic measurements (the scenario defaults; a job has none)"],
}  # fmt: skip


def scenario_yaml(doc: dict[str, Any], fit: TerrainFit) -> str:
    """The scenario as YAML text, with comments: where it came from and what the terrain is."""
    lines = [
        *(f"# {t}" for t in textwrap.wrap(doc["description"], 96)),
        "# A job has no ground truth: this scenario takes the job's orientation, points and map",
        "# sheet as the truth, and a terrain fitted to the control heights (below).",
    ]
    for key, value in doc.items():
        if key == "terrain":
            text = (f"TERRAIN (fitted, not measured): {fit.kind} — {fit.note}. Fitted to "
                    f"{fit.points} control heights: residual rms {fit.rms_m:.3f} m, max "
                    f"{fit.max_m:.3f} m. Change it freely: Z(X, Y) = base_height_m + "
                    "slope·(X, Y) + Σ Gaussian hills (docs/scenarios.md); the control and check "
                    "points keep their own Z_m below.")
            lines += [f"# {t}" for t in textwrap.wrap(text, 96)]
        lines += [f"# {t}" for t in _SECTION_NOTES.get(key, [])]
        text = yaml.safe_dump({key: value}, sort_keys=False, allow_unicode=True, width=100,
                              default_flow_style=None if key in ("photos", "points") else False)
        lines.append(text.rstrip("\n"))
    return "\n".join(lines) + "\n"


def write_job_scenario(
    job: Job, pair_name: str, path: str | os.PathLike[str]
) -> tuple[dict[str, Any], TerrainFit]:
    """Write the scenario of one pair of a job to ``path`` (atomically); the document and fit."""
    doc, fit, _ = job_pair_scenario(job, pair_name)
    atomic_write_bytes(path, scenario_yaml(doc, fit).encode("utf-8"))
    return doc, fit
