"""The production job file ``stereoplotter-job/1``: the setup sheets of a block from real data.

A *job* holds what a production office has, not a ground truth (``docs/production.md``): the
camera's calibration certificate, the exterior orientation of every photo by number from the
aerotriangulation, the fiducial distances measured on each diapositive, the control and check
points of the catalogue, the map sheets, the stereopairs as pairs of photo numbers and the
instrument. :func:`load_job` validates it (pydantic models on :mod:`stereoplotter.io.validation`;
JSON Schema ``docs/schemas/job.schema.json``) into a frozen :class:`Job`;
:mod:`stereoplotter.io.job_measured` turns its pairs into the measured inputs of
:func:`stereoplotter.setup.sheet.compute_sheet_from_measurements`. Nothing here draws a random
number: the same job gives the same sheets.

The passage to the photogrammetric frame (``frame.kind``)
--------------------------------------------------------
* ``sk42``: centres and points are SK-42 Gauss–Krüger (x north, conventional ordinate ȳ with the
  zone, geodetic height H). Every pair is computed in its own local system of §10
  (:mod:`stereoplotter.geodesy.photogrammetric`) with the origin ``frame.origin`` when given,
  else at the midpoint of the pair's two stations (whole metres) at H = 0. The angles α, ω, κ
  of Eq. (2.50) are given relative to the grid axes at the photo's nadir (X grid east, Y grid
  north, Z along the normal, up); they are carried into the local system by the rotation R whose
  columns are the local directions of grid east, grid north and up at the nadir
  (:func:`stereoplotter.io.job_measured.grid_to_local_rotation`): M_local = R·M_grid.
* ``local``: centres, angles and points are already in one photogrammetric system; with
  ``frame.origin`` that system is the §10 system at that SK-42 origin (then map sheets and the
  similarity (6.8) are available), without it there is no geodetic tie (no sheet corners).
"""

from __future__ import annotations

import csv
import math
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

import numpy as np
import yaml
from numpy.typing import NDArray
from pydantic import BeforeValidator, ConfigDict, Field, field_validator

from stereoplotter.errors import ConfigError, StereoplotterError, describe_value
from stereoplotter.geometry.film import fiducial_spans_mm
from stereoplotter.io.scenario_file import (
    MAX_FILM_DEFORMATION_PPM,
    Corner,
    Distances,
    Fiducials,
    MapSheetModel,
    Origin,
    camera_from_model,
)
from stereoplotter.io.validation import (
    FileModel,
    check_date,
    integer,
    invalid,
    number,
    one_of,
    sequence,
    text,
    validate,
    vector,
)
from stereoplotter.io.yaml_input import load_yaml_mapping, read_text_file
from stereoplotter.scenario import frame as frame_tie
from stereoplotter.scenario.model import Camera, Frame, MapSheet, Point

__all__ = [
    "FORMAT",
    "Job",
    "JobFile",
    "JobPair",
    "JobPhoto",
    "is_job_file",
    "load_job",
]

#: The value of the ``format`` key that marks a job file.
FORMAT = "stereoplotter-job/1"
MAX_TILT_DEG = 15.0
_TILT_BASIS = f"near-vertical aerial photos only: |tilt| ≤ {MAX_TILT_DEG:g}°"
_EAST = "m (conventional ordinate: zone × 10⁶ + 500 000 + y)"


# --- the models -------------------------------------------------------------------------------


def _check_identifier(v: Any) -> str:
    """A photo number or point id is text: written as text, or an unquoted integer read back as
    its digits (an unquoted number with a leading zero is refused before this, by
    :func:`_unquoted_identifiers`: YAML has already read it as another number)."""
    if isinstance(v, bool) or not isinstance(v, str | int) or str(v).strip() == "":
        raise invalid("an identifier as text (quote it: \"0415\")", describe_value(v))
    return str(v).strip()


#: A photo number or point id: text, compared as written (``0415`` and ``415`` are two ids).
identifier = Annotated[
    str,
    BeforeValidator(_check_identifier),
    Field(
        min_length=1,
        description="text, compared as written (0415 and 415 are two); write it quoted: an "
        "unquoted number with a leading zero is refused",
    ),
]


#: A photo number names the pair's folder of the outputs (``101-102/sheet.pdf``): no path
#: separator, no leading dot, no control character.
_PHOTO_NUMBER = r"[^./\\\x00-\x1f\x7f][^/\\\x00-\x1f\x7f]*"


def _check_photo_number(v: Any) -> str:
    v = _check_identifier(v)
    if not re.fullmatch(_PHOTO_NUMBER, v):
        raise invalid(
            "a photo number usable in a folder name (no / or \\, no leading dot, no control "
            "character)", describe_value(v),
        )  # fmt: skip
    return v


#: A photo number: an :data:`identifier` that can name the pair's output folder.
photo_number = Annotated[
    str,
    BeforeValidator(_check_photo_number),
    Field(
        min_length=1,
        pattern=_PHOTO_NUMBER,
        description="text, compared as written (0415 and 415 are two); write it quoted: an "
        "unquoted number with a leading zero is refused; it names the pair's output folder",
    ),
]


class Certificate(FileModel):
    """The camera's calibration certificate."""

    camera: text | None = None  # type: ignore[valid-type]
    focal_length_mm: number("mm", 0.0, 1000.0, low_open=True)  # type: ignore[valid-type]
    principal_point_mm: vector(2, "mm", -5.0, 5.0) = (0.0, 0.0)  # type: ignore[valid-type]
    format_mm: number("mm", 50.0, 300.0) = 180.0  # type: ignore[valid-type]
    fiducials: Fiducials
    distortion: sequence(  # type: ignore[valid-type]
        vector(2, "mm, µm", -1000.0, 1000.0, "r [mm], Δr [µm]")
    ) | None = None


class FrameModel(FileModel):
    kind: one_of("sk42", "local")  # type: ignore[valid-type]
    origin: Origin | None = None


class PhotoModel(FileModel):
    """One photo: its number and exterior orientation (SK-42 or local by ``frame.kind``)."""

    number: photo_number
    north_m: number("m", 0.0, 1.0e7) | None = None  # type: ignore[valid-type]
    east_m: number(_EAST, 1.0e6, 61.0e6) | None = None  # type: ignore[valid-type]
    height_m: number("m", -500.0, 50000.0) | None = None  # type: ignore[valid-type]
    X_m: number("m", -1.0e7, 1.0e7) | None = None  # type: ignore[valid-type]
    Y_m: number("m", -1.0e7, 1.0e7) | None = None  # type: ignore[valid-type]
    Z_m: number("m", -500.0, 50000.0) | None = None  # type: ignore[valid-type]
    alpha_deg: number("°", -MAX_TILT_DEG, MAX_TILT_DEG, basis=_TILT_BASIS)  # type: ignore[valid-type]
    omega_deg: number("°", -MAX_TILT_DEG, MAX_TILT_DEG, basis=_TILT_BASIS)  # type: ignore[valid-type]
    kappa_deg: number("°", -180.0, 180.0)  # type: ignore[valid-type]
    fiducial_distances_mm: Distances | None = None


class FiducialRow(FileModel):
    """A row of the fiducial-distance CSV: photo number, measured 1–2 and 3–4."""

    photo: photo_number
    d12_mm: number("mm", 0.0, 300.0, low_open=True)  # type: ignore[valid-type]
    d34_mm: number("mm", 0.0, 300.0, low_open=True)  # type: ignore[valid-type]


class PointModel(FileModel):
    """A control or check point (SK-42 or local coordinates, by ``frame.kind``)."""

    id: identifier
    role: one_of("control", "check") = "control"  # type: ignore[valid-type]
    kind: one_of("full", "plan", "height") = "full"  # type: ignore[valid-type]
    north_m: number("m", 0.0, 1.0e7) | None = None  # type: ignore[valid-type]
    east_m: number(_EAST, 1.0e6, 61.0e6) | None = None  # type: ignore[valid-type]
    height_m: number("m", -500.0, 9000.0) | None = None  # type: ignore[valid-type]
    X_m: number("m", -1.0e7, 1.0e7) | None = None  # type: ignore[valid-type]
    Y_m: number("m", -1.0e7, 1.0e7) | None = None  # type: ignore[valid-type]
    Z_m: number("m", -500.0, 9000.0) | None = None  # type: ignore[valid-type]


class NamedSheet(MapSheetModel):
    """A map sheet: scale and nomenclature, or scale and corners NW, NE, SE, SW (then a name)."""

    name: text | None = None  # type: ignore[valid-type]


class WorkingArea(FileModel):
    lowest_m: number("m", -500.0, 9000.0)  # type: ignore[valid-type]
    highest_m: number("m", -500.0, 9000.0)  # type: ignore[valid-type]


class PairModel(FileModel):
    left: photo_number
    right: photo_number
    map_sheet: text | None = None  # type: ignore[valid-type]
    working_area: WorkingArea | None = None


class ScalesModel(FileModel):
    horizontal: integer(100, 10_000_000) | None = None  # type: ignore[valid-type]
    vertical: integer(100, 10_000_000) | None = None  # type: ignore[valid-type]


class OptionsModel(FileModel):
    book_sign: bool = False
    bz_scale_sense: integer(-1, 1) = 1  # type: ignore[valid-type]


class JobFile(FileModel):
    """A production job file (``docs/production.md``)."""

    model_config = ConfigDict(extra="forbid", frozen=True, title="stereoplotter job file")

    format: one_of(FORMAT, expected=f"the text {FORMAT}")  # type: ignore[valid-type]
    name: text  # type: ignore[valid-type]
    date: str = Field(description="YYYY-MM-DD, printed on the forms")
    description: str | None = None
    instrument: text  # type: ignore[valid-type]
    camera: Certificate
    frame: FrameModel
    photos: sequence(PhotoModel, min_length=2)  # type: ignore[valid-type]
    fiducial_distances_csv: text | None = None  # type: ignore[valid-type]
    points: sequence(PointModel) = Field(default_factory=list)  # type: ignore[valid-type]
    points_csv: sequence(text) = Field(default_factory=list)  # type: ignore[valid-type]
    map_sheets: sequence(NamedSheet, min_length=1)  # type: ignore[valid-type]
    pairs: sequence(PairModel, min_length=1)  # type: ignore[valid-type]
    scales: ScalesModel = ScalesModel()
    options: OptionsModel = OptionsModel()

    @field_validator("date", mode="before")
    @classmethod
    def _date(cls, v: Any) -> str:
        return check_date(v)


# --- the job as data ----------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class JobPhoto:
    """One photo of a job.

    ``centre`` is (x north, ȳ, H) for an SK-42 job, (X, Y, Z) for a local one [m]; the angles
    are α, ω, κ of Eq. (2.50) [rad] (relative to the grid axes at the nadir for SK-42);
    ``fiducial_distances_mm`` the measured 1–2 and 3–4 [mm].
    """

    number: str
    centre: tuple[float, float, float]
    angles: tuple[float, float, float]
    fiducial_distances_mm: tuple[float, float]


@dataclass(frozen=True, slots=True)
class JobPair:
    """A stereopair by photo numbers, its map sheet and optional working-area heights [m]."""

    left: str
    right: str
    map_sheet: MapSheet | None
    working_area_m: tuple[float, float] | None

    @property
    def name(self) -> str:
        return f"{self.left}-{self.right}"


@dataclass(frozen=True, slots=True)
class Job:
    """A validated job file."""

    name: str
    date: str
    description: str
    source: str
    instrument: str
    camera: Camera
    camera_name: str
    distortion: tuple[tuple[float, float], ...]
    frame_kind: str
    origin_sk42_m: tuple[float, float, float] | None
    photos: dict[str, JobPhoto]
    points: tuple[Point, ...]
    pairs: tuple[JobPair, ...]
    horizontal_scale: int | None
    vertical_scale: int | None
    book_sign: bool
    bz_scale_sense: int
    #: Where each point's coordinates were written (as ``points``): (source, field) of its
    #: ordinate, ``FILE:LINE:COLUMN`` for a CSV row.
    point_places: tuple[tuple[str, str], ...] = ()


def is_job_file(data: Any) -> bool:
    """True when a parsed YAML document declares ``format: stereoplotter-job/…``, or has the
    ``pairs`` of a job (then a missing ``format`` is reported by the job's validation)."""
    if not isinstance(data, dict):
        return False
    return str(data.get("format", "")).startswith("stereoplotter-job") or "pairs" in data


def load_job(path: str | os.PathLike[str]) -> Job:
    """Read and validate a job file (CSV files relative to it).

    Photo numbers and point ids are text, compared as written; an unquoted YAML number with a
    leading zero (read by YAML as another number: ``012417`` as octal 5391) is refused with the
    advice to quote it. A CSV value's error names ``FILE:LINE:COLUMN`` (physical lines: comment
    and blank lines counted); a CSV file that cannot be read names the job field that points
    to it.

    Raises
    ------
    ConfigError
        One line: file (or CSV file, line and column), field, expected, found.
    """
    data, source = load_yaml_mapping(path)
    _unquoted_identifiers(read_text_file(path), source)
    doc = validate(JobFile, data, source)
    folder = Path(path).parent
    camera = camera_from_model(source, doc.camera)  # type: ignore[arg-type]
    origin = _origin(source, doc.frame)
    distances = (
        _fiducial_csv(folder, doc.fiducial_distances_csv, source)
        if doc.fiducial_distances_csv else {}
    )  # fmt: skip
    photos = _photos(source, doc, distances, fiducial_spans_mm(camera.fiducials_mm))
    rows = [_Row(source, f"points[{i}]", p, {}) for i, p in enumerate(doc.points)]
    for i, name in enumerate(doc.points_csv):
        rows += _csv_rows(folder / name, PointModel, (source, f"points_csv[{i}]"))
    points = _points(doc.frame.kind, origin, rows)
    sheets = _map_sheets(source, doc.map_sheets)
    pairs = _pairs(source, doc, photos, sheets)
    return Job(
        name=doc.name,
        date=doc.date,
        description=(doc.description or "").strip(),
        source=source,
        instrument=doc.instrument,
        camera=camera,
        camera_name=doc.camera.camera or "",
        distortion=tuple((float(r), float(d)) for r, d in doc.camera.distortion or ()),
        frame_kind=doc.frame.kind,
        origin_sk42_m=origin,
        photos=photos,
        points=points,
        pairs=pairs,
        horizontal_scale=doc.scales.horizontal,
        vertical_scale=doc.scales.vertical,
        book_sign=doc.options.book_sign,
        bz_scale_sense=doc.options.bz_scale_sense,
        point_places=tuple(r.place(_ORDINATE[doc.frame.kind]) for r in rows),
    )


#: The identifier fields of a job file: section → the keys of its entries that are identifiers.
_IDENTIFIERS = {"photos": ("number",), "pairs": ("left", "right"), "points": ("id",)}
_ORDINATE = {"sk42": "east_m", "local": "Y_m"}


def _unquoted_identifiers(text: str, source: str) -> None:
    """Refuse an identifier YAML has read as a number other than its digits.

    An unquoted ``012417`` is octal 5391 to YAML 1.1, ``0415`` the text '0415' but ``0417``
    the number 271; ``1_000`` is 1000. Only an unquoted integer written as its own decimal digits
    (``101``) stands for its text. The document was checked (size, depth, aliases) by
    :func:`load_yaml_mapping` before this second composition.
    """
    root = yaml.compose(text, Loader=yaml.SafeLoader)
    if not isinstance(root, yaml.MappingNode):
        return
    for key, section in root.value:
        fields = _IDENTIFIERS.get(key.value) if isinstance(key, yaml.ScalarNode) else None
        if not fields or not isinstance(section, yaml.SequenceNode):
            continue
        for i, entry in enumerate(section.value):
            if not isinstance(entry, yaml.MappingNode):
                continue
            for k, v in entry.value:
                if not (isinstance(k, yaml.ScalarNode) and k.value in fields):
                    continue
                if not isinstance(v, yaml.ScalarNode) or v.style is not None:
                    continue  # quoted, or not a scalar (the validation names it)
                number = v.tag in ("tag:yaml.org,2002:int", "tag:yaml.org,2002:float")
                if number and not re.fullmatch(r"[1-9][0-9]*|0", v.value):
                    expected, found = _misread(v.value)
                    raise ConfigError(
                        source, f"{key.value}[{i}].{k.value}", expected,
                        f"{found} (line {v.start_mark.line + 1}, column "
                        f"{v.start_mark.column + 1})",
                    )  # fmt: skip


def _misread(text: str) -> tuple[str, str]:
    """(expected, found) for an unquoted identifier YAML read as a number: the advice to quote
    it only where YAML 1.1 read it as another number (a leading zero: octal; a colon:
    sexagesimal; an underscore or a base prefix); a signed or decimal number is no identifier
    an office writes, and is said to be one."""
    value = yaml.safe_load(text)
    kinds = (
        (r"[-+]?0[0-7_]+", "octal"), (r"[-+]?0[0-9_]+", "decimal"),
        (r"[-+]?0[xob][0-9a-fA-F_]+", "base-prefixed"), (r".*:.*", "sexagesimal"),
        (r".*_.*", "underscore-grouped"),
    )  # fmt: skip
    for pattern, kind in kinds:
        if re.fullmatch(pattern, text) and str(value) != text:
            return (f'an identifier as text: quote it ("{text}"), since YAML 1.1 reads it as '
                    f"another number", f"{text} unquoted, read as the {kind} number "
                    f"{value}")  # fmt: skip
    return ("an identifier: text, or an unquoted whole number of digits (101)",
            f"the number {text}")  # fmt: skip


def _origin(source: str, model: FrameModel) -> tuple[float, float, float] | None:
    if model.origin is None:
        return None
    o = model.origin
    try:
        frame_tie.local_frame(Frame("sk42", (o.north_m, o.east_m, o.height_m)))
    except StereoplotterError as exc:
        raise ConfigError(
            source, "frame.origin", "an origin inside the SK-42 Gauss–Krüger domain",
            [o.north_m, o.east_m, o.height_m], str(exc),
        ) from None  # fmt: skip
    return (o.north_m, o.east_m, o.height_m)


@dataclass(frozen=True, slots=True)
class _Row:
    """A validated entry of ``points`` or row of a CSV file: where it was written (the file, or
    ``FILE:LINE`` of a CSV row), its field path in the file, the model and, for a CSV row, the
    ``FILE:LINE:COLUMN`` of each value."""

    where: str
    path: str
    model: Any
    cells: dict[str, str]

    def place(self, field: str) -> tuple[str, str]:
        """(source, field) of a value for a message."""
        if field in self.cells:
            return self.cells[field], field
        return self.where, f"{self.path}.{field}".lstrip(".")


def _cell_columns(line: str) -> list[int]:
    """The 1-based character column where each comma-separated field of one physical CSV line
    starts (commas inside double quotes do not separate)."""
    starts, quoted = [1], False
    for i, ch in enumerate(line):
        if ch == '"':
            quoted = not quoted
        elif ch == "," and not quoted:
            starts.append(i + 2)
    return starts


def _csv_rows(path: Path, model: type[FileModel], named_by: tuple[str, str]) -> list[_Row]:
    """Validated rows of a CSV file with a header line, every cell read as text (a text field
    stays as written: the id ``0415`` is not the number 415; a number field is parsed by its
    own check); lines starting with ``#`` and blank lines are skipped but counted.

    ``named_by`` is the (job file, field) that names the CSV: a file that cannot be read is
    reported there.
    """
    source = str(path)
    try:
        with open(path, newline="", encoding="utf-8") as f:
            physical = f.read().splitlines()
            f.seek(0)
            reader = csv.reader(f)
            lines = []
            for row in reader:
                if row and not row[0].lstrip().startswith("#") and any(c.strip() for c in row):
                    lines.append((reader.line_num, row))
    except (OSError, UnicodeDecodeError) as exc:
        found = getattr(exc, "strerror", None) or str(exc)
        raise ConfigError(named_by[0], named_by[1], "a readable UTF-8 CSV file (relative to the "
                          "job file)", f"{source}: {found}") from None  # fmt: skip
    except csv.Error as exc:
        raise ConfigError(f"{source}:{reader.line_num}", "(row)", "valid CSV", str(exc)) from None
    if not lines:
        raise ConfigError(source, "(header)", "a header line and rows", "an empty file")
    header = [h.strip() for h in lines[0][1]]
    texts = {n for n, info in model.model_fields.items() if _is_text(info.annotation)}
    out = []
    for n, row in lines[1:]:
        where = f"{source}:{n}"
        if len(row) != len(header):
            raise ConfigError(
                where, "(row)", f"{len(header)} values ({', '.join(header)})",
                f"{len(row)} values",
            )  # fmt: skip
        columns = _cell_columns(physical[n - 1]) if n - 1 < len(physical) else []
        cells = {h: f"{where}:{columns[j]}" if j < len(columns) else where
                 for j, h in enumerate(header)}  # fmt: skip
        item = {h: v.strip() if h in texts else _csv_number(v)
                for h, v in zip(header, row, strict=True) if v.strip() != ""}  # fmt: skip
        try:
            value = validate(model, item, where)
        except ConfigError as exc:
            key = exc.field.split(".")[0].split("[")[0]
            if key not in cells:
                raise
            raise ConfigError(cells[key], exc.field, exc.expected, exc.found, exc.hint) from None
        out.append(_Row(where, "", value, cells))
    return out


def _is_text(annotation: Any) -> bool:
    """True for a field declared as text (an identifier, a word, a name): kept as written."""
    return annotation is str or annotation in (str | None,) or "Literal" in str(annotation)


def _csv_number(v: str) -> Any:
    """A CSV cell of a number field: an int or float when it reads as one, else the text (which
    the field's check then refuses, quoting it)."""
    v = v.strip()
    for kind in (int, float):
        try:
            return kind(v)
        except ValueError:
            pass
    return v


def _fiducial_csv(folder: Path, name: str, job_source: str) -> dict[str, _Row]:
    """photo → its row of measured 1–2, 3–4 [mm]."""
    out: dict[str, _Row] = {}
    for row in _csv_rows(folder / name, FiducialRow, (job_source, "fiducial_distances_csv")):
        photo = row.model.photo
        if photo in out:
            raise ConfigError(*row.place("photo"), "each photo once", photo)
        out[photo] = row
    return out


def _coordinates(row: _Row, kind: str) -> tuple[float, float, float]:
    model = row.model
    names = ("north_m", "east_m", "height_m") if kind == "sk42" else ("X_m", "Y_m", "Z_m")
    other = ("X_m", "Y_m", "Z_m") if kind == "sk42" else ("north_m", "east_m", "height_m")
    values = [getattr(model, n) for n in names]
    wrong = [n for n in other if getattr(model, n) is not None]
    if wrong or any(v is None for v in values):
        missing = [n for n, v in zip(names, values, strict=True) if v is None]
        raise ConfigError(
            row.where, row.path or "(row)",
            f"the coordinates {', '.join(names)} (frame.kind: {kind})",
            ("also " + ", ".join(wrong)) if wrong else "no " + ", ".join(missing),
        )  # fmt: skip
    if kind == "sk42":
        try:
            frame_tie.check_conventional_ordinate(values[1])
        except StereoplotterError as exc:
            raise ConfigError(*row.place("east_m"), "a conventional ordinate", values[1],
                              str(exc)) from None
    return (float(values[0]), float(values[1]), float(values[2]))


def _photos(
    source: str,
    doc: JobFile,
    csv_distances: dict[str, _Row],
    spans: NDArray[np.float64],
) -> dict[str, JobPhoto]:
    photos: dict[str, JobPhoto] = {}
    for i, p in enumerate(doc.photos):
        path = f"photos[{i}]"
        if p.number in photos:
            raise ConfigError(source, f"{path}.number", "a photo number used once", p.number)
        centre = _coordinates(_Row(source, path, p, {}), doc.frame.kind)
        if p.fiducial_distances_mm is not None and p.number in csv_distances:
            raise ConfigError(
                source, f"{path}.fiducial_distances_mm", "the measured distances in one place",
                "them here and in " + csv_distances[p.number].where,
            )  # fmt: skip
        if p.fiducial_distances_mm is not None:
            d = (p.fiducial_distances_mm.d12, p.fiducial_distances_mm.d34)
            where = [(source, f"{path}.fiducial_distances_mm.{k}") for k in ("1-2", "3-4")]
        elif p.number in csv_distances:
            row = csv_distances[p.number]
            d = (row.model.d12_mm, row.model.d34_mm)
            where = [row.place(k) for k in ("d12_mm", "d34_mm")]
        else:
            raise ConfigError(
                source, f"{path}.fiducial_distances_mm",
                "the fiducial distances 1-2, 3-4 measured on this diapositive (here or in "
                "fiducial_distances_csv)", "nothing",
            )  # fmt: skip
        for (where_file, field), measured, span in zip(where, d, spans, strict=True):
            _check_film(where_file, field, measured, float(span))
        angles = tuple(math.radians(a) for a in (p.alpha_deg, p.omega_deg, p.kappa_deg))
        photos[p.number] = JobPhoto(p.number, centre, angles, (float(d[0]), float(d[1])))  # type: ignore[arg-type]
    unknown = [n for n in csv_distances if n not in photos]
    if unknown:
        raise ConfigError(*csv_distances[unknown[0]].place("photo"), "a photo number of the job",
                          unknown[0])
    return photos


def _check_film(source: str, field: str, measured: float, span: float) -> None:
    """A measured span within ±0.5 % of the certificate's (the film deformation a scenario takes:
    beyond it no usable film base, or a typing error)."""
    limit = MAX_FILM_DEFORMATION_PPM * 1e-6
    ratio = measured / span if span > 0.0 else math.inf  # a certificate span that underflows
    if not (math.isfinite(ratio) and abs(ratio - 1.0) <= limit):
        raise ConfigError(
            source, field, f"a measured distance within ±{limit:.1%} of the certificate's "
            f"{span:.3f} mm (film deformation ≤ {MAX_FILM_DEFORMATION_PPM:g} ppm)", measured,
        )  # fmt: skip


def _points(
    kind: str, origin: tuple[float, float, float] | None, rows: list[_Row]
) -> tuple[Point, ...]:
    points: list[Point] = []
    seen: dict[str, str] = {}
    for row in rows:
        p = row.model
        if p.id in seen:
            raise ConfigError(*row.place("id"), "a unique point id (ids are text, compared as "
                              "written)", p.id, f"first at {seen[p.id]}")  # fmt: skip
        src, fld = row.place("id")
        seen[p.id] = src if row.cells else f"{src}: {fld}"
        xyz = _coordinates(row, kind)
        if kind == "sk42":  # the local coordinates depend on the pair's frame: set per pair
            points.append(Point(p.id, p.role, p.kind, (math.nan,) * 3, xyz))
        else:
            sk42 = frame_tie.sk42_from_local(Frame("sk42", origin), xyz) if origin else None
            points.append(Point(p.id, p.role, p.kind, xyz, sk42))  # type: ignore[arg-type]
    return tuple(points)


def _map_sheets(source: str, models: list[NamedSheet]) -> dict[str, MapSheet]:
    sheets: dict[str, MapSheet] = {}
    for i, m in enumerate(models):
        path = f"map_sheets[{i}]"
        if m.corners is not None:
            if len(m.corners) != 4:
                raise ConfigError(source, f"{path}.corners", "4 corners (NW, NE, SE, SW)",
                                   f"{len(m.corners)} corners")
            corners = np.array([_corner(source, c, f"{path}.corners[{j}]")
                                for j, c in enumerate(m.corners)])  # fmt: skip
            name = m.name or f"sheet {i + 1}"
            sheet = MapSheet(m.scale, corners, m.name)
        else:
            assert m.nomenclature is not None
            try:
                corners, scale = frame_tie.sheet_corners_sk42(m.nomenclature)
            except StereoplotterError as exc:
                raise ConfigError(source, f"{path}.nomenclature", "a valid SK-42 nomenclature",
                                   m.nomenclature, str(exc)) from None
            if scale != m.scale:
                raise ConfigError(source, f"{path}.scale",
                                  f"{scale} (the scale of {m.nomenclature})", m.scale)
            name = m.nomenclature
            sheet = MapSheet(m.scale, corners, m.nomenclature)
        if name in sheets:
            raise ConfigError(source, path, "a map sheet listed once", name)
        sheets[name] = sheet
    return sheets


def _corner(source: str, c: Corner, path: str) -> tuple[float, float]:
    try:
        frame_tie.check_conventional_ordinate(c.east_m)
    except StereoplotterError as exc:
        raise ConfigError(
            source, f"{path}.east_m", "a conventional ordinate", c.east_m, str(exc)
        ) from None
    return (c.north_m, c.east_m)


def _pairs(
    source: str, doc: JobFile, photos: dict[str, JobPhoto], sheets: dict[str, MapSheet]
) -> tuple[JobPair, ...]:
    pairs = []
    for i, p in enumerate(doc.pairs):
        path = f"pairs[{i}]"
        for side in ("left", "right"):
            if getattr(p, side) not in photos:
                raise ConfigError(source, f"{path}.{side}", "a photo number of photos",
                                   getattr(p, side), f"photos: {', '.join(photos)}")
        if p.left == p.right:
            raise ConfigError(source, f"{path}.right", "another photo than the left one", p.right)
        if p.map_sheet is not None and p.map_sheet not in sheets:
            raise ConfigError(source, f"{path}.map_sheet", "a sheet of map_sheets", p.map_sheet,
                               "listed: " + (", ".join(sheets) or "none"))
        sheet = sheets[p.map_sheet] if p.map_sheet else None
        if sheet is None and len(sheets) == 1:
            sheet = next(iter(sheets.values()))
        if sheet is None and sheets:
            raise ConfigError(source, f"{path}.map_sheet",
                              "the sheet of this pair (several are listed)", "nothing")
        area = None
        if p.working_area is not None:
            area = (p.working_area.lowest_m, p.working_area.highest_m)
            if area[0] > area[1]:
                raise ConfigError(source, f"{path}.working_area", "lowest_m ≤ highest_m",
                                  list(area))
        pairs.append(JobPair(p.left, p.right, sheet, area))
    return tuple(pairs)
