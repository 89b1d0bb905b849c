"""The passage from SK-42 to the photogrammetric frame of a job.

A job whose orientation is given in SK-42 Gauss–Krüger (centres x, ȳ, H; angles to the grid axes
at the nadir), converted by the program, gives the same sheet as a hand-made job of the same pair
in the local frame, to 1 µm in every sheet value. The grid angles of the SK-42 job are made here
from the local truth of the shipped scenario pair60 *without* the program's conversion: the
rotation from the grid axes at the nadir to the local frame is R = R_O·R_Nᵀ, with R_O, R_N the
analytic east-north-up rotations of the geodesy layer (turned by the meridian convergence) at the
frame origin O and at the nadir N; the program differentiates Gauss–Krüger numerically instead.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from stereoplotter.commands.setup_job import compute_job
from stereoplotter.geodesy import split_conventional_ordinate
from stereoplotter.geodesy.photogrammetric import LocalFrame
from stereoplotter.geometry.rotation import angles_from_matrix
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.job_file import load_job
from stereoplotter.io.job_measured import grid_to_local_rotation
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.report.sheet import sheet_to_dict
from stereoplotter.scenario.frame import local_frame, sk42_from_local

TRUTH = load_scenario("pair60")
FILM_MM = {1: (169.9931, 169.9942), 2: (169.9925, 169.9936)}  # measured 1–2, 3–4


def _analytic_grid_to_local(north: float, east: float, height: float) -> np.ndarray:
    zone, y = split_conventional_ordinate(east)
    at_nadir = LocalFrame.from_gauss_kruger(north, float(y), height, int(zone)).rotation
    return local_frame(TRUTH.frame).rotation @ at_nadir.T


def test_grid_rotation_agrees_with_the_analytic_one():
    for photo in TRUTH.photos:
        n, e, h = sk42_from_local(TRUTH.frame, photo.exterior.projection_centre_m)
        for dn, de in ((0.0, 0.0), (15_000.0, -20_000.0), (-30_000.0, 25_000.0)):
            numeric = grid_to_local_rotation(TRUTH.frame, n + dn, e + de, h)
            assert np.abs(numeric - _analytic_grid_to_local(n + dn, e + de, h)).max() < 1e-9


def _job(kind: str) -> dict[str, Any]:
    origin = dict(zip(("north_m", "east_m", "height_m"), TRUTH.frame.origin_sk42_m, strict=True))
    photos, points = [], []
    for number, photo in enumerate(TRUTH.photos, start=1):
        ext = photo.exterior
        item: dict[str, Any] = {"number": number}
        if kind == "local":
            item.update(X_m=ext.projection_centre_m[0], Y_m=ext.projection_centre_m[1],
                        Z_m=ext.projection_centre_m[2])  # fmt: skip
            angles = (ext.alpha, ext.omega, ext.kappa)
        else:
            n, e, h = sk42_from_local(TRUTH.frame, ext.projection_centre_m)
            item.update(north_m=n, east_m=e, height_m=h)
            grid = _analytic_grid_to_local(n, e, h).T @ ext.rotation
            angles = tuple(float(a) for a in angles_from_matrix(grid))
        names = ("alpha_deg", "omega_deg", "kappa_deg")
        item.update({a: math.degrees(v) for a, v in zip(names, angles, strict=True)})
        item["fiducial_distances_mm"] = dict(zip(("1-2", "3-4"), FILM_MM[number], strict=True))
        photos.append(item)
    for p in TRUTH.points:
        xyz = p.local_m if kind == "local" else p.sk42_m
        names = ("X_m", "Y_m", "Z_m") if kind == "local" else ("north_m", "east_m", "height_m")
        points.append({"id": p.id, "role": p.role, "kind": p.kind,
                       **dict(zip(names, (float(v) for v in xyz), strict=True))})  # fmt: skip
    return {
        "format": "stereoplotter-job/1",
        "name": f"pair60-{kind}",
        "date": "2026-11-24",
        "instrument": "sc1",
        "camera": {"focal_length_mm": 70.0, "fiducials": {"distances_mm": {"1-2": 170.0,
                                                                          "3-4": 170.0}}},
        "frame": {"kind": kind, "origin": origin},
        "photos": photos,
        "points": points,
        "map_sheets": [{"nomenclature": TRUTH.map_sheet.nomenclature, "scale": 10000}],
        "pairs": [{"left": 1, "right": 2}],
    }


def _leaves(node: Any, path: str = "") -> dict[str, Any]:
    if isinstance(node, dict):
        out: dict[str, Any] = {}
        for k, v in node.items():
            out.update(_leaves(v, f"{path}.{k}"))
        return out
    if isinstance(node, list):
        out = {}
        for i, v in enumerate(node):
            out.update(_leaves(v, f"{path}[{i}]"))
        return out
    return {path: node}


@pytest.mark.parametrize("instrument", ["sc1", "spr3"])
def test_sk42_job_agrees_with_local_job_to_one_micrometre(tmp_path: Path, instrument: str):
    sheets = {}
    for kind in ("sk42", "local"):
        path = tmp_path / f"{kind}.yaml"
        path.write_text(yaml.safe_dump(_job(kind), allow_unicode=True), "utf-8")
        (pair,) = compute_job(load_job(path), load_instrument(instrument)).pairs
        assert pair.accepted, pair.reason
        sheets[kind] = _leaves(sheet_to_dict(pair.sheet))
    a, b = sheets["sk42"], sheets["local"]
    assert sorted(a) == sorted(b)
    numbers = [k for k in a if isinstance(a[k], float)]
    assert len(numbers) > 120  # Table 24, readings, corners, similarity, Z_i, …
    worst = max(numbers, key=lambda k: abs(a[k] - b[k]))
    assert abs(a[worst] - b[worst]) <= 1e-3, (worst, a[worst], b[worst])  # 1 µm in mm
    # texts equal but for the sign of a printed zero (b_y is 0 up to 1e-13 mm either way)
    texts = [k for k in a if k not in numbers]
    assert {k: _unsigned_zero(a[k]) for k in texts} == {k: _unsigned_zero(b[k]) for k in texts}


def _unsigned_zero(value: Any) -> Any:
    return value.replace("-0.000", "0.000") if isinstance(value, str) else value
