"""A production job file (``stereoplotter-job/1``) from a triangulated block.

The job is written in the block's own local system of §10 (``frame: {kind: local, origin: …}``):
the centres X_S, Y_S, Z_S and the angles α, ω, κ of Eq. (2.50) exactly as the triangulation gives
them, the control and check points of the catalogue in the same system (``control_points.csv``), the
fiducial distances 1–2 and 3–4 measured on the comparator (``fiducials.csv``), the camera
certificate, the instrument, date and map sheets of the block's ``production`` section, and one
pair per two consecutive photos of a strip, each on the map sheet that holds the pair's centre.
``stereoplotter setup job.yaml`` turns it into the forms (``docs/production.md``).

Photo numbers are text in the job format: each is written quoted, exactly as the block file
has it (``"0415"`` stays ``0415``).
"""

from __future__ import annotations

import csv
import io
import math
import os
from itertools import pairwise
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from stereoplotter.geodesy.gauss_kruger import geographic_from_gauss_kruger
from stereoplotter.geodesy.map_sheet import sheet_bounds
from stereoplotter.geodesy.photogrammetric import gauss_kruger_from_local
from stereoplotter.geometry.film import fiducial_spans_mm
from stereoplotter.io.atomic_write import write_files
from stereoplotter.io.block_measurements_file import Production, camera_data, origin_data
from stereoplotter.io.job_file import FORMAT as JOB_FORMAT
from stereoplotter.io.yaml_output import Flow, Folded, Quoted, yaml_document
from stereoplotter.scenario import frame as frame_tie
from stereoplotter.triangulation.block import (
    Block,
    block_frame,
    catalogue_local,
    sk42_from_block_local,
)

__all__ = ["job_files", "nomenclature_10000", "sheets_of_pairs", "write_triangulated_job"]


def _sheet_polygons(production: Production) -> list[tuple[str, NDArray[np.float64]]]:
    out = []
    for i, m in enumerate(production.map_sheets):
        if m.nomenclature is not None:
            corners, _ = frame_tie.sheet_corners_sk42(m.nomenclature)
            out.append((m.nomenclature, corners))
        else:
            corners = np.array([(c.north_m, c.east_m) for c in m.corners or ()], float)
            out.append((m.name or f"sheet {i + 1}", corners))
    return out


def _inside(point: NDArray, polygon: NDArray) -> bool:
    """Point (north, east) inside a convex quadrilateral (any orientation of its corners)."""
    edges = np.roll(polygon, -1, axis=0) - polygon
    rel = point - polygon
    cross = edges[:, 0] * rel[:, 1] - edges[:, 1] * rel[:, 0]
    return bool(np.all(cross >= 0.0) or np.all(cross <= 0.0))


def _pair_sheet(centre_sk42: NDArray, sheets: list[tuple[str, NDArray]]) -> str:
    """The sheet holding the pair's centre, else the sheet whose centre is nearest."""
    for name, poly in sheets:
        if _inside(centre_sk42[:2], poly):
            return name
    distances = [float(np.linalg.norm(poly.mean(axis=0) - centre_sk42[:2])) for _, poly in sheets]
    return sheets[int(np.argmin(distances))][0]


_BANDS = "ABCDEFGHIJKLMNOPQRSTUV"


def nomenclature_10000(latitude_deg: float, longitude_deg: float) -> str:
    """The SK-42 1:10 000 sheet holding a point (northern hemisphere, eastern longitudes).

    The inverse of :func:`stereoplotter.geodesy.map_sheet.sheet_bounds` for one scale: the
    1:1 000 000 sheet (4° × 6°), its 1:100 000 part (12 × 12), the quarters А–Г (1:50 000), а–г
    (1:25 000) and 1–4 (1:10 000), each numbered row by row from the north-west. The result is
    checked by ``sheet_bounds``: the point lies inside.

    Examples
    --------
    >>> nomenclature_10000(55.6, 24.65)
    'N-35-14-А-б-3'
    """
    lat, lon = latitude_deg, longitude_deg
    band = math.floor(lat / 4.0)
    column = math.floor(lon / 6.0) + 31
    north, west = 4.0 * (band + 1), 6.0 * (column - 31)
    height, width = 4.0 / 12.0, 6.0 / 12.0
    row, col = math.floor((north - lat) / height), math.floor((lon - west) / width)
    parts = [_BANDS[band], str(column), str(12 * row + col + 1)]
    north, west = north - row * height, west + col * width
    for names in ("АБВГ", "абвг", "1234"):
        height, width = height / 2.0, width / 2.0
        row, col = math.floor((north - lat) / height), math.floor((lon - west) / width)
        parts.append(names[2 * row + col])
        north, west = north - row * height, west + col * width
    name = "-".join(parts)
    b = sheet_bounds(name)
    assert b.south_deg <= lat <= b.north_deg and b.west_deg <= lon <= b.east_deg, name
    return name


def sheets_of_pairs(block: Block, orientations: NDArray[np.float64]) -> list[str]:
    """The 1:10 000 sheets holding the centres of the pairs of consecutive photos, in order."""
    index = {p: j for j, p in enumerate(block.photos)}
    lf = block_frame(block)
    out: list[str] = []
    for strip in block.strips:
        for left, right in pairwise(strip):
            c = (orientations[index[left], 3:] + orientations[index[right], 3:]) / 2.0
            north, y, _ = gauss_kruger_from_local(lf, c[0], c[1], 0.0)
            lat, lon = geographic_from_gauss_kruger(north, y, lf.zone)
            name = nomenclature_10000(math.degrees(float(lat)), math.degrees(float(lon)))
            if name not in out:
                out.append(name)
    return out


def _sheets_data(production: Production) -> list[dict[str, Any]]:
    return [m.model_dump(exclude_none=True, by_alias=True) for m in production.map_sheets]


def _photo_row(number: str, o: NDArray[np.float64]) -> Flow:
    """A photo of the job: its number (text) and orientation, centres to 1 mm, angles to 10⁻⁶°."""
    a, w, k = (round(math.degrees(float(v)), 6) for v in o[:3])
    x, y, z = (round(float(v), 3) for v in o[3:6])
    return Flow({"number": Quoted(number), "X_m": x, "Y_m": y, "Z_m": z, "alpha_deg": a,
                 "omega_deg": w, "kappa_deg": k})  # fmt: skip


def job_files(
    block: Block,
    production: Production,
    orientations: NDArray[np.float64],
    *,
    source: str,
    description: str,
) -> dict[str, str]:
    """The text of ``job.yaml``, ``fiducials.csv`` and ``control_points.csv`` of the block
    (orientations (n_photos, 6): α, ω, κ [rad], X_S, Y_S, Z_S [m] local; centres written to
    1 mm, angles to 10⁻⁶°, as a listing prints them). ``job.yaml`` goes through the safe YAML
    emitter (:func:`~stereoplotter.io.yaml_output.yaml_document`): names and photo numbers read
    back as the same text."""
    numbers = [str(p) for p in block.photos]
    measured = fiducial_spans_mm({str(k + 1): block.fiducials_mm[:, k] for k in range(4)})
    sheets = _sheet_polygons(production)
    index = {p: j for j, p in enumerate(block.photos)}
    pairs = []
    for strip in block.strips:
        for left, right in pairwise(strip):
            centre = (orientations[index[left], 3:] + orientations[index[right], 3:]) / 2.0
            sheet = _pair_sheet(sk42_from_block_local(block, centre), sheets)
            pairs.append(Flow({"left": Quoted(left), "right": Quoted(right), "map_sheet": sheet}))
    doc = {
        "format": JOB_FORMAT,
        "name": block.name,
        "date": Quoted(production.date),
        "description": Folded(description),
        "instrument": production.instrument,
        "camera": camera_data(block.camera),
        "frame": {"kind": "local", "origin": origin_data(block.origin_sk42_m)},
        "photos": [_photo_row(n, o) for n, o in zip(numbers, orientations, strict=True)],
        "fiducial_distances_csv": "fiducials.csv",
        "points_csv": Flow(["control_points.csv"]),
        "map_sheets": _sheets_data(production),
        "pairs": pairs,
    }
    comment = (
        f"Written by stereoplotter triangulate from {Path(source).name}: the exterior\n"
        "orientation of every photo from the triangulation, in the block's local system."
    )
    text = yaml_document(doc, comment=comment)
    fid = io.StringIO()
    w = csv.writer(fid, lineterminator="\n")
    w.writerow(("photo", "d12_mm", "d34_mm"))
    w.writerows((n, f"{d[0]:.3f}", f"{d[1]:.3f}") for n, d in zip(numbers, measured, strict=True))
    pts = io.StringIO()
    w = csv.writer(pts, lineterminator="\n")
    w.writerow(("id", "role", "kind", "X_m", "Y_m", "Z_m"))
    local = catalogue_local(block)
    w.writerows(
        (c.id, c.role, c.kind, *(f"{v:.3f}" for v in xyz))
        for c, xyz in zip(block.catalogue, local, strict=True)
    )
    return {"fiducials.csv": fid.getvalue(), "control_points.csv": pts.getvalue(), "job.yaml": text}


def write_triangulated_job(
    folder: str | os.PathLike[str],
    block: Block,
    production: Production,
    orientations: NDArray[np.float64],
    *,
    source: str,
    description: str,
) -> list[Path]:
    """Write :func:`job_files` into ``folder`` (each file whole or not at all; ``job.yaml``
    last). Returns the paths."""
    files = job_files(block, production, orientations, source=source, description=description)
    written = write_files(folder, {name: text.encode("utf-8") for name, text in files.items()})
    return list(written.values())
