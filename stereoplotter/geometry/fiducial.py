r"""The photo (fiducial) coordinate system from the four fiducial marks.

Reference
---------
.. [1] Kushtin & Lyskov, *Фотограмметрия снимка и стереоскопических моделей*, Nedra, 1984,
   ch. 1, §2 (OCR L193) and ch. 2, §8 (OCR L894).

The x axis is the line through marks 1 (−x) and 2 (+x); the y axis is perpendicular to it (the
line 3–4 fixes the origin, not the direction of y). The origin o′ is either the intersection of the
lines 1–2 and 3–4 (``"intersection"``, the book's definition, our default) or the mean of the four
marks (``"mean_of_marks"``, the common alternative the book mentions at L894). The numbering
(1 at −x, 2 at +x, 3 at +y, 4 at −y) is our assumption for 1 and 2, the book's for 3 and 4
(``docs/conventions.md`` §2).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.errors import GeometryError

__all__ = ["FIDUCIAL_ORIGINS", "fiducial_frame", "to_fiducial_system"]

#: The allowed definitions of the origin o′.
FIDUCIAL_ORIGINS = ("intersection", "mean_of_marks")


def fiducial_frame(
    marks_mm: ArrayLike, origin: str = "intersection"
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Origin and axes of the fiducial system, from the four marks measured in any plane system.

    Parameters
    ----------
    marks_mm : array_like, shape (4, 2)
        Marks 1, 2, 3, 4 (in this order) in the measuring system (e.g. comparator). [mm]
    origin : {"intersection", "mean_of_marks"}
        Definition of o′.

    Returns
    -------
    origin_mm : ndarray, shape (2,)
        o′ in the measuring system. [mm]
    axes : ndarray, shape (2, 2)
        Rows: the unit x axis (from mark 1 to mark 2) and the unit y axis (x turned by +90°).

    Raises
    ------
    GeometryError
        Unknown origin, coincident marks 1 and 2, or lines 1–2 and 3–4 (nearly) parallel.

    Examples
    --------
    >>> o, axes = fiducial_frame([[-85, 1], [85, 1], [0.5, 86], [0.5, -84]])
    >>> o.tolist(), axes.tolist()
    ([0.5, 1.0], [[1.0, 0.0], [-0.0, 1.0]])
    """
    if origin not in FIDUCIAL_ORIGINS:
        raise GeometryError(
            f"fiducial origin: expected one of {', '.join(FIDUCIAL_ORIGINS)}, found {origin!r}"
        )
    m = np.asarray(marks_mm, float)
    if m.shape != (4, 2) or not np.all(np.isfinite(m)):
        raise GeometryError(f"fiducial marks: expected 4 finite points (4, 2), found {m.shape}")
    d12 = m[1] - m[0]
    length = float(np.hypot(*d12))
    if length < 1e-6:
        raise GeometryError("fiducial marks 1 and 2 coincide: the x axis is undefined")
    ex = d12 / length
    ey = np.array([-ex[1], ex[0]])
    if origin == "mean_of_marks":
        return m.mean(axis=0), np.stack([ex, ey])
    d34 = m[3] - m[2]
    cross = ex[0] * d34[1] - ex[1] * d34[0]
    if abs(cross) < 1e-3 * float(np.hypot(*d34)):
        raise GeometryError("fiducial lines 1–2 and 3–4 are (nearly) parallel: no intersection")
    # m[0] + s·ex = m[2] + t·d34, solved for s
    w = m[2] - m[0]
    s = (w[0] * d34[1] - w[1] * d34[0]) / cross
    return m[0] + s * ex, np.stack([ex, ey])


def to_fiducial_system(
    points_mm: ArrayLike, marks_mm: ArrayLike, origin: str = "intersection"
) -> NDArray[np.float64]:
    """Coordinates of measured points in the fiducial system defined by the measured marks.

    Parameters
    ----------
    points_mm : array_like, shape (..., 2)
        Points in the measuring system. [mm]
    marks_mm : array_like, shape (4, 2)
        Marks 1–4 in the same system. [mm]
    origin : {"intersection", "mean_of_marks"}

    Returns
    -------
    ndarray, shape (..., 2)
        x, y in the fiducial system. [mm]
    """
    o, axes = fiducial_frame(marks_mm, origin)
    return (np.asarray(points_mm, float) - o) @ axes.T
