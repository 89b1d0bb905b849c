"""Eyepiece views: the window of a photo at the measuring mark, as the operator sees it.

Scale (assumed): one view pixel shows :data:`SCREEN_PIXEL_MM` / magnification of photo, i.e. a
screen pixel stands for 0.1 mm seen at the eyepiece's magnification (a 256-px view at ×6 covers
4.3 mm of photo, about the field of a stereoplotter eyepiece at ×6). Orientation: view column u
grows to the right, row v downwards; the photo vector of view offset (u, v) is
s·R(κ)·(u, −v) with R(κ) the rotation by the carrier's κ (counter-clockwise positive, photo
axes x right, y up). The view centre (size_px − 1)/2 is the measuring mark's photo point.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.ndimage import map_coordinates

from stereoplotter.errors import StereoplotterError
from stereoplotter.imagery.photo import PhotoRaster

__all__ = ["SCREEN_PIXEL_MM", "anaglyph", "check_view", "eyepiece_view", "view_to_photo"]

SCREEN_PIXEL_MM = 0.1
_COLOURS = {"red": (1, 0, 0), "cyan": (0, 1, 1), "green": (0, 1, 0), "blue": (0, 0, 1)}


def view_to_photo(
    u: NDArray,
    v: NDArray,
    x_mm: float,
    y_mm: float,
    kappa_rad: float,
    magnification: float,
    size_px: int,
) -> tuple[NDArray, NDArray]:
    """Photo x, y [mm] of view column u, row v (fractional) of a view centred at x_mm, y_mm."""
    s = SCREEN_PIXEL_MM / magnification
    c0 = (size_px - 1) / 2.0
    du, dv = (np.asarray(u, float) - c0) * s, -(np.asarray(v, float) - c0) * s
    ck, sk = np.cos(kappa_rad), np.sin(kappa_rad)
    return x_mm + ck * du - sk * dv, y_mm + sk * du + ck * dv


def check_view(magnification: float, size_px: int) -> None:
    """Refuse a magnification outside [0.5, 60] or a view size outside [8, 2048] px."""
    if not 0.5 <= magnification <= 60.0:
        raise StereoplotterError(
            f"eyepiece_view: magnification must be in [0.5, 60], got {magnification}"
        )
    if not 8 <= size_px <= 2048:
        raise StereoplotterError(f"eyepiece_view: size_px must be in [8, 2048], got {size_px}")


def eyepiece_view(
    raster: PhotoRaster,
    x_mm: float,
    y_mm: float,
    kappa_rad: float,
    *,
    magnification: float = 6.0,
    size_px: int = 256,
) -> NDArray[np.uint8]:
    """The size_px × size_px view (uint8) centred on photo point x_mm, y_mm, rotated by κ.

    Bilinear interpolation of ``raster``; beyond the film it is black. The mark is not drawn.
    """
    check_view(magnification, size_px)
    v, u = np.mgrid[0:size_px, 0:size_px]
    x, y = view_to_photo(u, v, x_mm, y_mm, kappa_rad, magnification, size_px)
    col, row = raster.to_pixel(x, y)
    out = map_coordinates(
        raster.image,
        [row.ravel(), col.ravel()],
        order=1,
        mode="constant",
        cval=0.0,
        output=np.float32,
    )
    return np.round(np.clip(out, 0, 255)).astype(np.uint8).reshape(size_px, size_px)


def anaglyph(
    left_view: NDArray[np.uint8],
    right_view: NDArray[np.uint8],
    colours: tuple[str, str] = ("red", "cyan"),
) -> NDArray[np.uint8]:
    """H × W × 3 uint8: the left view in the first colour's channels, the right in the second's."""
    if left_view.shape != right_view.shape:
        raise StereoplotterError(
            f"anaglyph: views differ in shape {left_view.shape} vs {right_view.shape}"
        )
    try:
        cl, cr = _COLOURS[colours[0]], _COLOURS[colours[1]]
    except KeyError as exc:
        raise StereoplotterError(
            f"anaglyph: colour {exc.args[0]!r} is not one of {sorted(_COLOURS)}"
        ) from None
    out = np.zeros((*left_view.shape, 3), np.uint8)
    for ch in range(3):
        if cl[ch]:
            out[..., ch] = left_view
        elif cr[ch]:
            out[..., ch] = right_view
    return out
