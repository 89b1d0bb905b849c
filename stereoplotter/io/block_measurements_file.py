"""The block measurements file ``stereoplotter-block-measurements/1``: the input of ``triangulate``.

A YAML file (pydantic models on :mod:`stereoplotter.io.validation`; JSON Schema
``docs/schemas/block-measurements.schema.json``) with two CSV files beside it::

    format: stereoplotter-block-measurements/1
    name: block3x6
    camera: {focal_length_mm: 70.0, format_mm: 180.0,
             fiducials: {distances_mm: {"1-2": 170.0, "3-4": 170.0}}}   # the certificate
    frame: {origin: {north_m: 6167100.0, east_m: 5352300.0, height_m: 0.0}}
    strips: [["101", "102", "103"], ["201", "202", "203"]]              # photo numbers, text
    measurements_csv: measurements.csv   # photo,point,kind,x_mm,y_mm  (kind: fiducial | point)
    control_csv: control.csv             # id,role,kind,north_m,east_m,height_m  (SK-42)
    sigma: {photo_mm: 0.005, control_plan_m: 0.05, control_height_m: 0.05,
            centre_plan_m: 0.1, centre_height_m: 0.15}
    centres_csv: centres.csv             # optional: photo,north_m,east_m,height_m (GNSS, SK-42)
    lever_arm_m: [0.0, 0.0, 1.2]         # optional: the antenna in the camera system
    production: {instrument: sc1, date: "2026-11-26", map_sheets: [...]}  # for the job file

Photo numbers and point ids are text everywhere (``0415`` is not ``415``): in YAML they must be
quoted, in the CSV files they are read as written. Fiducial rows name the mark (1–4) in
``point``. Bad input is one line naming the file, the field or CSV line, what was expected and
what was found. :func:`write_block_measurements` writes a block (e.g. a synthetic one) in this
format, every file whole or not at all.
"""

from __future__ import annotations

import csv
import io
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import ConfigDict, Field, field_validator

from stereoplotter.errors import ConfigError, StereoplotterError
from stereoplotter.geometry.film import fiducial_spans_mm
from stereoplotter.io.atomic_write import write_files
from stereoplotter.io.job_file import Certificate, NamedSheet
from stereoplotter.io.scenario_file import Origin, camera_from_model
from stereoplotter.io.validation import (
    FileModel,
    check_date,
    invalid,
    number,
    one_of,
    sequence,
    text,
    validate,
)
from stereoplotter.io.yaml_input import load_yaml_mapping
from stereoplotter.io.yaml_output import Flow, Folded, Quoted, yaml_document
from stereoplotter.scenario import frame as frame_tie
from stereoplotter.scenario.model import Camera, Frame
from stereoplotter.triangulation.block import Block, CataloguePoint, Sigmas

__all__ = [
    "FORMAT",
    "BlockMeasurementsFile",
    "Production",
    "camera_data",
    "load_block_measurements",
    "origin_data",
    "production_data",
    "write_block_measurements",
]

FORMAT = "stereoplotter-block-measurements/1"
MEASUREMENT_COLUMNS = ("photo", "point", "kind", "x_mm", "y_mm")
CONTROL_COLUMNS = ("id", "role", "kind", "north_m", "east_m", "height_m")
CENTRE_COLUMNS = ("photo", "north_m", "east_m", "height_m")


def _identifier(v: Any) -> str:
    if not isinstance(v, str) or not v.strip() or v != v.strip():
        expected = 'a photo number as quoted text ("0415"; YAML reads 0415 as a number)'
        raise invalid(expected, repr(v))
    return v


class SigmaModel(FileModel):
    """A priori standard deviations (defaults: a stereocomparator and a 5 cm catalogue)."""

    photo_mm: number("mm", 0.0, 1.0, low_open=True) = 0.005  # type: ignore[valid-type]
    control_plan_m: number("m", 0.0, 100.0, low_open=True) = 0.05  # type: ignore[valid-type]
    control_height_m: number("m", 0.0, 100.0, low_open=True) = 0.05  # type: ignore[valid-type]
    centre_plan_m: number("m", 0.0, 100.0, low_open=True) = 0.1  # type: ignore[valid-type]
    centre_height_m: number("m", 0.0, 100.0, low_open=True) = 0.15  # type: ignore[valid-type]


class BlockFrame(FileModel):
    """The origin of the local system of §10 in which the block is adjusted (SK-42)."""

    origin: Origin


class ProductionModel(FileModel):
    """What ``triangulate`` needs to write a production job file (``docs/production.md``)."""

    instrument: text = "sc1"  # type: ignore[valid-type]
    date: str = Field(description="YYYY-MM-DD, printed on the forms")
    map_sheets: sequence(NamedSheet, min_length=1)  # type: ignore[valid-type]

    @field_validator("date", mode="before")
    @classmethod
    def _date(cls, v: Any) -> str:
        return check_date(v)


class BlockMeasurementsFile(FileModel):
    """A block of comparator measurements (``docs/triangulation.md``)."""

    model_config = ConfigDict(
        extra="forbid", frozen=True, title="stereoplotter block measurements file"
    )

    format: one_of(FORMAT, expected=f"the text {FORMAT}")  # type: ignore[valid-type]
    name: text  # type: ignore[valid-type]
    description: str | None = None
    camera: Certificate
    frame: BlockFrame
    strips: sequence(sequence(str, min_length=1), min_length=1)  # type: ignore[valid-type]
    measurements_csv: text  # type: ignore[valid-type]
    control_csv: text  # type: ignore[valid-type]
    sigma: SigmaModel = SigmaModel()
    centres_csv: text | None = None  # type: ignore[valid-type]
    lever_arm_m: sequence(number("m", -100.0, 100.0), min_length=3, max_length=3) = Field(  # type: ignore[valid-type]
        default_factory=lambda: [0.0, 0.0, 0.0],
        description="the GNSS antenna in the camera system (x, y, z) [m]",
    )
    production: ProductionModel | None = None

    @field_validator("strips", mode="before")
    @classmethod
    def _ids(cls, v: Any) -> Any:
        if isinstance(v, list):
            for strip in v:
                if isinstance(strip, list):
                    for p in strip:
                        _identifier(p)
        return v


@dataclass(frozen=True, slots=True)
class Production:
    """The production section: instrument, date and map sheets (validated models)."""

    instrument: str
    date: str
    map_sheets: tuple[NamedSheet, ...]


def _read_csv(path: Path, columns: tuple[str, ...]) -> list[tuple[str, dict[str, str]]]:
    """Rows of a CSV file with exactly ``columns`` in its header; values as text."""
    source = str(path)
    try:
        with open(path, newline="", encoding="utf-8") as f:
            lines = [(n, r) for n, r in enumerate(csv.reader(f), start=1) if r and r[0][:1] != "#"]
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(source, "(file)", "a readable UTF-8 CSV file", str(exc)) from None
    if not lines:
        raise ConfigError(source, "(header)", ", ".join(columns), "an empty file")
    header = tuple(h.strip() for h in lines[0][1])
    if header != columns:
        raise ConfigError(
            f"{source}:{lines[0][0]}", "(header)", ", ".join(columns), ", ".join(header)
        )
    out = []
    for n, row in lines[1:]:
        if len(row) != len(columns):
            raise ConfigError(
                f"{source}:{n}", "(row)", f"{len(columns)} values", f"{len(row)} values"
            )
        out.append((f"{source}:{n}", dict(zip(columns, (v.strip() for v in row), strict=True))))
    return out


def _number(where: str, column: str, value: str, low: float, high: float, unit: str) -> float:
    try:
        v = float(value)
    except ValueError:
        v = math.nan
    if not (math.isfinite(v) and low <= v <= high):
        raise ConfigError(where, column, f"a number in [{low:g}, {high:g}] {unit}", repr(value))
    return v


def _choice(where: str, column: str, value: str, words: tuple[str, ...]) -> str:
    if value not in words:
        raise ConfigError(where, column, "one of " + ", ".join(words), repr(value))
    return value


def _measurements(path: Path, photos: dict[str, int]) -> tuple[Any, ...]:
    """Fiducials (n_photos, 4, 2) and the point measurements of the measurements CSV."""
    fiducials = np.full((len(photos), 4, 2), np.nan)
    obs_photo, obs_point, xy, ids, seen = [], [], [], {}, set()
    for where, row in _read_csv(path, MEASUREMENT_COLUMNS):
        photo = row["photo"]
        if photo not in photos:
            raise ConfigError(where, "photo", "a photo number of strips", repr(photo))
        kind = _choice(where, "kind", row["kind"], ("fiducial", "point"))
        x = _number(where, "x_mm", row["x_mm"], -1000.0, 1000.0, "mm")
        y = _number(where, "y_mm", row["y_mm"], -1000.0, 1000.0, "mm")
        key = (photo, kind, row["point"])
        if key in seen or not row["point"]:
            raise ConfigError(
                where, "point", f"a {kind} measured once per photo", repr(row["point"])
            )
        seen.add(key)
        if kind == "fiducial":
            mark = _choice(where, "point", row["point"], ("1", "2", "3", "4"))
            fiducials[photos[photo], int(mark) - 1] = (x, y)
            continue
        obs_photo.append(photos[photo])
        obs_point.append(ids.setdefault(row["point"], len(ids)))
        xy.append((x, y))
    missing = np.argwhere(np.isnan(fiducials[:, :, 0]))
    if missing.size:
        name = list(photos)[missing[0][0]]
        raise ConfigError(
            str(path),
            "kind",
            f"the four fiducial marks of photo {name}",
            f"no mark {missing[0][1] + 1}",
        )
    return (
        fiducials,
        np.array(obs_photo, np.int64),
        np.array(obs_point, np.int64),
        np.array(xy, float).reshape(-1, 2),
        tuple(ids),
    )


def _catalogue(path: Path, zone: int) -> tuple[CataloguePoint, ...]:
    out: dict[str, CataloguePoint] = {}
    for where, row in _read_csv(path, CONTROL_COLUMNS):
        pid = row["id"]
        if not pid or pid in out:
            raise ConfigError(where, "id", "a unique point id", repr(pid))
        role = _choice(where, "role", row["role"], ("control", "check"))
        kind = _choice(where, "kind", row["kind"], ("full", "plan", "height"))
        north = _number(where, "north_m", row["north_m"], 0.0, 1.0e7, "m")
        east = _number(where, "east_m", row["east_m"], 1.0e6, 61.0e6, "m (conventional)")
        height = _number(where, "height_m", row["height_m"], -500.0, 9000.0, "m")
        try:
            z, _ = frame_tie.check_conventional_ordinate(east)
        except StereoplotterError as exc:
            raise ConfigError(where, "east_m", "a conventional ordinate", east, str(exc)) from None
        if z != zone:
            raise ConfigError(where, "east_m", f"a point in the origin's zone {zone}", f"zone {z}")
        out[pid] = CataloguePoint(pid, role, kind, (north, east, height))
    return tuple(out.values())


def _centres(path: Path, photos: dict[str, int], zone: int) -> tuple:
    """The measured projection centres: (photo, (north, east, height)) per row, SK-42 [m]."""
    out: dict[str, tuple[float, float, float]] = {}
    for where, row in _read_csv(path, CENTRE_COLUMNS):
        photo = row["photo"]
        if photo not in photos or photo in out:
            raise ConfigError(where, "photo", "a photo number of strips, once", repr(photo))
        north = _number(where, "north_m", row["north_m"], 0.0, 1.0e7, "m")
        east = _number(where, "east_m", row["east_m"], 1.0e6, 61.0e6, "m (conventional)")
        height = _number(where, "height_m", row["height_m"], -500.0, 20000.0, "m")
        z, _ = frame_tie.check_conventional_ordinate(east)
        if z != zone:
            raise ConfigError(where, "east_m", f"a point in the origin's zone {zone}", f"zone {z}")
        out[photo] = (north, east, height)
    return tuple(out.items())


def load_block_measurements(path: str | os.PathLike[str]) -> tuple[Block, Production | None]:
    """Read and validate a block measurements file (CSV files relative to it).

    Raises
    ------
    ConfigError
        One line: file (or CSV file and line), field, expected, found.
    """
    data, source = load_yaml_mapping(path)
    doc = validate(BlockMeasurementsFile, data, source)
    folder = Path(path).parent
    camera = camera_from_model(source, doc.camera)  # type: ignore[arg-type]
    o = doc.frame.origin
    try:
        zone, _ = frame_tie.check_conventional_ordinate(o.east_m)
        frame_tie.local_frame(Frame("sk42", (o.north_m, o.east_m, o.height_m)))
    except StereoplotterError as exc:
        where = [o.north_m, o.east_m, o.height_m]
        expected = "an origin inside the SK-42 Gauss–Krüger domain"
        raise ConfigError(source, "frame.origin", expected, where, str(exc)) from None
    photos: dict[str, int] = {}
    for i, strip in enumerate(doc.strips):
        for j, p in enumerate(strip):
            if p in photos:
                raise ConfigError(source, f"strips[{i}][{j}]", "a photo number used once", p)
            photos[p] = len(photos)
    fid, obs_photo, obs_point, xy, ids = _measurements(folder / doc.measurements_csv, photos)
    catalogue = _catalogue(folder / doc.control_csv, zone)
    centres = _centres(folder / doc.centres_csv, photos, zone) if doc.centres_csv else ()
    s = doc.sigma
    block = Block(
        name=doc.name,
        camera=camera,
        strips=tuple(tuple(strip) for strip in doc.strips),
        fiducials_mm=fid,
        obs_photo=obs_photo,
        obs_point=obs_point,
        comparator_mm=xy,
        point_ids=ids,
        catalogue=catalogue,
        origin_sk42_m=(o.north_m, o.east_m, o.height_m),
        sigmas=Sigmas(
            s.photo_mm, s.control_plan_m, s.control_height_m, s.centre_plan_m, s.centre_height_m
        ),
        centres=centres,
        lever_arm_m=tuple(float(v) for v in doc.lever_arm_m),  # type: ignore[arg-type]
    )
    prod = doc.production
    production = Production(prod.instrument, prod.date, tuple(prod.map_sheets)) if prod else None
    return block, production


def camera_data(cam: Camera) -> dict[str, Any]:
    """The ``camera:`` section of a certificate with marks on the axes (data for
    :func:`~stereoplotter.io.yaml_output.yaml_document`)."""
    spans = [float(v) for v in fiducial_spans_mm(cam.fiducials_mm)]
    return {
        "focal_length_mm": float(cam.focal_length_mm),
        "principal_point_mm": Flow([float(v) for v in cam.principal_point_mm]),
        "format_mm": float(cam.format_mm),
        "fiducials": {"distances_mm": Flow({Quoted("1-2"): spans[0], Quoted("3-4"): spans[1]})},
    }


def origin_data(origin_sk42_m: tuple[float, float, float]) -> Flow:
    """The SK-42 origin of the local system of §10 as a one-line mapping."""
    north, east, height = (float(v) for v in origin_sk42_m)
    return Flow({"north_m": north, "east_m": east, "height_m": height})


def production_data(instrument: str, date: str, map_sheets: list[str]) -> dict[str, Any]:
    """The ``production:`` section of a block file: the instrument, the date (YYYY-MM-DD) and
    the 1:10 000 sheets by nomenclature."""
    return {
        "instrument": instrument,
        "date": Quoted(date),
        "map_sheets": [Flow({"nomenclature": name, "scale": 10000}) for name in map_sheets],
    }


def _csv_text(header: tuple[str, ...], rows: list[tuple[Any, ...]]) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    w.writerows(rows)
    return buf.getvalue()


def write_block_measurements(
    folder: str | os.PathLike[str],
    block: Block,
    *,
    description: str = "",
    production: dict[str, Any] | None = None,
) -> list[Path]:
    """Write ``block.yaml``, ``measurements.csv`` and ``control.csv`` into ``folder`` (comparator
    readings to 0.1 µm, catalogue to 1 mm); ``production`` is the optional ``production:``
    section (:func:`production_data`). ``block.yaml`` goes through the safe YAML emitter
    (:func:`~stereoplotter.io.yaml_output.yaml_document`): a name or photo number is written so
    that it reads back as the same text. Returns the paths written."""
    out = Path(folder)
    photos = block.photos
    rows: list[tuple[Any, ...]] = []
    for j, p in enumerate(photos):
        rows += [
            (p, str(k + 1), "fiducial", f"{x:.4f}", f"{y:.4f}")
            for k, (x, y) in enumerate(block.fiducials_mm[j])
        ]
    order = np.lexsort((block.obs_point, block.obs_photo))
    rows += [
        (
            photos[block.obs_photo[i]],
            block.point_ids[block.obs_point[i]],
            "point",
            f"{block.comparator_mm[i, 0]:.4f}",
            f"{block.comparator_mm[i, 1]:.4f}",
        )
        for i in order
    ]
    control = [
        (c.id, c.role, c.kind, f"{c.sk42_m[0]:.3f}", f"{c.sk42_m[1]:.3f}", f"{c.sk42_m[2]:.3f}")
        for c in block.catalogue
    ]
    s = block.sigmas
    doc: dict[str, Any] = {"format": FORMAT, "name": block.name}
    if description:
        doc["description"] = Folded(description)
    doc |= {
        "camera": camera_data(block.camera),
        "frame": {"origin": origin_data(block.origin_sk42_m)},
        "strips": [Flow([Quoted(p) for p in strip]) for strip in block.strips],
        "measurements_csv": "measurements.csv",
        "control_csv": "control.csv",
        "sigma": Flow(
            {
                "photo_mm": float(s.photo_mm),
                "control_plan_m": float(s.control_plan_m),
                "control_height_m": float(s.control_height_m),
                "centre_plan_m": float(s.centre_plan_m),
                "centre_height_m": float(s.centre_height_m),
            }
        ),
    }
    files = {}
    if block.centres:
        doc["centres_csv"] = "centres.csv"
        doc["lever_arm_m"] = Flow([float(v) for v in block.lever_arm_m])
        files["centres.csv"] = _csv_text(
            CENTRE_COLUMNS,
            [(p, *(f"{v:.3f}" for v in xyz)) for p, xyz in block.centres],
        )
    if production is not None:
        doc["production"] = production
    files |= {
        "measurements.csv": _csv_text(MEASUREMENT_COLUMNS, rows),
        "control.csv": _csv_text(CONTROL_COLUMNS, control),
        "block.yaml": yaml_document(doc),
    }
    # the YAML last: it refers to the CSV files
    written = write_files(out, {name: text.encode("utf-8") for name, text in files.items()})
    return list(written.values())
