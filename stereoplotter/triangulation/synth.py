r"""A synthetic block made from a ground truth, so that every triangulation is checked against it.

The truth is invented in the local system of §10 at an SK-42 origin: strips flying east, photos
at a forward overlap and strips at a side overlap, each station with random tilts, swing, height
and position deviations; a terrain of Gaussian hills (:class:`~stereoplotter.scenario.model.
Terrain`); tie and pass points on a grid of half a base along and half a strip spacing across
(the six standard positions of every model, shared by the neighbouring strips); control points
at the block's edges every ``control_every_bases`` bases (full) and height points on the inner
strip boundaries at the same stations; all other grid points are check points.

What an office would get is then *measured*: each point imaged by Eq. (2.53)
(:func:`~stereoplotter.geometry.collinearity.object_to_photo`), the diapositive shrunk by a film
deformation, placed on the comparator with a shift and turn, and read with a normal error of σ
per coordinate; the four fiducial marks are read the same way; the catalogue coordinates get
their own normal error. Randomness only from the ``Generator`` passed in.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from stereoplotter.geometry.collinearity import object_to_photo
from stereoplotter.geometry.rotation import rotation_matrix, rotation_z
from stereoplotter.scenario.model import Camera, Hill, Terrain
from stereoplotter.triangulation.block import (
    Block,
    CataloguePoint,
    Sigmas,
    block_frame,
    sk42_from_block_local,
)
from stereoplotter.triangulation.camera_model import camera_image
from stereoplotter.triangulation.control_spacing import choose_control_spacing

__all__ = ["SynthSpec", "Truth", "control_stations_for_degree", "synthesize_block"]

#: The §10 origin of the shipped scenario pair60 (SK-42 zone 5, the book's §27 setting). [m]
DEFAULT_ORIGIN_SK42_M = (6167100.0, 5352300.0, 0.0)


@dataclass(frozen=True, slots=True)
class SynthSpec:
    """The ground truth of a synthetic block and how it is measured.

    Defaults: the book's §27 setting of the worked job ``jobs/strip8`` (f = 70 mm, 180 mm
    format, marks 85 mm from the centre, photo scale ≈ 1:20 000), forward overlap 60 % and side
    overlap 30 % (the usual aerial survey), tilts of σ 1° and swing of σ 1.5°, both clipped at
    2σ (the tilts of the shipped block strip60 stay within 1°; a tie point at the next photo's
    nadir must stay in the usable field), σ 5 µm per comparator coordinate (a
    stereocomparator), control to 5 cm. ``control_stations`` (base numbers 0 … n_bases along
    every strip) replaces the regular ``control_every_bases`` (e.g.
    :func:`control_stations_for_degree`). ``centre_sigma_m``: every photo's GNSS antenna
    (S + M·``lever_arm_m``) measured with this σ on each axis (None: no centres).
    ``camera_error``: the true camera differs from its certificate by Δf, x₀, y₀ and has the
    distortion k₁, k₂, p₁, p₂ (:mod:`~stereoplotter.triangulation.camera_model`).
    ``sigma_fiducial_mm``: σ of a fiducial mark's reading (default: that of a point).
    """

    strips: int = 4
    photos_per_strip: int = 10
    focal_length_mm: float = 70.0
    format_mm: float = 180.0
    scale: float = 20000.0
    forward_overlap: float = 0.6
    side_overlap: float = 0.3
    tilt_sigma_deg: float = 1.0
    swing_sigma_deg: float = 1.5
    height_sigma_m: float = 10.0
    position_sigma_m: float = 20.0
    terrain_relief_m: float = 100.0
    control_every_bases: int = 4
    control_stations: tuple[int, ...] | None = None
    sigma_photo_mm: float = 0.005
    sigma_control_m: float = 0.05
    film_deformation_ppm: float = 50.0
    centre_sigma_m: float | None = None
    lever_arm_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    camera_error: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    sigma_fiducial_mm: float | None = None
    origin_sk42_m: tuple[float, float, float] = DEFAULT_ORIGIN_SK42_M
    name: str = "synthetic"

    @property
    def base_m(self) -> float:
        """B = (1 − p)·l·m. [m]"""
        return (1.0 - self.forward_overlap) * self.format_mm * 1e-3 * self.scale

    @property
    def strip_spacing_m(self) -> float:
        """D = (1 − q)·l·m. [m]"""
        return (1.0 - self.side_overlap) * self.format_mm * 1e-3 * self.scale


@dataclass(frozen=True, slots=True)
class Truth:
    """The truth of a synthetic block (local system of §10).

    ``orientations`` (n_photos, 6): α, ω, κ [rad], X_S, Y_S, Z_S [m] in the photo order of the
    block; ``points_m`` (n_points, 3) in the order of ``Block.point_ids``; ``terrain``.
    """

    orientations: NDArray[np.float64]
    points_m: NDArray[np.float64]
    terrain: Terrain


def control_stations_for_degree(n_bases: int, degree: int) -> tuple[int, ...]:
    """Base numbers of degree + 1 control stations along a strip of ``n_bases`` bases, chosen
    from the residual variances of the strip polynomial (Burshtynskaya's control spacing,
    :func:`stereoplotter.triangulation.control_spacing.choose_control_spacing`)."""
    return tuple(int(b) for b in choose_control_spacing(n_bases, degree))


def _terrain(spec: SynthSpec, rng: np.random.Generator, extent: NDArray) -> Terrain:
    """A base of 150 m, a gentle slope and one hill or hollow of up to ± relief per ~100 km²
    (denser hills add up to twice the relief, which takes tie points out of the usable field)."""
    area = float(np.prod(extent[1] - extent[0]))
    n = max(2, round(area / 100e6))
    hills = tuple(
        Hill(
            float(rng.uniform(extent[0, 0], extent[1, 0])),
            float(rng.uniform(extent[0, 1], extent[1, 1])),
            float(rng.choice([-1.0, 1.0]) * rng.uniform(0.3, 1.0) * spec.terrain_relief_m),
            float(rng.uniform(1500.0, 4000.0)),
        )
        for _ in range(n)
    )
    return Terrain(150.0, (0.002, -0.001), hills)


def _stations(spec: SynthSpec, rng: np.random.Generator, terrain: Terrain) -> NDArray:
    """Stations on the strip lines; each strip flown at the photo scale's height above the mean
    ground under it (a pilot keeps the scale over a slope)."""
    ns, npp = spec.strips, spec.photos_per_strip
    X = (np.arange(npp) - (npp - 1) / 2.0) * spec.base_m
    Y = (np.arange(ns) - (ns - 1) / 2.0) * spec.strip_spacing_m
    gx, gy = np.meshgrid(X, Y)
    n = ns * npp
    ground = terrain.height_m(gx, gy).mean(axis=1, keepdims=True) + 0.0 * gx
    flying = ground.ravel() + spec.focal_length_mm * 1e-3 * spec.scale
    tilt, swing = np.radians(spec.tilt_sigma_deg), np.radians(spec.swing_sigma_deg)
    return np.column_stack(
        [
            np.clip(rng.normal(0.0, tilt, n), -2 * tilt, 2 * tilt),
            np.clip(rng.normal(0.0, tilt, n), -2 * tilt, 2 * tilt),
            np.clip(rng.normal(0.0, swing, n), -2 * swing, 2 * swing),
            gx.ravel() + rng.normal(0.0, spec.position_sigma_m, n),
            gy.ravel() + rng.normal(0.0, spec.position_sigma_m, n),
            flying + rng.normal(0.0, spec.height_sigma_m, n),
        ]
    )


def _grid(spec: SynthSpec, rng: np.random.Generator) -> tuple[NDArray, NDArray, NDArray]:
    """Ground grid X, Y [m] and its column and row numbers (half base, half strip spacing)."""
    ns, npp = spec.strips, spec.photos_per_strip
    cols = np.arange(-1, 2 * (npp - 1) + 2)  # half-base columns, one beyond each end nadir
    rows = np.arange(-1, 2 * (ns - 1) + 2)  # half-spacing rows, the outer edges included
    c, r = np.meshgrid(cols, rows)
    c, r = c.ravel(), r.ravel()
    X = (c / 2.0 - (npp - 1) / 2.0) * spec.base_m + rng.uniform(-0.02, 0.02, c.size) * spec.base_m
    Y = (r / 2.0 - (ns - 1) / 2.0) * spec.strip_spacing_m + rng.uniform(
        -0.05, 0.05, c.size
    ) * spec.strip_spacing_m
    return np.column_stack([X, Y]), c, r


def _roles(spec: SynthSpec, c: NDArray, r: NDArray) -> tuple[NDArray, NDArray]:
    """Role and kind per grid point: full control on the outer rows and end columns every
    ``control_every_bases`` bases, height control on inner strip boundaries at those columns."""
    last = 2 * (spec.photos_per_strip - 1)
    if spec.control_stations is not None:
        at_station = np.isin(c, 2 * np.asarray(spec.control_stations))
    else:
        at_station = (c % (2 * spec.control_every_bases) == 0) | (c == last)
    at_station &= (c >= 0) & (c <= last)
    outer = (r == r.min()) | (r == r.max())
    boundary = (r % 2 == 1) & ~outer
    full = at_station & outer
    full |= ((c == 0) | (c == last)) & (r % 2 == 1)
    height = at_station & boundary & ~full
    role = np.where(full | height, "control", "check")
    kind = np.where(height, "height", "full")
    return role, kind


def _camera(spec: SynthSpec) -> Camera:
    m = 0.85 * spec.format_mm / 2.0 / 0.9 if spec.format_mm != 180.0 else 85.0
    marks = {"1": (-m, 0.0), "2": (m, 0.0), "3": (0.0, m), "4": (0.0, -m)}
    return Camera(spec.focal_length_mm, (0.0, 0.0), spec.format_mm, marks, "distances")


def synthesize_block(spec: SynthSpec, rng: np.random.Generator) -> tuple[Block, Truth]:
    """Make a block and its truth from ``spec`` with the random numbers of ``rng``.

    Photo numbers are ``100·strip + photo`` (``"101"`` … ``"110"``, ``"201"`` …); grid points
    ``"P<row>.<column>"`` (row and column of the grid, from 0). A point is measured on every photo
    on which Eq. (2.53) puts it inside 47 % of the format from the centre (the usable field).
    """
    cam = _camera(spec)
    xy, c, r = _grid(spec, rng)
    extent = np.array([xy.min(axis=0), xy.max(axis=0)])
    terrain = _terrain(spec, rng, extent)
    points = np.column_stack([xy, terrain.height_m(xy[:, 0], xy[:, 1])])
    stations = _stations(spec, rng, terrain)
    strips = tuple(
        tuple(str(100 * (s + 1) + k + 1) for k in range(spec.photos_per_strip))
        for s in range(spec.strips)
    )
    ids = tuple(f"P{int(rr) + 1}.{int(cc) + 1}" for rr, cc in zip(r, c, strict=True))
    rot = rotation_matrix(stations[:, 0], stations[:, 1], stations[:, 2])
    photo, seen = _true_images(spec, cam, points, stations, rot)
    obs_photo, obs_point = np.nonzero(seen)
    measured, fiducials = _comparator_readings(spec, cam, rng, photo, obs_photo, obs_point)
    block0 = Block(
        spec.name,
        cam,
        strips,
        fiducials,
        obs_photo,
        obs_point,
        measured,
        ids,
        (),
        spec.origin_sk42_m,
    )
    block_frame(block0)  # the origin is checked before any point is converted
    catalogue = _catalogue(spec, rng, block0, points, c, r)
    sigmas, centres = _measured_centres(spec, rng, block0, stations, rot)
    block = dataclasses.replace(
        block0,
        catalogue=catalogue,
        sigmas=sigmas,
        centres=centres,
        lever_arm_m=tuple(map(float, spec.lever_arm_m)),
    )
    return block, Truth(stations, points, terrain)


def _true_images(
    spec: SynthSpec, cam: Camera, points: NDArray, stations: NDArray, rot: NDArray
) -> tuple[NDArray, NDArray]:
    """Every point's image on every photo [mm] by Eq. (2.53) with the camera's true errors
    (photos × points × 2), and where it lies in the usable field."""
    true = np.array(spec.camera_error, float)
    true[0] += cam.focal_length_mm
    photo = object_to_photo(points[None], stations[:, None, 3:], rot[:, None], true[0])
    with np.errstate(invalid="ignore"):
        seen = np.all(np.abs(photo) <= 0.47 * spec.format_mm, axis=-1)
    if np.any(true[1:] != 0.0):
        flat = photo.reshape(-1, 2)
        ok = np.all(np.isfinite(flat), axis=1)
        flat[ok] = camera_image(flat[ok], true)[0]
        photo = flat.reshape(photo.shape)
    return photo, seen


def _comparator_readings(
    spec: SynthSpec,
    cam: Camera,
    rng: np.random.Generator,
    photo: NDArray,
    obs_photo: NDArray,
    obs_point: NDArray,
) -> tuple[NDArray, NDArray]:
    """The measured points and fiducial marks in comparator coordinates [mm]: the diapositive
    on the comparator with film deformation, a turn and a shift per photo, and the σ of a
    reading."""
    n_photos, n_obs = photo.shape[0], obs_photo.size
    film = 1.0 + rng.uniform(-spec.film_deformation_ppm, 0.0, (n_photos, 2)) * 1e-6
    turn = rotation_z(np.radians(rng.uniform(-2.0, 2.0, n_photos)))[:, :2, :2]
    shift = 100.0 + rng.uniform(-5.0, 5.0, (n_photos, 2))

    def comparator(j: NDArray, xy_mm: NDArray) -> NDArray:
        return np.einsum("nij,nj->ni", turn[j], xy_mm * film[j]) + shift[j]

    measured = comparator(obs_photo, photo[obs_photo, obs_point])
    measured += rng.normal(0.0, spec.sigma_photo_mm, (n_obs, 2))
    marks = cam.fiducial_array_mm()
    jj = np.repeat(np.arange(n_photos), 4)
    fiducials = comparator(jj, np.tile(marks, (n_photos, 1))).reshape(n_photos, 4, 2)
    sf = spec.sigma_photo_mm if spec.sigma_fiducial_mm is None else spec.sigma_fiducial_mm
    fiducials += rng.normal(0.0, sf, fiducials.shape)
    return measured, fiducials


def _catalogue(
    spec: SynthSpec,
    rng: np.random.Generator,
    block0: Block,
    points: NDArray,
    c: NDArray,
    r: NDArray,
) -> tuple[CataloguePoint, ...]:
    """The catalogue: every measured point with its role and kind, in SK-42 with the σ of
    control."""
    role, kind = _roles(spec, c, r)
    ids = block0.point_ids
    in_catalogue = np.flatnonzero(np.isin(np.arange(len(ids)), block0.obs_point))
    noisy = points[in_catalogue] + rng.normal(0.0, spec.sigma_control_m, (in_catalogue.size, 3))
    sk42 = sk42_from_block_local(block0, noisy)
    return tuple(
        CataloguePoint(ids[i], str(role[i]), str(kind[i]), tuple(map(float, s)))  # type: ignore[arg-type]
        for i, s in zip(in_catalogue, sk42, strict=True)
    )


def _measured_centres(
    spec: SynthSpec,
    rng: np.random.Generator,
    block0: Block,
    stations: NDArray,
    rot: NDArray,
) -> tuple[Sigmas, tuple]:
    """The block's σ and, with ``spec.centre_sigma_m``, every photo's antenna position (the
    projection centre plus the lever arm turned by the photo) measured with that σ, in SK-42."""
    sigmas = Sigmas(spec.sigma_photo_mm, spec.sigma_control_m, spec.sigma_control_m)
    if spec.centre_sigma_m is None:
        return sigmas, ()
    sigmas = dataclasses.replace(
        sigmas, centre_plan_m=spec.centre_sigma_m, centre_height_m=spec.centre_sigma_m
    )
    antenna = stations[:, 3:] + rot @ np.asarray(spec.lever_arm_m)
    antenna += rng.normal(0.0, spec.centre_sigma_m, antenna.shape)
    geo = sk42_from_block_local(block0, antenna)
    photos = [p for strip in block0.strips for p in strip]
    return sigmas, tuple((p, tuple(map(float, g))) for p, g in zip(photos, geo, strict=True))
