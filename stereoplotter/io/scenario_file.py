"""Load and validate ``scenarios/*.yaml`` into a frozen :class:`~stereoplotter.scenario.Scenario`.

Every problem is one :class:`~stereoplotter.errors.ConfigError` naming the file, the field, what
was expected and what was found. The schema is documented in ``docs/scenarios.md``.
"""

from __future__ import annotations

import dataclasses
import math
import os
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BeforeValidator, ConfigDict, Field, field_validator, model_validator

from stereoplotter.errors import ConfigError, StereoplotterError, describe_value
from stereoplotter.geometry.collinearity import object_to_photo
from stereoplotter.io.paths import resolve_data_file
from stereoplotter.io.scenario_outline import refuse_block_file
from stereoplotter.io.validation import (
    FileModel,
    check_number,
    integer,
    invalid,
    number,
    number_at,
    one_of,
    sequence,
    text,
    validate,
    vector,
)
from stereoplotter.io.yaml_input import load_yaml_mapping
from stereoplotter.scenario import frame as frame_tie
from stereoplotter.scenario.model import (
    FIDUCIAL_NAMES,
    Camera,
    ErrorSettings,
    ExteriorOrientation,
    Frame,
    Hill,
    MapSheet,
    Photo,
    Point,
    Scenario,
    Terrain,
)

__all__ = [
    "CameraModel",
    "ScenarioFile",
    "camera_from_model",
    "load_scenario",
    "scenario_from_mapping",
]

#: Limits of the input, with their basis (shown in the messages).
MAX_TILT_DEG = 15.0  # near-vertical aerial photography; the instruments correct far less
MAX_FILM_DEFORMATION_PPM = 5000.0  # 0.5 %: beyond any usable film base
MIN_RESECTION_POINTS = 3
MIN_SIMILARITY_POINTS = 2



def load_scenario(path: str | os.PathLike[str]) -> Scenario:
    """Read a scenario file.

    Parameters
    ----------
    path : str or path-like
        A scenario YAML file, or the name of a shipped or user scenario (``"pair60"``,
        :func:`stereoplotter.io.paths.resolve_data_file`).

    Returns
    -------
    Scenario

    Raises
    ------
    ConfigError
        With the file, field, expected and found values in the message.
    """
    data, source = load_yaml_mapping(resolve_data_file("scenarios", path))
    return scenario_from_mapping(data, source)


def scenario_from_mapping(data: dict[str, Any], source: str = "<scenario>") -> Scenario:
    """Validate a parsed scenario document and build the :class:`Scenario`.

    The document is validated by :class:`ScenarioFile` (types, ranges, unknown keys); then the
    checks that span fields run here: the fiducial numbering, the SK-42 tie of the frame and the
    points, the map sheet and the geometry (:func:`_check_geometry`).

    Parameters
    ----------
    data : dict
        The parsed YAML.
    source : str
        Name of the file, for messages.
    """
    refuse_block_file(data, source)
    doc = validate(ScenarioFile, _drop_nulls(data, _NULLABLE_TOP), source)
    camera = camera_from_model(source, doc.camera)
    frame = _frame(source, doc.frame)
    terrain = Terrain(
        doc.terrain.base_height_m,
        doc.terrain.slope,
        tuple(Hill(h.X_m, h.Y_m, h.height_m, h.radius_m) for h in doc.terrain.hills),
    )
    photos = _photos(source, doc.photos)
    points = _points(source, doc.points, frame, terrain)
    map_sheet = _map_sheet(source, doc.map_sheet, frame) if doc.map_sheet else None
    errors = ErrorSettings(doc.errors.photo_point_sigma_um, doc.errors.fiducial_sigma_um)
    scenario = Scenario(
        name=doc.name,
        description=doc.description or "",
        source=source,
        camera=camera,
        photos=photos,
        terrain=terrain,
        points=points,
        frame=frame,
        map_sheet=map_sheet,
        errors=errors,
        seed=doc.seed,
    )
    _check_geometry(source, scenario)
    return scenario


def _drop_nulls(data: Any, keys: tuple[str, ...]) -> Any:
    """The document without the optional sections written empty (``terrain:`` with nothing)."""
    if not isinstance(data, dict):
        return data
    return {k: v for k, v in data.items() if not (k in keys and v in (None, {}))}


_NULLABLE_TOP = ("frame", "terrain", "map_sheet", "errors", "seed", "description")


# --- the models -------------------------------------------------------------------------------

_TILT_BASIS = f"near-vertical aerial photos only: |tilt| ≤ {MAX_TILT_DEG:g}°"
_EAST_UNIT = "m (conventional ordinate: zone × 10⁶ + 500 000 + y)"
_XY = number("m", -1.0e7, 1.0e7)
_GROUND = number("m", -500.0, 9000.0)


def _present(v: Any) -> Any:
    """A mapping without its keys written with no value (they count as absent)."""
    return {k: x for k, x in v.items() if x is not None} if isinstance(v, dict) else v


class Distances(FileModel):
    """Distances between opposite fiducial marks; the marks sit symmetrically on the axes."""

    d12: float = Field(alias="1-2", json_schema_extra={"description": "[mm]"})
    d34: float = Field(alias="3-4", json_schema_extra={"description": "[mm]"})

    model_config = ConfigDict(extra="forbid", frozen=True, populate_by_name=False)

    @field_validator("d12", "d34", mode="before")
    @classmethod
    def _positive(cls, v: Any) -> float:
        return check_number(v, unit="mm", low=0.0, high=300.0, low_open=True)


class Coordinates(FileModel):
    """x, y of the four fiducial marks (1 at −x, 2 at +x, 3 at +y, 4 at −y)."""

    m1: vector(2, "mm", -150.0, 150.0) = Field(alias="1")  # type: ignore[valid-type]
    m2: vector(2, "mm", -150.0, 150.0) = Field(alias="2")  # type: ignore[valid-type]
    m3: vector(2, "mm", -150.0, 150.0) = Field(alias="3")  # type: ignore[valid-type]
    m4: vector(2, "mm", -150.0, 150.0) = Field(alias="4")  # type: ignore[valid-type]

    @model_validator(mode="before")
    @classmethod
    def _text_keys(cls, v: Any) -> Any:
        return {str(k): x for k, x in v.items()} if isinstance(v, dict) else v


class Fiducials(FileModel):
    """Exactly one of ``coordinates_mm``, ``distances_mm``."""

    coordinates_mm: Coordinates | None = None
    distances_mm: Distances | None = None

    @model_validator(mode="before")
    @classmethod
    def _exactly_one(cls, v: Any) -> Any:
        v = _present(v)
        if isinstance(v, dict) and not set(v) - {"coordinates_mm", "distances_mm"}:
            if ("coordinates_mm" in v) == ("distances_mm" in v):
                found = ", ".join(v) or "neither"
                raise invalid("exactly one of coordinates_mm, distances_mm", found)
        return v


class CameraModel(FileModel):
    focal_length_mm: number("mm", 0.0, 1000.0, low_open=True)  # type: ignore[valid-type]
    principal_point_mm: vector(2, "mm", -5.0, 5.0) = (0.0, 0.0)  # type: ignore[valid-type]
    format_mm: number("mm", 50.0, 300.0) = 180.0  # type: ignore[valid-type]
    fiducials: Fiducials


class Origin(FileModel):
    north_m: number("m", 0.0, 1.0e7)  # type: ignore[valid-type]
    east_m: number(_EAST_UNIT, 1.0e6, 61.0e6)  # type: ignore[valid-type]
    height_m: _GROUND  # type: ignore[valid-type]


class Corner(FileModel):
    north_m: number("m", 0.0, 1.0e7)  # type: ignore[valid-type]
    east_m: number(_EAST_UNIT, 1.0e6, 61.0e6)  # type: ignore[valid-type]


class FrameModel(FileModel):
    kind: one_of("local", "sk42") = "local"  # type: ignore[valid-type]
    origin: Origin | None = None


class HillModel(FileModel):
    X_m: _XY  # type: ignore[valid-type]
    Y_m: _XY  # type: ignore[valid-type]
    height_m: number("m", -3000.0, 3000.0)  # type: ignore[valid-type]
    radius_m: number("m", 1.0, 1.0e6)  # type: ignore[valid-type]


class TerrainModel(FileModel):
    base_height_m: _GROUND = 0.0  # type: ignore[valid-type]
    slope: vector(2, "—", -1.0, 1.0) = (0.0, 0.0)  # type: ignore[valid-type]
    hills: sequence(HillModel) = Field(default_factory=list)  # type: ignore[valid-type]


class Exterior(FileModel):
    X_m: _XY  # type: ignore[valid-type]
    Y_m: _XY  # type: ignore[valid-type]
    Z_m: number("m", -500.0, 50000.0)  # type: ignore[valid-type]
    alpha_deg: number("°", -MAX_TILT_DEG, MAX_TILT_DEG, basis=_TILT_BASIS)  # type: ignore[valid-type]
    omega_deg: number("°", -MAX_TILT_DEG, MAX_TILT_DEG, basis=_TILT_BASIS)  # type: ignore[valid-type]
    kappa_deg: number("°", -180.0, 180.0)  # type: ignore[valid-type]
    source: one_of("given", "resection") = "given"  # type: ignore[valid-type]


_FILM = number("ppm", -MAX_FILM_DEFORMATION_PPM, MAX_FILM_DEFORMATION_PPM)


class PhotoModel(FileModel):
    name: text  # type: ignore[valid-type]
    exterior: Exterior
    film_deformation_ppm: vector(  # type: ignore[valid-type]
        2, "ppm", -MAX_FILM_DEFORMATION_PPM, MAX_FILM_DEFORMATION_PPM
    ) = (0.0, 0.0)


def _z_or_terrain(v: Any) -> Any:
    if v == "terrain":
        return v
    return check_number(v, unit="m (or the word terrain)", low=-500.0, high=9000.0)


class Local(FileModel):
    X_m: _XY  # type: ignore[valid-type]
    Y_m: _XY  # type: ignore[valid-type]
    Z_m: Annotated[  # type: ignore[valid-type]
        float | Literal["terrain"],
        BeforeValidator(_z_or_terrain),
        Field(description="[m] or the word terrain (the height of the terrain there)"),
    ] = "terrain"


class PointModel(FileModel):
    id: text  # type: ignore[valid-type]
    role: one_of("control", "check") = "control"  # type: ignore[valid-type]
    kind: one_of("full", "plan", "height") = "full"  # type: ignore[valid-type]
    local: Local | None = None
    sk42: Origin | None = None

    @model_validator(mode="before")
    @classmethod
    def _exactly_one(cls, v: Any) -> Any:
        v = _present(v)
        if isinstance(v, dict) and ("local" in v) == ("sk42" in v):
            if not set(v) - {"id", "role", "kind", "local", "sk42"} and "id" in v:
                raise invalid("exactly one of local, sk42", "both" if "local" in v else "neither")
        return v


class MapSheetModel(FileModel):
    scale: integer(100, 1_000_000)  # type: ignore[valid-type]
    nomenclature: text | None = None  # type: ignore[valid-type]
    corners: sequence(Corner, min_length=4) | None = None  # type: ignore[valid-type]

    @model_validator(mode="before")
    @classmethod
    def _exactly_one(cls, v: Any) -> Any:
        v = _present(v)
        if isinstance(v, dict) and not set(v) - {"scale", "nomenclature", "corners"}:
            if "scale" in v and ("nomenclature" in v) == ("corners" in v):
                raise invalid(
                    "exactly one of nomenclature, corners",
                    "both" if "corners" in v else "neither",
                )
        return v


#: The defaults of the optional ``errors`` section, from the dataclass fields (not from
#: ``ErrorSettings.photo_point_sigma_um``: on a dataclass with slots that is a slot descriptor).
_ERROR_DEFAULTS = {f.name: f.default for f in dataclasses.fields(ErrorSettings)}


class ErrorsModel(FileModel):
    photo_point_sigma_um: number("µm", 0.0, 1000.0) = _ERROR_DEFAULTS[  # type: ignore[valid-type]
        "photo_point_sigma_um"
    ]
    fiducial_sigma_um: number("µm", 0.0, 1000.0) = _ERROR_DEFAULTS[  # type: ignore[valid-type]
        "fiducial_sigma_um"
    ]


class ScenarioFile(FileModel):
    """A scenario file (``docs/scenarios.md``)."""

    model_config = ConfigDict(
        extra="forbid", frozen=True, title="stereoplotter scenario file"
    )

    name: text  # type: ignore[valid-type]
    description: str | None = None
    seed: integer(0, 2**63 - 1) = 0  # type: ignore[valid-type]
    camera: CameraModel
    frame: FrameModel = FrameModel()
    terrain: TerrainModel = TerrainModel()
    photos: list[PhotoModel]
    points: sequence(PointModel, min_length=1)  # type: ignore[valid-type]
    map_sheet: MapSheetModel | None = None
    errors: ErrorsModel = ErrorsModel()

    @field_validator("photos", mode="before")
    @classmethod
    def _one_or_two(cls, v: Any) -> Any:
        if not isinstance(v, list) or not 1 <= len(v) <= 2:
            raise invalid(
                "a list of 1 photo or 2 photos named left and right",
                f"a list of {len(v)}" if isinstance(v, list) else describe_value(v),
            )
        return v


# --- from the models to the domain ----------------------------------------------------------


def camera_from_model(source: str, model: CameraModel) -> Camera:
    """The :class:`Camera` of a validated camera section; checks the marks against the format
    and their numbering (``docs/conventions.md`` §2: 1 at −x, 2 at +x, 3 at +y, 4 at −y)."""
    fmt = model.format_mm
    half = fmt / 2.0
    fid_path = "camera.fiducials"
    marks: dict[str, tuple[float, float]] = {}
    if model.fiducials.coordinates_mm is not None:
        given_as = "coordinates"
        cpath = f"{fid_path}.coordinates_mm"
        c = model.fiducials.coordinates_mm
        given = {"1": c.m1, "2": c.m2, "3": c.m3, "4": c.m4}
        for name in FIDUCIAL_NAMES:
            for i, v in enumerate(given[name]):
                number_at(source, f"{cpath}.{name}[{i}]", v, unit="mm", low=-half, high=half)
            marks[name] = (given[name][0], given[name][1])
        expected_side = {"1": (0, -1), "2": (0, 1), "3": (1, 1), "4": (1, -1)}
        for name, (axis, sign) in expected_side.items():
            if marks[name][axis] * sign <= 0:
                raise ConfigError(
                    source,
                    f"{cpath}.{name}",
                    f"mark {name} on the {'+' if sign > 0 else '−'}{'xy'[axis]} side "
                    "(numbering: 1 at −x, 2 at +x, 3 at +y, 4 at −y)",
                    list(marks[name]),
                )
    else:
        given_as = "distances"
        dpath = f"{fid_path}.distances_mm"
        d = model.fiducials.distances_mm
        assert d is not None  # the model has exactly one of the two
        d12 = number_at(source, f"{dpath}.1-2", d.d12, unit="mm", low=0.0, high=fmt,
                                  low_open=True)
        d34 = number_at(source, f"{dpath}.3-4", d.d34, unit="mm", low=0.0, high=fmt,
                                  low_open=True)
        marks = {"1": (-d12 / 2, 0.0), "2": (d12 / 2, 0.0), "3": (0.0, d34 / 2),
                 "4": (0.0, -d34 / 2)}
    pp = model.principal_point_mm
    return Camera(model.focal_length_mm, (pp[0], pp[1]), fmt, marks, given_as)


def _frame(source: str, model: FrameModel) -> Frame:
    if model.kind == "local":
        if model.origin is not None:
            raise ConfigError(
                source,
                "frame.origin",
                "no origin for kind local",
                "an origin",
                "set kind: sk42 to tie the frame to SK-42",
            )
        return Frame("local", None)
    if model.origin is None:
        raise ConfigError(source, "frame.origin", "a value (the field is required)", "nothing")
    origin = _sk42(source, model.origin, "frame.origin")
    frame = Frame("sk42", origin)
    try:
        frame_tie.local_frame(frame)
    except StereoplotterError as exc:  # e.g. a latitude beyond the geodesy's range
        raise ConfigError(
            source,
            "frame.origin", "an origin inside the SK-42 Gauss–Krüger domain", list(origin), str(exc)
        ) from None
    return frame


def _sk42(source: str, model: Origin | Corner, path: str) -> tuple[float, ...]:
    try:
        frame_tie.check_conventional_ordinate(model.east_m)
    except StereoplotterError as exc:
        raise ConfigError(
            source,
            f"{path}.east_m",
            "a conventional ordinate zone·10⁶ + 500 000 + y, |y| < 400 km",
            model.east_m,
            str(exc),
        ) from None
    if isinstance(model, Origin):
        return (model.north_m, model.east_m, model.height_m)
    return (model.north_m, model.east_m)


def _photos(source: str, models: list[PhotoModel]) -> tuple[Photo, ...]:
    photos = []
    for p in models:
        e = p.exterior
        photos.append(
            Photo(
                p.name,
                ExteriorOrientation(
                    (e.X_m, e.Y_m, e.Z_m),
                    math.radians(e.alpha_deg),
                    math.radians(e.omega_deg),
                    math.radians(e.kappa_deg),
                    e.source,
                ),
                (p.film_deformation_ppm[0], p.film_deformation_ppm[1]),
            )
        )
    names = [p.name for p in photos]
    if len(photos) == 2 and names != ["left", "right"]:
        raise ConfigError(source, "photos", "two photos named left and right, in that order", names)
    return tuple(photos)


def _points(
    source: str, models: list[PointModel], frame: Frame, terrain: Terrain
) -> tuple[Point, ...]:
    points: list[Point] = []
    seen: set[str] = set()
    for i, item in enumerate(models):
        ppath = f"points[{i}]"
        pid = item.id
        if pid in seen:
            raise ConfigError(source, f"{ppath}.id", "a unique point id", pid)
        seen.add(pid)
        if item.local is not None:
            lpath = f"{ppath}.local"
            X, Y = item.local.X_m, item.local.Y_m
            z = item.local.Z_m
            Z = float(terrain.height_m(X, Y)) if z == "terrain" else float(z)
            sk42 = None
            if frame.kind == "sk42":
                try:
                    sk42 = frame_tie.sk42_from_local(frame, (X, Y, Z))
                except StereoplotterError as exc:  # far outside the origin's zone
                    raise ConfigError(
                        source,
                        lpath,
                        f"a point inside the zone of frame.origin (point {pid})",
                        [X, Y, Z],
                        str(exc),
                    ) from None
            points.append(Point(pid, item.role, item.kind, (X, Y, Z), sk42))
            continue
        spath = f"{ppath}.sk42"
        if frame.kind != "sk42":
            raise ConfigError(
                source,
                spath,
                "local coordinates (the frame has no SK-42 tie)",
                "sk42 coordinates",
                "set frame.kind: sk42 with an origin",
            )
        assert item.sk42 is not None  # the model has exactly one of local, sk42
        sk42 = _sk42(source, item.sk42, spath)
        try:
            local = frame_tie.local_from_sk42(frame, sk42)
        except StereoplotterError as exc:  # e.g. the point lies in another zone
            raise ConfigError(
                source,
                f"{spath}.east_m",
                f"a point in the zone of frame.origin (point {pid})",
                sk42[1],
                str(exc),
            ) from None
        points.append(Point(pid, item.role, item.kind, local, sk42))
    return tuple(points)


def _map_sheet(source: str, model: MapSheetModel, frame: Frame) -> MapSheet:
    path = "map_sheet"
    if frame.kind != "sk42":
        raise ConfigError(
            source,
            path,
            "a frame tied to SK-42 (frame.kind: sk42)",
            "frame.kind: local",
            "a map sheet is defined in Gauss–Krüger coordinates",
        )
    scale = model.scale
    if model.corners is not None:
        cpath = f"{path}.corners"
        if len(model.corners) != 4:
            raise ConfigError(
                source, cpath, "4 corners (NW, NE, SE, SW)", f"{len(model.corners)} corners"
            )
        corners = np.array([_sk42(source, c, f"{cpath}[{i}]") for i, c in enumerate(model.corners)])
        return MapSheet(scale, corners, None)
    name = model.nomenclature
    assert name is not None  # the model has exactly one of nomenclature, corners
    try:
        corners, sheet_scale = frame_tie.sheet_corners_sk42(name)
    except StereoplotterError as exc:
        raise ConfigError(
            source,
            f"{path}.nomenclature", "a valid SK-42 nomenclature", name, str(exc)
        ) from None
    if sheet_scale != scale:
        raise ConfigError(
            source, f"{path}.scale", f"{sheet_scale} (the scale of sheet {name})", scale
        )
    return MapSheet(scale, corners, name)


def _check_geometry(source: str, scenario: Scenario) -> None:
    """Refuse degenerate geometry: a station at or below the ground, a zero base, too few
    control points for a resection or for the sheet fit (6.8)."""
    pts = np.array([p.local_m for p in scenario.points])
    half = scenario.camera.format_mm / 2.0
    for i, photo in enumerate(scenario.photos):
        ext = photo.exterior
        epath = f"photos[{i}].exterior"
        lowest_clearance = ext.projection_centre_m[2] - pts[:, 2].max()
        if lowest_clearance <= 0:
            top = scenario.points[int(np.argmax(pts[:, 2]))]
            raise ConfigError(
                source,
                f"{epath}.Z_m",
                f"a projection centre above every point (point {top.id} is at "
                f"Z = {top.local_m[2]:g} m)",
                ext.projection_centre_m[2],
            )
        if ext.source == "resection":
            xy = object_to_photo(
                pts,
                ext.centre,
                ext.rotation,
                scenario.camera.focal_length_mm,
                scenario.camera.principal_point_mm,
            )
            inside = np.all(np.abs(xy) <= half, axis=-1)
            usable = [
                p.id
                for p, ok in zip(scenario.points, inside, strict=True)
                if ok and p.role == "control" and p.kind == "full"
            ]
            if len(usable) < MIN_RESECTION_POINTS:
                raise ConfigError(
                    source,
                    f"{epath}.source",
                    f"at least {MIN_RESECTION_POINTS} full control points imaged on photo "
                    f"{photo.name!r} for a resection",
                    f"{len(usable)} ({', '.join(usable)})",
                )
    if len(scenario.photos) == 2:
        left, right = (p.exterior.centre for p in scenario.photos)
        base = float(np.linalg.norm(right[:2] - left[:2]))
        if base < 1.0:
            raise ConfigError(
                source,
                "photos[1].exterior",
                "a horizontal base of at least 1 m",
                f"{base:.3g} m",
                "the two stations coincide",
            )
    if scenario.map_sheet is not None:
        plan = [p.id for p in scenario.points if p.role == "control" and p.kind in ("full", "plan")]
        if len(plan) < MIN_SIMILARITY_POINTS:
            raise ConfigError(
                source,
                "points",
                f"at least {MIN_SIMILARITY_POINTS} control points of "
                "kind full or plan for the sheet fit (6.8)",
                f"{len(plan)} ({', '.join(plan)})",
            )
