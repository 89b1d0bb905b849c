"""PNG encoding of rendered photos and eyepiece views (Pillow), and their atomic writing."""

from __future__ import annotations

import io
import os

import numpy as np
from numpy.typing import NDArray
from PIL import Image

from stereoplotter.io.yaml_files import atomic_write_bytes

__all__ = ["png_bytes", "write_png"]


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
