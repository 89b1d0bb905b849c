"""The scenario's tie between its photogrammetric system and SK-42 Gauss–Krüger.

A scenario with ``frame.kind: sk42`` uses the local system of §10 (``geodesy.photogrammetric``)
with its origin at ``frame.origin`` (Gauss–Krüger x, conventional ordinate ȳ, geodetic height).
All points of the scenario are in the origin's zone. This module only adapts the scenario's
conventional-ordinate triplets to the geodesy layer; the transformations live there.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from stereoplotter.errors import StereoplotterError
from stereoplotter.geodesy import (
    conventional_from_geographic,
    conventional_ordinate,
    split_conventional_ordinate,
)
from stereoplotter.geodesy.map_sheet import sheet_bounds
from stereoplotter.geodesy.photogrammetric import (
    LocalFrame,
    gauss_kruger_from_local,
    local_from_gauss_kruger,
)
from stereoplotter.scenario.model import Frame

__all__ = [
    "check_conventional_ordinate",
    "local_frame",
    "local_from_sk42",
    "sheet_corners_sk42",
    "sk42_from_local",
]

#: The largest plain ordinate accepted, ±400 km from the axial meridian (zones are ±~330 km wide
#: at the equator; the book's own example uses y = 236 km).
MAX_PLAIN_ORDINATE_M = 400_000.0


def check_conventional_ordinate(east_m: float) -> tuple[int, float]:
    """Split ȳ into (zone, y) and refuse |y| > 400 km."""
    zone, y = split_conventional_ordinate(east_m)
    if abs(float(y)) > MAX_PLAIN_ORDINATE_M:
        raise StereoplotterError(
            f"plain ordinate y = {float(y):.3f} m is more than 400 km from the axial meridian of "
            f"zone {int(zone)}; is the zone number (the leading digits of ȳ) right?"
        )
    return int(zone), float(y)


@lru_cache(maxsize=64)
def local_frame(frame: Frame) -> LocalFrame:
    """The geodesy layer's :class:`LocalFrame` for a scenario frame tied to SK-42."""
    if frame.kind != "sk42" or frame.origin_sk42_m is None:
        raise StereoplotterError("the scenario frame is local: it has no SK-42 tie")
    north, east, height = frame.origin_sk42_m
    zone, y = check_conventional_ordinate(east)
    return LocalFrame.from_gauss_kruger(north, y, height, zone=zone)


def local_from_sk42(frame: Frame, sk42_m: tuple[float, float, float]) -> tuple[float, ...]:
    """Local X, Y, Z [m] of a point given as (x north, ȳ conventional, H) [m]."""
    lf = local_frame(frame)
    north, east, height = sk42_m
    zone, y = check_conventional_ordinate(east)
    if zone != lf.zone:
        raise StereoplotterError(
            f"point in zone {zone} but the frame origin is in zone {lf.zone}; give all points "
            "in the origin's zone"
        )
    X, Y, Z = local_from_gauss_kruger(lf, north, y, height)
    return (float(X), float(Y), float(Z))


def sk42_from_local(frame: Frame, local_m: tuple[float, float, float]) -> tuple[float, ...]:
    """(x north, ȳ conventional, H) [m] of a point given in local X, Y, Z [m]."""
    lf = local_frame(frame)
    north, y, height = gauss_kruger_from_local(lf, *local_m)
    return (float(north), float(conventional_ordinate(lf.zone, y)), float(height))


def sheet_corners_sk42(nomenclature: str) -> tuple[NDArray[np.float64], int]:
    """Corners NW, NE, SE, SW of a map sheet as (x north, ȳ conventional) [m], and its scale."""
    bounds = sheet_bounds(nomenclature)
    lat, lon = np.radians(np.array(bounds.corners_deg())).T
    north, east = conventional_from_geographic(lat, lon, bounds.zone)
    return np.column_stack([north, east]), bounds.scale_denominator
