r"""A block of aerial photos as a triangulation office has it, and its interior orientation.

The block holds the camera certificate, the photo numbers strip by strip, the comparator
measurements (four fiducial marks and the tie, pass and control points of every photo), the
control catalogue in SK-42 and the a priori standard deviations. Identifiers (photo numbers,
point ids) are text: ``"0415"`` and ``"415"`` are two photos.

Units: comparator and photo coordinates [mm]; object coordinates [m]; angles [rad]. The adjustment
works in the local photogrammetric system of §10 at the block's SK-42 origin
(:mod:`stereoplotter.geodesy.photogrammetric`): Cartesian, Z up, X ≈ east, so the collinearity
equations (2.52)/(2.53) hold in it exactly, whatever the size of the block.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from stereoplotter.errors import GeometryError
from stereoplotter.geodesy import conventional_ordinate, split_conventional_ordinate
from stereoplotter.geodesy.photogrammetric import (
    LocalFrame,
    gauss_kruger_from_local,
    local_from_gauss_kruger,
)
from stereoplotter.geometry.fiducial import to_fiducial_system
from stereoplotter.geometry.film import fiducial_spans_mm
from stereoplotter.scenario.model import Camera

__all__ = [
    "Block",
    "CataloguePoint",
    "Sigmas",
    "block_frame",
    "catalogue_local",
    "centres_local",
    "interior_orientation",
    "photo_coordinates",
    "sk42_from_block_local",
]

#: Roles and kinds of a catalogue point (as in a production job's control CSV).
ROLES = ("control", "check")
KINDS = ("full", "plan", "height")


@dataclass(frozen=True, slots=True)
class Sigmas:
    """A priori standard deviations of the measurements.

    Attributes
    ----------
    photo_mm : float
        One comparator coordinate of a point, after interior orientation. [mm]
    control_plan_m, control_height_m : float
        Catalogue X, Y and Z of a control point. [m]
    centre_plan_m, centre_height_m : float
        A measured projection centre (GNSS antenna) in plan and height. [m] (default 0.1 and
        0.15: kinematic carrier-phase GNSS of an aerial survey, height the weaker)
    """

    photo_mm: float = 0.005
    control_plan_m: float = 0.05
    control_height_m: float = 0.05
    centre_plan_m: float = 0.1
    centre_height_m: float = 0.15


@dataclass(frozen=True, slots=True)
class CataloguePoint:
    """A point of the control catalogue: id, role (control, check), kind (full, plan, height)
    and SK-42 coordinates (x north, conventional ordinate ȳ, H) [m]."""

    id: str
    role: str
    kind: str
    sk42_m: tuple[float, float, float]


@dataclass(frozen=True, slots=True)
class Block:
    """A block of photos with its measurements.

    Attributes
    ----------
    name : str
    camera : Camera
        The certificate: f, principal point, format and the calibrated fiducial marks. [mm]
    strips : tuple of tuple of str
        Photo numbers strip by strip, in flight order.
    fiducials_mm : ndarray, shape (n_photos, 4, 2)
        Comparator coordinates of marks 1–4 on each photo (photo order of :attr:`photos`). [mm]
    obs_photo, obs_point : ndarray of int, shape (n_obs,)
        Index of the photo (into :attr:`photos`) and of the point (into :attr:`point_ids`) of
        each point measurement.
    comparator_mm : ndarray, shape (n_obs, 2)
        Comparator x, y of each point measurement. [mm]
    point_ids : tuple of str
        Every measured point (tie, pass, control, check).
    catalogue : tuple of CataloguePoint
        Control and check points with their SK-42 coordinates.
    origin_sk42_m : tuple of float
        Origin of the local system of §10 (x north, ȳ, H). [m]
    sigmas : Sigmas
    centres : tuple of (str, (float, float, float))
        Measured projection centres (GNSS antenna positions): photo number and SK-42 (x north,
        ȳ, H) [m]; empty when the block has none.
    lever_arm_m : tuple of float
        The antenna's offset from the projection centre in the camera system (x, y along the
        photo's axes, z along the optical axis towards the sky): antenna = S + M·e (M of
        Eq. (2.50)). [m]
    """

    name: str
    camera: Camera
    strips: tuple[tuple[str, ...], ...]
    fiducials_mm: NDArray[np.float64]
    obs_photo: NDArray[np.int64]
    obs_point: NDArray[np.int64]
    comparator_mm: NDArray[np.float64]
    point_ids: tuple[str, ...]
    catalogue: tuple[CataloguePoint, ...]
    origin_sk42_m: tuple[float, float, float]
    sigmas: Sigmas = field(default_factory=Sigmas)
    centres: tuple[tuple[str, tuple[float, float, float]], ...] = ()
    lever_arm_m: tuple[float, float, float] = (0.0, 0.0, 0.0)

    @property
    def photos(self) -> tuple[str, ...]:
        """Every photo number, strip after strip."""
        return tuple(p for strip in self.strips for p in strip)

    @property
    def strip_of_photo(self) -> NDArray[np.int64]:
        """Index of the strip of each photo. [—]"""
        return np.array([i for i, s in enumerate(self.strips) for _ in s], dtype=np.int64)


def interior_orientation(block: Block) -> NDArray[np.float64]:
    r"""Photo coordinates x, y [mm] of every point measurement, relative to the principal point.

    Each photo: the fiducial system of its measured marks 1–4 (origin at the intersection of the
    lines 1–2 and 3–4, x along 1→2; :func:`~stereoplotter.geometry.fiducial.to_fiducial_system`),
    then the uniform film deformation of ``docs/conventions.md`` §7 removed per axis by the ratio
    of the certificate's span to the measured one, l₁₂/d₁₂ on x and l₃₄/d₃₄ on y
    (:func:`~stereoplotter.geometry.film.fiducial_spans_mm`), minus the principal point (x₀, y₀).

    Raises
    ------
    GeometryError
        Degenerate fiducial marks on a photo (names the photo).
    """
    out = np.empty_like(block.comparator_mm)
    order = np.argsort(block.obs_photo, kind="stable")
    bounds = np.searchsorted(block.obs_photo[order], np.arange(len(block.photos) + 1))
    for j, photo in enumerate(block.photos):
        rows = order[bounds[j] : bounds[j + 1]]
        try:
            out[rows] = photo_coordinates(
                block.camera, block.comparator_mm[rows], block.fiducials_mm[j]
            )
        except GeometryError as exc:
            raise GeometryError(f"photo {photo}: {exc}") from None
    return out


def photo_coordinates(cam: Camera, comparator_mm: NDArray, marks_mm: NDArray) -> NDArray:
    """The interior orientation of :func:`interior_orientation` for one photo: comparator
    points (n, 2) and its four measured marks (4, 2) → x, y relative to the principal point."""
    calibrated = fiducial_spans_mm(cam.fiducials_mm)
    measured = fiducial_spans_mm({str(k + 1): marks_mm[k] for k in range(4)})
    xy = to_fiducial_system(comparator_mm, marks_mm) * (calibrated / measured)
    return xy - np.asarray(cam.principal_point_mm, float)


def block_frame(block: Block) -> LocalFrame:
    """The local system of §10 at the block's origin (:class:`LocalFrame`)."""
    north, east, height = block.origin_sk42_m
    zone, y = split_conventional_ordinate(east)
    return LocalFrame.from_gauss_kruger(north, float(y), height, zone=int(zone))


def catalogue_local(block: Block) -> NDArray[np.float64]:
    """Local X, Y, Z [m] of the catalogue points (order of :attr:`Block.catalogue`), shape (n, 3).

    Raises
    ------
    GeometryError
        A point in another Gauss–Krüger zone than the origin (names the point).
    """
    lf = block_frame(block)
    sk42 = np.array([p.sk42_m for p in block.catalogue], float).reshape(-1, 3)
    zone, y = split_conventional_ordinate(sk42[:, 1])
    far = np.flatnonzero(np.asarray(zone) != lf.zone)
    if far.size:
        raise GeometryError(
            f"catalogue point {block.catalogue[far[0]].id} is in zone {int(zone[far[0]])}, the "
            f"block's origin in zone {lf.zone}: give the catalogue in one zone"
        )
    X, Y, Z = local_from_gauss_kruger(lf, sk42[:, 0], np.asarray(y, float), sk42[:, 2])
    return np.stack([X, Y, Z], axis=-1)


def centres_local(block: Block) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Photo indices (n,) and local X, Y, Z [m] (n, 3) of the measured projection centres."""
    index = {p: j for j, p in enumerate(block.photos)}
    if not block.centres:
        return np.zeros(0, np.int64), np.zeros((0, 3))
    lf = block_frame(block)
    sk42 = np.array([c for _, c in block.centres], float).reshape(-1, 3)
    _, y = split_conventional_ordinate(sk42[:, 1])
    X, Y, Z = local_from_gauss_kruger(lf, sk42[:, 0], np.asarray(y, float), sk42[:, 2])
    photos = np.array([index[p] for p, _ in block.centres], np.int64)
    return photos, np.stack([X, Y, Z], axis=-1)


def sk42_from_block_local(block: Block, xyz_m: NDArray[np.float64]) -> NDArray[np.float64]:
    """(x north, ȳ conventional, H) [m] of local points, shape (..., 3) (inverse of
    :func:`catalogue_local`)."""
    lf = block_frame(block)
    xyz = np.asarray(xyz_m, float)
    north, y, height = gauss_kruger_from_local(lf, xyz[..., 0], xyz[..., 1], xyz[..., 2])
    east = conventional_ordinate(lf.zone, y)
    return np.stack([north, east, height], axis=-1)
