r"""Pure kinematics of a transformed-bundle stereoplotter (SC-1, SPR-3, SD-3).

The correction unit of each photo (correction plane + decentration + cassette rotation) and the
instrument's two rods, as closed-form, vectorised maps between counter readings, rod coordinates
and photo coordinates. The model is fixed by ``kinematics.md`` (design decision, §2–§4 and §8);
this module implements its §3.3 (forward map) and §3.4 (inverse maps); the settings of a unit and
the knob semantics of decision D1 (§4.1, §8) are :mod:`stereoplotter.instrument.knobs`.

Reference
---------
.. [1] Kushtin I. F. & Lyskov G. A., *Фотограмметрия снимка и стереоскопических моделей*,
   Moscow: Nedra, 1984, ch. 6, §26–§27, pp. 153–163 (OCR L3680–4030).
.. [2] F. V. Drobyshev, "Soviet stereophotogrammetric instruments", ISP Congress 1960,
   Comm. II, pp. 767–773 (transformed bundles, k = F/f_k, planes at kα, kω).

Frames and conventions (``kinematics.md`` §3.1)
-----------------------------------------------
* Counters X, Y [mm] along the instrument guides; D [mm] = reading of the absolute height counter
  = depth of the model point below the left pivot S_л. The counters read MO_X, MO_Y with the left
  mark on the plumb of S_л. The right pivot is S_п = S_л + (b_x, b_y, b_z′), b_z′ = k·b_z.
* Rod coordinates (ξ, η) [mm] of a photo: the horizontal offset of the model point from the
  pivot's plumb divided by n = D_j / f_пр, i.e. the book's x⁰/n, y⁰/n: nadir-referenced
  rectified coordinates at the camera principal distance f′.
* Photo coordinates (x, y) [mm] in the fiducial system, principal point at the origin, positive
  plane. κ turns the cassette about its centre, innermost (after the tilts).
* Tilts are represented by T_α = tan θ_α / k, T_ω = tan θ_ω / k: the tangent of the tilt that the
  correction plane of inclination θ represents (tan θ = k tan α, [2] eq. (4)).

Shapes: every function broadcasts. A point argument has shape ``(..., 2)``; the fields of a
:class:`CorrectionUnit` or :class:`InstrumentSetting` and the counters are scalars or arrays that
broadcast against the leading dimensions ``...`` of the points (e.g. one row per trial and one
column per point).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.decentration_variants import LINKAGES
from stereoplotter.instrument.row_blocks import ndim, rowwise

__all__ = [
    "CorrectionUnit",
    "InstrumentSetting",
    "StereoReading",
    "UnitMap",
    "counters_from_homologous_points",
    "counters_from_photo",
    "depths_of_homologous_points",
    "marks_from_counters",
    "parallaxes_at_marks",
    "photo_from_rod",
    "rod_frame",
    "rod_from_counters",
    "rod_from_photo",
    "rods_intersection",
    "rods_intersection_xy",
    "rods_y_parallax",
    "x_parallaxes_at_marks",
]


def _a(v: ArrayLike) -> NDArray[np.float64]:
    return np.asarray(v, dtype=float)


def _pair(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """Stack two broadcastable arrays along a new last axis (..., 2), without broadcast views."""
    out = np.empty((*np.broadcast_shapes(np.shape(a), np.shape(b)), 2))
    out[..., 0] = a
    out[..., 1] = b
    return out


@dataclass(frozen=True, slots=True)
class CorrectionUnit:
    r"""State of the correction unit of one photo (``kinematics.md`` §3.2).

    Every field is a scalar or an array; arrays broadcast against the leading dimensions of the
    points passed to :func:`photo_from_rod` and :func:`rod_from_photo`.

    Attributes
    ----------
    focal_length_mm : float or ndarray
        f′, the camera principal distance known to the unit (decision D3). [mm]
    tan_alpha, tan_omega : float or ndarray
        T_α = tan θ_α / k, T_ω = tan θ_ω / k: the tangent of the tilt represented by the
        correction-plane settings "k_α", "k_ω". [—]
    decentration_x_mm, decentration_y_mm : float or ndarray
        e = (e_x, e_y): the photo decentration. [mm]
    kappa : float or ndarray
        κ, the cassette rotation about its centre. [rad]
    plane_decentration_x_mm, plane_decentration_y_mm : float, ndarray or None
        c = (c_x, c_y): the decentration of the correction plane. None (default) means c = e,
        the merged pair of decision D2; separate values are needed for variant "A". [mm]
    strict_per_axis : bool
        Use the strict per-axis mechanism (α only in x, ω only in y, no common change of F;
        ``kinematics.md`` §3.3, last paragraph) instead of the correction plane.
    mechanism : CorrectionMechanism or None
        The instrument's own construction (:mod:`stereoplotter.instrument.principles`): its
        second-order scale factor s multiplies τ·(ξ, η) before the decentration. None: s = 1.
    """

    focal_length_mm: ArrayLike
    tan_alpha: ArrayLike = 0.0
    tan_omega: ArrayLike = 0.0
    decentration_x_mm: ArrayLike = 0.0
    decentration_y_mm: ArrayLike = 0.0
    kappa: ArrayLike = 0.0
    plane_decentration_x_mm: ArrayLike | None = None
    plane_decentration_y_mm: ArrayLike | None = None
    strict_per_axis: bool = False
    mechanism: Any = None

    @property
    def plane_decentration_mm(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(c_x, c_y), with the D2 default c = e resolved. [mm]"""
        cx = self.decentration_x_mm
        cy = self.decentration_y_mm
        if self.plane_decentration_x_mm is not None:
            cx = self.plane_decentration_x_mm
        if self.plane_decentration_y_mm is not None:
            cy = self.plane_decentration_y_mm
        return _a(cx), _a(cy)


@dataclass(frozen=True, slots=True)
class InstrumentSetting:
    r"""Global state of the instrument apart from the counters (``kinematics.md`` §3.2).

    The counters X, Y and the absolute height counter D are passed to the functions as arrays (one
    value per point or per trial), so that one setting serves many points.

    Attributes
    ----------
    f_instrument_mm : float or ndarray
        f_пр, the instrument principal distance. [mm]
    base_x_mm, base_y_mm : float or ndarray
        b_x, b_y at the horizontal model scale. [mm]
    base_z_mm : float or ndarray
        b_z′ = k·b_z, the vertical base component as set (positive: right pivot higher). [mm]
    model_origin_x_mm, model_origin_y_mm : float or ndarray
        MO_X, MO_Y: the counter readings with the left mark on the plumb of S_л. [mm]
    """

    f_instrument_mm: ArrayLike
    base_x_mm: ArrayLike = 0.0
    base_y_mm: ArrayLike = 0.0
    base_z_mm: ArrayLike = 0.0
    model_origin_x_mm: ArrayLike = 0.0
    model_origin_y_mm: ArrayLike = 0.0

    def pivot(self, side: str) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray]:
        """Plumb position (S_x, S_y) [mm] and height above S_л [mm] of the "left"/"right" pivot."""
        if side == "left":
            return _a(self.model_origin_x_mm), _a(self.model_origin_y_mm), _a(0.0)
        if side == "right":
            return (
                _a(self.model_origin_x_mm) + _a(self.base_x_mm),
                _a(self.model_origin_y_mm) + _a(self.base_y_mm),
                _a(self.base_z_mm),
            )
        raise StereoplotterError(f"side must be 'left' or 'right', found {side!r}")


class StereoReading(NamedTuple):
    """Counters of a model point seen in both photos, and the y-parallax left there.

    Attributes
    ----------
    x_mm, y_mm : ndarray
        X, Y counters. [mm]
    depth_mm : ndarray
        D, the absolute height counter (depth below S_л). [mm]
    y_parallax_mm : ndarray
        q, the y-parallax in photo mm (n·q in model mm). [mm]
    """

    x_mm: NDArray[np.float64]
    y_mm: NDArray[np.float64]
    depth_mm: NDArray[np.float64]
    y_parallax_mm: NDArray[np.float64]


# --------------------------------------------------------------------------------------------
# The correction unit: rod coordinates <-> photo coordinates
# --------------------------------------------------------------------------------------------


def photo_from_rod(rod_mm: ArrayLike, unit: CorrectionUnit) -> NDArray[np.float64]:
    r"""Photo point under the mark for given rod coordinates (the correction unit's forward map).

    Parameters
    ----------
    rod_mm : array_like, shape (..., 2)
        Rod coordinates (ξ, η) = ((X − S_x)/n, (Y − S_y)/n), the book's x⁰/n, y⁰/n. [mm]
    unit : CorrectionUnit
        State of the photo's correction unit.

    Returns
    -------
    ndarray, shape (..., 2)
        (x, y), photo coordinates in the fiducial system. [mm]

    Notes
    -----
    Implements ``kinematics.md`` §3.3 (correction plane with common change of F, then photo
    decentration, then the cassette rotation):

    .. math::
        \tau = \frac{f' + c_x T_\alpha + c_y T_\omega}{f' + \xi T_\alpha + \eta T_\omega},\quad
        (u, v) = \tau\,(\xi, \eta) - (e_x, e_y),\quad
        (x, y)^T = R_2(\kappa)^T (u, v)^T

    with R₂(κ) = [[cos κ, −sin κ], [sin κ, cos κ]]. With e = c = f′(T_α, T_ω) and κ = 0 a point
    on a fiducial axis obeys Eq. (6.1) (x axis) or Eq. (6.2) (y axis) of [1]_ exactly, for any
    combination of α and ω; off the axes the unit is the per-axis approximation (§3.3, §6).

    With ``unit.strict_per_axis`` the plane is replaced by two independent single-axis units,
    u = ξ (f′ + c_x T_α)/(f′ + ξ T_α) − e_x and v = η (f′ + c_y T_ω)/(f′ + η T_ω) − e_y
    (§3.3, last paragraph; with e = c = f′T this is x = f′(ξ − f′T_α)/(f′ + ξT_α)).

    Examples
    --------
    The principal point of a photo tilted by α = 3° lies under the rod at x⁰ = f′ tan α:

    >>> import numpy as np
    >>> from stereoplotter.instrument.knobs import unit_for_orientation
    >>> unit = unit_for_orientation(np.radians(3.0), 0.0, 0.0, 100.0)
    >>> np.round(photo_from_rod([100.0 * np.tan(np.radians(3.0)), 0.0], unit), 12) + 0.0
    array([0., 0.])
    """
    return UnitMap(unit).photo_from_rod(rod_mm)


def rod_from_photo(photo_mm: ArrayLike, unit: CorrectionUnit) -> NDArray[np.float64]:
    r"""Rod coordinates that bring the mark onto a photo point (inverse of :func:`photo_from_rod`).

    Parameters
    ----------
    photo_mm : array_like, shape (..., 2)
        (x, y), photo coordinates in the fiducial system. [mm]
    unit : CorrectionUnit
        State of the photo's correction unit.

    Returns
    -------
    ndarray, shape (..., 2)
        (ξ, η), rod coordinates (the book's x⁰/n, y⁰/n). [mm]

    Notes
    -----
    Implements ``kinematics.md`` §3.4, closed form:

    .. math::
        (u, v)^T = R_2(\kappa)(x, y)^T,\quad P = (u + e_x, v + e_y),\quad
        \tau = \frac{f' + c_x T_\alpha + c_y T_\omega - P_x T_\alpha - P_y T_\omega}{f'},\quad
        (\xi, \eta) = P / \tau

    On the fiducial axes, with the true settings (e = c = f′ tan α, f′ tan ω; κ = 0), ξ of a
    point (x, 0) is Eq. (6.1) and η of a point (0, y) is Eq. (6.2) of [1]_, n-free (the counters
    apply n once). The strict per-axis unit inverts each axis separately.

    Examples
    --------
    Eq. (6.1) at the fiducial x = 85 mm of a photo with α = 1°, ω = −2°, f′ = 100 mm:

    >>> import numpy as np
    >>> from stereoplotter.geometry.transformed import transformed_x_single_tilt
    >>> from stereoplotter.instrument.knobs import unit_for_orientation
    >>> unit = unit_for_orientation(np.radians(1.0), np.radians(-2.0), 0.0, 100.0)
    >>> xi = rod_from_photo([85.0, 0.0], unit)[0]
    >>> bool(abs(xi - transformed_x_single_tilt(85.0, np.radians(1.0), 100.0)) < 1e-12)
    True
    """
    return UnitMap(unit).rod_from_photo(photo_mm)


class UnitMap:
    r"""The maps of one :class:`CorrectionUnit` with its invariants computed once.

    :func:`photo_from_rod` and :func:`rod_from_photo` are this class applied once; an operator
    that evaluates the same unit many times (a 1-D solve, a look per pass) keeps a
    :class:`UnitMap` and saves cos κ, sin κ and the plane's numerator f′ + c_x T_α + c_y T_ω
    (``kinematics.md`` §3.3, §3.4). The arithmetic is the same, in the same order, so the
    results are bit-identical to the functions.

    Parameters
    ----------
    unit : CorrectionUnit
    trig : (ndarray, ndarray), optional
        (cos κ, sin κ) of ``unit.kappa`` when already known (e.g. after a knob turn, which
        leaves κ alone).

    Examples
    --------
    >>> import numpy as np
    >>> from stereoplotter.instrument.knobs import unit_for_orientation
    >>> unit = unit_for_orientation(0.02, -0.01, 0.003, 100.0)
    >>> m = UnitMap(unit)
    >>> bool(np.array_equal(m.rod_from_photo([40.0, 30.0]), rod_from_photo([40.0, 30.0], unit)))
    True
    """

    __slots__ = (
        "c",
        "ex",
        "ey",
        "f",
        "kx",
        "ky",
        "mech",
        "ms",
        "num",
        "s",
        "strict",
        "ta",
        "to",
        "unit",
    )

    def __init__(
        self,
        unit: CorrectionUnit,
        trig: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
    ):
        self.unit = unit
        f = _a(unit.focal_length_mm)
        ta, to = _a(unit.tan_alpha), _a(unit.tan_omega)
        cx, cy = unit.plane_decentration_mm
        self.strict = bool(unit.strict_per_axis)
        self.f, self.ta, self.to = f, ta, to
        if self.strict:
            self.kx, self.ky = f + cx * ta, f + cy * to
            self.num = None
        else:
            self.num = f + cx * ta + cy * to
            self.kx = self.ky = None
        self.ex = _a(unit.decentration_x_mm)
        self.ey = _a(unit.decentration_y_mm)
        self.mech = None
        if unit.mechanism is not None:
            self.mech = unit.mechanism.scale(f, ta, to, self.ex, self.ey)
        if trig is None:
            kappa = _a(unit.kappa)
            trig = (np.cos(kappa), np.sin(kappa))
        self.c, self.s = trig
        self.ms = -self.s

    @property
    def trig(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(cos κ, sin κ)."""
        return self.c, self.s

    def with_kappa(self, kappa: ArrayLike) -> UnitMap:
        """The map of the same unit with the cassette turned to ``kappa`` (only κ recomputed)."""
        out = object.__new__(UnitMap)
        for name in UnitMap.__slots__:
            setattr(out, name, getattr(self, name))
        out.unit = None
        k = _a(kappa)
        out.c, out.s = np.cos(k), np.sin(k)
        out.ms = -out.s
        return out

    def with_knob(self, axis: str, tan_tilt: ArrayLike, linkage: str = "L") -> UnitMap:
        """The map of ``turn_correction_knob(self.unit, axis, tan_tilt, linkage)`` with κ kept:
        the same arithmetic as ``UnitMap(turn_correction_knob(...), self.trig)``, from this
        map's fields, without building the turned :class:`CorrectionUnit` (an operator's 1-D
        solve on a knob evaluates a dozen turns).

        Examples
        --------
        >>> from stereoplotter.instrument.knobs import turn_correction_knob, unit_for_orientation
        >>> unit = unit_for_orientation(0.02, -0.01, 0.003, 100.0)
        >>> m = UnitMap(unit)
        >>> a = m.with_knob("omega", 0.03).rod_xy(40.0, 30.0)
        >>> b = UnitMap(turn_correction_knob(unit, "omega", 0.03), m.trig).rod_xy(40.0, 30.0)
        >>> a == b
        True
        """
        unit = self.unit
        if unit is None:
            raise StereoplotterError("with_knob: a map of a unit is needed (not a turned map)")
        if linkage not in LINKAGES:
            raise StereoplotterError(f"linkage must be one of {LINKAGES}, found {linkage!r}")
        if axis not in ("alpha", "omega"):
            raise StereoplotterError(f"axis must be 'alpha' or 'omega', found {axis!r}")
        i = 0 if axis == "alpha" else 1  # (T_α, e_x, c_x) or (T_ω, e_y, c_y) move
        f, t, e = self.f, [self.ta, self.to], [self.ex, self.ey]
        c = list(unit.plane_decentration_mm)
        t_new = _a(tan_tilt)
        delta = f * (t_new - t[i])
        t[i] = t_new
        if linkage in ("L", "A"):
            e[i] = e[i] + delta
        if linkage == "L":
            c[i] = c[i] + delta
        (ta, to), (ex, ey), (cx, cy) = t, e, c
        out = object.__new__(UnitMap)
        out.unit, out.strict, out.f, out.ta, out.to, out.ex, out.ey = (
            None, self.strict, f, ta, to, ex, ey
        )  # fmt: skip
        if self.strict:
            out.kx, out.ky, out.num = f + cx * ta, f + cy * to, None
        else:
            out.num, out.kx, out.ky = f + cx * ta + cy * to, None, None
        out.mech = None
        if unit.mechanism is not None:
            out.mech = unit.mechanism.scale(f, ta, to, ex, ey)
        out.c, out.s, out.ms = self.c, self.s, self.ms
        return out

    def photo_xy(self, xi: ArrayLike, eta: ArrayLike) -> tuple[NDArray, NDArray]:
        """:func:`photo_from_rod` on separate ξ, η arrays, returning (x, y) separately."""
        args = (xi, eta, *_map_fields(self))
        if ndim(xi) < 2 and ndim(self.c) < 2:  # no (trials × points) grid: at once
            return _photo_xy(*args)
        return rowwise(_photo_xy, args, 2)

    def photo_from_rod(self, rod_mm: ArrayLike) -> NDArray[np.float64]:
        """See :func:`photo_from_rod`."""
        rod = _a(rod_mm)
        return _pair(*self.photo_xy(rod[..., 0], rod[..., 1]))

    def rod_xy(self, x: ArrayLike, y: ArrayLike) -> tuple[NDArray, NDArray]:
        """:func:`rod_from_photo` on separate x, y arrays, returning (ξ, η) separately."""
        args = (x, y, *_rod_fields(self))
        if ndim(x) < 2 and ndim(self.c) < 2:  # no (trials × points) grid: at once
            return _rod_xy(*args)
        return rowwise(_rod_xy, args, 2)

    def rod_from_photo(self, photo_mm: ArrayLike) -> NDArray[np.float64]:
        """See :func:`rod_from_photo`."""
        p = _a(photo_mm)
        return _pair(*self.rod_xy(p[..., 0], p[..., 1]))


def _photo_xy(xi, eta, f, ta, to, kx, ky, num, mech, ex, ey, c, s, ms):
    """:meth:`UnitMap.photo_xy`'s arithmetic on its fields (``kx`` None: not strict per axis)."""
    u, v = _photo_uv(xi, eta, f, ta, to, kx, ky, num, mech, ex, ey)
    return c * u + s * v, ms * u + c * v


def _photo_uv(xi, eta, f, ta, to, kx, ky, num, mech, ex, ey):
    """:func:`_photo_xy` before the cassette's κ: the decentred photo point (u, v)."""
    if kx is not None:
        u = xi * kx / (f + xi * ta)
        v = eta * ky / (f + eta * to)
    else:
        tau = num / (f + xi * ta + eta * to)
        u, v = tau * xi, tau * eta
    if mech is not None:
        u, v = mech * u, mech * v
    return u - ex, v - ey


def _rod_xy(x, y, c, s, ex, ey, mech, f, ta, to, kx, ky, num):
    """:meth:`UnitMap.rod_xy`'s arithmetic on its fields (``kx`` None: not strict per axis)."""
    px, py = _rod_plane(x, y, c, s, ex, ey, mech)
    if kx is not None:
        return px * f / (kx - px * ta), py * f / (ky - py * to)
    tau = (num - px * ta - py * to) / f
    return px / tau, py / tau


def _rod_plane(x, y, c, s, ex, ey, mech):
    """:func:`_rod_xy`'s point on the correction plane, before the projection to the rod."""
    px = c * x - s * y + ex
    py = s * x + c * y + ey
    if mech is not None:
        px, py = px / mech, py / mech
    return px, py


def _rod_x(x, y, c, s, ex, ey, mech, f, ta, to, kx, ky, num):
    """ξ of :func:`_rod_xy` alone (the same arithmetic)."""
    px, py = _rod_plane(x, y, c, s, ex, ey, mech)
    if kx is not None:
        return px * f / (kx - px * ta)
    return px / ((num - px * ta - py * to) / f)


# --------------------------------------------------------------------------------------------
# The instrument: counters <-> rods <-> photos
# --------------------------------------------------------------------------------------------


def _depth(setting: InstrumentSetting, side: str, depth_mm: ArrayLike):
    sx, sy, sz = setting.pivot(side)
    return sx, sy, _a(depth_mm) + sz


def rod_frame(
    setting: InstrumentSetting, side: str, depth_mm: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    r"""(S_x, S_y, n_j) of one rod at the absolute height counter D: ξ = (X − S_x)/n_j,
    η = (Y − S_y)/n_j, n_j = D_j/f_пр (:func:`rod_from_counters` split for reuse).

    Examples
    --------
    >>> sx, sy, n = rod_frame(InstrumentSetting(130.0, base_x_mm=100.0), "right", 260.0)
    >>> float(sx), float(sy), float(n)
    (100.0, 0.0, 2.0)
    """
    sx, sy, dj = _depth(setting, side, depth_mm)
    return sx, sy, dj / _a(setting.f_instrument_mm)


def rod_from_counters(
    x_mm: ArrayLike,
    y_mm: ArrayLike,
    depth_mm: ArrayLike,
    setting: InstrumentSetting,
    side: str = "left",
) -> NDArray[np.float64]:
    r"""Rod coordinates (ξ, η) of one photo for given counter readings.

    Parameters
    ----------
    x_mm, y_mm : float or ndarray
        X, Y counters. [mm]
    depth_mm : float or ndarray
        D, the absolute height counter (depth below S_л). [mm]
    setting : InstrumentSetting
        f_пр, base and MO.
    side : {"left", "right"}
        Which rod.

    Returns
    -------
    ndarray, shape (..., 2)
        (ξ, η) = ((X − S_x)/n_j, (Y − S_y)/n_j), n_j = D_j/f_пр, D_л = D, D_п = D + b_z′. [mm]

    Notes
    -----
    ``kinematics.md`` §3.3, first two lines; n_л is Eq. (6.3) of [1]_ when D = D_max, and n_п the
    geometric reading of Eq. (6.4) (D_п = D + b_z′).

    Examples
    --------
    >>> setting = InstrumentSetting(130.0, base_x_mm=100.0, base_z_mm=2.0)
    >>> rod_from_counters(100.0 + 1.5 * 10.0, 0.0, 1.5 * 130.0 - 2.0, setting, "right")
    array([10.,  0.])
    """
    sx, sy, n = rod_frame(setting, side, depth_mm)
    return _pair((_a(x_mm) - sx) / n, (_a(y_mm) - sy) / n)


def counters_from_photo(
    photo_mm: ArrayLike,
    depth_mm: ArrayLike,
    unit: CorrectionUnit,
    setting: InstrumentSetting,
    side: str = "left",
) -> NDArray[np.float64]:
    r"""Monocular setting: the X, Y counters that put one mark on a photo point at a given D.

    Parameters
    ----------
    photo_mm : array_like, shape (..., 2)
        (x, y) on the photo of ``side``. [mm]
    depth_mm : float or ndarray
        D, the absolute height counter. [mm]
    unit : CorrectionUnit
        The correction unit of that photo.
    setting : InstrumentSetting
        f_пр, base and MO.
    side : {"left", "right"}
        Which photo.

    Returns
    -------
    ndarray, shape (..., 2)
        (X, Y) = S_j + n_j·(ξ, η). [mm]

    Notes
    -----
    ``kinematics.md`` §3.4, "monocular". With the true unit and κ = 0 these are the book's
    fiducial targets MO + n·x⁰, MO + n·y⁰ of Eqs. (6.12)/(6.13) of [1]_ (with per-photo MO,
    decision D6).

    Examples
    --------
    >>> import numpy as np
    >>> from stereoplotter.instrument.knobs import unit_for_orientation
    >>> unit = unit_for_orientation(0.0, np.radians(1.0), 0.0, 100.0)
    >>> xy = counters_from_photo([0.0, 85.0], 185.0, unit, InstrumentSetting(130.0))
    >>> np.round(xy, 4) + 0.0
    array([  0.    , 125.3046])
    """
    sx, sy, n = rod_frame(setting, side, depth_mm)
    rod = rod_from_photo(photo_mm, unit)
    return _pair(sx + n * rod[..., 0], sy + n * rod[..., 1])


def marks_from_counters(
    x_mm: ArrayLike,
    y_mm: ArrayLike,
    depth_mm: ArrayLike,
    setting: InstrumentSetting,
    left: CorrectionUnit,
    right: CorrectionUnit,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    r"""Photo points under the left and the right mark for given counters.

    Parameters
    ----------
    x_mm, y_mm, depth_mm : float or ndarray
        X, Y counters and the absolute height counter D. [mm]
    setting : InstrumentSetting
        f_пр, base and MO.
    left, right : CorrectionUnit
        The correction units of the two photos.

    Returns
    -------
    photo_left, photo_right : ndarray, shape (..., 2)
        (x, y) under each mark. [mm]

    Notes
    -----
    ``kinematics.md`` §3.3: :func:`rod_from_counters` followed by :func:`photo_from_rod` for each
    photo. On the fiducial axes the relation is Eqs. (6.1)/(6.2) of [1]_ scaled by n.

    Examples
    --------
    >>> setting = InstrumentSetting(130.0, base_x_mm=90.0)
    >>> unit = CorrectionUnit(100.0)
    >>> pl, pr = marks_from_counters(45.0, 0.0, 130.0, setting, unit, unit)
    >>> pl.tolist(), pr.tolist()
    ([45.0, 0.0], [-45.0, 0.0])
    """
    out = []
    for side, unit in (("left", left), ("right", right)):
        # rod_from_counters, then photo_from_rod: the rod not stacked into pairs in between
        sx, sy, sz = setting.pivot(side)
        f = _a(setting.f_instrument_mm)
        args = (_a(x_mm), _a(y_mm), _a(depth_mm), sx, sy, sz, f, *_map_fields(UnitMap(unit)))
        out.append(_pair(*rowwise(_photo_of_counters, args, 2)))
    return out[0], out[1]


def parallaxes_at_marks(
    x_mm: ArrayLike,
    y_mm: ArrayLike,
    depth_mm: ArrayLike,
    setting: InstrumentSetting,
    left: CorrectionUnit,
    right: CorrectionUnit,
    photo_left_mm: ArrayLike,
    photo_right_mm: ArrayLike,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    r"""x- and y-parallax of the photo points under the marks (:func:`marks_from_counters`)
    against the photo points ``photo_left_mm``, ``photo_right_mm`` (shape (..., 2)):
    (x_л − x⁰_л) − (x_п − x⁰_п) and (y_л − y⁰_л) − (y_п − y⁰_п). [mm]

    The same arithmetic as :func:`marks_from_counters` followed by the two differences (the
    same numbers), evaluated a block of rows at a time on a (trials × points) grid, without
    the marks' (..., 2) pairs.

    Examples
    --------
    >>> setting = InstrumentSetting(130.0, base_x_mm=90.0, base_y_mm=0.5)
    >>> unit = CorrectionUnit(100.0, tan_alpha=0.01)
    >>> pl, pr = marks_from_counters(40.0, 7.0, 125.0, setting, unit, unit)
    >>> p0l, p0r = np.array([30.0, 5.0]), np.array([-40.0, 5.5])
    >>> dp, q = parallaxes_at_marks(40.0, 7.0, 125.0, setting, unit, unit, p0l, p0r)
    >>> bool(dp == (pl - p0l)[0] - (pr - p0r)[0] and q == (pl - p0l)[1] - (pr - p0r)[1])
    True
    """
    sides = _pivots_and_fields(setting, left, right)
    pl, pr = _a(photo_left_mm), _a(photo_right_mm)
    args = (
        _a(x_mm),
        _a(y_mm),
        _a(depth_mm),
        _a(setting.f_instrument_mm),
        pl[..., 0],
        pl[..., 1],
        pr[..., 0],
        pr[..., 1],
        *sides[0],
        *sides[1],
    )
    return rowwise(_parallaxes_of_counters, args, 2)


def x_parallaxes_at_marks(
    x_mm: ArrayLike,
    y_mm: ArrayLike,
    depth_mm: ArrayLike,
    setting: InstrumentSetting,
    left: CorrectionUnit,
    right: CorrectionUnit,
    photo_left_x_mm: ArrayLike,
    photo_right_x_mm: ArrayLike,
) -> NDArray[np.float64]:
    r"""The x-parallax of :func:`parallaxes_at_marks` alone, against the photo points' x
    ``photo_left_x_mm``, ``photo_right_x_mm`` (the same numbers; the marks' y not computed). [mm]

    Examples
    --------
    >>> setting = InstrumentSetting(130.0, base_x_mm=90.0, base_y_mm=0.5)
    >>> unit = CorrectionUnit(100.0, tan_alpha=0.01)
    >>> p0l, p0r = np.array([30.0, 5.0]), np.array([-40.0, 5.5])
    >>> dp, _ = parallaxes_at_marks(40.0, 7.0, 125.0, setting, unit, unit, p0l, p0r)
    >>> bool(x_parallaxes_at_marks(40.0, 7.0, 125.0, setting, unit, unit, 30.0, -40.0) == dp)
    True
    """
    sides = _pivots_and_fields(setting, left, right)
    args = (
        _a(x_mm),
        _a(y_mm),
        _a(depth_mm),
        _a(setting.f_instrument_mm),
        _a(photo_left_x_mm),
        _a(photo_right_x_mm),
        *sides[0],
        *sides[1],
    )
    return rowwise(_x_parallax_of_counters, args, 1)[0]


def _x_parallax_of_counters(x, y, depth, f_instrument, x0l, x0r, *fields):
    """:func:`x_parallaxes_at_marks`' arithmetic: per side (its pivot and 12 map fields) the
    photo x of :func:`_photo_of_counters`, then the difference (one output, as a tuple)."""
    xs = []
    for side in (fields[:15], fields[15:]):
        sx, sy, sz, *m = side
        u, v = _photo_uv(*_rod_of_counters(x, y, depth, sx, sy, sz, f_instrument), *m[:9])
        c, s = m[9], m[10]
        xs.append(c * u + s * v)
    return ((xs[0] - x0l) - (xs[1] - x0r),)


def _parallaxes_of_counters(x, y, depth, f_instrument, x0l, y0l, x0r, y0r, *fields):
    """:func:`parallaxes_at_marks`' arithmetic: :func:`_photo_of_counters` of each side (its
    pivot and 12 map fields, 15 arguments a side), then the differences."""
    xl, yl = _photo_of_counters(x, y, depth, *fields[:3], f_instrument, *fields[3:15])
    xr, yr = _photo_of_counters(x, y, depth, *fields[15:18], f_instrument, *fields[18:])
    return (xl - x0l) - (xr - x0r), (yl - y0l) - (yr - y0r)


def _pivots_and_fields(
    setting: InstrumentSetting, left: CorrectionUnit, right: CorrectionUnit
) -> tuple[tuple[Any, ...], ...]:
    """Per side, its pivot (S_x, S_y, S_z) and its map's fields (:func:`_map_fields`): the 15
    arguments a side of :func:`_parallaxes_of_counters` and :func:`_x_parallax_of_counters`."""
    return tuple(
        (*setting.pivot(side), *_map_fields(UnitMap(unit)))
        for side, unit in (("left", left), ("right", right))
    )


def _map_fields(m: UnitMap) -> tuple[Any, ...]:
    """The fields of a map in the order of :func:`_photo_xy`'s arguments after ξ, η."""
    return (m.f, m.ta, m.to, m.kx, m.ky, m.num, m.mech, m.ex, m.ey, m.c, m.s, m.ms)


def _rod_of_counters(x, y, depth, sx, sy, sz, f_instrument):
    """:func:`rod_frame`'s ξ, η of counters (one side, its pivot S_x, S_y, S_z)."""
    n = (depth + sz) / f_instrument
    return (x - sx) / n, (y - sy) / n


def _photo_of_counters(x, y, depth, sx, sy, sz, f_instrument, *fields):
    """:func:`_rod_of_counters`, then :func:`_photo_xy` (one side)."""
    return _photo_xy(*_rod_of_counters(x, y, depth, sx, sy, sz, f_instrument), *fields)


def rods_intersection(
    rod_left_mm: ArrayLike, rod_right_mm: ArrayLike, setting: InstrumentSetting
) -> StereoReading:
    r"""Counters and y-parallax where the two rods meet in the XZ plane (x-parallax cleared).

    Parameters
    ----------
    rod_left_mm, rod_right_mm : array_like, shape (..., 2)
        (ξ, η) of the left and the right rod. [mm]
    setting : InstrumentSetting
        f_пр, base and MO.

    Returns
    -------
    StereoReading
        X, Y, D [mm] and q [mm, photo scale].

    Notes
    -----
    ``kinematics.md`` §3.4, "stereo": rays S_j + t_j (ξ_j, η_j, −f_пр) with
    t_л ξ_л − t_п ξ_п = b_x and t_п − t_л = b_z′/f_пр; then X = MO_X + t_л ξ_л, D = t_л f_пр,
    Y = MO_Y + ½(t_л η_л + b_y + t_п η_п) and

    .. math:: q = \frac{t_л \eta_л - (b_y + t_п \eta_п)}{t_л}

    (t_л = n_л, so n·q is the parallax in model mm). Rods parallel in X give inf/NaN.
    """
    rl, rr = _a(rod_left_mm), _a(rod_right_mm)
    return rods_intersection_xy((rl[..., 0], rl[..., 1]), (rr[..., 0], rr[..., 1]), setting)


def rods_intersection_xy(
    rod_left: tuple[ArrayLike, ArrayLike],
    rod_right: tuple[ArrayLike, ArrayLike],
    setting: InstrumentSetting,
) -> StereoReading:
    """:func:`rods_intersection` with the rods as (ξ, η) pairs of arrays (the same arithmetic).

    Examples
    --------
    >>> s = InstrumentSetting(130.0, base_x_mm=90.0, base_y_mm=0.5)
    >>> a = rods_intersection([45.0, 3.0], [-45.0, 2.0], s)
    >>> bool(rods_intersection_xy((45.0, 3.0), (-45.0, 2.0), s) == a)
    True
    """
    xi_l, eta_l = (_a(v) for v in rod_left)
    xi_r, eta_r = (_a(v) for v in rod_right)
    f = _a(setting.f_instrument_mm)
    t_l, y_l, y_r, q = _rays(xi_l, eta_l, xi_r, eta_r, setting)
    x = _a(setting.model_origin_x_mm) + t_l * xi_l
    y = _a(setting.model_origin_y_mm) + 0.5 * (y_l + y_r)
    return StereoReading(*np.broadcast_arrays(x, y, t_l * f, q))


def _rays(xi_l, eta_l, xi_r, eta_r, setting: InstrumentSetting):
    """t_л, the two ray heights y_л, y_п and q of :func:`rods_intersection` (§3.4, "stereo")."""
    f = _a(setting.f_instrument_mm)
    bx, by, bz = _a(setting.base_x_mm), _a(setting.base_y_mm), _a(setting.base_z_mm)
    args = (xi_l, eta_l, xi_r, eta_r, f, bx, by, bz)
    with np.errstate(divide="ignore", invalid="ignore"):
        if ndim(xi_l) < 2 and ndim(xi_r) < 2:  # no (trials × points) grid: at once
            return _ray_arithmetic(*args)
        return rowwise(_ray_arithmetic, args, 4)


def _ray_arithmetic(xi_l, eta_l, xi_r, eta_r, f, bx, by, bz):
    t_l = (bx + xi_r * bz / f) / (xi_l - xi_r)
    t_r = t_l + bz / f
    y_l = t_l * eta_l
    y_r = by + t_r * eta_r
    q = (y_l - y_r) / t_l
    return t_l, y_l, y_r, q


def rods_y_parallax(
    rod_left: tuple[ArrayLike, ArrayLike],
    rod_right: tuple[ArrayLike, ArrayLike],
    setting: InstrumentSetting,
) -> NDArray[np.float64]:
    r"""Only q of :func:`rods_intersection`, with the rods as (ξ, η) pairs of arrays. [mm]

    The same arithmetic as :func:`rods_intersection` (bit-identical q), without X, Y, D.

    Examples
    --------
    >>> s = InstrumentSetting(130.0, base_x_mm=90.0, base_y_mm=0.5)
    >>> r = rods_intersection([45.0, 3.0], [-45.0, 2.0], s)
    >>> bool(rods_y_parallax((45.0, 3.0), (-45.0, 2.0), s) == r.y_parallax_mm)
    True
    """
    xi_l, eta_l = (_a(v) for v in rod_left)
    xi_r, eta_r = (_a(v) for v in rod_right)
    return _rays(xi_l, eta_l, xi_r, eta_r, setting)[3]


def counters_from_homologous_points(
    photo_left_mm: ArrayLike,
    photo_right_mm: ArrayLike,
    setting: InstrumentSetting,
    left: CorrectionUnit,
    right: CorrectionUnit,
) -> StereoReading:
    r"""Counters X, Y, D of the model point of two homologous photo points, and its y-parallax q.

    Parameters
    ----------
    photo_left_mm, photo_right_mm : array_like, shape (..., 2)
        (x, y) of the point on the left and on the right photo. [mm]
    setting : InstrumentSetting
        f_пр, base and MO.
    left, right : CorrectionUnit
        The correction units of the two photos.

    Returns
    -------
    StereoReading
        X, Y, D [mm] and q [mm, photo scale].

    Notes
    -----
    ``kinematics.md`` §3.4: :func:`rod_from_photo` for each photo, then
    :func:`rods_intersection`. It inverts :func:`marks_from_counters` (q = 0 then).

    Examples
    --------
    >>> setting = InstrumentSetting(130.0, base_x_mm=90.0)
    >>> unit = CorrectionUnit(100.0)
    >>> r = counters_from_homologous_points([45.0, 0.0], [-45.0, 0.0], setting, unit, unit)
    >>> [float(v) for v in r]
    [45.0, 0.0, 130.0, 0.0]
    """
    pl, pr = _a(photo_left_mm), _a(photo_right_mm)
    # rod_from_photo of each photo (not stacked into pairs), then rods_intersection_xy
    sides = [(p[..., 0], p[..., 1], *_rod_fields(UnitMap(u))) for p, u in ((pl, left), (pr, right))]
    f = _a(setting.f_instrument_mm)
    bx, by, bz = _a(setting.base_x_mm), _a(setting.base_y_mm), _a(setting.base_z_mm)
    ox, oy = _a(setting.model_origin_x_mm), _a(setting.model_origin_y_mm)
    args = (*sides[0], *sides[1], f, bx, by, bz, ox, oy)
    return StereoReading(*np.broadcast_arrays(*rowwise(_homologous, args, 4)))


def depths_of_homologous_points(
    photo_left_mm: ArrayLike,
    photo_right_mm: ArrayLike,
    setting: InstrumentSetting,
    left: CorrectionUnit,
    right: CorrectionUnit,
) -> NDArray[np.float64]:
    r"""The absolute height counter D of :func:`counters_from_homologous_points` alone (the
    same numbers; X, Y, q and the rods' η not computed). [mm]

    Examples
    --------
    >>> setting = InstrumentSetting(130.0, base_x_mm=90.0, base_y_mm=0.5)
    >>> unit = CorrectionUnit(100.0, tan_alpha=0.01)
    >>> r = counters_from_homologous_points([45.0, 1.0], [-44.0, 2.0], setting, unit, unit)
    >>> bool(depths_of_homologous_points([45.0, 1.0], [-44.0, 2.0], setting, unit, unit)
    ...      == r.depth_mm)
    True
    """
    pl, pr = _a(photo_left_mm), _a(photo_right_mm)
    sides = [(p[..., 0], p[..., 1], *_rod_fields(UnitMap(u))) for p, u in ((pl, left), (pr, right))]
    f = _a(setting.f_instrument_mm)
    bx, bz = _a(setting.base_x_mm), _a(setting.base_z_mm)
    (depth,) = rowwise(_homologous_depth, (*sides[0], *sides[1], f, bx, bz), 1)
    # the shape of counters_from_homologous_points' four outputs, broadcast together
    others = (setting.base_y_mm, setting.model_origin_x_mm, setting.model_origin_y_mm)
    shape = np.broadcast_shapes(
        *(np.shape(a) for a in (*sides[0], *sides[1], f, bx, bz, *others) if a is not None)
    )
    return np.broadcast_to(depth, shape)


def _homologous_depth(*args):
    """D of :func:`_homologous` alone: ξ of each side (:func:`_rod_x`), then t_л of
    :func:`_ray_arithmetic` and D = t_л f_пр (one output, as a tuple)."""
    xi_l = _rod_x(*args[:13])
    xi_r = _rod_x(*args[13:26])
    f, bx, bz = args[26:]
    with np.errstate(divide="ignore", invalid="ignore"):
        t_l = (bx + xi_r * bz / f) / (xi_l - xi_r)
    return (t_l * f,)


def _rod_fields(m: UnitMap) -> tuple[Any, ...]:
    """The fields of a map in the order of :func:`_rod_xy`'s arguments after x, y."""
    return (m.c, m.s, m.ex, m.ey, m.mech, m.f, m.ta, m.to, m.kx, m.ky, m.num)


def _homologous(*args):
    """X, Y, D and q of :func:`counters_from_homologous_points` from the photo points and the
    two maps' fields (13 arguments a side, :func:`_rod_xy`'s) and f_пр, b_x, b_y, b_z, MO_X,
    MO_Y: :func:`_rod_xy` of each side, then :func:`rods_intersection_xy`'s arithmetic."""
    xi_l, eta_l = _rod_xy(*args[:13])
    xi_r, eta_r = _rod_xy(*args[13:26])
    f, bx, by, bz, ox, oy = args[26:]
    with np.errstate(divide="ignore", invalid="ignore"):
        t_l, y_l, y_r, q = _ray_arithmetic(xi_l, eta_l, xi_r, eta_r, f, bx, by, bz)
    return ox + t_l * xi_l, oy + 0.5 * (y_l + y_r), t_l * f, q
