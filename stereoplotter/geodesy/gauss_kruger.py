r"""SK-42 Gauss–Krüger coordinates on the Krasovsky ellipsoid, through pyproj.

The book computes the Gauss–Krüger projection with the series (2.10) (plane → geographic) and
(2.16) (geographic → plane) of [1]_. This module does **not** implement those series: PROJ's
transverse Mercator (``+proj=tmerc``, the Poder/Engsager algorithm, accurate to well below a
millimetre) replaces them. After the errata of ``docs/conventions.md`` §12 the book's series agree
with pyproj to 0.00005″ and 0.2 mm, and pyproj reproduces Table 1 of [1]_ (see
``tests/test_reference_geodesy.py``).

Conventions (``docs/conventions.md`` §3)
----------------------------------------
* Gauss–Krüger x points **north** and y points **east** (book: x, y; chapter 6: X_г, Y_г). The
  triple (x north, y east, up) is left-handed.
* The *plain* ordinate y is counted from the axial meridian, without the 500 km and the zone number
  (the y of (2.10) and (2.16)).
* The *conventional* ordinate is ȳ = 1 000 000·N + 500 000 + y [m] with the zone number N
  ([1]_, §8, OCR L875: N = 8, y = −55 451.54 m gives ȳ = 8 444 548.46 m).
* 6° zones: zone N spans longitudes 6(N − 1)° … 6N° east of Greenwich; its axial meridian is
  L₀ = 6N − 3 degrees (wrapped into (−180°, 180°]).
* Angles are radians, lengths metres. Functions broadcast over numpy arrays; the zone is one
  integer per call (the conventional-ordinate functions accept mixed zones).

The plain form uses ``+proj=tmerc +ellps=krass +lon_0=<L0> +k=1 +x_0=0 +y_0=0``; the conventional
form uses EPSG:284NN, "Pulkovo 1942 / Gauss-Kruger zone N" (zones 2–32 exist in the EPSG
database), from the geographic Pulkovo 1942 CRS EPSG:4284 (same datum: no datum shift is involved).

References
----------
.. [1] Куштин (Kushtin) & Лысков (Lyskov), *Фотограмметрия снимка и стереоскопических моделей*,
   Moscow: Nedra, 1984, ch. 2, §8–§11, pp. 33–52 (OCR L820–1340).
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pyproj import CRS, Proj, Transformer

from stereoplotter.constants import DEG_PER_RAD, KRASOVSKY
from stereoplotter.errors import StereoplotterError

__all__ = [
    "CONVENTIONAL_EPSG_ZONES",
    "MAX_DISTANCE_FROM_AXIAL_MERIDIAN",
    "GeodesyRangeError",
    "axial_meridian",
    "check_zone",
    "conventional_from_geographic",
    "conventional_ordinate",
    "gauss_kruger_from_geographic",
    "geographic_from_conventional",
    "geographic_from_gauss_kruger",
    "meridian_convergence",
    "split_conventional_ordinate",
    "zone_from_longitude",
]

#: Zones for which EPSG defines "Pulkovo 1942 / Gauss-Kruger zone N" (EPSG:28402 … EPSG:28432).
CONVENTIONAL_EPSG_ZONES: range = range(2, 33)
#: Largest accepted |L − L₀|: the 3° half-width of a 6° zone plus the largest zone overlap of 3°
#: allowed by the map regulations quoted in [1] §8 (OCR L877). [rad]
MAX_DISTANCE_FROM_AXIAL_MERIDIAN: float = math.radians(6.0)

_ZONE_MIN, _ZONE_MAX = 1, 60
_ZONE_FACTOR_M = 1_000_000.0
_FALSE_EASTING_M = 500_000.0


class GeodesyRangeError(StereoplotterError):
    """A zone number, latitude or longitude lies outside the range a function accepts.

    Attributes
    ----------
    quantity : str
        What was out of range.
    value : object
        The offending value (the first offending element for arrays).
    allowed : str
        The accepted range, in words.
    """

    def __init__(self, quantity: str, value: object, allowed: str):
        self.quantity = quantity
        self.value = value
        self.allowed = allowed
        super().__init__(f"{quantity} = {value!r} is outside the allowed range {allowed}")


# --------------------------------------------------------------------------------------------
# validation helpers


def check_zone(zone: object, allowed: range | None = None) -> int:
    lo, hi = (_ZONE_MIN, _ZONE_MAX) if allowed is None else (allowed.start, allowed.stop - 1)
    text = f"{lo}…{hi} (integer 6° zone number)"
    if isinstance(zone, bool) or not isinstance(zone, int | np.integer):
        raise GeodesyRangeError("zone", zone, text)
    if not lo <= int(zone) <= hi:
        raise GeodesyRangeError("zone", int(zone), text)
    return int(zone)


def _check_latitude(latitude: NDArray[np.float64]) -> None:
    bad = ~(np.abs(latitude) <= math.pi / 2)
    if np.any(bad):
        value = float(np.asarray(latitude)[bad].flat[0])
        raise GeodesyRangeError(
            "latitude", f"{value * DEG_PER_RAD:.9g}°", "[-90°, 90°] (given in radians)"
        )


def _wrap(angle: ArrayLike) -> NDArray[np.float64]:
    """Wrap an angle into [−π, π). [rad]"""
    return (np.asarray(angle, dtype=float) + math.pi) % (2.0 * math.pi) - math.pi


def _check_longitude_in_zone(longitude: NDArray[np.float64], zone: int) -> None:
    dl = _wrap(longitude - axial_meridian(zone))
    bad = ~(np.abs(dl) <= MAX_DISTANCE_FROM_AXIAL_MERIDIAN + 1e-12)
    if np.any(bad):
        value = float(np.asarray(longitude)[bad].flat[0]) * DEG_PER_RAD
        l0 = axial_meridian(zone) * DEG_PER_RAD
        raise GeodesyRangeError(
            "longitude",
            f"{value:.9g}°",
            f"[{l0 - 6:g}°, {l0 + 6:g}°] for zone {zone} (axial meridian {l0:g}° ± 6°)",
        )


def _out(a: ArrayLike) -> NDArray[np.float64]:
    """Return float64 arrays; 0-d results become numpy scalars."""
    return np.asarray(a, dtype=float)[()]


# --------------------------------------------------------------------------------------------
# cached pyproj objects


@cache
def _tmerc_definition(zone: int) -> str:
    lon0 = axial_meridian(zone) * DEG_PER_RAD
    return f"+proj=tmerc +ellps={KRASOVSKY.proj_name} +lon_0={lon0:.0f} +k=1 +x_0=0 +y_0=0 +units=m"


@cache
def _plain_transformer(zone: int) -> Transformer:
    geographic = CRS.from_proj4(f"+proj=longlat +ellps={KRASOVSKY.proj_name} +no_defs")
    return Transformer.from_crs(geographic, CRS.from_proj4(_tmerc_definition(zone)), always_xy=True)


@cache
def _plain_proj(zone: int) -> Proj:
    return Proj(_tmerc_definition(zone))


@cache
def _conventional_transformer(zone: int) -> Transformer:
    return Transformer.from_crs("EPSG:4284", f"EPSG:{28400 + zone}", always_xy=True)


# --------------------------------------------------------------------------------------------
# zones


def axial_meridian(zone: int) -> float:
    """Longitude L₀ of the axial meridian of a 6° zone.

    Parameters
    ----------
    zone : int
        Zone number N, 1…60. [—]

    Returns
    -------
    float
        L₀ = 6N − 3 degrees, wrapped into (−180°, 180°]. [rad]

    Raises
    ------
    GeodesyRangeError
        If the zone is not an integer in 1…60.

    Notes
    -----
    Zone numbering of [1]_, §8 (OCR L873): zones are counted eastwards from Greenwich, which is the
    western boundary of zone 1.

    Examples
    --------
    >>> round(math.degrees(axial_meridian(4)), 9)
    21.0
    >>> round(math.degrees(axial_meridian(32)), 9)
    -171.0
    """
    n = check_zone(zone)
    degrees = 6.0 * n - 3.0
    if degrees > 180.0:
        degrees -= 360.0
    return math.radians(degrees)


def zone_from_longitude(longitude: ArrayLike) -> NDArray[np.int64]:
    """Number of the 6° zone that contains a longitude.

    Parameters
    ----------
    longitude : float or ndarray
        Geodetic longitude L, east positive. [rad]

    Returns
    -------
    ndarray of int
        N = ⌊L/6°⌋ + 1 with L taken in [0°, 360°); a longitude on a zone boundary belongs to the
        zone to its east. [—]

    Notes
    -----
    Zone numbering of [1]_, §8 (OCR L873).

    Examples
    --------
    >>> int(zone_from_longitude(math.radians(24.7188)))
    5
    """
    lon_deg = np.mod(np.asarray(longitude, dtype=float) * DEG_PER_RAD, 360.0)
    return (np.floor(lon_deg / 6.0).astype(np.int64) % 60 + 1)[()]


def conventional_ordinate(zone: ArrayLike, y_east_m: ArrayLike) -> NDArray[np.float64]:
    """Conventional ordinate ȳ = 1 000 000·N + 500 000 + y.

    Parameters
    ----------
    zone : int or ndarray of int
        Zone number N, 1…60. [—]
    y_east_m : float or ndarray
        Plain Gauss–Krüger ordinate y, counted from the axial meridian, |y| < 500 000. [m]

    Returns
    -------
    ndarray
        ȳ. [m]

    Raises
    ------
    GeodesyRangeError
        If a zone is not in 1…60 or |y| ≥ 500 000 m.

    Notes
    -----
    Definition of [1]_, §8 (OCR L875).

    Examples
    --------
    >>> round(float(conventional_ordinate(8, -55451.54)), 2)  # the book's example, OCR L875
    8444548.46
    """
    zones = np.asarray(zone)
    if not np.issubdtype(zones.dtype, np.integer):
        raise GeodesyRangeError("zone", zone, f"{_ZONE_MIN}…{_ZONE_MAX} (integer 6° zone number)")
    for n in np.unique(zones):
        check_zone(int(n))
    y = np.asarray(y_east_m, dtype=float)
    bad = ~(np.abs(y) < _FALSE_EASTING_M)
    if np.any(bad):
        raise GeodesyRangeError("y_east_m", float(y[bad].flat[0]), "(-500000, 500000) m")
    return _out(_ZONE_FACTOR_M * zones + _FALSE_EASTING_M + y)


def split_conventional_ordinate(
    conventional_ordinate_m: ArrayLike,
) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Split a conventional ordinate ȳ into the zone number N and the plain ordinate y.

    Parameters
    ----------
    conventional_ordinate_m : float or ndarray
        ȳ = 1 000 000·N + 500 000 + y. [m]

    Returns
    -------
    zone : ndarray of int
        N = ⌊ȳ / 1 000 000⌋. [—]
    y_east_m : ndarray
        y = ȳ − 1 000 000·N − 500 000, counted from the axial meridian. [m]

    Raises
    ------
    GeodesyRangeError
        If the leading digits do not give a zone in 1…60 (for example an ordinate given without
        its zone number).

    Notes
    -----
    Inverse of the definition of [1]_, §8 (OCR L875).

    Examples
    --------
    >>> zone, y = split_conventional_ordinate(8444548.46)
    >>> int(zone), round(float(y), 2)
    (8, -55451.54)
    """
    ybar = np.asarray(conventional_ordinate_m, dtype=float)
    if not np.all(np.isfinite(ybar)):
        raise GeodesyRangeError(
            "conventional_ordinate_m", float(ybar[~np.isfinite(ybar)].flat[0]), "finite values"
        )
    zone = np.floor(ybar / _ZONE_FACTOR_M).astype(np.int64)
    bad = (zone < _ZONE_MIN) | (zone > _ZONE_MAX)
    if np.any(bad):
        raise GeodesyRangeError(
            "conventional_ordinate_m",
            float(ybar[bad].flat[0]),
            "[1 000 000, 61 000 000) m, i.e. with a leading zone number 1…60 "
            "(ȳ = 1 000 000·N + 500 000 + y)",
        )
    return zone[()], _out(ybar - _ZONE_FACTOR_M * zone - _FALSE_EASTING_M)


# --------------------------------------------------------------------------------------------
# plain Gauss–Krüger


def gauss_kruger_from_geographic(
    latitude: ArrayLike, longitude: ArrayLike, zone: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    r"""Plain Gauss–Krüger x (north), y (east) from geodetic latitude and longitude (SK-42).

    Parameters
    ----------
    latitude : float or ndarray
        Geodetic latitude B on the Krasovsky ellipsoid. [rad]
    longitude : float or ndarray
        Geodetic longitude L, east of Greenwich. [rad]
    zone : int
        Zone number N whose axial meridian L₀ = 6N − 3° is used. [—]

    Returns
    -------
    gk_north_m : ndarray
        Abscissa x, from the equator, north positive. [m]
    gk_east_m : ndarray
        Plain ordinate y from the axial meridian, east positive (no 500 km, no zone number). [m]

    Raises
    ------
    GeodesyRangeError
        For an invalid zone, |B| > 90° or |L − L₀| > 6°.

    Notes
    -----
    Replaces Eq. (2.16) of [1]_ (the series of [36] of the book, OCR L1125) by PROJ's
    ``+proj=tmerc +ellps=krass +lon_0=<L0> +k=1 +x_0=0 +y_0=0``. The book's series, with the
    bracket misprint of (2.16) corrected (``docs/conventions.md`` §12, item 14), agrees with it to
    0.2 mm.

    Examples
    --------
    >>> x, y = gauss_kruger_from_geographic(math.radians(55.0), math.radians(24.0), 4)
    >>> round(float(x), 3), round(float(y), 3)
    (6101455.311, 191955.601)
    """
    n = check_zone(zone)
    lat, lon = np.broadcast_arrays(
        np.asarray(latitude, dtype=float), np.asarray(longitude, dtype=float)
    )
    _check_latitude(lat)
    _check_longitude_in_zone(lon, n)
    east, north = _plain_transformer(n).transform(
        _wrap(lon) * DEG_PER_RAD, lat * DEG_PER_RAD, errcheck=True
    )
    return _out(north), _out(east)


def geographic_from_gauss_kruger(
    gk_north_m: ArrayLike, gk_east_m: ArrayLike, zone: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    r"""Geodetic latitude and longitude from plain Gauss–Krüger x (north), y (east) (SK-42).

    Parameters
    ----------
    gk_north_m : float or ndarray
        Abscissa x, from the equator, north positive. [m]
    gk_east_m : float or ndarray
        Plain ordinate y from the axial meridian, east positive. [m]
    zone : int
        Zone number N. [—]

    Returns
    -------
    latitude : ndarray
        Geodetic latitude B on the Krasovsky ellipsoid. [rad]
    longitude : ndarray
        Geodetic longitude L = L₀ + l, in (−π, π]. [rad]

    Raises
    ------
    GeodesyRangeError
        For an invalid zone, or if the point lies more than 6° from the axial meridian.

    Notes
    -----
    Replaces Eq. (2.10) of [1]_ (OCR L925–960) by PROJ's inverse transverse Mercator. With the
    B₁₃ bracket restored (``docs/conventions.md`` §12, item 12) the book's series agrees with it to
    0.00005″. Table 1 of [1]_ is reproduced: for the book's point O (x = 6 140 794.660 m,
    y = 235 949.468 m) B = 55°20′01.49999″ and l = L − L₀ = 3°43′07.80003″.

    Examples
    --------
    >>> b, l = geographic_from_gauss_kruger(6140794.660, 235949.468, 4)
    >>> round(math.degrees(float(b)), 8), round(math.degrees(float(l)), 8)
    (55.33375, 24.71883334)
    """
    n = check_zone(zone)
    north, east = np.broadcast_arrays(
        np.asarray(gk_north_m, dtype=float), np.asarray(gk_east_m, dtype=float)
    )
    lon_deg, lat_deg = _plain_transformer(n).transform(
        east, north, direction="INVERSE", errcheck=True
    )
    lat = np.asarray(lat_deg, dtype=float) / DEG_PER_RAD
    lon = _wrap(np.asarray(lon_deg, dtype=float) / DEG_PER_RAD)
    _check_longitude_in_zone(lon, n)
    return _out(lat), _out(lon)


def meridian_convergence(
    latitude: ArrayLike, longitude: ArrayLike, zone: int
) -> NDArray[np.float64]:
    r"""Meridian convergence γ of the Gauss–Krüger projection.

    Parameters
    ----------
    latitude : float or ndarray
        Geodetic latitude B. [rad]
    longitude : float or ndarray
        Geodetic longitude L. [rad]
    zone : int
        Zone number N. [—]

    Returns
    -------
    ndarray
        γ, the angle from true north to grid north, clockwise positive, so that the grid bearing
        α and the azimuth A satisfy A = α + γ. γ > 0 east of the axial meridian in the northern
        hemisphere. [rad]

    Raises
    ------
    GeodesyRangeError
        For an invalid zone, |B| > 90° or |L − L₀| > 6°.

    Notes
    -----
    The γ₀ of Eq. (2.14) of [1]_ and of Table 2 (OCR L1065: γ₀ = 3°03′36.2212″ for point O;
    this function gives 3°03′36.2226″). Computed by PROJ's projection factors
    (``pyproj.Proj.get_factors``), not by the series of spheroidal geodesy. The book's §10 uses
    the first-order form γ₀ = (y₀/N₀) tan B₀ of Eq. (2.29) instead (Table 3: 3.0579055°).

    Examples
    --------
    >>> b, l = geographic_from_gauss_kruger(6140794.660, 235949.468, 4)
    >>> round(math.degrees(float(meridian_convergence(b, l, 4))) * 3600 - 11000, 3)
    16.223
    """
    n = check_zone(zone)
    lat = np.asarray(latitude, dtype=float)
    lon = np.asarray(longitude, dtype=float)
    _check_latitude(lat)
    _check_longitude_in_zone(lon, n)
    lat_b, lon_b = np.broadcast_arrays(lat, lon)
    factors = _plain_proj(n).get_factors(
        np.atleast_1d(_wrap(lon_b) * DEG_PER_RAD),
        np.atleast_1d(lat_b * DEG_PER_RAD),
        errcheck=True,
    )
    gamma = np.asarray(factors.meridian_convergence, dtype=float) / DEG_PER_RAD
    return _out(gamma.reshape(lat_b.shape))


# --------------------------------------------------------------------------------------------
# conventional (EPSG:284NN) Gauss–Krüger


def conventional_from_geographic(
    latitude: ArrayLike, longitude: ArrayLike, zone: int | None = None
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Gauss–Krüger x and conventional ordinate ȳ (with the zone number) from B, L (SK-42).

    Parameters
    ----------
    latitude : float or ndarray
        Geodetic latitude B (Pulkovo 1942, Krasovsky ellipsoid). [rad]
    longitude : float or ndarray
        Geodetic longitude L. [rad]
    zone : int, optional
        Zone number N, 2…32 (the zones EPSG defines). Default: the zone containing each point
        (``zone_from_longitude``); then points may fall in different zones.

    Returns
    -------
    gk_north_m : ndarray
        Abscissa x. [m]
    conventional_ordinate_m : ndarray
        ȳ = 1 000 000·N + 500 000 + y. [m]

    Raises
    ------
    GeodesyRangeError
        For a zone outside 2…32, |B| > 90°, |L − L₀| > 6° or |y| ≥ 500 km.

    Notes
    -----
    The projection of (2.16) of [1]_ with the conventional ordinate of §8 (OCR L875), computed
    by pyproj from EPSG:4284 to EPSG:284NN (Pulkovo 1942 / Gauss-Kruger zone N).

    Examples
    --------
    >>> x, ybar = conventional_from_geographic(math.radians(55.0), math.radians(23.0))
    >>> round(float(x), 3), round(float(ybar), 3)
    (6099167.239, 4627981.509)
    """
    lat = np.asarray(latitude, dtype=float)
    lon = np.asarray(longitude, dtype=float)
    _check_latitude(lat)
    lat, lon = np.broadcast_arrays(lat, lon)
    zones = zone_from_longitude(lon) if zone is None else np.full(lat.shape, zone)
    north = np.empty(lat.shape)
    ybar = np.empty(lat.shape)
    for n in np.unique(zones):
        n = check_zone(int(n), CONVENTIONAL_EPSG_ZONES)
        sel = zones == n
        _check_longitude_in_zone(lon[sel], n)
        e, nn = _conventional_transformer(n).transform(
            _wrap(lon[sel]) * DEG_PER_RAD, lat[sel] * DEG_PER_RAD, errcheck=True
        )
        ybar[sel], north[sel] = e, nn
    y = ybar - _ZONE_FACTOR_M * zones - _FALSE_EASTING_M
    bad = ~(np.abs(y) < _FALSE_EASTING_M)
    if np.any(bad):
        raise GeodesyRangeError(
            "y_east_m",
            float(y[bad].flat[0]),
            "(-500000, 500000) m: a larger ordinate would change the zone digit of ȳ",
        )
    return _out(north), _out(ybar)


def geographic_from_conventional(
    gk_north_m: ArrayLike, conventional_ordinate_m: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Geodetic B, L from Gauss–Krüger x and the conventional ordinate ȳ (SK-42).

    Parameters
    ----------
    gk_north_m : float or ndarray
        Abscissa x. [m]
    conventional_ordinate_m : float or ndarray
        ȳ = 1 000 000·N + 500 000 + y; the zone N is read from its leading digits. [m]

    Returns
    -------
    latitude, longitude : ndarray
        Geodetic B, L on the Krasovsky ellipsoid. [rad]

    Raises
    ------
    GeodesyRangeError
        If the zone read from ȳ is outside 2…32 or the point is more than 6° from its axial
        meridian.

    Notes
    -----
    Inverse of ``conventional_from_geographic``: replaces Eq. (2.10) of [1]_ by pyproj, from
    EPSG:284NN to EPSG:4284.

    Examples
    --------
    >>> b, l = geographic_from_conventional(6099167.239, 4627981.509)
    >>> round(math.degrees(float(b)), 7), round(math.degrees(float(l)), 7)
    (55.0, 23.0)
    """
    north, ybar = np.broadcast_arrays(
        np.asarray(gk_north_m, dtype=float), np.asarray(conventional_ordinate_m, dtype=float)
    )
    zones, _ = split_conventional_ordinate(ybar)
    zones = np.asarray(zones)
    lat = np.empty(north.shape)
    lon = np.empty(north.shape)
    for n in np.unique(zones):
        n = check_zone(int(n), CONVENTIONAL_EPSG_ZONES)
        sel = zones == n
        lo, la = _conventional_transformer(n).transform(
            ybar[sel], north[sel], direction="INVERSE", errcheck=True
        )
        lat[sel] = np.asarray(la) / DEG_PER_RAD
        lon[sel] = _wrap(np.asarray(lo) / DEG_PER_RAD)
        _check_longitude_in_zone(lon[sel], n)
    return _out(lat), _out(lon)
