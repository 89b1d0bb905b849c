r"""Settings of a correction unit and the semantics of its knobs (decision D1).

The correction unit at a photo's true settings, the correction-plane angle a knob stands for
and the tilt it represents, how turning a knob moves the decentrations under each linkage
(``kinematics.md`` §4.1, §8), and setting the decentrations on their scales. The maps these
units enter are :mod:`stereoplotter.instrument.kinematics`.

Reference
---------
.. [1] Kushtin I. F. & Lyskov G. A., *Фотограмметрия снимка и стереоскопических моделей*,
   Moscow: Nedra, 1984, ch. 6, §26–§27, pp. 153–163 (OCR L3680–4030).
.. [2] F. V. Drobyshev, "Soviet stereophotogrammetric instruments", ISP Congress 1960,
   Comm. II, pp. 767–773 (transformed bundles, k = F/f_k, planes at kα, kω).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.errors import StereoplotterError
from stereoplotter.geometry.tilt_correction import correction_inclination, decentration
from stereoplotter.instrument.decentration_variants import LINKAGES
from stereoplotter.instrument.kinematics import CorrectionUnit

__all__ = [
    "correction_angle",
    "dependent_decentration_change",
    "represented_tilt_tangent",
    "set_decentrations",
    "turn_correction_knob",
    "unit_for_orientation",
]


def _a(v: ArrayLike) -> NDArray[np.float64]:
    return np.asarray(v, dtype=float)


def unit_for_orientation(
    alpha: ArrayLike,
    omega: ArrayLike,
    kappa: ArrayLike,
    focal_length_mm: ArrayLike,
    *,
    strict_per_axis: bool = False,
) -> CorrectionUnit:
    r"""The correction unit at the true settings for a photo of tilts α, ω and swing κ.

    Parameters
    ----------
    alpha, omega, kappa : float or ndarray
        α, ω, κ of Eq. (2.50) of [1]_ (M = R_Y(−α)·R_X(ω)·R_Z(κ)). [rad]
    focal_length_mm : float or ndarray
        f′. [mm]
    strict_per_axis : bool
        Build the strict per-axis unit instead of the correction plane.

    Returns
    -------
    CorrectionUnit
        T_α = tan α, T_ω = tan ω, e = c = (f′ tan α, f′ tan ω) (``decentration``), κ.

    Notes
    -----
    ``kinematics.md`` §2.4 and §3.6: the decentrations the computer provides and the plane
    inclinations tan θ = k tan α ([2]_ eq. (4)) expressed as T = tan θ/k.

    Examples
    --------
    >>> unit = unit_for_orientation(0.01, 0.0, 0.0, 100.0)
    >>> round(float(unit.decentration_x_mm), 6)
    1.000033
    """
    return CorrectionUnit(
        focal_length_mm=focal_length_mm,
        tan_alpha=np.tan(_a(alpha)),
        tan_omega=np.tan(_a(omega)),
        decentration_x_mm=decentration(focal_length_mm, alpha),
        decentration_y_mm=decentration(focal_length_mm, omega),
        kappa=_a(kappa),
        strict_per_axis=strict_per_axis,
    )


def represented_tilt_tangent(
    plane_inclination: ArrayLike, transformation_coefficient_k: ArrayLike
) -> NDArray[np.float64]:
    r"""T = tan θ / k: the tangent of the tilt represented by a correction plane at θ.

    Parameters
    ----------
    plane_inclination : float or ndarray
        θ_α or θ_ω, the inclination of the correction plane. [rad]
    transformation_coefficient_k : float or ndarray
        k = f_пр / f′. [—]

    Returns
    -------
    ndarray
        T. [—]

    Notes
    -----
    Inverse of tan θ = k tan α ([2]_ eq. (4); ``kinematics.md`` §3.2). The forward relation is
    :func:`correction_angle` (which uses ``geometry.tilt_correction.correction_inclination``).

    Examples
    --------
    >>> theta = correction_angle(0.05, 1.3)
    >>> round(float(represented_tilt_tangent(theta, 1.3)), 12)
    0.05
    """
    return np.tan(_a(plane_inclination)) / _a(transformation_coefficient_k)


def correction_angle(
    tan_tilt: ArrayLike, transformation_coefficient_k: ArrayLike
) -> NDArray[np.float64]:
    r"""θ = atan(k·T), the plane inclination that represents a tilt of tangent T.

    Parameters
    ----------
    tan_tilt : float or ndarray
        T_α or T_ω. [—]
    transformation_coefficient_k : float or ndarray
        k = f_пр / f′. [—]

    Returns
    -------
    ndarray
        θ. [rad]

    Notes
    -----
    [2]_ eq. (4), tan θ = k tan α, via ``geometry.tilt_correction.correction_inclination``.

    Examples
    --------
    >>> import numpy as np
    >>> round(float(np.degrees(correction_angle(np.tan(np.radians(1.0)), 1.3))), 4)
    1.2999
    """
    return correction_inclination(transformation_coefficient_k, np.arctan(_a(tan_tilt)))


def dependent_decentration_change(
    focal_length_mm: ArrayLike,
    plane_inclination_before: ArrayLike,
    plane_inclination_after: ArrayLike,
    transformation_coefficient_k: ArrayLike,
) -> NDArray[np.float64]:
    r"""Change of the decentration dragged by turning a correction knob (decision D1).

    Parameters
    ----------
    focal_length_mm : float or ndarray
        f′. [mm]
    plane_inclination_before, plane_inclination_after : float or ndarray
        θ before and after the turn. [rad]
    transformation_coefficient_k : float or ndarray
        k = f_пр / f′. [—]

    Returns
    -------
    ndarray
        Δd = f′·Δ(tan θ / k) = f′·ΔT. [mm]

    Notes
    -----
    ``kinematics.md`` §4.1 and §8: the θ_α knob changes tan θ_α by Δ and d_x by f′·Δ/k; the
    θ_ω knob acts likewise on d_y. Starting from d = 0 at θ = 0 it keeps d = f′ T, the value
    f′ tan α of the computed decentration.

    Examples
    --------
    >>> import numpy as np
    >>> theta = correction_angle(np.tan(np.radians(1.0)), 1.3)
    >>> round(float(dependent_decentration_change(100.0, 0.0, theta, 1.3)), 6)
    1.745506
    """
    k = _a(transformation_coefficient_k)
    return (
        _a(focal_length_mm)
        * (np.tan(_a(plane_inclination_after)) - np.tan(_a(plane_inclination_before)))
        / k
    )


def turn_correction_knob(
    unit: CorrectionUnit, axis: str, tan_tilt: ArrayLike, linkage: str = "L"
) -> CorrectionUnit:
    r"""The unit after turning the k_α or k_ω knob to represent the tilt tangent ``tan_tilt``.

    Parameters
    ----------
    unit : CorrectionUnit
        The unit before the turn.
    axis : {"alpha", "omega"}
        "alpha" turns θ_α (moves T_α, drags d_x), "omega" turns θ_ω (T_ω, d_y).
    tan_tilt : float or ndarray
        The new T = tan θ / k. [—]
    linkage : {"L", "A", "B"}
        "L" (default, D1): photo and plane decentrations move by f′·ΔT; "A": only the photo
        decentration moves; "B": the decentrations stay (independent).

    Returns
    -------
    CorrectionUnit
        A new unit (the argument is frozen).

    Notes
    -----
    ``kinematics.md`` §4.1 (variants) and §8 (knob semantics); the drag is
    :func:`dependent_decentration_change` written in T.

    Examples
    --------
    >>> u = turn_correction_knob(CorrectionUnit(100.0), "omega", 0.02)
    >>> float(u.tan_omega), float(u.decentration_y_mm), u.plane_decentration_mm[1].item()
    (0.02, 2.0, 2.0)
    >>> u = turn_correction_knob(CorrectionUnit(100.0), "omega", 0.02, linkage="A")
    >>> float(u.decentration_y_mm), u.plane_decentration_mm[1].item()
    (2.0, 0.0)
    """
    if linkage not in LINKAGES:
        raise StereoplotterError(f"linkage must be one of {LINKAGES}, found {linkage!r}")
    if axis == "alpha":
        t_name, e_name, c_index = "tan_alpha", "decentration_x_mm", 0
    elif axis == "omega":
        t_name, e_name, c_index = "tan_omega", "decentration_y_mm", 1
    else:
        raise StereoplotterError(f"axis must be 'alpha' or 'omega', found {axis!r}")
    t_new = _a(tan_tilt)
    delta = _a(unit.focal_length_mm) * (t_new - _a(getattr(unit, t_name)))
    c = list(unit.plane_decentration_mm)
    e = _a(getattr(unit, e_name))
    changes: dict[str, object] = {t_name: t_new}
    if linkage in ("L", "A"):
        changes[e_name] = e + delta
    if linkage == "L":
        c[c_index] = c[c_index] + delta
    changes["plane_decentration_x_mm"] = c[0]
    changes["plane_decentration_y_mm"] = c[1]
    return replace(unit, **changes)


def set_decentrations(
    unit: CorrectionUnit, decentration_x_mm: ArrayLike, decentration_y_mm: ArrayLike
) -> CorrectionUnit:
    r"""The unit after setting the computed decentrations on the scales (photo and plane).

    Parameters
    ----------
    unit : CorrectionUnit
        The unit before.
    decentration_x_mm, decentration_y_mm : float or ndarray
        d_x = f′ tan α, d_y = f′ tan ω from the computer (``tilt_correction.decentration``). [mm]

    Returns
    -------
    CorrectionUnit
        e = c = (d_x, d_y): "set the computed decentrations" overrides the dependent value
        (``kinematics.md`` §4.1, decision D1; D2 merges e and c).

    Examples
    --------
    >>> u = set_decentrations(CorrectionUnit(100.0, tan_alpha=0.01), 1.0, 0.0)
    >>> float(u.decentration_x_mm), u.plane_decentration_mm[0].item()
    (1.0, 1.0)
    """
    return replace(
        unit,
        decentration_x_mm=_a(decentration_x_mm),
        decentration_y_mm=_a(decentration_y_mm),
        plane_decentration_x_mm=None,
        plane_decentration_y_mm=None,
    )
