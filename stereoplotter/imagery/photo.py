"""A synthetic aerial photograph of one side of a scenario: :func:`render_photo`.

Each photo pixel's centre (film coordinates x, y [mm], fiducial system) has its film deformation
removed (``scenario.synthetic.film_deformed`` inverted), its ray intersected with the terrain
(:mod:`stereoplotter.imagery.raytrace`) and the ground texture
(:mod:`stereoplotter.imagery.texture`) sampled at the ground point. The ray-terrain intersection
is solved exactly on a coarse grid of every :data:`COARSE_STEP`-th pixel and its Z interpolated
bilinearly between them; X, Y then follow exactly from the ray of Eq. (2.52) at that Z (the
interpolation error in Z is below 1 mm for the shipped terrains, whose curvature radius is
hundreds of metres). Outside the format the film is black (the camera's frame); the four
fiducial marks (``camera.fiducials_mm``, deformed with the film) are drawn as white crosses in
a black disc.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.ndimage import map_coordinates

from stereoplotter.errors import StereoplotterError
from stereoplotter.geometry.collinearity import photo_to_object
from stereoplotter.imagery.raytrace import ground_heights_m, terrain_bounds_m
from stereoplotter.imagery.texture import PREMARK_PHOTO_MM, GroundTexture
from stereoplotter.scenario.model import Scenario

__all__ = [
    "COARSE_STEP",
    "FRAME_MARGIN_MM",
    "PhotoGeometry",
    "PhotoRaster",
    "photo_geometry",
    "render_photo",
    "render_region",
]

COARSE_STEP = 16
"""Pixels between exact ray-terrain solutions (bilinear Z in between)."""
FRAME_MARGIN_MM = 3.0
"""Film shown outside the format on every side (the dark frame). [mm]"""
FIDUCIAL_RADIUS_MM = 1.2
FIDUCIAL_ARM_MM = 0.8
FIDUCIAL_LINE_MM = 0.06
_ROWS_PER_BLOCK = 256


@dataclass(frozen=True)
class PhotoRaster:
    """A rendered photo: grey ``image`` (uint8, rows × columns), ``pixel_mm`` [mm],
    ``origin_mm`` (x, y of the centre of pixel [0, 0]; x grows with columns, y decreases with
    rows) [mm], ``side``."""

    image: NDArray[np.uint8]
    pixel_mm: float
    origin_mm: tuple[float, float]
    side: str

    def to_pixel(self, x_mm: NDArray | float, y_mm: NDArray | float) -> tuple[NDArray, NDArray]:
        """Column and row (fractional; integer at pixel centres) of photo point x, y [mm]."""
        col = (np.asarray(x_mm, float) - self.origin_mm[0]) / self.pixel_mm
        row = (self.origin_mm[1] - np.asarray(y_mm, float)) / self.pixel_mm
        return col, row

    def to_photo(self, col: NDArray | float, row: NDArray | float) -> tuple[NDArray, NDArray]:
        """Photo x, y [mm] of (fractional) column and row."""
        x = self.origin_mm[0] + np.asarray(col, float) * self.pixel_mm
        y = self.origin_mm[1] - np.asarray(row, float) * self.pixel_mm
        return x, y


def _film_scale(scenario: Scenario, side: str) -> NDArray[np.float64]:
    return 1.0 + 1e-6 * np.asarray(scenario.photo(side).film_deformation_ppm, float)


@dataclass(frozen=True)
class PhotoGeometry:
    """What rendering any region of one photo needs: the raster grid, the ground texture, the
    height bracket of the ray-terrain solution. Build with :func:`photo_geometry`."""

    scenario: Scenario
    side: str
    pixel_mm: float
    size_px: int
    origin_mm: tuple[float, float]
    texture: GroundTexture
    z_bounds_m: tuple[float, float]

    def empty_raster(self) -> PhotoRaster:
        """A black raster of the full photo at this pixel size."""
        n = self.size_px
        return PhotoRaster(np.zeros((n, n), np.uint8), self.pixel_mm, self.origin_mm, self.side)


def photo_geometry(
    scenario: Scenario, side: str, pixel_mm: float, seed: int | None = None
) -> PhotoGeometry:
    """The :class:`PhotoGeometry` of photo ``side`` at ``pixel_mm`` [mm] and texture ``seed``."""
    if side not in [p.name for p in scenario.photos]:
        raise StereoplotterError(
            f"render_photo: side must be one of the scenario's photos, got {side!r}"
        )
    if not 0.002 <= pixel_mm <= 0.5:
        raise StereoplotterError(
            f"render_photo: pixel_mm must be in [0.002, 0.5] mm, got {pixel_mm}"
        )
    cam = scenario.camera
    half = cam.format_mm / 2.0 + FRAME_MARGIN_MM
    n = int(np.ceil(2 * half / pixel_mm))
    origin = (-(n - 1) * pixel_mm / 2.0, (n - 1) * pixel_mm / 2.0)
    height = float(np.mean([p.exterior.centre[2] for p in scenario.photos]))
    z_lo, z_hi = terrain_bounds_m(scenario, 0.0)
    reach = (height - z_lo) * (cam.format_mm / cam.focal_length_mm) + 2000.0
    bounds = terrain_bounds_m(scenario, reach)
    controls = np.array([p.local_m for p in scenario.points_with_role("control")]).reshape(-1, 3)
    premark = PREMARK_PHOTO_MM * (height - 0.5 * (z_lo + z_hi)) / cam.focal_length_mm
    centre = np.mean([p.exterior.centre for p in scenario.photos], axis=0)
    texture = GroundTexture.build(
        scenario.seed if seed is None else seed, centre, controls, premark
    )
    return PhotoGeometry(scenario, side, pixel_mm, n, origin, texture, bounds)


def render_photo(
    scenario: Scenario, side: str, *, pixel_mm: float = 0.02, seed: int | None = None
) -> PhotoRaster:
    """Render photo ``side`` ("left"/"right") of ``scenario`` at ``pixel_mm`` [mm].

    ``seed`` (default ``scenario.seed``) fixes the ground texture; the same seed gives the same
    image byte for byte (both photos of a pair share one texture: one ground). The cost grows
    with the pixel count (9 300² px at 0.02 mm; the times: benchmarks/bench_imagery.py), so
    :class:`~stereoplotter.imagery.cache.ViewCache` renders the fine levels lazily by tiles with
    :func:`render_region` instead.
    """
    geo = photo_geometry(scenario, side, pixel_mm, seed)
    raster = geo.empty_raster()
    n = geo.size_px
    for r0 in range(0, n, _ROWS_PER_BLOCK):
        r1 = min(n, r0 + _ROWS_PER_BLOCK)
        raster.image[r0:r1] = render_region(geo, r0, r1, 0, n)
    return raster


def render_region(geo: PhotoGeometry, r0: int, r1: int, c0: int, c1: int) -> NDArray[np.uint8]:
    """Rows r0:r1, columns c0:c1 of the photo (uint8); identical to the same part of
    :func:`render_photo` (the exact heights sit on the global grid of every COARSE_STEP-th
    pixel)."""
    scenario, side = geo.scenario, geo.side
    cam = scenario.camera
    ext = scenario.photo(side).exterior
    grid = PhotoRaster(np.zeros((0, 0), np.uint8), geo.pixel_mm, geo.origin_mm, side)
    g0r, g0c = (r0 // COARSE_STEP) * COARSE_STEP, (c0 // COARSE_STEP) * COARSE_STEP
    gr = np.arange(g0r, r1 + COARSE_STEP, COARSE_STEP)
    gc = np.arange(g0c, c1 + COARSE_STEP, COARSE_STEP)
    scale = _film_scale(scenario, side)
    Rg, Cg = np.meshgrid(gr, gc, indexing="ij")
    xg, yg = grid.to_photo(Cg, Rg)
    zc = ground_heights_m(
        scenario, side, np.stack([xg / scale[0], yg / scale[1]], axis=-1), geo.z_bounds_m
    )
    R, C = np.meshgrid(np.arange(r0, r1), np.arange(c0, c1), indexing="ij")
    x, y = grid.to_photo(C, R)
    inside = (np.abs(x) <= cam.format_mm / 2) & (np.abs(y) <= cam.format_mm / 2)
    Z = map_coordinates(
        zc, [(R - g0r) / COARSE_STEP, (C - g0c) / COARSE_STEP], order=1, mode="nearest"
    )
    ideal = np.stack([x / scale[0], y / scale[1]], axis=-1)
    P = photo_to_object(
        ideal, Z, ext.centre, ext.rotation, cam.focal_length_mm, cam.principal_point_mm
    )
    footprint = geo.pixel_mm * (ext.centre[2] - Z) / cam.focal_length_mm
    v = geo.texture.brightness(P[..., 0], P[..., 1], footprint)
    v = np.where(inside, v, 0.0)
    v = _draw_fiducials(v, x, y, cam.fiducial_array_mm() * scale, geo.pixel_mm)
    return np.round(255.0 * np.clip(v, 0.0, 1.0)).astype(np.uint8)


def _draw_fiducials(v: NDArray, x: NDArray, y: NDArray, marks: NDArray, pixel_mm: float) -> NDArray:
    for mx, my in marks:
        dx, dy = np.abs(x - mx), np.abs(y - my)
        r = np.hypot(dx, dy)
        if r.min() > FIDUCIAL_RADIUS_MM + pixel_mm:
            continue
        disc = np.clip((FIDUCIAL_RADIUS_MM - r) / pixel_mm + 0.5, 0, 1)
        hw = FIDUCIAL_LINE_MM / 2
        arm_x = np.clip((hw - dy) / pixel_mm + 0.5, 0, 1) * (dx <= FIDUCIAL_ARM_MM)
        arm_y = np.clip((hw - dx) / pixel_mm + 0.5, 0, 1) * (dy <= FIDUCIAL_ARM_MM)
        cross = np.maximum(arm_x, arm_y)
        v = (1 - disc) * v + disc * 0.02
        v = (1 - cross) * v + cross * 0.95
    return v
