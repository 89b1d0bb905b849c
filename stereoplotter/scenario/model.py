"""Frozen dataclasses that describe a scenario: the ground truth of a photo or a stereopair.

A scenario is loaded from ``scenarios/*.yaml`` by :func:`stereoplotter.scenario.load_scenario`;
the YAML schema is documented in ``docs/scenarios.md``. Units follow ``docs/conventions.md``:
photo quantities in mm, ground quantities in m, angles in radians (the YAML holds degrees).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from stereoplotter.geometry.rotation import rotation_matrix

__all__ = [
    "Camera",
    "ErrorSettings",
    "ExteriorOrientation",
    "Frame",
    "Hill",
    "MapSheet",
    "Photo",
    "Point",
    "Scenario",
    "Terrain",
]

FIDUCIAL_NAMES = ("1", "2", "3", "4")


@dataclass(frozen=True, slots=True)
class Camera:
    """Camera certificate.

    Attributes
    ----------
    focal_length_mm : float
        Calibrated f. [mm]
    principal_point_mm : tuple of float
        x₀, y₀ in the fiducial system. [mm]
    format_mm : float
        Side of the square photo format. [mm]
    fiducials_mm : dict
        Calibrated coordinates of marks "1".."4" (1 at −x, 2 at +x, 3 at +y, 4 at −y). [mm]
    fiducials_given_as : str
        ``"coordinates"`` or ``"distances"`` (then the marks are placed symmetrically on the axes).
    """

    focal_length_mm: float
    principal_point_mm: tuple[float, float]
    format_mm: float
    fiducials_mm: dict[str, tuple[float, float]]
    fiducials_given_as: str

    def fiducial_array_mm(self) -> NDArray[np.float64]:
        """Marks 1–4 as an array of shape (4, 2). [mm]"""
        return np.array([self.fiducials_mm[k] for k in FIDUCIAL_NAMES])


@dataclass(frozen=True, slots=True)
class ExteriorOrientation:
    """Exterior orientation of one photo.

    Attributes
    ----------
    projection_centre_m : tuple of float
        X_S, Y_S, Z_S. [m]
    alpha, omega, kappa : float
        Angles of Eq. (2.50). [rad]
    source : str
        How the setup computation obtains it: ``"given"`` (from aerotriangulation) or
        ``"resection"`` (derived from the measured control points). The values here are the truth.
    """

    projection_centre_m: tuple[float, float, float]
    alpha: float
    omega: float
    kappa: float
    source: str = "given"

    @property
    def rotation(self) -> NDArray[np.float64]:
        """M of Eq. (2.50). [—]"""
        return rotation_matrix(self.alpha, self.omega, self.kappa)

    @property
    def centre(self) -> NDArray[np.float64]:
        """X_S, Y_S, Z_S as an array. [m]"""
        return np.array(self.projection_centre_m)


@dataclass(frozen=True, slots=True)
class Photo:
    """One photo: its name ("left", "right" or free for a single photo), its exterior orientation
    and the uniform film deformation of its negative (x and y, parts per million; negative means
    shrinkage)."""

    name: str
    exterior: ExteriorOrientation
    film_deformation_ppm: tuple[float, float] = (0.0, 0.0)


@dataclass(frozen=True, slots=True)
class Hill:
    """A Gaussian hill (or hollow, with negative height) of the synthetic terrain. [m]"""

    X_m: float
    Y_m: float
    height_m: float
    radius_m: float


@dataclass(frozen=True, slots=True)
class Terrain:
    """Analytic terrain Z(X, Y) = base + slope·(X, Y) + Σ hills, in the photogrammetric system.

    Attributes
    ----------
    base_height_m : float
        Height at the origin. [m]
    slope : tuple of float
        dZ/dX, dZ/dY. [—]
    hills : tuple of Hill
    """

    base_height_m: float = 0.0
    slope: tuple[float, float] = (0.0, 0.0)
    hills: tuple[Hill, ...] = ()

    def height_m(self, X_m: NDArray | float, Y_m: NDArray | float) -> NDArray[np.float64]:
        """Terrain height Z at X, Y (broadcasting). [m]"""
        X = np.asarray(X_m, float)
        Y = np.asarray(Y_m, float)
        Z = self.base_height_m + self.slope[0] * X + self.slope[1] * Y
        for h in self.hills:
            r2 = ((X - h.X_m) ** 2 + (Y - h.Y_m) ** 2) / h.radius_m**2
            Z = Z + h.height_m * np.exp(-0.5 * r2)
        return np.asarray(Z, float)


@dataclass(frozen=True, slots=True)
class Point:
    """A control or check point.

    Attributes
    ----------
    id : str
    role : str
        ``"control"`` (used for orientation) or ``"check"`` (independent, only for evaluation).
    kind : str
        ``"full"`` (plan and height), ``"plan"`` or ``"height"``: which coordinates the point
        contributes as control.
    local_m : tuple of float
        X, Y, Z in the photogrammetric system (the truth). [m]
    sk42_m : tuple of float or None
        Gauss–Krüger x (north), conventional ordinate ȳ (zone in the easting) and height, where
        the scenario has a geodetic tie. [m]
    """

    id: str
    role: str
    kind: str
    local_m: tuple[float, float, float]
    sk42_m: tuple[float, float, float] | None = None


@dataclass(frozen=True, slots=True)
class Frame:
    """The photogrammetric system of the scenario.

    Attributes
    ----------
    kind : str
        ``"local"`` (no geodetic tie) or ``"sk42"`` (the local system of §10 at an SK-42 origin:
        Z along the ellipsoid normal, plane OYZ parallel to the axial meridian, X ≈ east).
    origin_sk42_m : tuple of float or None
        Origin: Gauss–Krüger x (north), conventional ordinate ȳ, height. [m]
    """

    kind: str = "local"
    origin_sk42_m: tuple[float, float, float] | None = None


@dataclass(frozen=True, slots=True)
class MapSheet:
    """The map sheet to compile.

    Attributes
    ----------
    scale_denominator : int
        Map scale 1:M. [—]
    corners_sk42_m : ndarray, shape (4, 2)
        Frame corners 1–4 as Gauss–Krüger x (north), conventional ordinate ȳ; in the order
        north-west, north-east, south-east, south-west. [m]
    nomenclature : str or None
        SK-42 sheet nomenclature, where the corners came from it.
    """

    scale_denominator: int
    corners_sk42_m: NDArray[np.float64]
    nomenclature: str | None = None


@dataclass(frozen=True, slots=True)
class ErrorSettings:
    """Default measurement errors of the synthetic data (σ of zero-mean normal errors).

    Attributes
    ----------
    photo_point_sigma_um : float
        Measurement of a photo point (control, check, grid). [µm]
    fiducial_sigma_um : float
        Measurement of a fiducial mark. [µm]
    """

    photo_point_sigma_um: float = 3.0
    fiducial_sigma_um: float = 2.0


@dataclass(frozen=True, slots=True)
class Scenario:
    """The ground truth of a single photo or a stereopair, and what the user asks of it."""

    name: str
    description: str
    source: str
    camera: Camera
    photos: tuple[Photo, ...]
    terrain: Terrain
    points: tuple[Point, ...]
    frame: Frame = field(default_factory=Frame)
    map_sheet: MapSheet | None = None
    errors: ErrorSettings = field(default_factory=ErrorSettings)
    seed: int = 0

    @property
    def is_stereopair(self) -> bool:
        """True when the scenario holds the photos "left" and "right"."""
        return [p.name for p in self.photos] == ["left", "right"]

    def photo(self, name: str) -> Photo:
        """The photo called ``name``."""
        for p in self.photos:
            if p.name == name:
                return p
        raise KeyError(
            f"scenario {self.name!r} has no photo {name!r}; it has "
            + ", ".join(p.name for p in self.photos)
        )

    def points_with_role(self, role: str) -> tuple[Point, ...]:
        """The control (``"control"``) or check (``"check"``) points."""
        return tuple(p for p in self.points if p.role == role)
