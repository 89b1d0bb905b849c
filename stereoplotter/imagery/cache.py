"""Tile pyramid and view cache: eyepiece views of both photos sampled from rendered tiles.

Level k of the pyramid is the photo rendered at pixel ``pixel_mm``·2ᵏ (k = 0 … until the pixel
exceeds :data:`EAGER_PIXEL_MM`·2). Each level is rendered directly at its pixel size (the
texture fades detail finer than the pixel), not averaged down, so every level is exact
collinearity. Levels with a pixel of :data:`EAGER_PIXEL_MM` or more are rendered whole when
the cache is built (the "rasters once"); finer levels are rendered lazily in
:data:`TILE`² tiles the first time a view needs them and kept (a 0.02 mm photo is 9 300² px;
a view at ×6 needs at most 4 tiles of it). A view samples the level
whose pixel is the largest not exceeding the view's pixel (0.1 mm / magnification), bilinearly.
Finished views are kept in a small LRU cache. Tile, level and view are pure functions of
(scenario, seed, pixel_mm), so the order in which views are requested never changes a byte.
"""

from __future__ import annotations

import threading
from collections import OrderedDict

import numpy as np
from numpy.typing import NDArray
from scipy.ndimage import map_coordinates

from stereoplotter.errors import StereoplotterError
from stereoplotter.imagery.eyepiece import SCREEN_PIXEL_MM, check_view, view_to_photo
from stereoplotter.imagery.photo import PhotoGeometry, PhotoRaster, photo_geometry, render_region
from stereoplotter.scenario.model import Scenario

__all__ = ["EAGER_PIXEL_MM", "TILE", "ViewCache"]

TILE = 128
EAGER_PIXEL_MM = 0.16
_VIEWS_KEPT = 64


class ViewCache:
    """Both photos of ``scenario`` as a tile pyramid; :meth:`view` serves eyepiece views."""

    def __init__(
        self,
        scenario: Scenario,
        seed: int | None = None,
        *,
        pixel_mm: float = 0.02,
        sides: tuple[str, ...] | None = None,
    ):
        self.scenario = scenario
        self.seed = scenario.seed if seed is None else seed
        self.sides = tuple(p.name for p in scenario.photos) if sides is None else tuple(sides)
        self.levels: dict[str, list[PhotoGeometry]] = {}
        self._tiles: dict[tuple[str, int, int, int], NDArray[np.uint8]] = {}
        self._whole: dict[tuple[str, int], PhotoRaster] = {}
        self._views: OrderedDict[tuple, NDArray[np.uint8]] = OrderedDict()
        self._lock = threading.Lock()  # the views' LRU order; tiles are only ever added
        for side in self.sides:
            levels, p = [], pixel_mm
            while True:
                levels.append(photo_geometry(scenario, side, p, self.seed))
                if p >= 2 * EAGER_PIXEL_MM:
                    break
                p *= 2.0
            self.levels[side] = levels
            for k, geo in enumerate(levels):
                if geo.pixel_mm >= EAGER_PIXEL_MM:
                    raster = geo.empty_raster()
                    raster.image[:] = render_region(geo, 0, geo.size_px, 0, geo.size_px)
                    self._whole[(side, k)] = raster

    def __getstate__(self) -> dict:
        state = self.__dict__.copy()
        del state["_lock"]
        return state

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self._lock = threading.Lock()

    def forget_views(self) -> None:
        """Forget the kept eyepiece views (the tiles stay): the next :meth:`view` of each spot
        is sampled from the tiles again."""
        with self._lock:
            self._views.clear()

    def prefetch(self, side: str, x_mm: float, y_mm: float, radius_mm: float = 3.0) -> int:
        """Render the finest level's tiles within ``radius_mm`` of photo point x, y [mm] ahead of
        use (a view whose tiles are rendered only samples them; the times of both:
        benchmarks/bench_imagery.py). Returns the number of tiles rendered now."""
        geo = self.levels[side][0]
        grid = PhotoRaster(np.zeros((0, 0), np.uint8), geo.pixel_mm, geo.origin_mm, side)
        col, row = grid.to_pixel(
            np.array([x_mm - radius_mm, x_mm + radius_mm]),
            np.array([y_mm + radius_mm, y_mm - radius_mm]),
        )
        before = len(self._tiles)
        self._patch(side, 0, int(row[0]), int(row[1]) + 1, int(col[0]), int(col[1]) + 1)
        return len(self._tiles) - before

    def raster(self, side: str) -> PhotoRaster:
        """The finest whole-rendered raster of ``side`` (the overview photo)."""
        k = min(k for s, k in self._whole if s == side)
        return self._whole[(side, k)]

    def level_for(self, side: str, magnification: float) -> int:
        """Pyramid level sampled at ``magnification``: the largest pixel ≤ the view pixel."""
        s = SCREEN_PIXEL_MM / magnification
        ks = [k for k, g in enumerate(self.levels[side]) if g.pixel_mm <= s * (1 + 1e-9)]
        return max(ks) if ks else 0

    def _tile(self, side: str, k: int, ti: int, tj: int) -> NDArray[np.uint8]:
        key = (side, k, ti, tj)
        if key not in self._tiles:
            geo = self.levels[side][k]
            n = geo.size_px
            r0, c0 = ti * TILE, tj * TILE
            self._tiles[key] = render_region(geo, r0, min(n, r0 + TILE), c0, min(n, c0 + TILE))
        return self._tiles[key]

    def _patch(self, side: str, k: int, r0: int, r1: int, c0: int, c1: int) -> NDArray[np.uint8]:
        """Rows r0:r1, columns c0:c1 of level k (clipped to the photo; black beyond)."""
        out = np.zeros((r1 - r0, c1 - c0), np.uint8)
        if (side, k) in self._whole:
            img = self._whole[(side, k)].image
            n = img.shape[0]
            a, b, c, d = max(r0, 0), min(r1, n), max(c0, 0), min(c1, n)
            if a < b and c < d:
                out[a - r0 : b - r0, c - c0 : d - c0] = img[a:b, c:d]
            return out
        n = self.levels[side][k].size_px
        nt = -(-n // TILE)
        for ti in range(max(r0, 0) // TILE, min(r1 - 1, n - 1) // TILE + 1):
            for tj in range(max(c0, 0) // TILE, min(c1 - 1, n - 1) // TILE + 1):
                if ti >= nt or tj >= nt:
                    continue
                t = self._tile(side, k, ti, tj)
                a, c = ti * TILE, tj * TILE
                rr0, rr1 = max(r0, a), min(r1, a + t.shape[0])
                cc0, cc1 = max(c0, c), min(c1, c + t.shape[1])
                if rr0 < rr1 and cc0 < cc1:
                    out[rr0 - r0 : rr1 - r0, cc0 - c0 : cc1 - c0] = t[
                        rr0 - a : rr1 - a, cc0 - c : cc1 - c
                    ]
        return out

    def view(
        self,
        side: str,
        x_mm: float,
        y_mm: float,
        kappa_rad: float,
        magnification: float = 6.0,
        size_px: int = 256,
    ) -> NDArray[np.uint8]:
        """Eyepiece view as :func:`~stereoplotter.imagery.eyepiece.eyepiece_view` of the level
        for ``magnification`` (uint8, size_px × size_px)."""
        key = (side, float(x_mm), float(y_mm), float(kappa_rad), float(magnification), int(size_px))
        with self._lock:
            if key in self._views:
                self._views.move_to_end(key)
                return self._views[key]
        check_view(magnification, size_px)
        if side not in self.levels:
            raise StereoplotterError(
                f"ViewCache.view: side must be one of {self.sides}, got {side!r}"
            )
        k = self.level_for(side, magnification)
        geo = self.levels[side][k]
        grid = PhotoRaster(np.zeros((0, 0), np.uint8), geo.pixel_mm, geo.origin_mm, side)
        v, u = np.mgrid[0:size_px, 0:size_px]
        x, y = view_to_photo(u, v, x_mm, y_mm, kappa_rad, magnification, size_px)
        col, row = grid.to_pixel(x, y)
        r0, c0 = int(np.floor(row.min())) - 1, int(np.floor(col.min())) - 1
        r1, c1 = int(np.ceil(row.max())) + 2, int(np.ceil(col.max())) + 2
        patch = self._patch(side, k, r0, r1, c0, c1)
        out = map_coordinates(
            patch,
            [(row - r0).ravel(), (col - c0).ravel()],
            order=1,
            mode="constant",
            cval=0.0,
            output=np.float32,
        )
        view = np.round(np.clip(out, 0, 255)).astype(np.uint8).reshape(size_px, size_px)
        with self._lock:
            self._views[key] = view
            if len(self._views) > _VIEWS_KEPT:
                self._views.popitem(last=False)
        return view
