"""Load and validate ``scenarios/*.yaml`` into a frozen :class:`~stereoplotter.scenario.Scenario`.

Every problem is one :class:`~stereoplotter.errors.ConfigError` naming the file, the field, what
was expected and what was found. The schema is documented in ``docs/scenarios.md``.
"""

from __future__ import annotations

import math
import os
from typing import Any

import numpy as np

from stereoplotter.errors import StereoplotterError
from stereoplotter.geometry.collinearity import object_to_photo
from stereoplotter.io.yaml_files import Fields, load_yaml_mapping
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

__all__ = ["load_scenario", "scenario_from_mapping"]

#: Limits of the input, with their basis (shown in the messages).
MAX_TILT_DEG = 15.0  # near-vertical aerial photography; the instruments correct far less
MAX_FILM_DEFORMATION_PPM = 5000.0  # 0.5 %: beyond any usable film base
MIN_RESECTION_POINTS = 3
MIN_SIMILARITY_POINTS = 2

#: The defaults of the optional ``errors`` section. (Not ``ErrorSettings.photo_point_sigma_um``:
#: on a dataclass with slots that is the slot descriptor, not the default value.)
_DEFAULT_ERRORS = ErrorSettings()
#: Top-level fields that only a block file has (``stereoplotter.setup.block``).
_BLOCK_FIELDS = ("models", "models_csv")

_TOP = (
    "name",
    "description",
    "seed",
    "camera",
    "frame",
    "terrain",
    "photos",
    "points",
    "map_sheet",
    "errors",
)


def load_scenario(path: str | os.PathLike[str]) -> Scenario:
    """Read a scenario file.

    Parameters
    ----------
    path : str or path-like
        A ``scenarios/*.yaml`` file.

    Returns
    -------
    Scenario

    Raises
    ------
    ConfigError
        With the file, field, expected and found values in the message.
    """
    data, source = load_yaml_mapping(path)
    return scenario_from_mapping(data, source)


def scenario_from_mapping(data: dict[str, Any], source: str = "<scenario>") -> Scenario:
    """Validate a parsed scenario document and build the :class:`Scenario`.

    Parameters
    ----------
    data : dict
        The parsed YAML.
    source : str
        Name of the file, for messages.
    """
    fields = Fields(source)
    block_fields = [k for k in _BLOCK_FIELDS if isinstance(data, dict) and k in data]
    if block_fields:
        raise fields.error(
            block_fields[0],
            "a scenario (one photo or one stereopair: fields photos, points)",
            "a block file (it has " + ", ".join(block_fields) + ")",
            "a block file is set up model by model with: stereoplotter setup FILE --instrument "
            "NAME",
        )
    fields.mapping(data, "", _TOP, required=("name", "camera", "photos", "points"))
    camera = _camera(fields, fields.get(data, "camera", ""))
    frame = _frame(fields, data.get("frame", {}) or {})
    terrain = _terrain(fields, data.get("terrain", {}) or {})
    photos = _photos(fields, fields.get(data, "photos", ""))
    points = _points(fields, fields.get(data, "points", ""), frame, terrain)
    map_sheet = _map_sheet(fields, data["map_sheet"], frame) if data.get("map_sheet") else None
    errors = _errors(fields, data.get("errors", {}) or {})
    seed = fields.integer(data, "seed", "", low=0, high=2**63 - 1, default=0)
    scenario = Scenario(
        name=fields.text(data, "name", ""),
        description=str(data.get("description", "") or ""),
        source=source,
        camera=camera,
        photos=photos,
        terrain=terrain,
        points=points,
        frame=frame,
        map_sheet=map_sheet,
        errors=errors,
        seed=seed,
    )
    _check_geometry(fields, scenario)
    return scenario


def _camera(fields: Fields, node: Any) -> Camera:
    path = "camera"
    fields.mapping(
        node,
        path,
        ("focal_length_mm", "principal_point_mm", "format_mm", "fiducials"),
        required=("focal_length_mm", "fiducials"),
    )
    f = fields.number(node, "focal_length_mm", path, unit="mm", low=0.0, high=1000.0, low_open=True)
    pp = fields.vector(
        node, "principal_point_mm", path, 2, unit="mm", low=-5.0, high=5.0, default=[0.0, 0.0]
    )
    fmt = fields.number(node, "format_mm", path, unit="mm", low=50.0, high=300.0, default=180.0)
    fid_path = fields.join(path, "fiducials")
    fid = fields.mapping(
        fields.get(node, "fiducials", path), fid_path, ("coordinates_mm", "distances_mm")
    )
    half = fmt / 2.0
    if ("coordinates_mm" in fid) == ("distances_mm" in fid):
        raise fields.error(
            fid_path, "exactly one of coordinates_mm, distances_mm", ", ".join(fid) or "neither"
        )
    marks: dict[str, tuple[float, float]] = {}
    if "coordinates_mm" in fid:
        given_as = "coordinates"
        cpath = fields.join(fid_path, "coordinates_mm")
        coords = fields.mapping(
            {str(k): v for k, v in (fid["coordinates_mm"] or {}).items()}
            if isinstance(fid["coordinates_mm"], dict)
            else fid["coordinates_mm"],
            cpath,
            FIDUCIAL_NAMES,
            required=FIDUCIAL_NAMES,
        )
        for name in FIDUCIAL_NAMES:
            marks[name] = fields.vector(coords, name, cpath, 2, unit="mm", low=-half, high=half)
        # Numbering (docs/conventions.md §2): 1 at −x, 2 at +x, 3 at +y, 4 at −y.
        expected_side = {"1": (0, -1), "2": (0, 1), "3": (1, 1), "4": (1, -1)}
        for name, (axis, sign) in expected_side.items():
            if marks[name][axis] * sign <= 0:
                raise fields.error(
                    fields.join(cpath, name),
                    f"mark {name} on the {'+' if sign > 0 else '−'}{'xy'[axis]} side "
                    "(numbering: 1 at −x, 2 at +x, 3 at +y, 4 at −y)",
                    list(marks[name]),
                )
    else:
        given_as = "distances"
        dpath = fields.join(fid_path, "distances_mm")
        dist = fields.mapping(fid["distances_mm"], dpath, ("1-2", "3-4"), required=("1-2", "3-4"))
        d12 = fields.number(dist, "1-2", dpath, unit="mm", low=0.0, high=fmt, low_open=True)
        d34 = fields.number(dist, "3-4", dpath, unit="mm", low=0.0, high=fmt, low_open=True)
        marks = {
            "1": (-d12 / 2, 0.0),
            "2": (d12 / 2, 0.0),
            "3": (0.0, d34 / 2),
            "4": (0.0, -d34 / 2),
        }
    return Camera(f, (pp[0], pp[1]), fmt, marks, given_as)


def _frame(fields: Fields, node: Any) -> Frame:
    path = "frame"
    fields.mapping(node, path, ("kind", "origin"))
    kind = fields.choice(node, "kind", path, ("local", "sk42"), default="local")
    if kind == "local":
        if "origin" in node:
            raise fields.error(
                fields.join(path, "origin"),
                "no origin for kind local",
                "an origin",
                "set kind: sk42 to tie the frame to SK-42",
            )
        return Frame("local", None)
    opath = fields.join(path, "origin")
    origin = _sk42_triplet(fields, fields.get(node, "origin", path), opath)
    frame = Frame("sk42", origin)
    try:
        frame_tie.local_frame(frame)
    except StereoplotterError as exc:  # e.g. a latitude beyond the geodesy's range
        raise fields.error(
            opath, "an origin inside the SK-42 Gauss–Krüger domain", list(origin), str(exc)
        ) from None
    return frame


def _sk42_triplet(fields: Fields, node: Any, path: str, height: bool = True) -> tuple[float, ...]:
    keys = ("north_m", "east_m", "height_m") if height else ("north_m", "east_m")
    fields.mapping(node, path, keys, required=keys)
    north = fields.number(node, "north_m", path, unit="m", low=0.0, high=1.0e7)
    east = fields.number(
        node,
        "east_m",
        path,
        unit="m (conventional ordinate: zone × 10⁶ + 500 000 + y)",
        low=1.0e6,
        high=61.0e6,
    )
    try:
        frame_tie.check_conventional_ordinate(east)
    except StereoplotterError as exc:
        raise fields.error(
            fields.join(path, "east_m"),
            "a conventional ordinate zone·10⁶ + 500 000 + y, |y| < 400 km",
            east,
            str(exc),
        ) from None
    if not height:
        return (north, east)
    h = fields.number(node, "height_m", path, unit="m", low=-500.0, high=9000.0)
    return (north, east, h)


def _terrain(fields: Fields, node: Any) -> Terrain:
    path = "terrain"
    fields.mapping(node, path, ("base_height_m", "slope", "hills"))
    base = fields.number(
        node, "base_height_m", path, unit="m", low=-500.0, high=9000.0, default=0.0
    )
    slope = fields.vector(node, "slope", path, 2, unit="—", low=-1.0, high=1.0, default=[0.0, 0.0])
    hills = []
    for i, hill in enumerate(fields.sequence(node, "hills", path, default=[])):
        hpath = fields.join(fields.join(path, "hills"), i)
        fields.mapping(
            hill,
            hpath,
            ("X_m", "Y_m", "height_m", "radius_m"),
            required=("X_m", "Y_m", "height_m", "radius_m"),
        )
        hills.append(
            Hill(
                fields.number(hill, "X_m", hpath, unit="m", low=-1.0e7, high=1.0e7),
                fields.number(hill, "Y_m", hpath, unit="m", low=-1.0e7, high=1.0e7),
                fields.number(hill, "height_m", hpath, unit="m", low=-3000.0, high=3000.0),
                fields.number(hill, "radius_m", hpath, unit="m", low=1.0, high=1.0e6),
            )
        )
    return Terrain(base, (slope[0], slope[1]), tuple(hills))


def _photos(fields: Fields, node: Any) -> tuple[Photo, ...]:
    path = "photos"
    if not isinstance(node, list) or not 1 <= len(node) <= 2:
        raise fields.error(
            path,
            "a list of 1 photo or 2 photos named left and right",
            f"a list of {len(node)}" if isinstance(node, list) else node,
        )
    photos = []
    for i, item in enumerate(node):
        ppath = fields.join(path, i)
        fields.mapping(
            item, ppath, ("name", "exterior", "film_deformation_ppm"), required=("name", "exterior")
        )
        name = fields.text(item, "name", ppath)
        epath = fields.join(ppath, "exterior")
        ext = fields.mapping(
            item["exterior"],
            epath,
            ("X_m", "Y_m", "Z_m", "alpha_deg", "omega_deg", "kappa_deg", "source"),
            required=("X_m", "Y_m", "Z_m", "alpha_deg", "omega_deg", "kappa_deg"),
        )
        centre = tuple(
            fields.number(ext, k, epath, unit="m", low=-1.0e7, high=1.0e7) for k in ("X_m", "Y_m")
        )
        z = fields.number(ext, "Z_m", epath, unit="m", low=-500.0, high=50000.0)
        tilt_basis = f"near-vertical aerial photos only: |tilt| ≤ {MAX_TILT_DEG:g}°"
        alpha = fields.number(
            ext,
            "alpha_deg",
            epath,
            unit="°",
            low=-MAX_TILT_DEG,
            high=MAX_TILT_DEG,
            basis=tilt_basis,
        )
        omega = fields.number(
            ext,
            "omega_deg",
            epath,
            unit="°",
            low=-MAX_TILT_DEG,
            high=MAX_TILT_DEG,
            basis=tilt_basis,
        )
        kappa = fields.number(ext, "kappa_deg", epath, unit="°", low=-180.0, high=180.0)
        source = fields.choice(ext, "source", epath, ("given", "resection"), default="given")
        film = fields.vector(
            item,
            "film_deformation_ppm",
            ppath,
            2,
            unit="ppm",
            low=-MAX_FILM_DEFORMATION_PPM,
            high=MAX_FILM_DEFORMATION_PPM,
            default=[0.0, 0.0],
        )
        photos.append(
            Photo(
                name,
                ExteriorOrientation(
                    (centre[0], centre[1], z),
                    math.radians(alpha),
                    math.radians(omega),
                    math.radians(kappa),
                    source,
                ),
                (film[0], film[1]),
            )
        )
    names = [p.name for p in photos]
    if len(photos) == 2 and names != ["left", "right"]:
        raise fields.error(path, "two photos named left and right, in that order", names)
    return tuple(photos)


def _points(fields: Fields, node: Any, frame: Frame, terrain: Terrain) -> tuple[Point, ...]:
    path = "points"
    items = fields.sequence({"points": node}, "points", "", min_length=1)
    points: list[Point] = []
    seen: set[str] = set()
    for i, item in enumerate(items):
        ppath = fields.join(path, i)
        fields.mapping(item, ppath, ("id", "role", "kind", "local", "sk42"), required=("id",))
        pid = fields.text(item, "id", ppath)
        if pid in seen:
            raise fields.error(fields.join(ppath, "id"), "a unique point id", pid)
        seen.add(pid)
        role = fields.choice(item, "role", ppath, ("control", "check"), default="control")
        kind = fields.choice(item, "kind", ppath, ("full", "plan", "height"), default="full")
        if ("local" in item) == ("sk42" in item):
            raise fields.error(
                ppath, "exactly one of local, sk42", "both" if "local" in item else "neither"
            )
        if "local" in item:
            lpath = fields.join(ppath, "local")
            local = fields.mapping(
                item["local"], lpath, ("X_m", "Y_m", "Z_m"), required=("X_m", "Y_m")
            )
            X = fields.number(local, "X_m", lpath, unit="m", low=-1.0e7, high=1.0e7)
            Y = fields.number(local, "Y_m", lpath, unit="m", low=-1.0e7, high=1.0e7)
            if local.get("Z_m", "terrain") == "terrain":
                Z = float(terrain.height_m(X, Y))
            else:
                Z = fields.number(
                    local, "Z_m", lpath, unit="m (or the word terrain)", low=-500.0, high=9000.0
                )
            sk42 = None
            if frame.kind == "sk42":
                try:
                    sk42 = frame_tie.sk42_from_local(frame, (X, Y, Z))
                except StereoplotterError as exc:  # far outside the origin's zone
                    raise fields.error(
                        lpath,
                        f"a point inside the zone of frame.origin (point {pid})",
                        [X, Y, Z],
                        str(exc),
                    ) from None
            points.append(Point(pid, role, kind, (X, Y, Z), sk42))
        else:
            spath = fields.join(ppath, "sk42")
            if frame.kind != "sk42":
                raise fields.error(
                    spath,
                    "local coordinates (the frame has no SK-42 tie)",
                    "sk42 coordinates",
                    "set frame.kind: sk42 with an origin",
                )
            sk42 = _sk42_triplet(fields, item["sk42"], spath)
            try:
                local = frame_tie.local_from_sk42(frame, sk42)
            except StereoplotterError as exc:  # e.g. the point lies in another zone
                raise fields.error(
                    fields.join(spath, "east_m"),
                    f"a point in the zone of frame.origin (point {pid})",
                    sk42[1],
                    str(exc),
                ) from None
            points.append(Point(pid, role, kind, local, sk42))
    return tuple(points)


def _map_sheet(fields: Fields, node: Any, frame: Frame) -> MapSheet:
    path = "map_sheet"
    fields.mapping(node, path, ("scale", "nomenclature", "corners"), required=("scale",))
    if frame.kind != "sk42":
        raise fields.error(
            path,
            "a frame tied to SK-42 (frame.kind: sk42)",
            "frame.kind: local",
            "a map sheet is defined in Gauss–Krüger coordinates",
        )
    scale = fields.integer(node, "scale", path, low=100, high=1_000_000)
    if ("nomenclature" in node) == ("corners" in node):
        raise fields.error(
            path, "exactly one of nomenclature, corners", "both" if "corners" in node else "neither"
        )
    if "corners" in node:
        cpath = fields.join(path, "corners")
        items = fields.sequence(node, "corners", path, min_length=4)
        if len(items) != 4:
            raise fields.error(cpath, "4 corners (NW, NE, SE, SW)", f"{len(items)} corners")
        corners = np.array(
            [
                _sk42_triplet(fields, c, fields.join(cpath, i), height=False)
                for i, c in enumerate(items)
            ]
        )
        return MapSheet(scale, corners, None)
    name = fields.text(node, "nomenclature", path)
    try:
        corners, sheet_scale = frame_tie.sheet_corners_sk42(name)
    except StereoplotterError as exc:
        raise fields.error(
            fields.join(path, "nomenclature"), "a valid SK-42 nomenclature", name, str(exc)
        ) from None
    if sheet_scale != scale:
        raise fields.error(
            fields.join(path, "scale"), f"{sheet_scale} (the scale of sheet {name})", scale
        )
    return MapSheet(scale, corners, name)


def _errors(fields: Fields, node: Any) -> ErrorSettings:
    path = "errors"
    fields.mapping(node, path, ("photo_point_sigma_um", "fiducial_sigma_um"))
    return ErrorSettings(
        fields.number(
            node,
            "photo_point_sigma_um",
            path,
            unit="µm",
            low=0.0,
            high=1000.0,
            default=_DEFAULT_ERRORS.photo_point_sigma_um,
        ),
        fields.number(
            node,
            "fiducial_sigma_um",
            path,
            unit="µm",
            low=0.0,
            high=1000.0,
            default=_DEFAULT_ERRORS.fiducial_sigma_um,
        ),
    )


def _check_geometry(fields: Fields, scenario: Scenario) -> None:
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
            raise fields.error(
                fields.join(epath, "Z_m"),
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
                raise fields.error(
                    fields.join(epath, "source"),
                    f"at least {MIN_RESECTION_POINTS} full control points imaged on photo "
                    f"{photo.name!r} for a resection",
                    f"{len(usable)} ({', '.join(usable)})",
                )
    if len(scenario.photos) == 2:
        left, right = (p.exterior.centre for p in scenario.photos)
        base = float(np.linalg.norm(right[:2] - left[:2]))
        if base < 1.0:
            raise fields.error(
                "photos[1].exterior",
                "a horizontal base of at least 1 m",
                f"{base:.3g} m",
                "the two stations coincide",
            )
    if scenario.map_sheet is not None:
        plan = [p.id for p in scenario.points if p.role == "control" and p.kind in ("full", "plan")]
        if len(plan) < MIN_SIMILARITY_POINTS:
            raise fields.error(
                "points",
                f"at least {MIN_SIMILARITY_POINTS} control points of "
                "kind full or plan for the sheet fit (6.8)",
                f"{len(plan)} ({', '.join(plan)})",
            )
