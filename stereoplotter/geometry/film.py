r"""Film deformation and the corrected focal length f′ of chapter 6.

Reference
---------
.. [1] Kushtin & Lyskov, *Фотограмметрия снимка и стереоскопических моделей*, Nedra, 1984: ch. 1,
   §3, (1.22) (a uniform scale change of the image equals a change of f); §6 (film deformation);
   ch. 6, §26, OCR L3709 (f′, "the focal length corrected for the deformation of the negative").

The book gives no formula for f′. We use (an *assumption*, derived from (1.22)): a uniform film
scale change is indistinguishable from a change of principal distance, hence

    f′ = f · l_measured / l_calibrated,

with l the distance between opposite fiducial marks (1–2 and 3–4), averaged as a ratio over the
spans (and over both photos of a pair: one f′ per pair, ``docs/conventions.md``).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.errors import GeometryError

__all__ = [
    "FIDUCIAL_SPANS",
    "corrected_focal_length",
    "fiducial_spans_mm",
]

#: The spans between opposite fiducial marks used for f′: marks 1–2 (x axis) and 3–4 (y axis).
FIDUCIAL_SPANS: tuple[tuple[str, str], ...] = (("1", "2"), ("3", "4"))


def fiducial_spans_mm(fiducials_mm: Mapping[str, ArrayLike]) -> NDArray[np.float64]:
    """Distances 1–2 and 3–4 between opposite fiducial marks.

    Parameters
    ----------
    fiducials_mm : mapping of mark number ("1".."4") to array_like, shape (..., 2)
        Mark coordinates x, y. [mm]

    Returns
    -------
    ndarray, shape (..., 2)
        l₁₂, l₃₄. [mm]

    Examples
    --------
    >>> fiducial_spans_mm({"1": [-85, 0], "2": [85, 0], "3": [0, 85], "4": [0, -85]})
    array([170., 170.])
    """
    spans = [
        np.linalg.norm(
            np.asarray(fiducials_mm[j], float) - np.asarray(fiducials_mm[i], float), axis=-1
        )
        for i, j in FIDUCIAL_SPANS
    ]
    return np.stack(spans, axis=-1)


def corrected_focal_length(
    focal_length_mm: ArrayLike,
    measured_span_mm: ArrayLike,
    calibrated_span_mm: ArrayLike,
) -> NDArray[np.float64]:
    r"""f′: the focal length corrected for a uniform deformation of the film.

    Parameters
    ----------
    focal_length_mm : float or ndarray
        Calibrated f from the camera certificate. [mm]
    measured_span_mm : array_like, shape (..., k)
        Distances between opposite fiducial marks measured on the film (k spans, e.g. 1–2 and 3–4,
        of one or both photos). [mm]
    calibrated_span_mm : array_like, shape (..., k)
        The same distances from the camera certificate. [mm]

    Returns
    -------
    ndarray
        f′ = f · mean(l_measured / l_calibrated) over the last axis. [mm]

    Raises
    ------
    GeometryError
        A span that is not positive and finite.

    Notes
    -----
    The f′ of Eqs. (6.1)/(6.2) of [1]_ (OCR L3709), by the assumption in the module docstring.
    Film shrinkage (l_measured < l_calibrated) gives f′ < f. Differential deformation (different
    ratios on the x and y spans) cannot be absorbed by one f′; the caller reports the spread.

    Examples
    --------
    >>> float(corrected_focal_length(70.0, [169.983, 169.983], [170.0, 170.0]))
    69.993
    """
    measured = np.asarray(measured_span_mm, float)
    calibrated = np.asarray(calibrated_span_mm, float)
    for name, v in (("measured", measured), ("calibrated", calibrated)):
        if not np.all(np.isfinite(v) & (v > 0)):
            raise GeometryError(
                f"f′: expected positive finite {name} fiducial spans [mm], found {v.tolist()}"
            )
    ratio = np.mean(measured / calibrated, axis=-1)
    return np.asarray(focal_length_mm, float) * ratio
