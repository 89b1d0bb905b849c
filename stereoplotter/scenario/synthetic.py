"""Synthetic measurements: what a perfect camera and a measuring operator would record.

From a :class:`~stereoplotter.scenario.Scenario`, the image coordinates of the fiducial marks and
of the control, check and grid points on each photo, by rigorous collinearity (Eq. (2.53)), with
the film deformation of each negative and seeded measurement noise. These are the ground truth
every later stage (setup data, instrument, operator, accuracy) is judged against.

Film deformation is uniform per axis: a film coordinate is (1 + s_x·10⁻⁶)·x, (1 + s_y·10⁻⁶)·y in the
fiducial system, for marks and points alike (``docs/conventions.md`` §7).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.constants import UM_PER_MM
from stereoplotter.geometry.collinearity import object_to_photo, photo_to_object
from stereoplotter.geometry.film import corrected_focal_length, fiducial_spans_mm
from stereoplotter.scenario.model import FIDUCIAL_NAMES, Photo, Scenario

__all__ = [
    "Measurements",
    "PhotoMeasurements",
    "film_deformed",
    "footprint_m",
    "points_in_format",
    "synthesize_measurements",
    "working_area_grid_m",
]


@dataclass(frozen=True, slots=True)
class PhotoMeasurements:
    """Measurements on one photo.

    Attributes
    ----------
    photo : str
        Photo name.
    fiducials_true_mm : ndarray, shape (4, 2)
        Marks 1–4 on the (deformed) film, before measurement noise. [mm]
    fiducials_mm : ndarray, shape (4, 2)
        Measured marks 1–4. [mm]
    points_true_mm, points_mm : ndarray, shape (n, 2)
        Control and check points, in the order of ``Scenario.points``; NaN where not imaged. [mm]
    points_imaged : ndarray of bool, shape (n,)
        Whether each point falls inside the photo format.
    grid_true_mm, grid_mm : ndarray, shape (g, 2)
        Grid points of the working area. [mm]
    """

    photo: str
    fiducials_true_mm: NDArray[np.float64]
    fiducials_mm: NDArray[np.float64]
    points_true_mm: NDArray[np.float64]
    points_mm: NDArray[np.float64]
    points_imaged: NDArray[np.bool_]
    grid_true_mm: NDArray[np.float64]
    grid_mm: NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class Measurements:
    """Synthetic measurements of a scenario.

    Attributes
    ----------
    photos : tuple of PhotoMeasurements
    point_ids : tuple of str
    grid_m : ndarray, shape (g, 3)
        Ground grid of the working area (X, Y on a regular grid, Z on the terrain). [m]
    focal_length_corrected_mm : float
        f′ of the pair from the measured fiducial spans (one f′ per pair). [mm]
    focal_length_corrected_per_photo_mm : tuple of float
        f′ of each photo; their spread is a residual the instrument cannot remove. [mm]
    """

    photos: tuple[PhotoMeasurements, ...]
    point_ids: tuple[str, ...]
    grid_m: NDArray[np.float64]
    focal_length_corrected_mm: float
    focal_length_corrected_per_photo_mm: tuple[float, ...]

    def photo(self, name: str) -> PhotoMeasurements:
        """The measurements of photo ``name``."""
        for p in self.photos:
            if p.photo == name:
                return p
        raise KeyError(name)


def footprint_m(scenario: Scenario, photo: Photo, Z_m: float) -> NDArray[np.float64]:
    """Ground footprint of the photo format on the plane Z. Corners (+,+), (−,+), (−,−), (+,−).

    Returns
    -------
    ndarray, shape (4, 3)
        [m]
    """
    h = scenario.camera.format_mm / 2.0
    corners = np.array([[h, h], [-h, h], [-h, -h], [h, -h]])
    ext = photo.exterior
    return photo_to_object(
        corners,
        Z_m,
        ext.centre,
        ext.rotation,
        scenario.camera.focal_length_mm,
        scenario.camera.principal_point_mm,
    )


def working_area_grid_m(
    scenario: Scenario, shape: tuple[int, int] = (7, 7), margin: float = 0.05
) -> NDArray[np.float64]:
    """Regular ground grid over the working area: the overlap of the photos' footprints (or the
    single photo's footprint), at the mean terrain height, shrunk by ``margin`` of its size on each
    side; heights from the terrain. Points not imaged on every photo are dropped.

    Returns
    -------
    ndarray, shape (g, 3)
        X, Y, Z of the grid points, row-major from low Y, low X. [m]
    """
    z0 = float(np.mean([p.local_m[2] for p in scenario.points])) if scenario.points else 0.0
    boxes = [footprint_m(scenario, p, z0) for p in scenario.photos]
    lo = np.max([b[:, :2].min(axis=0) for b in boxes], axis=0)
    hi = np.min([b[:, :2].max(axis=0) for b in boxes], axis=0)
    pad = margin * (hi - lo)
    X, Y = np.meshgrid(
        np.linspace(lo[0] + pad[0], hi[0] - pad[0], shape[1]),
        np.linspace(lo[1] + pad[1], hi[1] - pad[1], shape[0]),
    )
    grid = np.column_stack([X.ravel(), Y.ravel(), scenario.terrain.height_m(X, Y).ravel()])
    keep = np.ones(len(grid), bool)
    for photo in scenario.photos:
        keep &= points_in_format(scenario, photo, grid)
    return grid[keep]


def _project(scenario: Scenario, photo: Photo, points_m: NDArray) -> NDArray[np.float64]:
    ext = photo.exterior
    return object_to_photo(
        points_m,
        ext.centre,
        ext.rotation,
        scenario.camera.focal_length_mm,
        scenario.camera.principal_point_mm,
    )


def points_in_format(scenario: Scenario, photo: Photo, points_m: NDArray) -> NDArray[np.bool_]:
    """Which ground points [m] the photo images inside its format (|x|, |y| ≤ format/2)."""
    xy = _project(scenario, photo, points_m)
    with np.errstate(invalid="ignore"):
        return np.all(np.abs(xy) <= scenario.camera.format_mm / 2.0, axis=-1)


def film_deformed(photo: Photo, xy: ArrayLike) -> NDArray[np.float64]:
    """Fiducial-system coordinates on the deformed film: (1 + s_x·10⁻⁶)·x, (1 + s_y·10⁻⁶)·y.

    The uniform film deformation of ``photo`` (``docs/conventions.md`` §7), for marks and points.
    [mm]
    """
    return np.asarray(xy, float) * (1.0 + 1e-6 * np.asarray(photo.film_deformation_ppm, float))


def synthesize_measurements(
    scenario: Scenario,
    rng: np.random.Generator,
    *,
    noise: bool = True,
    grid_shape: tuple[int, int] = (7, 7),
) -> Measurements:
    """Image coordinates of fiducials, control, check and grid points on every photo.

    Parameters
    ----------
    scenario : Scenario
    rng : numpy.random.Generator
        Source of the measurement noise; the same seed gives the same measurements.
    noise : bool
        Add zero-mean normal noise with the σ of ``scenario.errors``.
    grid_shape : tuple of int
        Rows and columns of the working-area grid.

    Returns
    -------
    Measurements

    Notes
    -----
    Points by Eq. (2.53) (:func:`~stereoplotter.geometry.collinearity.object_to_photo`); the film
    deformation scales fiducial-system coordinates; f′ from the measured spans (``film.py``).
    Noise is drawn in a fixed order (per photo: fiducials, points, grid) so that a run is
    reproducible from its seed.
    """
    cam = scenario.camera
    pts = np.array([p.local_m for p in scenario.points], float).reshape(-1, 3)
    grid = working_area_grid_m(scenario, grid_shape)
    fid_cal = cam.fiducial_array_mm()
    sig_f = scenario.errors.fiducial_sigma_um / UM_PER_MM if noise else 0.0
    sig_p = scenario.errors.photo_point_sigma_um / UM_PER_MM if noise else 0.0
    photos = []
    ratios = []
    for photo in scenario.photos:
        fid_true = film_deformed(photo, fid_cal)
        fid = fid_true + rng.normal(0.0, 1.0, fid_true.shape) * sig_f
        xy = _project(scenario, photo, pts)
        imaged = np.all(np.abs(xy) <= cam.format_mm / 2.0, axis=-1)
        xy = np.where(imaged[:, None], film_deformed(photo, xy), np.nan)
        xy_meas = xy + rng.normal(0.0, 1.0, xy.shape) * sig_p
        g = film_deformed(photo, _project(scenario, photo, grid))
        g_meas = g + rng.normal(0.0, 1.0, g.shape) * sig_p
        photos.append(PhotoMeasurements(photo.name, fid_true, fid, xy, xy_meas, imaged, g, g_meas))
        spans = fiducial_spans_mm(dict(zip(FIDUCIAL_NAMES, fid, strict=True)))
        ratios.append(spans / fiducial_spans_mm(cam.fiducials_mm))
    f = cam.focal_length_mm
    per_photo = tuple(float(f * np.mean(r)) for r in ratios)
    # One f′ per pair: the mean ratio over all spans of all photos (docs/conventions.md §7).
    pair = float(corrected_focal_length(f, np.concatenate(ratios), np.ones(2 * len(ratios))))
    return Measurements(tuple(photos), tuple(p.id for p in scenario.points), grid, pair, per_photo)
