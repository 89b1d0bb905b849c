r"""Gauss–Krüger ↔ the local photogrammetric system X, Y, Z of chapter 2, §9–§11 of [1]_.

The local system (``docs/conventions.md`` §3, "the §10 system")
----------------------------------------------------------------
* Origin: a control point O, *on* the point (at its geodetic height H₀): O itself has
  X = Y = Z = 0 (Table 1 of [1]_).
* Z: along the ellipsoid normal at O, up.
* Y: in the tangent plane at O, in the azimuth γ₀ (the meridian convergence at O), i.e. the
  direction of grid north at O, so that the plane OYZ is parallel to the axial meridian
  ([1]_ §10, OCR L1093; Eq. (2.14)).
* X = Y × Z: in the tangent plane, ≈ grid east. (X, Y, Z) is **right-handed**.

Built step by step as in §9: the geocentric system with X′_Г in the meridian of O (2.7)–(2.8);
the topocentric north-east-up system X_Г Y_Г Z_Г of (2.9), which is **left-handed** although the
book calls it right (``docs/conventions.md`` §12, item 11); the right-handed east-north-up system
X′ Y′ Z′ of (2.11), obtained from (2.9) by the explicit swap X′ = Y_Г, Y′ = X_Г; finally the
rotation by +γ₀ about Z′ of (2.14).

Gauss–Krüger (x north, y east) is left-handed relative to (X, Y): to first order X ≈ Δy,
Y ≈ Δx, so the plane part of GK → local is a reflection (determinant < 0 in the (north, east)
order). That reflection is the axis swap written out in ``local_from_gauss_kruger_corrections``
(Eq. (2.30): X = Δy + δX, Y = Δx + δY) and is why the similarity of (6.8) has det < 0.

Two families of functions:

* rigorous (§9): GK → B, L (pyproj) → geocentric (2.7) → local (2.11), (2.14), and back
  (``local_from_gauss_kruger``, ``gauss_kruger_from_local``). Round trip ≤ 1e-6 m.
* the book's direct §10–§11 forms with the errata of ``docs/conventions.md`` §12 items 15–18
  (``gauss_kruger_reductions``, ``local_from_gauss_kruger_direct`` (2.28),
  ``local_from_gauss_kruger_corrections`` (2.30), ``gauss_kruger_from_local_direct``
  (2.32)–(2.38), ``gauss_kruger_from_local_corrections`` (2.39)–(2.41)). They agree with the
  rigorous transform to about 1 cm over 100 × 100 km ([1]_ §10) and give the linearised
  similarity of (6.8): b ≈ 1 + k, a ≈ −(1 + k)·δ₀ᵢ.

Heights are geodetic heights H; for normal heights use ``geodetic_height`` (2.6) first (the book's
examples take ζ = 0). Angles in radians, lengths in metres.

References
----------
.. [1] Куштин (Kushtin) & Лысков (Lyskov), *Фотограмметрия снимка и стереоскопических моделей*,
   Moscow: Nedra, 1984, ch. 2, §9–§11, pp. 36–52 (OCR L896–1340).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.constants import KRASOVSKY
from stereoplotter.geodesy.gauss_kruger import (
    check_zone,
    gauss_kruger_from_geographic,
    geographic_from_gauss_kruger,
    meridian_convergence,
)
from stereoplotter.geodesy.geocentric import geocentric_from_geodetic, geodetic_from_geocentric
from stereoplotter.geometry.rotation import rotation_z

__all__ = [
    "ChordReductions",
    "LocalFrame",
    "MeridianFrameCoordinates",
    "gauss_kruger_from_local",
    "gauss_kruger_from_local_corrections",
    "gauss_kruger_from_local_direct",
    "gauss_kruger_reductions",
    "geocentric_from_local",
    "height_correction_from_local",
    "local_from_gauss_kruger",
    "local_from_gauss_kruger_corrections",
    "local_from_gauss_kruger_direct",
    "local_from_geocentric",
    "meridian_frame_from_geodetic",
]


def _out(a: ArrayLike) -> NDArray[np.float64]:
    return np.asarray(a, dtype=float)[()]


@dataclass(frozen=True, slots=True)
class LocalFrame:
    """Origin and orientation of the photogrammetric system of [1]_ §9–§10.

    Build it with :meth:`from_gauss_kruger` or :meth:`from_geographic`; the fields are derived
    consistently there.

    Attributes
    ----------
    zone : int
        Gauss–Krüger zone N of the origin's plane coordinates. [—]
    origin_north_m, origin_east_m : float
        Plain Gauss–Krüger x₀, y₀ of the origin O. [m]
    origin_height_m : float
        Geodetic height H₀ of O. [m]
    latitude, longitude : float
        Geodetic B₀, L₀ of O (L₀ here is O's longitude, as in (2.7)–(2.9), not the axial
        meridian). [rad]
    convergence : float
        Meridian convergence γ₀ at O, rigorous (pyproj). [rad]
    """

    zone: int
    origin_north_m: float
    origin_east_m: float
    origin_height_m: float
    latitude: float
    longitude: float
    convergence: float

    @classmethod
    def from_gauss_kruger(
        cls, gk_north_m: float, gk_east_m: float, height_m: float, zone: int
    ) -> LocalFrame:
        """Frame with its origin at the point with plain GK x₀, y₀ [m] and height H₀ [m].

        Examples
        --------
        >>> frame = LocalFrame.from_gauss_kruger(6140794.660, 235949.468, 500.0, zone=4)
        >>> round(float(np.degrees(frame.convergence)), 7)
        3.0600618
        """
        n = check_zone(zone)
        b0, l0 = geographic_from_gauss_kruger(gk_north_m, gk_east_m, n)
        gamma = meridian_convergence(b0, l0, n)
        return cls(
            zone=n,
            origin_north_m=float(gk_north_m),
            origin_east_m=float(gk_east_m),
            origin_height_m=float(height_m),
            latitude=float(b0),
            longitude=float(l0),
            convergence=float(gamma),
        )

    @classmethod
    def from_geographic(
        cls, latitude: float, longitude: float, height_m: float, zone: int
    ) -> LocalFrame:
        """Frame with its origin at geodetic B₀ [rad], L₀ [rad], H₀ [m]; GK of zone N."""
        n = check_zone(zone)
        x0, y0 = gauss_kruger_from_geographic(latitude, longitude, n)
        return cls(
            zone=n,
            origin_north_m=float(x0),
            origin_east_m=float(y0),
            origin_height_m=float(height_m),
            latitude=float(latitude),
            longitude=float(longitude),
            convergence=float(meridian_convergence(latitude, longitude, n)),
        )

    @property
    def rotation(self) -> NDArray[np.float64]:
        r"""Rotation from Earth-centred (Greenwich) differences to local X, Y, Z. [—]

        Rows are the local X, Y, Z axes in the Earth-centred system:
        R = R_Z(γ₀)·[e; n; u] with e, n, u the east, north and up unit vectors at O. The
        east-north-up rows are (2.11) (the swap of (2.9)'s north-east-up into east-north-up);
        R_Z(+γ₀) is (2.14): X = X′ cos γ₀ − Y′ sin γ₀, Y = Y′ cos γ₀ + X′ sin γ₀.
        """
        sb, cb = np.sin(self.latitude), np.cos(self.latitude)
        sl, cl = np.sin(self.longitude), np.cos(self.longitude)
        enu = np.array(
            [
                [-sl, cl, 0.0],  # X′ = Y_Г: east (2.11), first line
                [-sb * cl, -sb * sl, cb],  # Y′ = X_Г: north (2.9)/(2.11), second line
                [cb * cl, cb * sl, sb],  # Z′ = Z_Г: up, along the normal
            ]
        )
        return rotation_z(self.convergence) @ enu  # (2.14)

    @property
    def origin_geocentric_m(self) -> NDArray[np.float64]:
        """Earth-centred coordinates of O, Eq. (2.8) with L₀ = 0. [m]"""
        return np.array(
            geocentric_from_geodetic(self.latitude, self.longitude, self.origin_height_m),
            dtype=float,
        )


def local_from_geocentric(
    frame: LocalFrame, x_m: ArrayLike, y_m: ArrayLike, z_m: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    r"""Local photogrammetric X, Y, Z from Earth-centred coordinates.

    Parameters
    ----------
    frame : LocalFrame
        Origin O and orientation.
    x_m, y_m, z_m : float or ndarray
        Earth-centred X′_Г, Y′_Г, Z′_Г (X′_Г towards Greenwich). [m]

    Returns
    -------
    X_m, Y_m, Z_m : ndarray
        Local coordinates: X ≈ grid east, Y = grid north at O, Z up along O's normal. [m]

    Notes
    -----
    Implements Eqs. (2.9), (2.11) and (2.14) of [1]_ (§9, OCR L909, L963–967, L1001–1005):
    the left-handed north-east-up X_Г Y_Г Z_Г of (2.9) is swapped into the right-handed
    east-north-up X′ Y′ Z′ of (2.11) (X′ = Y_Г, Y′ = X_Г), then rotated by γ₀ about Z′ (2.14).
    Rigorous; in double precision the 10–11 significant digits the book asks for are no problem.
    """
    d = np.stack(np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (x_m, y_m, z_m))), -1)
    local = (d - frame.origin_geocentric_m) @ frame.rotation.T
    return _out(local[..., 0]), _out(local[..., 1]), _out(local[..., 2])


def geocentric_from_local(
    frame: LocalFrame, X_m: ArrayLike, Y_m: ArrayLike, Z_m: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Earth-centred coordinates from local photogrammetric X, Y, Z (inverse of
    ``local_from_geocentric``).

    Parameters
    ----------
    frame : LocalFrame
        Origin O and orientation.
    X_m, Y_m, Z_m : float or ndarray
        Local coordinates. [m]

    Returns
    -------
    x_m, y_m, z_m : ndarray
        Earth-centred X′_Г, Y′_Г, Z′_Г. [m]

    Notes
    -----
    Steps 1–4 of the inverse procedure of [1]_ §9 (OCR L1020–1110): undo (2.14), swap back to
    (2.9), rotate by B₀ and add the origin (2.8). The rotation is orthogonal, so its inverse is
    its transpose.
    """
    d = np.stack(np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (X_m, Y_m, Z_m))), -1)
    g = d @ frame.rotation + frame.origin_geocentric_m
    return _out(g[..., 0]), _out(g[..., 1]), _out(g[..., 2])


def local_from_gauss_kruger(
    frame: LocalFrame, gk_north_m: ArrayLike, gk_east_m: ArrayLike, height_m: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    r"""Local photogrammetric X, Y, Z from plain Gauss–Krüger x, y and geodetic height (rigorous).

    Parameters
    ----------
    frame : LocalFrame
        Origin O and orientation; its zone is the zone of ``gk_north_m``, ``gk_east_m``.
    gk_north_m : float or ndarray
        Gauss–Krüger x (north). [m]
    gk_east_m : float or ndarray
        Plain Gauss–Krüger y (east, from the axial meridian). [m]
    height_m : float or ndarray
        Geodetic height H. [m]

    Returns
    -------
    X_m, Y_m, Z_m : ndarray
        Local coordinates (X ≈ east, Y ≈ north, Z up; right-handed). [m]

    Notes
    -----
    The procedure of [1]_ §9, Table 1 (OCR L1039–1056): Eq. (2.10) (replaced by pyproj, see
    ``geographic_from_gauss_kruger``), then (2.7), (2.8), (2.11) and (2.14). For the book's
    point 1 it gives X = 10 366.524, Y = −30 844.118, Z = 1907.048 m; Table 1 prints 10 366.519,
    −30 844.115, 1907.048 (its X′ is 5 mm low from a rounded l₁ − l₀).

    Examples
    --------
    >>> frame = LocalFrame.from_gauss_kruger(6140794.660, 235949.468, 500.0, zone=4)
    >>> X, Y, Z = local_from_gauss_kruger(frame, 6109939.518, 246316.596, 2490.0)
    >>> round(float(X), 3), round(float(Y), 3), round(float(Z), 3)
    (10366.524, -30844.118, 1907.048)
    """
    b, lon = geographic_from_gauss_kruger(gk_north_m, gk_east_m, frame.zone)  # (2.10), pyproj
    geocentric = geocentric_from_geodetic(b, lon, height_m)  # (2.7)
    return local_from_geocentric(frame, *geocentric)  # (2.8), (2.11), (2.14)


def gauss_kruger_from_local(
    frame: LocalFrame, X_m: ArrayLike, Y_m: ArrayLike, Z_m: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    r"""Plain Gauss–Krüger x, y and geodetic height from local X, Y, Z (rigorous).

    Parameters
    ----------
    frame : LocalFrame
        Origin O and orientation; the result is in ``frame.zone``.
    X_m, Y_m, Z_m : float or ndarray
        Local coordinates. [m]

    Returns
    -------
    gk_north_m, gk_east_m : ndarray
        Gauss–Krüger x (north) and plain y (east). [m]
    height_m : ndarray
        Geodetic height H. [m]

    Notes
    -----
    The inverse procedure of [1]_ §9, Table 2 (OCR L1020–1127): steps 1–4 (inverse of (2.14),
    (2.11), (2.9), (2.8)), step 5 (Eq. (2.15), replaced by PROJ's exact geocentric inverse) and
    step 6 (Eq. (2.16), replaced by pyproj's transverse Mercator).

    Examples
    --------
    >>> frame = LocalFrame.from_gauss_kruger(6140794.660, 235949.468, 500.0, zone=4)
    >>> x, y, h = gauss_kruger_from_local(frame, 10366.524, -30844.118, 1907.048)
    >>> round(float(x), 2), round(float(y), 2), round(float(h), 2)
    (6109939.52, 246316.6, 2490.0)
    """
    geocentric = geocentric_from_local(frame, X_m, Y_m, Z_m)
    b, lon, h = geodetic_from_geocentric(*geocentric)  # (2.15) via PROJ
    x, y = gauss_kruger_from_geographic(b, lon, frame.zone)  # (2.16) via pyproj
    return x, y, h


class MeridianFrameCoordinates(NamedTuple):
    """Result of Eq. (2.12): coordinates in the east-north-up system X′ Y′ Z′ at O. [m]"""

    x_east_m: NDArray[np.float64]  #: X′ (east at O) [m]
    y_north_m: NDArray[np.float64]  #: Y′ (north at O) [m]
    z_up_m: NDArray[np.float64]  #: Z′ (along O's normal) [m]
    v_m: NDArray[np.float64]  #: v = 2(N + H) sin²(l/2) of (2.13) [m]
    q_m: NDArray[np.float64]  #: Q = e²(N sin B − N₀ sin B₀) of (2.13) [m]


def meridian_frame_from_geodetic(
    frame: LocalFrame, latitude: ArrayLike, longitude: ArrayLike, height_m: ArrayLike
) -> MeridianFrameCoordinates:
    r"""East-north-up X′, Y′, Z′ at O from geodetic B, L, H by the book's stable form (2.12).

    Parameters
    ----------
    frame : LocalFrame
        Origin O (B₀, L₀, H₀).
    latitude, longitude : float or ndarray
        Geodetic B, L of the points. [rad]
    height_m : float or ndarray
        Geodetic height H. [m]

    Returns
    -------
    MeridianFrameCoordinates
        X′, Y′, Z′ before the rotation by γ₀ of (2.14), and the auxiliaries v, Q. [m]

    Notes
    -----
    Implements Eqs. (2.12)–(2.13) of [1]_ (§9, OCR L973–995), the differences of (2.11)
    rewritten so that no large numbers cancel:

    .. math::
        X' = (N + H)\cos B\sin l,\qquad
        Y' = (N + H)\sin\Delta B + v\cos B\sin B_0 - Q\cos B_0,

        Z' = \left[\frac{N_0 e'^2\sin\Delta B\sin(B + B_0)}{V(V_0 + V)} + (H - H_0)\right]
        \cos\Delta B - 2(N_0 + H_0)\sin^2\frac{\Delta B}{2} - v\cos B\cos B_0 - Q\sin B_0

    with l = L − L₀, ΔB = B − B₀, V = √(1 + e′² cos² B). ERRATA (``docs/conventions.md`` §12,
    item 13): the first Z′ term has e′², not e² as printed (with e², Z′ of Table 1 is 0.66 m
    off). With that fix it equals (2.11) to 1e-8 m.
    """
    ell = KRASOVSKY
    b = np.asarray(latitude, dtype=float)
    dl = np.asarray(longitude, dtype=float) - frame.longitude
    h = np.asarray(height_m, dtype=float)
    b0, h0 = frame.latitude, frame.origin_height_m
    n = ell.a_m / np.sqrt(1.0 - ell.e2 * np.sin(b) ** 2)
    n0 = ell.a_m / np.sqrt(1.0 - ell.e2 * np.sin(b0) ** 2)
    db = b - b0
    v = 2.0 * (n + h) * np.sin(dl / 2.0) ** 2  # (2.13)
    q = ell.e2 * (n * np.sin(b) - n0 * np.sin(b0))
    vv = np.sqrt(1.0 + ell.second_e2 * np.cos(b) ** 2)
    vv0 = np.sqrt(1.0 + ell.second_e2 * np.cos(b0) ** 2)
    x = (n + h) * np.cos(b) * np.sin(dl)  # (2.12)
    y = (n + h) * np.sin(db) + v * np.cos(b) * np.sin(b0) - q * np.cos(b0)
    z = (
        (n0 * ell.second_e2 * np.sin(db) * np.sin(b + b0) / (vv * (vv0 + vv)) + (h - h0))
        * np.cos(db)
        - 2.0 * (n0 + h0) * np.sin(db / 2.0) ** 2
        - v * np.cos(b) * np.cos(b0)
        - q * np.sin(b0)
    )
    return MeridianFrameCoordinates(*(_out(a) for a in (x, y, z, v, q)))


# ---------------------------------------------------------------------------------------------
# The book's direct forms, §10–§11


class ChordReductions(NamedTuple):
    """Auxiliary quantities of Eqs. (2.29) and (2.31) of [1]_ for the line O → i.

    All fields are ndarrays broadcast over the points. Angles [rad], lengths [m], others [—].
    """

    delta_north_m: NDArray[np.float64]  #: Δx = x_i − x₀ [m]
    delta_east_m: NDArray[np.float64]  #: Δy = y_i − y₀ [m]
    height_difference_m: NDArray[np.float64]  #: h = H_i − H₀ [m]
    mean_ordinate_m: NDArray[np.float64]  #: y_m = (y₀ + y_i)/2 [m]
    chord_length_m: NDArray[np.float64]  #: d [m]
    grid_bearing: NDArray[np.float64]  #: α, the grid bearing of the chord [rad]
    eta0_sq: float  #: η₀² = e′² cos² B₀ [—]
    v0: float  #: V₀ = √(1 + η₀²) [—]
    n0_m: float  #: N₀ = c/V₀ [m]
    rm_m: float  #: R_m = c/V₀² [m]
    convergence: float  #: γ₀ = (y₀/N₀) tan B₀, the book's first-order form [rad]
    epsilon: NDArray[np.float64]  #: ε = y_m²/(2R_m²) [—]
    arc_to_chord: NDArray[np.float64]  #: δ₀ᵢ [rad]
    azimuth: NDArray[np.float64]  #: A₀ = α + γ₀ − δ₀ᵢ [rad]
    ra_m: NDArray[np.float64]  #: R_A = N₀/(1 + η₀² cos² A₀) [m]
    scale_a: NDArray[np.float64]  #: A = −ε(1 − 5ε/6) − Δy²/(24R_m²) [—]
    scale_e: NDArray[np.float64]  #: E = h/(R_A + H₀) [—]
    geodesic_length_m: NDArray[np.float64]  #: s₀ = d(1 + A) [m]
    g: NDArray[np.float64]  #: g = s₀/(2R_A) [—]
    beta: NDArray[np.float64]  #: β = η₀² tan B₀ cos A₀ s₀²/(2N₀²) [—]
    s_prime_m: NDArray[np.float64]  #: s′ = s₀(1 + E)(1 + H₀/R_A) [m]
    distance_m: NDArray[np.float64]  #: D = s′(1 − 2g²/3) [m]
    scale_k: NDArray[np.float64]  #: k = D/d − 1 (the definition in (2.31)) [—]
    scale_k_as_printed: NDArray[np.float64]  #: k by the printed (2.31), without A·E [—]


def _reductions(
    frame: LocalFrame,
    dx: NDArray[np.float64],
    dy: NDArray[np.float64],
    h: NDArray[np.float64],
) -> ChordReductions:
    """Eqs. (2.29)/(2.31) for given Δx, Δy, h (shared by the forward and inverse forms)."""
    ell = KRASOVSKY
    b0, h0, y0 = frame.latitude, frame.origin_height_m, frame.origin_east_m
    eta0_sq = ell.second_e2 * np.cos(b0) ** 2  # (2.29): e′², not e² (errata item 15)
    v0 = np.sqrt(1.0 + eta0_sq)
    c = ell.polar_radius_c_m
    n0 = c / v0
    rm = c / v0**2
    gamma0 = y0 / n0 * np.tan(b0)  # (2.29), first-order convergence
    d = np.hypot(dx, dy)  # (2.18)
    alpha = np.arctan2(dy, dx)
    ym = y0 + dy / 2.0
    eps = ym**2 / (2.0 * rm**2)
    # (2.29)/(2.31): y_m, not y_m², in the bracket (errata item 17)
    delta = -dx / (2.0 * rm**2) * (ym - dy / 6.0 - 2.0 * eps * ym / 3.0 + eta0_sq * dy / 3.0)
    a0 = alpha + gamma0 - delta
    ra = n0 / (1.0 + eta0_sq * np.cos(a0) ** 2)
    scale_a = -eps * (1.0 - 5.0 * eps / 6.0) - dy**2 / (24.0 * rm**2)
    scale_e = h / (ra + h0)
    s0 = d * (1.0 + scale_a)
    g = s0 / (2.0 * ra)
    beta = eta0_sq * np.tan(b0) * np.cos(a0) / (2.0 * n0**2) * s0**2
    s_prime = s0 * (1.0 + scale_e) * (1.0 + h0 / ra)
    big_d = s_prime * (1.0 - 2.0 * g**2 / 3.0)
    # (2.31) k = D/d − 1, evaluated exactly (errata item 17: the printed expansion omits A·E;
    # (1 + A)(1 + E)(1 + H0/RA − s0²/(6RA²)) − 1 still drops H0·s0²/(6RA³), 3e-10 here)
    safe_d = np.where(d > 0.0, d, 1.0)
    k = np.where(d > 0.0, big_d / safe_d, (1 + scale_a) * (1 + scale_e) * (1 + h0 / ra)) - 1.0
    k_printed = scale_a + scale_e + (1 + scale_a) * (1 + scale_e) / ra * (h0 - s0**2 / (6 * ra))
    return ChordReductions(
        *(_out(v) for v in (dx, dy, h, ym, d, alpha)),
        float(eta0_sq),
        float(v0),
        float(n0),
        float(rm),
        float(gamma0),
        *(_out(v) for v in (eps, delta, a0, ra, scale_a, scale_e, s0, g, beta, s_prime, big_d)),
        _out(k),
        _out(k_printed),
    )


def gauss_kruger_reductions(
    frame: LocalFrame, gk_north_m: ArrayLike, gk_east_m: ArrayLike, height_m: ArrayLike
) -> ChordReductions:
    r"""Reductions of the chord O → i of the §10 direct method.

    Parameters
    ----------
    frame : LocalFrame
        Origin O (x₀, y₀, H₀, B₀).
    gk_north_m, gk_east_m : float or ndarray
        Plain Gauss–Krüger x_i, y_i of the points. [m]
    height_m : float or ndarray
        Geodetic heights H_i (the book: normal heights with ζ = 0). [m]

    Returns
    -------
    ChordReductions
        Every auxiliary quantity printed in Tables 3 and 4 of [1]_.

    Notes
    -----
    Implements Eqs. (2.18), (2.29) and (2.31) of [1]_ (§10, OCR L1100–1160, L1215–1220) with
    the errata of ``docs/conventions.md`` §12:

    * item 15: η₀² = e′² cos² B₀ (the OCR prints e²);
    * item 17: the δ₀ᵢ bracket holds y_m (not y_m²)

      .. math::
          \delta_{0i} = -\frac{\Delta x}{2R_m^2}\left(y_m - \frac{\Delta y}{6}
          - \frac{2\varepsilon y_m}{3} + \frac{\eta_0^2}{3}\Delta y\right)

      and k is evaluated as its definition D/d − 1 (= (1 + A)(1 + E)(1 + H₀/R_A)(1 − 2g²/3) − 1);
      the printed expansion k = A + E + (1 + A)(1 + E)(H₀ − s₀²/(6R_A))/R_A omits A·E (7 mm
      over 32 km) and is kept as ``scale_k_as_printed``.

    γ₀ here is the book's first-order (y₀/N₀) tan B₀ (Table 3: 3.0579055°, against the rigorous
    3.0600618°); it enters only through A₀ in R_A and β.

    Examples
    --------
    >>> frame = LocalFrame.from_gauss_kruger(6140794.660, 235949.468, 500.0, zone=4)
    >>> r = gauss_kruger_reductions(frame, 6109939.518, 246316.596, 2490.0)
    >>> round(float(r.chord_length_m), 3), round(float(r.distance_m), 3)
    (32550.225, 32539.583)
    """
    dx = np.asarray(gk_north_m, dtype=float) - frame.origin_north_m
    dy = np.asarray(gk_east_m, dtype=float) - frame.origin_east_m
    h = np.asarray(height_m, dtype=float) - frame.origin_height_m
    dx, dy, h = np.broadcast_arrays(dx, dy, h)
    return _reductions(frame, dx, dy, h)


def local_from_gauss_kruger_direct(
    frame: LocalFrame, gk_north_m: ArrayLike, gk_east_m: ArrayLike, height_m: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    r"""Local X, Y, Z from Gauss–Krüger x, y, H by the book's direct formulas (2.28).

    Parameters
    ----------
    frame : LocalFrame
        Origin O.
    gk_north_m, gk_east_m : float or ndarray
        Plain Gauss–Krüger x_i (north), y_i (east). [m]
    height_m : float or ndarray
        Geodetic heights H_i. [m]

    Returns
    -------
    X_m, Y_m, Z_m : ndarray
        Local coordinates. [m]

    Notes
    -----
    Implements Eq. (2.28) of [1]_ (§10, OCR L1136–1142) with the quantities of (2.29)
    (``gauss_kruger_reductions``):

    .. math::
        X = D\sin(\alpha - \delta_{0i}),\quad Y = D\cos(\alpha - \delta_{0i}),\quad
        Z = h - s'(g - \beta)

    α is the grid bearing from O; the Y axis is grid north at O, so the direction angle of the
    chord from Y is α − δ₀ᵢ. Good to about 1 cm for |Δx|, |Δy| ≤ 50 km. Table 3 gives X 10 366.529,
    Y −30 844.112, Z 1907.055; the Z is an arithmetic slip for 1907.048 (errata item 18).

    Examples
    --------
    >>> frame = LocalFrame.from_gauss_kruger(6140794.660, 235949.468, 500.0, zone=4)
    >>> X, Y, Z = local_from_gauss_kruger_direct(frame, 6109939.518, 246316.596, 2490.0)
    >>> round(float(X), 3), round(float(Y), 3), round(float(Z), 3)
    (10366.531, -30844.116, 1907.048)
    """
    r = gauss_kruger_reductions(frame, gk_north_m, gk_east_m, height_m)
    direction = r.grid_bearing - r.arc_to_chord
    x = r.distance_m * np.sin(direction)  # (2.28)
    y = r.distance_m * np.cos(direction)
    z = r.height_difference_m - r.s_prime_m * (r.g - r.beta)
    return _out(x), _out(y), _out(z)


def local_from_gauss_kruger_corrections(
    frame: LocalFrame,
    gk_north_m: ArrayLike,
    gk_east_m: ArrayLike,
    height_m: ArrayLike,
    k_as_printed: bool = False,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    r"""Local X, Y, Z as grid differences plus corrections, Eqs. (2.30)–(2.31).

    Parameters
    ----------
    frame : LocalFrame
        Origin O.
    gk_north_m, gk_east_m : float or ndarray
        Plain Gauss–Krüger x_i (north), y_i (east). [m]
    height_m : float or ndarray
        Geodetic heights H_i. [m]
    k_as_printed : bool, optional
        Use the book's printed k (without the A·E term) to reproduce Table 4; default False, the
        corrected k = D/d − 1.

    Returns
    -------
    X_m, Y_m, Z_m : ndarray
        Local coordinates. [m]

    Notes
    -----
    Implements Eqs. (2.30)–(2.31) of [1]_ (§10, OCR L1190–1220):

    .. math::
        X = \Delta y + \delta X,\quad Y = \Delta x + \delta Y,\quad Z = h + \delta h,

        \delta X = k\Delta y - (k + 1)\Delta x\,\delta_{0i},\quad
        \delta Y = k\Delta x + (k + 1)\Delta y\,\delta_{0i},\quad \delta h = -s'(g - \beta)

    Note the explicit axis swap: X (≈ east) takes Δy (east), Y (≈ north) takes Δx (north). As a
    map from (Δx, Δy) to (X, Y) it is [[−(1+k)δ₀ᵢ, 1+k], [1+k, (1+k)δ₀ᵢ]], a similarity with
    reflection (det = −(1+k)²(1+δ₀ᵢ²) < 0): the (6.8) form with b = 1 + k, a = −(1 + k)δ₀ᵢ
    (``docs/conventions.md`` §3). It drops the terms 2D(Δ/d) sin²(δ₀ᵢ/2) (≤ 2 mm at 50 km).

    Examples
    --------
    >>> frame = LocalFrame.from_gauss_kruger(6140794.660, 235949.468, 500.0, zone=4)
    >>> X, Y, Z = local_from_gauss_kruger_corrections(frame, 6109939.518, 246316.596, 2490.0)
    >>> round(float(X), 3), round(float(Y), 3), round(float(Z), 3)
    (10366.531, -30844.116, 1907.048)
    """
    r = gauss_kruger_reductions(frame, gk_north_m, gk_east_m, height_m)
    k = r.scale_k_as_printed if k_as_printed else r.scale_k
    dx, dy, delta = r.delta_north_m, r.delta_east_m, r.arc_to_chord
    x = dy + (k * dy - (k + 1.0) * dx * delta)  # (2.30), (2.31): X = Δy + δX
    y = dx + (k * dx + (k + 1.0) * dy * delta)  # Y = Δx + δY
    z = r.height_difference_m - r.s_prime_m * (r.g - r.beta)  # Z = h + δh
    return _out(x), _out(y), _out(z)


def _first_approximation(
    frame: LocalFrame, X: NDArray[np.float64], Y: NDArray[np.float64], Z: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Δx′ = Y, Δy′ = X, h′ = Z + D²/(2R_m) of (2.41) (and §11 after (2.38))."""
    ell = KRASOVSKY
    rm = ell.polar_radius_c_m / (1.0 + ell.second_e2 * np.cos(frame.latitude) ** 2)
    return Y, X, Z + (X**2 + Y**2) / (2.0 * rm)


def gauss_kruger_from_local_direct(
    frame: LocalFrame, X_m: ArrayLike, Y_m: ArrayLike, Z_m: ArrayLike, iterations: int = 2
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    r"""Gauss–Krüger x, y and height from local X, Y, Z by the book's §11 iteration (2.32)–(2.38).

    Parameters
    ----------
    frame : LocalFrame
        Origin O.
    X_m, Y_m, Z_m : float or ndarray
        Local coordinates. [m]
    iterations : int, optional
        Number of approximations. The book stops after the first for x, y (Table 5); the
        default 2 also converges h to 1 mm for |Δ| ≤ 50 km. [—]

    Returns
    -------
    gk_north_m, gk_east_m : ndarray
        Plain Gauss–Krüger x, y. [m]
    height_m : ndarray
        Geodetic height H = H₀ + h. [m]

    Notes
    -----
    Implements Eqs. (2.32)–(2.38) of [1]_ (§11, OCR L1255–1283):

    .. math::
        \alpha = \delta_{0i} + \arctan\frac{X}{Y},\quad D = \sqrt{X^2 + Y^2},\quad
        s' = \frac{D}{1 - 2g^2/3},\quad
        s_0 = \frac{s'}{(1 + h/(R_A + H_0))(1 + H_0/R_A)},

        d = s_0\left[1 + \varepsilon\left(1 + \frac{\varepsilon}{6}\right)
        + \frac{\Delta y^2}{24R_m^2}\right],\quad x = x_0 + d\cos\alpha,\quad
        y = y_0 + d\sin\alpha,\quad h = Z + s'(g - \beta)

    The reductions (2.29) are evaluated with the current approximation of Δx, Δy, h; the first
    approximation is Δx′ = Y, Δy′ = X, h′ = Z + D²/(2R_m), and g′ = D/(2R_A) in (2.34).

    Examples
    --------
    >>> frame = LocalFrame.from_gauss_kruger(6140794.660, 235949.468, 500.0, zone=4)
    >>> x, y, h = gauss_kruger_from_local_direct(frame, 10366.531, -30844.116, 1907.048)
    >>> round(float(x), 3), round(float(y), 3), round(float(h), 3)
    (6109939.518, 246316.596, 2490.0)
    """
    X, Y, Z = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (X_m, Y_m, Z_m)))
    h0 = frame.origin_height_m
    dx, dy, h = _first_approximation(frame, X, Y, Z)
    big_d = np.hypot(X, Y)  # (2.33)
    g = None
    for _ in range(max(int(iterations), 1)):
        r = _reductions(frame, dx, dy, h)
        alpha = r.arc_to_chord + np.arctan2(X, Y)  # (2.32)
        if g is None:
            g = big_d / (2.0 * r.ra_m)  # first approximation g′ = D/(2R_A)
        s_prime = big_d / (1.0 - 2.0 * g**2 / 3.0)  # (2.34)
        s0 = s_prime / ((1.0 + h / (r.ra_m + h0)) * (1.0 + h0 / r.ra_m))  # (2.35)
        # (2.36); Δy of the current approximation
        d = s0 * (1.0 + r.epsilon * (1.0 + r.epsilon / 6.0) + dy**2 / (24.0 * r.rm_m**2))
        dx, dy = d * np.cos(alpha), d * np.sin(alpha)  # (2.37)
        g = s0 / (2.0 * r.ra_m)
        beta = r.eta0_sq * np.tan(frame.latitude) * np.cos(r.azimuth) / (2 * r.n0_m**2) * s0**2
        h = Z + s_prime * (g - beta)  # (2.38)
    return (
        _out(frame.origin_north_m + dx),
        _out(frame.origin_east_m + dy),
        _out(h0 + h),
    )


def gauss_kruger_from_local_corrections(
    frame: LocalFrame,
    X_m: ArrayLike,
    Y_m: ArrayLike,
    Z_m: ArrayLike,
    iterations: int = 2,
    k_as_printed: bool = False,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    r"""Gauss–Krüger x, y and height from local X, Y, Z by corrections, Eqs. (2.39)–(2.41).

    Parameters
    ----------
    frame : LocalFrame
        Origin O.
    X_m, Y_m, Z_m : float or ndarray
        Local coordinates. [m]
    iterations : int, optional
        Number of approximations; the book does one (Table 6). [—]
    k_as_printed : bool, optional
        Use the printed k of (2.31) (Table 6); default False, the corrected k = D/d − 1.

    Returns
    -------
    gk_north_m, gk_east_m : ndarray
        Plain Gauss–Krüger x, y. [m]
    height_m : ndarray
        Geodetic height H = H₀ + h. [m]

    Notes
    -----
    Implements Eqs. (2.39)–(2.41) of [1]_ (§11, OCR L1305–1317), with δX, δY of (2.31):

    .. math::
        x = x_0 + Y - \delta Y,\quad y = y_0 + X - \delta X,\quad h = Z - \delta h,

        \delta h = -\frac{\delta h'\left(1 - \frac{D}{R_A}\eta_0^2\tan B_0\cos A_0\right)}
        {\left(1 - \frac{\delta h'}{3R_A}\right)^2
        \left(1 + \frac{H_0 + Z + \delta h'}{R_A + H_0}\right)},\quad
        \delta h' = \frac{D^2}{2R_A}

    (2.41): first approximation Δx ≈ Y, Δy ≈ X, h ≈ Z + D²/(2R_m), s₀ ≈ D. In later
    approximations the reductions use the current Δx, Δy, h. δh of (2.40) does not depend on the
    approximation except through A₀ and R_A.

    Examples
    --------
    >>> frame = LocalFrame.from_gauss_kruger(6140794.660, 235949.468, 500.0, zone=4)
    >>> x, y, h = gauss_kruger_from_local_corrections(frame, 10366.531, -30844.116, 1907.048)
    >>> round(float(x), 3), round(float(y), 3), round(float(h), 3)
    (6109939.518, 246316.596, 2490.0)
    """
    X, Y, Z = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (X_m, Y_m, Z_m)))
    dx, dy, h = _first_approximation(frame, X, Y, Z)  # (2.41)
    for _ in range(max(int(iterations), 1)):
        r = _reductions(frame, dx, dy, h)
        h = Z - _height_correction(frame, r, X, Y, Z)  # (2.39), third line
        r = _reductions(frame, dx, dy, h)  # E with the corrected h (as Table 6 does)
        k = r.scale_k_as_printed if k_as_printed else r.scale_k
        delta = r.arc_to_chord
        d_x = k * dy - (k + 1.0) * dx * delta  # (2.31), with the current Δx, Δy
        d_y = k * dx + (k + 1.0) * dy * delta
        dx, dy = Y - d_y, X - d_x  # (2.39)
    h0 = frame.origin_height_m
    return (
        _out(frame.origin_north_m + dx),
        _out(frame.origin_east_m + dy),
        _out(h0 + h),
    )


def _height_correction(
    frame: LocalFrame,
    r: ChordReductions,
    X: NDArray[np.float64],
    Y: NDArray[np.float64],
    Z: NDArray[np.float64],
) -> NDArray[np.float64]:
    h0, b0 = frame.origin_height_m, frame.latitude
    big_d = np.hypot(X, Y)  # (2.40)
    ra = r.ra_m
    dh_prime = big_d**2 / (2.0 * ra)  # (2.40)
    numerator = dh_prime * (1.0 - big_d / ra * r.eta0_sq * np.tan(b0) * np.cos(r.azimuth))
    denominator = (1.0 - dh_prime / (3.0 * ra)) ** 2 * (1.0 + (h0 + Z + dh_prime) / (ra + h0))
    return -numerator / denominator


def height_correction_from_local(
    frame: LocalFrame, X_m: ArrayLike, Y_m: ArrayLike, Z_m: ArrayLike
) -> NDArray[np.float64]:
    r"""Earth-curvature height correction δh of the inverse correction form, Eq. (2.40).

    Parameters
    ----------
    frame : LocalFrame
        Origin O.
    X_m, Y_m, Z_m : float or ndarray
        Local coordinates. [m]

    Returns
    -------
    ndarray
        δh, so that the height difference is h = Z − δh (2.39). Negative. [m]

    Notes
    -----
    Implements Eq. (2.40) of [1]_ (§11, OCR L1307–1312), with A₀ and R_A from the first
    approximation (2.41):

    .. math::
        \delta h = -\frac{\delta h'\left(1 - \frac{D}{R_A}\eta_0^2\tan B_0\cos A_0\right)}
        {\left(1 - \frac{\delta h'}{3R_A}\right)^2
        \left(1 + \frac{H_0 + Z + \delta h'}{R_A + H_0}\right)},\qquad
        \delta h' = \frac{D^2}{2R_A},\qquad D = \sqrt{X^2 + Y^2}

    Roughly −D²/(2R): −0.31 m at 2 km, −1.96 m at 5 km, −82.95 m at 32.5 km.

    Examples
    --------
    >>> frame = LocalFrame.from_gauss_kruger(6140794.660, 235949.468, 500.0, zone=4)
    >>> round(float(height_correction_from_local(frame, 0.0, 2000.0, 0.0)), 2)
    -0.31
    """
    X, Y, Z = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (X_m, Y_m, Z_m)))
    dx, dy, h = _first_approximation(frame, X, Y, Z)
    return _out(_height_correction(frame, _reductions(frame, dx, dy, h), X, Y, Z))
