"""The exterior orientation of each photo as a user of the scenario knows it.

"given" photos carry the exterior orientation of the aerotriangulation (the scenario's truth);
"resection" photos get theirs by space resection from the *measured* full control points imaged
on them (:func:`stereoplotter.geometry.resection.space_resection`, rigorous least squares), with
the pair's f′. One place for this choice, used by the foundation job and the setup sheet.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from stereoplotter.geometry.resection import ResectionResult, space_resection
from stereoplotter.scenario.model import Scenario
from stereoplotter.scenario.synthetic import Measurements

__all__ = ["KnownExterior", "known_exterior_orientation"]


@dataclass(frozen=True, slots=True)
class KnownExterior:
    """Exterior orientation of one photo as known downstream.

    Attributes
    ----------
    photo : str
    source : str
        "given" or "resection".
    centre_m : ndarray, shape (3,)
        X_S, Y_S, Z_S. [m]
    rotation : ndarray, shape (3, 3)
        M of Eq. (2.50). [—]
    resection : ResectionResult or None
        The adjustment, for "resection" photos.
    point_ids : tuple of str
        The control points used by the resection.
    """

    photo: str
    source: str
    centre_m: NDArray[np.float64]
    rotation: NDArray[np.float64]
    resection: ResectionResult | None = None
    point_ids: tuple[str, ...] = ()


def known_exterior_orientation(
    scenario: Scenario, measurements: Measurements
) -> list[KnownExterior]:
    """The exterior orientation of every photo, given or by resection from measured control.

    Parameters
    ----------
    scenario : Scenario
    measurements : Measurements
        The synthetic measurements (photo coordinates with noise, f′ of the pair).

    Returns
    -------
    list of KnownExterior
        In the order of ``scenario.photos``.
    """
    out = []
    pts = np.array([p.local_m for p in scenario.points])
    for photo in scenario.photos:
        ext = photo.exterior
        if ext.source != "resection":
            out.append(KnownExterior(photo.name, ext.source, ext.centre, ext.rotation))
            continue
        pm = measurements.photo(photo.name)
        use = np.array(
            [
                pm.points_imaged[i] and p.role == "control" and p.kind == "full"
                for i, p in enumerate(scenario.points)
            ]
        )
        result = space_resection(
            pm.points_mm[use],
            pts[use],
            measurements.focal_length_corrected_mm,
            scenario.camera.principal_point_mm,
        )
        ids = tuple(p.id for p, u in zip(scenario.points, use, strict=True) if u)
        out.append(
            KnownExterior(
                photo.name, ext.source, result.projection_centre_m, result.rotation, result, ids
            )
        )
    return out
