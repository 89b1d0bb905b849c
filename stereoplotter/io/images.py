"""PNG encoding of rendered photos and eyepiece views (Pillow), and their atomic writing."""

from __future__ import annotations

import io
import os
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from PIL import Image

from stereoplotter.geometry.collinearity import object_to_photo
from stereoplotter.imagery.cache import ViewCache
from stereoplotter.imagery.eyepiece import anaglyph
from stereoplotter.imagery.photo import render_photo
from stereoplotter.io.atomic_write import atomic_write_bytes
from stereoplotter.scenario.model import Scenario
from stereoplotter.scenario.synthetic import film_deformed

__all__ = ["png_bytes", "write_png", "write_render"]


def png_bytes(array: NDArray[np.uint8]) -> bytes:
    """PNG of a 2-D grey or H × W × 3 RGB uint8 array (no metadata, so equal arrays give equal
    bytes)."""
    a = np.asarray(array)
    if a.dtype != np.uint8 or a.ndim not in (2, 3) or (a.ndim == 3 and a.shape[2] != 3):
        raise ValueError(f"png_bytes: need a 2-D or H×W×3 uint8 array, got {a.dtype} {a.shape}")
    buf = io.BytesIO()
    Image.fromarray(a, mode="L" if a.ndim == 2 else "RGB").save(buf, format="PNG", optimize=False)
    return buf.getvalue()


def write_png(path: str | os.PathLike[str], array: NDArray[np.uint8]) -> None:
    """Write ``array`` as a PNG file atomically (``atomic_write_bytes``)."""
    atomic_write_bytes(path, png_bytes(array))


def write_render(
    scenario: Scenario,
    out_dir: str | os.PathLike[str],
    *,
    sides: tuple[str, ...] = ("left", "right"),
    at_m: tuple[float, float] | None = None,
    magnification: float = 6.0,
    pixel_mm: float = 0.08,
    seed: int | None = None,
    size_px: int = 256,
) -> list[Path]:
    """Render the photos of ``sides`` at ``pixel_mm`` and the eyepiece views (κ = 0) at the
    ground point ``at_m`` (X, Y [m]; Z from the terrain; default: below the midpoint of the
    projection centres), and write them as PNG into ``out_dir`` atomically: ``photo_<side>.png``,
    ``view_<side>.png`` and, for both sides, ``anaglyph.png``. Returns the paths written."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if at_m is None:
        c = np.mean([p.exterior.centre for p in scenario.photos], axis=0)
        at_m = (float(c[0]), float(c[1]))
    ground = np.array([*at_m, float(scenario.terrain.height_m(*at_m))])
    cache = ViewCache(scenario, seed, sides=sides)
    written, views = [], {}
    for side in sides:
        raster = render_photo(scenario, side, pixel_mm=pixel_mm, seed=seed)
        ext = scenario.photo(side).exterior
        xy = film_deformed(
            scenario.photo(side),
            object_to_photo(
                ground,
                ext.centre,
                ext.rotation,
                scenario.camera.focal_length_mm,
                scenario.camera.principal_point_mm,
            ),
        )
        views[side] = cache.view(side, float(xy[0]), float(xy[1]), 0.0, magnification, size_px)
        for name, image in ((f"photo_{side}.png", raster.image), (f"view_{side}.png", views[side])):
            write_png(out / name, image)
            written.append(out / name)
    if {"left", "right"} <= set(views):
        write_png(out / "anaglyph.png", anaglyph(views["left"], views["right"]))
        written.append(out / "anaglyph.png")
    return written
