"""Geodesy of chapter 2, §8–§11 of the book: SK-42 Gauss–Krüger (via pyproj), geocentric
coordinates on the Krasovsky ellipsoid, and the local photogrammetric system.

Modules
-------
``gauss_kruger``
    Plain and conventional Gauss–Krüger coordinates ↔ geodetic B, L; zones; convergence.
``geocentric``
    Geodetic B, L, H ↔ geocentric X, Y, Z (2.7), the book's iteration (2.15), heights (2.6).
``photogrammetric``
    Gauss–Krüger ↔ the local system of §9–§11, rigorous and by the book's direct forms.
"""

from __future__ import annotations

from stereoplotter.geodesy.gauss_kruger import (
    CONVENTIONAL_EPSG_ZONES,
    MAX_DISTANCE_FROM_AXIAL_MERIDIAN,
    GeodesyRangeError,
    axial_meridian,
    conventional_from_geographic,
    conventional_ordinate,
    gauss_kruger_from_geographic,
    geographic_from_conventional,
    geographic_from_gauss_kruger,
    meridian_convergence,
    split_conventional_ordinate,
    zone_from_longitude,
)
from stereoplotter.geodesy.geocentric import (
    BookIteration,
    geocentric_from_geodetic,
    geodetic_from_geocentric,
    geodetic_from_geocentric_book_iteration,
    geodetic_height,
    normal_height,
    prime_vertical_radius,
)
from stereoplotter.geodesy.photogrammetric import (
    ChordReductions,
    LocalFrame,
    MeridianFrameCoordinates,
    gauss_kruger_from_local,
    gauss_kruger_from_local_corrections,
    gauss_kruger_from_local_direct,
    gauss_kruger_reductions,
    geocentric_from_local,
    height_correction_from_local,
    local_from_gauss_kruger,
    local_from_gauss_kruger_corrections,
    local_from_gauss_kruger_direct,
    local_from_geocentric,
    meridian_frame_from_geodetic,
)

__all__ = [
    "CONVENTIONAL_EPSG_ZONES",
    "MAX_DISTANCE_FROM_AXIAL_MERIDIAN",
    "BookIteration",
    "ChordReductions",
    "GeodesyRangeError",
    "LocalFrame",
    "MeridianFrameCoordinates",
    "axial_meridian",
    "conventional_from_geographic",
    "conventional_ordinate",
    "gauss_kruger_from_geographic",
    "gauss_kruger_from_local",
    "gauss_kruger_from_local_corrections",
    "gauss_kruger_from_local_direct",
    "gauss_kruger_reductions",
    "geocentric_from_geodetic",
    "geocentric_from_local",
    "geodetic_from_geocentric",
    "geodetic_from_geocentric_book_iteration",
    "geodetic_height",
    "geographic_from_conventional",
    "geographic_from_gauss_kruger",
    "height_correction_from_local",
    "local_from_gauss_kruger",
    "local_from_gauss_kruger_corrections",
    "local_from_gauss_kruger_direct",
    "local_from_geocentric",
    "meridian_convergence",
    "meridian_frame_from_geodetic",
    "normal_height",
    "prime_vertical_radius",
    "split_conventional_ordinate",
    "zone_from_longitude",
]
