"""Tilt correction of a transformed-bundle plotter: the decentration and the correction-plane
inclination for a tilt α (or ω).

Shared geometry: the setup-data computer prints these values (:mod:`stereoplotter.setup`) and the
virtual instrument's correction mechanisms are built from them
(:mod:`stereoplotter.instrument.kinematics`); neither borrows from the other.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.geometry.arrays import floats

__all__ = ["correction_inclination", "decentration"]


def decentration(focal_length_corrected_mm: ArrayLike, tilt: ArrayLike) -> NDArray[np.float64]:
    r"""Decentration of the photo and of its correction mechanism for one tilt.

    Parameters
    ----------
    focal_length_corrected_mm : float or ndarray
        f′. [mm]
    tilt : float or ndarray
        α (for the x decentration) or ω (for y). [rad]

    Returns
    -------
    ndarray
        d = f′·tan α (or f′·tan ω): the position of the principal point relative to the plumb on
        the photo. [mm]

    Notes
    -----
    The book gives no formula ("по общеизвестным формулам", item 3 of [1]_, OCR L3727). The
    exact value follows from the correction-plane geometry (``kinematics.md`` §2.4,
    e = c = f·tan α); to first order it is the book's fα = Δx (OCR L3843).
    """
    return floats(focal_length_corrected_mm) * np.tan(floats(tilt))


def correction_inclination(
    transformation_coefficient_k: ArrayLike, tilt: ArrayLike
) -> NDArray[np.float64]:
    r"""Inclination θ of a correction plane: tan θ = k·tan α (DRO60 eq. (4); θ ≈ kα, eq. (5)).

    Parameters
    ----------
    transformation_coefficient_k : float or ndarray
        k = f_пр/f′. [—]
    tilt : float or ndarray
        α or ω. [rad]

    Returns
    -------
    ndarray
        θ. [rad] (Not set from a scale: the book fits k_α, k_ω on the fiducials in stage 2.)
    """
    return np.arctan(floats(transformation_coefficient_k) * np.tan(floats(tilt)))
