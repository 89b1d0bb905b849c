"""The measured inputs of a job's pairs: each pair of a :class:`~stereoplotter.io.job_file.Job`
in its own photogrammetric frame (the passage to it: :mod:`stereoplotter.io.job_file`) as the
keyword arguments of :func:`stereoplotter.setup.sheet.compute_sheet_from_measurements` —
:func:`measured_pair` for one pair, :func:`measured_pairs` for all pairs of a job at once (the
same values, to the bit). Nothing here draws a random number.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from stereoplotter.errors import ConfigError, StereoplotterError
from stereoplotter.geodesy import (
    geocentric_from_geodetic,
    geographic_from_gauss_kruger,
    split_conventional_ordinate,
)
from stereoplotter.geodesy.photogrammetric import LocalFrame, local_from_gauss_kruger
from stereoplotter.geometry.collinearity import object_to_photo, photo_to_object
from stereoplotter.geometry.film import corrected_focal_length, fiducial_spans_mm
from stereoplotter.geometry.rotation import rotation_matrix
from stereoplotter.io.job_file import Job, JobPair, JobPhoto
from stereoplotter.scenario import frame as frame_tie
from stereoplotter.scenario.model import Frame, MapSheet, Point
from stereoplotter.setup.records import SetupRefusal

__all__ = [
    "GRID_STEP_M",
    "WORKING_AREA_MARGIN",
    "MeasuredPair",
    "grid_to_local_rotation",
    "measured_pair",
    "measured_pairs",
]

#: Margin of the working area inside the overlap of the two footprints (as for a scenario).
WORKING_AREA_MARGIN = 0.05


@dataclass(frozen=True, slots=True)
class MeasuredPair:
    """The measured inputs of one pair's sheet (the keyword arguments of
    :func:`stereoplotter.setup.sheet.compute_sheet_from_measurements`) and the frame they are
    in (``origin_sk42_m`` is None for a local job without a tie)."""

    name: str
    origin_sk42_m: tuple[float, float, float] | None
    focal_length_corrected_mm: float
    focal_length_corrected_per_photo_mm: tuple[float, float]
    marks_mm: NDArray[np.float64]
    centres_m: NDArray[np.float64]
    rotations: NDArray[np.float64]
    points: tuple[Point, ...]
    working_area_m: NDArray[np.float64]
    map_sheet: MapSheet | None

    def sheet_arguments(self) -> dict[str, Any]:
        """The keyword arguments of ``compute_sheet_from_measurements`` but spec and options."""
        return {
            "name": self.name,
            "focal_length_corrected_mm": self.focal_length_corrected_mm,
            "focal_length_corrected_per_photo_mm": self.focal_length_corrected_per_photo_mm,
            "marks_mm": self.marks_mm,
            "centres_m": self.centres_m,
            "rotations": self.rotations,
            "points": self.points,
            "working_area_m": self.working_area_m,
            "map_sheet": self.map_sheet,
            "exterior_sources": ("aerotriangulation", "aerotriangulation"),
        }


#: The step of the central differences of :func:`grid_to_local_rotation`. [m]
GRID_STEP_M = 10.0


def grid_to_local_rotation(
    frame: Frame, north_m: float, east_m: float, height_m: float, step_m: float = GRID_STEP_M
) -> NDArray[np.float64]:
    """R: the directions of grid east, grid north and up at a point, in the local frame.

    Columns: the central differences of :func:`~stereoplotter.geodesy.photogrammetric.
    local_from_gauss_kruger` along ȳ, x and H at the point, made orthonormal (the nearest
    rotation, by SVD: removes the grid scale factor). M_local = R·M_grid. [—]
    """
    lf = frame_tie.local_frame(frame)
    stepped = _stepped_points(lf, north_m, east_m, height_m, step_m)
    return _rotation_of_steps(local_from_gauss_kruger(lf, *stepped))


def _stepped_points(
    lf: LocalFrame, north_m: float, east_m: float, height_m: float, step_m: float = GRID_STEP_M
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The six points of :func:`grid_to_local_rotation` around a station (east, north, up; −
    then +) as Gauss–Krüger x, plain y and H of the frame's zone; a station in another zone is
    refused."""
    zone, y = split_conventional_ordinate(east_m)
    if int(zone) != lf.zone:
        raise StereoplotterError(f"a station in zone {int(zone)}, the frame in zone {lf.zone}")
    dn, de, dh = _steps(step_m)
    return north_m + dn, float(y) + de, height_m + dh


def _steps(step_m: float) -> tuple[NDArray, NDArray, NDArray]:
    """The steps in x, y, H of the six points of :func:`grid_to_local_rotation` (east, north,
    up; − then +). [m]"""
    d, zero = np.array([-step_m, step_m]), np.zeros(2)
    dn, de, dh = (np.concatenate(v) for v in ((zero, d, zero), (d, zero, zero), (zero, zero, d)))
    return dn, de, dh


def _rotation_of_steps(local: tuple[NDArray, NDArray, NDArray]) -> NDArray[np.float64]:
    """The rotation of :func:`grid_to_local_rotation` from its six stepped points in the local
    frame."""
    X, Y, Z = local
    cols = np.array([X[1::2] - X[0::2], Y[1::2] - Y[0::2], Z[1::2] - Z[0::2]])
    u, _, vt = np.linalg.svd(cols)
    return u @ vt


def _pair_frame(job: Job, left: JobPhoto, right: JobPhoto) -> Frame | None:
    if job.origin_sk42_m is not None:
        return Frame("sk42", job.origin_sk42_m)
    if job.frame_kind == "local":
        return None
    north = round((left.centre[0] + right.centre[0]) / 2.0)
    east = round((left.centre[1] + right.centre[1]) / 2.0)
    return Frame("sk42", (float(north), float(east), 0.0))


def _points_in_zone(job: Job, lf: LocalFrame) -> tuple[NDArray, NDArray, NDArray]:
    """The job's SK-42 points as Gauss–Krüger x, plain y and H, all in the zone of the pair's
    frame (a point in another zone is bad input)."""
    sk42 = np.array([p.sk42_m for p in job.points], float)
    zone, y = split_conventional_ordinate(sk42[:, 1])
    far = np.flatnonzero(np.asarray(zone) != lf.zone)
    if far.size:
        i = int(far[0])
        src, fld = job.point_places[i] if job.point_places else (job.source, "points")
        raise ConfigError(
            src, fld, f"a point in zone {lf.zone} (the points of a job in one Gauss–Krüger zone, "
            "the zone of the pair's frame)",
            f"point {job.points[i].id} in zone {int(np.asarray(zone)[i])}",
        )
    return sk42[:, 0], np.asarray(y, float), sk42[:, 2]


def _station_centre(job: Job, frame: Frame | None, photo: JobPhoto) -> NDArray[np.float64]:
    if job.frame_kind == "local":
        return np.array(photo.centre, float)
    assert frame is not None
    return np.array(frame_tie.local_from_sk42(frame, photo.centre), float)


def _stations_and_points(
    job: Job, frame: Frame | None, photos: tuple[JobPhoto, JobPhoto]
) -> tuple[list[NDArray], list[NDArray], NDArray[np.float64]]:
    """The two stations' centres and rotations (M_local = R·M_grid, :func:`
    grid_to_local_rotation`) and the job's points, all in the pair's frame.

    The stepped points of both rotations and the points go through one geodesy call (each
    value the one its own call gives: the calls are element-wise but the frame's final turn, a
    matrix product that gives the same bits for any number of rows above one)."""
    centres = [_station_centre(job, frame, photo) for photo in photos]
    grid_angles = [rotation_matrix(*photo.angles) for photo in photos]
    if job.frame_kind == "local":
        xyz = np.array([p.local_m for p in job.points], float).reshape(-1, 3)
        return centres, grid_angles, xyz
    assert frame is not None
    lf = frame_tie.local_frame(frame)
    parts = [_stepped_points(lf, *photo.centre) for photo in photos]
    if job.points:
        parts.append(_points_in_zone(job, lf))
    X, Y, Z = local_from_gauss_kruger(lf, *(np.concatenate(v) for v in zip(*parts, strict=True)))
    rotations = [
        _rotation_of_steps((X[k : k + 6], Y[k : k + 6], Z[k : k + 6])) @ m
        for k, m in zip((0, 6), grid_angles, strict=True)
    ]
    return centres, rotations, np.column_stack([X[12:], Y[12:], Z[12:]])


def _local_points(job: Job, xyz: NDArray[np.float64], keep: NDArray[np.bool_]) -> tuple[Point, ...]:
    """The job's points kept by ``keep``, at their places ``xyz`` in the pair's frame."""
    if job.frame_kind == "local":
        return tuple(p for p, k in zip(job.points, keep, strict=True) if k)
    return tuple(
        Point(p.id, p.role, p.kind, (float(X), float(Y), float(Z)), p.sk42_m)
        for p, k, (X, Y, Z) in zip(job.points, keep, xyz.tolist(), strict=True)
        if k
    )


def measured_pair(job: Job, pair: JobPair) -> MeasuredPair:
    """One pair of the job as the measured inputs of its sheet.

    f′ by :mod:`stereoplotter.geometry.film` from the measured 1–2, 3–4 against the certificate
    (one f′ per pair from all four spans; per photo for the record); the measured marks are the
    certificate's scaled per axis by the same ratios (the uniform film deformation of
    ``docs/conventions.md`` §7), relative to the principal point; the points of the pair are
    those imaged on both photos; the working area is the overlap of the two footprints at the
    mean point height, shrunk by 5 % a side, at the lowest and highest ground (``working_area``
    of the pair, else the points' heights).
    """
    left, right = job.photos[pair.left], job.photos[pair.right]
    frame = _pair_frame(job, left, right)
    (found,) = _measured(job, [pair], [frame], [_pair_geodesy(job, pair, frame)])
    if isinstance(found, SetupRefusal):
        raise found
    return found


def _pair_geodesy(
    job: Job, pair: JobPair, frame: Frame | None
) -> tuple[list[NDArray], list[NDArray], NDArray[np.float64]]:
    """:func:`_stations_and_points` of one pair, a station or point beyond the zone of its
    frame as the one-line error of the pair."""
    left, right = job.photos[pair.left], job.photos[pair.right]
    try:  # the geodesy of the pair's frame: a station or point beyond its zone is bad input
        return _stations_and_points(job, frame, (left, right))
    except StereoplotterError as exc:
        if isinstance(exc, ConfigError) or str(exc).startswith(f"{job.source}: "):
            raise
        origin = "" if frame is None or frame.origin_sk42_m is None else (
            " at x = {:.0f} m, ȳ = {:.0f} m".format(*frame.origin_sk42_m[:2]))  # fmt: skip
        raise StereoplotterError(
            f"{job.source}: pairs: pair {pair.name}: expected stations and points the pair's "
            f"frame{origin} can take (one Gauss–Krüger zone), found: {exc}"
        ) from None


def measured_pairs(job: Job) -> list[MeasuredPair | SetupRefusal]:
    """:func:`measured_pair` of every pair of the job, in order (a pair that cannot be set up
    as its :class:`SetupRefusal`).

    The geodesy of an SK-42 job's pairs (stations, the grid-to-local rotations and the points in
    each pair's frame) is one call for all pairs (:func:`_geodesy_of_pairs`): every value the
    bits of the pair computed alone. When a pair's stations or points are beyond its frame's
    zone, the pairs are computed one at a time, for the error of the first such pair.
    """
    photos = [(job.photos[p.left], job.photos[p.right]) for p in job.pairs]
    frames = [_pair_frame(job, left, right) for left, right in photos]
    geodesy = _geodesy_of_pairs(job, frames, photos)
    if geodesy is None:
        geodesy = [
            _pair_geodesy(job, pair, frame) for pair, frame in zip(job.pairs, frames, strict=True)
        ]
    return _measured(job, list(job.pairs), frames, geodesy)


def _geodesy_of_pairs(
    job: Job, frames: list[Frame | None], photos: list[tuple[JobPhoto, JobPhoto]]
) -> list[tuple[list[NDArray], list[NDArray], NDArray[np.float64]]] | None:
    """:func:`_stations_and_points` of every pair of an SK-42 job, in one geodesy call (None for
    a local job, or when a station or point is beyond its pair's frame: the caller then takes the
    pairs one at a time, for their errors).

    Each step is element-wise (PROJ per point; (2.7) by numpy's element-wise functions) but the
    frame's turn, a matrix product per pair, stacked: numpy gives each product the bits of its own
    call, the stations' with one row as the one-point call.
    """
    if job.frame_kind == "local" or not photos:
        return None
    try:
        lfs = [frame_tie.local_frame(frame) for frame in frames]  # type: ignore[arg-type]
        zones = {lf.zone for lf in lfs}
        if len(zones) != 1:
            return None
        (zone,) = zones
        centres = np.array([[p.centre for p in pair] for pair in photos], float)  # (P, 2, 3)
        station_zone, station_y = split_conventional_ordinate(centres[..., 1])
        if np.any(np.asarray(station_zone) != zone) or np.any(
            np.abs(np.asarray(station_y, float)) > frame_tie.MAX_PLAIN_ORDINATE_M
        ):
            return None
        if job.points:
            pn, py, ph = _points_in_zone(job, lfs[0])
        else:
            pn = py = ph = np.zeros(0)
    except StereoplotterError:
        return None
    n_pairs, n_points = len(photos), len(pn)
    dn, de, dh = _steps(GRID_STEP_M)
    y = np.asarray(station_y, float)
    # rows of each pair: the six stepped points of each station, then the job's points
    stepped_n = (centres[..., 0, None] + dn).reshape(n_pairs, 12)
    stepped_e = (y[..., None] + de).reshape(n_pairs, 12)
    stepped_h = (centres[..., 2, None] + dh).reshape(n_pairs, 12)
    rows_n = np.concatenate([stepped_n, np.broadcast_to(pn, (n_pairs, n_points))], axis=1)
    rows_e = np.concatenate([stepped_e, np.broadcast_to(py, (n_pairs, n_points))], axis=1)
    rows_h = np.concatenate([stepped_h, np.broadcast_to(ph, (n_pairs, n_points))], axis=1)
    every_n = np.concatenate([centres[..., 0].ravel(), rows_n.ravel()])
    every_e = np.concatenate([y.ravel(), rows_e.ravel()])
    every_h = np.concatenate([centres[..., 2].ravel(), rows_h.ravel()])
    try:
        b, lon = geographic_from_gauss_kruger(every_n, every_e, zone)  # (2.10), pyproj
    except Exception:  # the pairs one at a time raise it as each pair's own
        return None
    g = np.stack(geocentric_from_geodetic(b, lon, every_h), axis=-1)  # (2.7)
    origins = np.array([lf.origin_geocentric_m for lf in lfs])  # (P, 3)
    turns = np.array([lf.rotation for lf in lfs])  # (P, 3, 3)
    # (2.8), (2.11), (2.14) per pair: the stations one row each, the other rows together
    stations = (g[: 2 * n_pairs].reshape(n_pairs, 2, 1, 3) - origins[:, None, None, :]) @ (
        np.swapaxes(turns, 1, 2)[:, None]
    )
    rows = (g[2 * n_pairs :].reshape(n_pairs, 12 + n_points, 3) - origins[:, None, :]) @ (
        np.swapaxes(turns, 1, 2)
    )
    X, Y, Z = rows[..., 0], rows[..., 1], rows[..., 2]
    cols = np.stack([X[:, 1:12:2] - X[:, 0:12:2], Y[:, 1:12:2] - Y[:, 0:12:2],
                     Z[:, 1:12:2] - Z[:, 0:12:2]], axis=1)  # fmt: skip
    cols = cols.reshape(n_pairs, 3, 2, 3).transpose(0, 2, 1, 3)  # (P, station, axis, step)
    u, _, vt = np.linalg.svd(cols)
    angles = np.array([[p.angles for p in pair] for pair in photos], float)  # (P, 2, 3)
    alpha, omega, kappa = np.moveaxis(angles, -1, 0)
    rotations = (u @ vt) @ rotation_matrix(alpha, omega, kappa)  # (P, 2, 3, 3)
    out = []
    for i in range(n_pairs):
        out.append((
            [stations[i, 0, 0], stations[i, 1, 0]],
            [rotations[i, 0], rotations[i, 1]],
            rows[i, 12:],
        ))  # fmt: skip
    return out


def _film(
    job: Job, pairs: list[JobPair]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """f′ of each pair (from its four measured spans), f′ of each photo and the measured marks
    (the certificate's scaled per axis by the photo's span ratios, relative to the principal
    point) of every pair, as arrays. [mm]"""
    cam = job.camera
    n = len(pairs)
    spans = np.array(
        [[job.photos[p.left].fiducial_distances_mm, job.photos[p.right].fiducial_distances_mm]
         for p in pairs], float,
    ).reshape(n, 2, 2)  # fmt: skip
    ratios = spans / fiducial_spans_mm(cam.fiducials_mm)  # (pair, photo, span)
    f = cam.focal_length_mm
    f_pairs = corrected_focal_length(f, ratios.reshape(n, 4), np.ones(4))
    per_photo = f * np.mean(ratios, axis=-1)
    marks = cam.fiducial_array_mm() * ratios[:, :, None, :] - np.asarray(
        cam.principal_point_mm, float
    )
    return f_pairs, per_photo, marks


def _imaged_on_both(
    job: Job, every: list[NDArray], centres: NDArray, rotations: NDArray
) -> list[NDArray[np.bool_]]:
    """Per pair, which of the job's points (``every``: in the pair's frame) both photos image
    inside the format."""
    cam = job.camera
    f, pp, half = cam.focal_length_mm, np.asarray(cam.principal_point_mm, float), cam.format_mm / 2
    if len({len(xyz) for xyz in every}) == 1:  # the job's points in each pair's frame
        xy = object_to_photo(
            np.array(every).reshape(len(every), 1, -1, 3), centres[:, :, None],
            rotations[:, :, None], f, pp,
        )  # fmt: skip
        with np.errstate(invalid="ignore"):
            return list(np.all(np.abs(xy) <= half, axis=-1).all(axis=1))
    inside = []
    for xyz, c, m in zip(every, centres, rotations, strict=True):
        xy = object_to_photo(xyz, c[:, None], m[:, None], f, pp)
        with np.errstate(invalid="ignore"):
            inside.append(np.all(np.abs(xy) <= half, axis=-1).all(axis=0))
    return inside


def _plan_extents(
    job: Job, heights: NDArray, centres: NDArray, rotations: NDArray
) -> tuple[NDArray, NDArray]:
    """The lower and upper corner (X, Y) of each pair's working area: the overlap of the two
    footprints at the mean height, shrunk by :data:`WORKING_AREA_MARGIN` a side (NaN for a pair
    without heights). [m]"""
    cam = job.camera
    half = cam.format_mm / 2.0
    z0 = (heights[:, 0] + heights[:, 1]) / 2.0
    corners = np.array([[half, half], [-half, half], [-half, -half], [half, -half]])
    with np.errstate(invalid="ignore"):  # the refused pairs' NaN
        boxes = photo_to_object(
            corners, z0[:, None, None], centres[:, :, None], rotations[:, :, None],
            cam.focal_length_mm, np.asarray(cam.principal_point_mm, float),
        )[..., :2]  # (pair, photo, corner, X Y)  # fmt: skip
        lo = np.max(np.min(boxes, axis=2), axis=1)
        hi = np.min(np.max(boxes, axis=2), axis=1)
        pad = WORKING_AREA_MARGIN * (hi - lo)
    return lo + pad, hi - pad


def _measured(
    job: Job,
    pairs: list[JobPair],
    frames: list[Frame | None],
    geodesy: list[tuple[list[NDArray], list[NDArray], NDArray[np.float64]]],
) -> list[MeasuredPair | SetupRefusal]:
    """:func:`measured_pair` of each pair from its stations, rotations and points in its frame
    (:func:`_stations_and_points`): f′ and the marks, the points imaged on both photos and the
    working area of all pairs as arrays (element-wise arithmetic, minima and maxima: the bits of
    each pair computed alone); the points' records and the refusals pair by pair."""
    n = len(pairs)
    f_pairs, per_photo, marks = _film(job, pairs)
    centres = np.array([g[0] for g in geodesy], float).reshape(n, 2, 3)
    rotations = np.array([g[1] for g in geodesy], float).reshape(n, 2, 3, 3)
    every = [g[2] for g in geodesy]
    inside = _imaged_on_both(job, every, centres, rotations)
    out: list[MeasuredPair | SetupRefusal | None] = []
    kept, heights = [], np.full((n, 2), np.nan)
    for i, pair in enumerate(pairs):
        points = _local_points(job, every[i], inside[i])
        kept.append(points)
        z = [p.local_m[2] for p in points if p.kind != "plan"] or [p.local_m[2] for p in points]
        if pair.working_area_m is not None:
            heights[i] = _local_heights(frames[i], *centres[i], pair.working_area_m)
        elif z:
            heights[i] = min(z), max(z)
        else:  # this pair alone cannot be set up: the job's other pairs still can
            out.append(SetupRefusal(
                "no control point imaged on both photos and no working_area (lowest_m, "
                "highest_m) of the pair: nothing fixes the heights of its model"
                + _suspects(job, pair, _local_points(job, every[i], np.ones(len(every[i]), bool)),
                            tuple(zip(centres[i], rotations[i], strict=True)))
            ))  # fmt: skip
            continue
        out.append(None)
    lo, hi = _plan_extents(job, heights, centres, rotations)
    for i, pair in enumerate(pairs):
        if out[i] is not None:
            continue
        (x0, y0), (x1, y1) = lo[i].tolist(), hi[i].tolist()
        plan = ((x0, y0), (x1, y0), (x1, y1), (x0, y1))
        frame = frames[i]
        out[i] = MeasuredPair(
            name=pair.name,
            origin_sk42_m=frame.origin_sk42_m if frame is not None else None,
            focal_length_corrected_mm=float(f_pairs[i]),
            focal_length_corrected_per_photo_mm=(float(per_photo[i, 0]), float(per_photo[i, 1])),
            marks_mm=marks[i],
            centres_m=centres[i],
            rotations=rotations[i],
            points=kept[i],
            working_area_m=np.array([[x, y, z] for z in heights[i].tolist() for x, y in plan]),
            map_sheet=pair.map_sheet,
        )
    return out  # type: ignore[return-value]


def _suspects(
    job: Job,
    pair: JobPair,
    points: tuple[Point, ...],
    stations: tuple[tuple[NDArray, NDArray], ...],
) -> str:
    """Which input of a pair without imaged control looks wrong, and why, as "; suspicious: …"
    (empty when nothing does): a photo at or below the control's median height; two photos
    whose footprints cannot overlap (the base longer than a footprint); the control point
    nearest to being imaged, with how far its projection falls outside the format on each
    photo (or that it lies above the camera)."""
    cam, f = job.camera, job.camera.focal_length_mm
    half = cam.format_mm / 2.0
    names = (pair.left, pair.right)
    out = []
    xyz = np.array([p.local_m for p in points], float).reshape(-1, 3)
    ground = float(np.median(xyz[:, 2])) if len(points) else 0.0
    heights = [float(c[2]) - ground for c, _ in stations]
    for name, h in zip(names, heights, strict=True):
        if h <= 0:
            z = round(h + ground, 1) + 0.0  # no "-0.0"
            out.append(f"photo {name} at {z:.1f} m is not above the control's median height "
                       f"{ground:.1f} m (check its height)")  # fmt: skip
    if min(heights) > 0:
        base = float(np.hypot(*(stations[0][0][:2] - stations[1][0][:2])))
        footprint = cam.format_mm / f * float(np.mean(heights))
        if base > footprint:
            far = ""
            if len(points):
                near = [float(np.min(np.hypot(*(xyz[:, :2] - c[:2]).T))) for c, _ in stations]
                lost = [n for n, d in zip(names, near, strict=True) if d > footprint]
                if len(lost) == 1:
                    far = (f"; photo {lost[0]} is {max(near) / 1000:.1f} km from the nearest "
                           f"control point, the other {min(near) / 1000:.1f} km")  # fmt: skip
            out.append(f"photos {names[0]} and {names[1]} are {base:.0f} m apart, more than a "
                       f"footprint ({footprint:.0f} m at {np.mean(heights):.0f} m above the "
                       f"control): they cannot overlap (check their coordinates){far}")  # fmt: skip
    if len(points) and min(heights) > 0:
        outside = []
        for c, m in stations:
            xy = object_to_photo(xyz, c, m, f, cam.principal_point_mm)
            beyond = np.max(np.abs(xy), axis=-1) - half
            beyond[xyz[:, 2] >= c[2]] = np.inf  # above the camera: never imaged
            outside.append(np.where(np.isfinite(beyond), np.maximum(beyond, 0.0), np.inf))
        worst = np.max(outside, axis=0)
        i = int(np.argmin(worst))
        where = [("above the camera" if not np.isfinite(o[i]) else
                  "inside the format" if o[i] == 0 else f"{o[i]:.1f} mm outside the format")
                 + f" on photo {n}" for o, n in zip(outside, names, strict=True)]  # fmt: skip
        out.append(f"the control point nearest to being imaged, {points[i].id}, falls "
                   f"{' and '.join(where)} ({cam.format_mm:g} mm; check its coordinates or the "
                   "photos' orientation)")  # fmt: skip
    return "; suspicious: " + "; ".join(out) if out else ""


def _local_heights(
    frame: Frame | None, c_l: NDArray, c_r: NDArray, heights: tuple[float, float]
) -> tuple[float, float]:
    """The working area's lowest and highest ground as local Z under the pair's centre."""
    if frame is None:
        return heights
    centre = (c_l + c_r) / 2.0
    north, east, _ = frame_tie.sk42_from_local(frame, (centre[0], centre[1], 0.0))
    z = [frame_tie.local_from_sk42(frame, (north, east, h))[2] for h in heights]
    return (float(z[0]), float(z[1]))
