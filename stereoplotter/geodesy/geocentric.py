r"""Geodetic B, L, H ↔ geocentric X′_Г, Y′_Г, Z′_Г on the Krasovsky ellipsoid, and heights.

Conventions
-----------
* The geocentric system O′X′_Г Y′_Г Z′_Г of [1]_ §8 (OCR L889): origin at the centre of the
  ellipsoid, Z′_Г along the minor axis (north), X′_Г in the plane of the meridian L = L_ref, Y′_Г
  completing a right-handed system. With L_ref = 0 (the default) this is the usual
  Earth-centred, Earth-fixed system; §9 uses L_ref = L₀, the longitude of the origin point.
* H is the geodetic height above the ellipsoid. Normal heights H^γ are related to it by
  H = H^γ + ζ (2.6), ζ the height of the quasigeoid above the reference ellipsoid.
* Angles in radians, lengths in metres. Functions broadcast over numpy arrays.

References
----------
.. [1] Куштин (Kushtin) & Лысков (Lyskov), *Фотограмметрия снимка и стереоскопических моделей*,
   Moscow: Nedra, 1984, ch. 2, §8–§9, pp. 33–44 (OCR L820–1090).
"""

from __future__ import annotations

from functools import cache
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pyproj import CRS, Transformer

from stereoplotter.constants import DEG_PER_RAD, KRASOVSKY, Ellipsoid

__all__ = [
    "BookIteration",
    "geocentric_from_geodetic",
    "geodetic_from_geocentric",
    "geodetic_from_geocentric_book_iteration",
    "geodetic_height",
    "normal_height",
    "prime_vertical_radius",
]


def _out(a: ArrayLike) -> NDArray[np.float64]:
    return np.asarray(a, dtype=float)[()]


@cache
def _geocentric_transformer() -> Transformer:
    name = KRASOVSKY.proj_name
    return Transformer.from_crs(
        CRS.from_proj4(f"+proj=longlat +ellps={name} +no_defs"),
        CRS.from_proj4(f"+proj=cart +ellps={name} +units=m +no_defs"),
        always_xy=True,
    )


def prime_vertical_radius(
    latitude: ArrayLike, ellipsoid: Ellipsoid = KRASOVSKY
) -> NDArray[np.float64]:
    r"""Radius of curvature in the prime vertical N = a / √(1 − e² sin² B).

    Parameters
    ----------
    latitude : float or ndarray
        Geodetic latitude B. [rad]
    ellipsoid : Ellipsoid, optional
        Reference ellipsoid; default Krasovsky.

    Returns
    -------
    ndarray
        N. [m]

    Notes
    -----
    Defined under Eq. (2.7) of [1]_ (OCR L905). Table 1 prints N = 6 392 734.306 m for point O
    (6 392 734.292 m with the exact B₀; the book's value is 14 mm high).

    Examples
    --------
    >>> round(float(prime_vertical_radius(np.radians(55.33374583))), 2)
    6392734.29
    """
    b = np.asarray(latitude, dtype=float)
    return _out(ellipsoid.a_m / np.sqrt(1.0 - ellipsoid.e2 * np.sin(b) ** 2))


def geocentric_from_geodetic(
    latitude: ArrayLike,
    longitude: ArrayLike,
    height_m: ArrayLike,
    reference_longitude: ArrayLike = 0.0,
    ellipsoid: Ellipsoid = KRASOVSKY,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    r"""Geocentric rectangular coordinates from geodetic B, L, H.

    Parameters
    ----------
    latitude : float or ndarray
        Geodetic latitude B. [rad]
    longitude : float or ndarray
        Geodetic longitude L. [rad]
    height_m : float or ndarray
        Geodetic height H above the ellipsoid. [m]
    reference_longitude : float or ndarray, optional
        Longitude L₀ of the meridian that contains the X′_Г axis; default 0 (Greenwich). [rad]
    ellipsoid : Ellipsoid, optional
        Reference ellipsoid; default Krasovsky.

    Returns
    -------
    X, Y, Z : ndarray
        X′_Г, Y′_Г, Z′_Г. [m]

    Notes
    -----
    Implements Eq. (2.7) of [1]_ (§9, OCR L899–903), closed form (no series):

    .. math::
        X'_Г = (N + H)\cos B\cos(L - L_0),\quad Y'_Г = (N + H)\cos B\sin(L - L_0),\quad
        Z'_Г = [N(1 - e^2) + H]\sin B

    For L = L₀ it is Eq. (2.8).

    Examples
    --------
    >>> x, y, z = geocentric_from_geodetic(0.0, 0.0, 0.0)
    >>> float(x), float(y), float(z)
    (6378245.0, 0.0, 0.0)
    """
    b = np.asarray(latitude, dtype=float)
    dl = np.asarray(longitude, dtype=float) - np.asarray(reference_longitude, dtype=float)
    h = np.asarray(height_m, dtype=float)
    n = prime_vertical_radius(b, ellipsoid)
    x = (n + h) * np.cos(b) * np.cos(dl)  # (2.7)
    y = (n + h) * np.cos(b) * np.sin(dl)
    z = (n * (1.0 - ellipsoid.e2) + h) * np.sin(b)
    return _out(x), _out(y), _out(z)


def geodetic_from_geocentric(
    x_m: ArrayLike, y_m: ArrayLike, z_m: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    r"""Geodetic B, L, H on the Krasovsky ellipsoid from Earth-centred X, Y, Z.

    Parameters
    ----------
    x_m, y_m, z_m : float or ndarray
        Geocentric coordinates, X′_Г towards Greenwich (reference longitude 0). [m]

    Returns
    -------
    latitude, longitude : ndarray
        Geodetic B, L. [rad]
    height_m : ndarray
        Geodetic height H. [m]

    Notes
    -----
    Solves the inverse of Eq. (2.7) of [1]_. The book iterates Eq. (2.15) (see
    ``geodetic_from_geocentric_book_iteration``); here PROJ's ``+proj=cart`` inverse replaces that
    iteration (accurate to well below 1e-6 m near the Earth's surface).

    Examples
    --------
    >>> b, l, h = geodetic_from_geocentric(*geocentric_from_geodetic(0.9, 0.4, 2490.0))
    >>> round(float(b), 12), round(float(l), 12), round(float(h), 6)
    (0.9, 0.4, 2490.0)
    """
    lon, lat, h = _geocentric_transformer().transform(
        np.asarray(x_m, dtype=float),
        np.asarray(y_m, dtype=float),
        np.asarray(z_m, dtype=float),
        direction="INVERSE",
        errcheck=True,
    )
    return (
        _out(np.asarray(lat) / DEG_PER_RAD),
        _out(np.asarray(lon) / DEG_PER_RAD),
        _out(h),
    )


class BookIteration(NamedTuple):
    """One approximation of the iteration (2.15): B, N, H. [rad], [m], [m]"""

    latitude: NDArray[np.float64]
    prime_vertical_radius_m: NDArray[np.float64]
    height_m: NDArray[np.float64]


def geodetic_from_geocentric_book_iteration(
    x_m: ArrayLike,
    y_m: ArrayLike,
    z_m: ArrayLike,
    iterations: int = 3,
    reference_longitude: ArrayLike = 0.0,
    ellipsoid: Ellipsoid = KRASOVSKY,
) -> tuple[NDArray[np.float64], list[BookIteration]]:
    r"""Geodetic B, L, H from geocentric coordinates by the book's iteration (2.15).

    Parameters
    ----------
    x_m, y_m, z_m : float or ndarray
        X′_Г, Y′_Г, Z′_Г, with X′_Г in the meridian ``reference_longitude``. [m]
    iterations : int, optional
        Number of approximations; the book prints three (Table 2). [—]
    reference_longitude : float or ndarray, optional
        L₀ of Eq. (2.15). [rad]
    ellipsoid : Ellipsoid, optional
        Reference ellipsoid; default Krasovsky.

    Returns
    -------
    longitude : ndarray
        L = L₀ + arctan(Y′_Г / X′_Г). [rad]
    approximations : list of BookIteration
        (B, N, H) after each approximation, the first with H = 0 in the B formula.

    Notes
    -----
    Implements Eq. (2.15) of [1]_ (§9, OCR L1114–1118):

    .. math::
        \cot B = \frac{R}{Z'_Г}(1 - e^2) + \frac{e^2 R H}{(N + H) Z'_Г},\qquad
        H = \frac{Z'_Г}{\sin B} - N(1 - e^2) = R\sec B - N,\qquad R = \sqrt{X'^2_Г + Y'^2_Г}

    The first approximation takes H = 0 in the B formula. H is evaluated by the first form where
    |B| > 45° (as Table 2 does: it gives H^I = 2484.5 m, the second form 2501.2 m) and by the
    second elsewhere. Each step gains about two orders of magnitude (Table 2: H = 2484.493,
    2490.209, 2490.165 m; the last is 0.165 m off because the book's Z′_Г0 is 0.15 m high).
    Use ``geodetic_from_geocentric`` for production work.

    Examples
    --------
    >>> xyz = geocentric_from_geodetic(0.96, 0.0, 2490.0)
    >>> _, steps = geodetic_from_geocentric_book_iteration(*xyz, iterations=4)
    >>> round(float(steps[-1].height_m), 4)
    2490.0
    """
    x = np.asarray(x_m, dtype=float)
    y = np.asarray(y_m, dtype=float)
    z = np.asarray(z_m, dtype=float)
    e2 = ellipsoid.e2
    r = np.hypot(x, y)
    longitude = np.asarray(reference_longitude, dtype=float) + np.arctan2(y, x)
    h = np.zeros(np.broadcast(x, y, z).shape)
    n = np.full_like(h, ellipsoid.a_m)
    steps: list[BookIteration] = []
    for _ in range(iterations):
        cot_b = r / z * (1.0 - e2) + e2 * r * h / ((n + h) * z)  # (2.15), second line
        b = np.arctan2(1.0, cot_b)
        n = prime_vertical_radius(b, ellipsoid)
        # (2.15), third line: H = Z/sin B − N(1 − e²) = R sec B − N. Table 2 uses the first
        # form (the second gives H^I = 2501.2 m, not 2484.5 m); it is the better conditioned
        # one for |B| > 45°, the second below.
        steep = np.abs(np.sin(b)) > np.abs(np.cos(b))
        with np.errstate(divide="ignore", invalid="ignore"):
            h = np.where(steep, z / np.sin(b) - n * (1.0 - e2), r / np.cos(b) - n)
        steps.append(BookIteration(_out(b), _out(n), _out(h)))
    return _out(longitude), steps


def geodetic_height(normal_height_m: ArrayLike, height_anomaly_m: ArrayLike) -> NDArray[np.float64]:
    """Geodetic height H = H^γ + ζ.

    Parameters
    ----------
    normal_height_m : float or ndarray
        Normal height H^γ (Baltic system). [m]
    height_anomaly_m : float or ndarray
        Height ζ of the quasigeoid above the reference ellipsoid. [m]

    Returns
    -------
    ndarray
        Geodetic height H. [m]

    Notes
    -----
    Implements Eq. (2.6) of [1]_ (§8, OCR L881). The book's worked examples (Tables 1–6) take
    ζ = 0, i.e. they use the heights as geodetic.

    Examples
    --------
    >>> float(geodetic_height(500.0, 12.5))
    512.5
    """
    return _out(np.asarray(normal_height_m, dtype=float) + np.asarray(height_anomaly_m, float))


def normal_height(height_m: ArrayLike, height_anomaly_m: ArrayLike) -> NDArray[np.float64]:
    """Normal height H^γ = H − ζ.

    Parameters
    ----------
    height_m : float or ndarray
        Geodetic height H. [m]
    height_anomaly_m : float or ndarray
        Height ζ of the quasigeoid above the reference ellipsoid. [m]

    Returns
    -------
    ndarray
        Normal height H^γ. [m]

    Notes
    -----
    Implements Eq. (2.17) of [1]_ (§9, OCR L1080).

    Examples
    --------
    >>> float(normal_height(512.5, 12.5))
    500.0
    """
    return _out(np.asarray(height_m, dtype=float) - np.asarray(height_anomaly_m, float))
