r"""The conventional method's knowledge of its instrument: the book's dependent elements of
relative orientation α′₁, α′₂, ω′₂, κ′₁, κ′₂ on the instrument's controls, and the common tilts
of the model, found numerically on the nominal instrument (:func:`calibrate`), never by hand.

Used by :mod:`~stereoplotter.procedure.conventional` (C2 turns a control by the element's
mapping; C3 levels by a common tilt).

Reference
---------
.. [1] Kushtin I. F. & Lyskov G. A., *Фотограмметрия снимка и стереоскопических моделей*,
   Moscow: Nedra, 1984, ch. 5, §22, Eq. (5.10), Fig. 39 (OCR L2928–3010).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.kinematics import (
    CorrectionUnit,
    InstrumentSetting,
    counters_from_homologous_points,
)
from stereoplotter.instrument.knobs import turn_correction_knob
from stereoplotter.instrument.virtual import (
    CassetteName,
    KnobName,
    control_axis,
    control_kind,
    control_side,
)
from stereoplotter.procedure.arrays import Floats
from stereoplotter.procedure.relative_equations import y_parallax_first_order
from stereoplotter.procedure.run import Run
from stereoplotter.procedure.steps import control_point_m

__all__ = ["ELEMENTS", "Calibration", "calibrate", "control_sensitivity"]


#: Book element (basis system, (5.10)) → the instrument control that realises it.
ELEMENTS: dict[str, CassetteName | KnobName] = {
    "alpha1": "k_alpha_left",
    "alpha2": "k_alpha_right",
    "omega2": "k_omega_right",
    "kappa1": "kappa_left",
    "kappa2": "kappa_right",
}


#: Controls whose sensitivity :func:`control_sensitivity` knows.
_CONTROLS = (
    "kappa_left",
    "kappa_right",
    "k_alpha_left",
    "k_alpha_right",
    "k_omega_left",
    "k_omega_right",
    "by",
    "bz",
)


def _perturb(
    setting: InstrumentSetting,
    left: CorrectionUnit,
    right: CorrectionUnit,
    changes: dict[str, Any],
    linkage: str,
) -> tuple[InstrumentSetting, CorrectionUnit, CorrectionUnit]:
    """The instrument state after adding ``changes`` (control → increment) to it."""
    units = {"left": left, "right": right}
    for control, delta in changes.items():
        if control in ("by", "bz"):
            name = "base_y_mm" if control == "by" else "base_z_mm"
            setting = replace(setting, **{name: np.asarray(getattr(setting, name)) + delta})
        elif control_kind(control) == "cassette":
            side = control_side(control)
            units[side] = replace(units[side], kappa=np.asarray(units[side].kappa) + delta)
        elif control_kind(control) == "knob":
            axis, side = control_axis(control), control_side(control)
            now = units[side].tan_alpha if axis == "alpha" else units[side].tan_omega
            units[side] = turn_correction_knob(
                units[side], axis, np.asarray(now) + delta, linkage=linkage
            )
        else:
            raise StereoplotterError(f"no sensitivity for control {control!r}")
    return setting, units["left"], units["right"]


def control_sensitivity(
    images: tuple[ArrayLike, ArrayLike],
    setting: InstrumentSetting,
    left: CorrectionUnit,
    right: CorrectionUnit,
    changes: dict[str, float],
    *,
    linkage: str = "L",
    step: float = 1e-5,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    r"""Change of q and D at homologous points per unit of a combined turn of controls.

    Parameters
    ----------
    images : (ndarray, ndarray), shapes (n, 2)
        The points on the left and right photo. [mm]
    setting : InstrumentSetting
        f_пр and base (scalar fields).
    left, right : CorrectionUnit
        The units (scalar fields).
    changes : dict
        Control → increment per unit of the combined turn: "kappa_left", "kappa_right" [rad],
        "k_alpha_left", … "k_omega_right" (the represented tangent T) [—], "by", "bz" [mm].
    linkage : {"L", "A", "B"}
        How the decentrations follow a knob (``kinematics.md`` §4.1).
    step : float
        Central-difference step of the unit turn.

    Returns
    -------
    dq, dD : ndarray, shape (n,)
        ∂q [mm, photo] and ∂D [mm, model] per unit turn, q of
        :func:`~stereoplotter.instrument.kinematics.counters_from_homologous_points`.

    Examples
    --------
    Turning κ_п by 1 mrad on a point at x₂ = −90 mm gives q = ±0.09 mm:

    >>> s = InstrumentSetting(130.0, base_x_mm=90.0)
    >>> u = CorrectionUnit(100.0)
    >>> imgs = (np.array([[0.0, 0.0]]), np.array([[-90.0, 0.0]]))
    >>> dq, dd = control_sensitivity(imgs, s, u, u, {"kappa_right": 1.0})
    >>> round(abs(float(dq[0])), 6)
    90.0
    """
    pl, pr = (np.asarray(v, float) for v in images)
    out = []
    for sign in (1.0, -1.0):
        ch = {k: sign * step * v for k, v in changes.items()}
        s, lu, ru = _perturb(setting, left, right, ch, linkage)
        out.append(counters_from_homologous_points(pl, pr, s, lu, ru))
    dq = (out[0].y_parallax_mm - out[1].y_parallax_mm) / (2.0 * step)
    dd = (out[0].depth_mm - out[1].depth_mm) / (2.0 * step)
    return dq, dd


@dataclass(frozen=True)
class Calibration:
    """What the operator knows of the instrument's response (one table for all trials).

    Attributes
    ----------
    mapping : dict
        Book element → control turn per radian of the element (``ELEMENTS``): turning the
        control by ``mapping[e]·ε`` makes the q of the element ε in (5.10) at the six standard
        points, in the instrument's sign of q. [rad⁻¹·control unit]
    fit : dict
        Book element → relative misfit ‖J m − g‖/‖g‖ of that column. [—]
    common_alpha, common_omega : dict
        Control → turn per radian of a common tilt of the model about the Y / X axis (both photos
        and the base, q unchanged to first order).
    level_design : ndarray, shape (n, 3)
        Columns 1, ∂H/∂φ_α, ∂H/∂φ_ω at the levelling points. [m, m/rad]
    level_weights : ndarray, shape (3, n)
        Least-squares pseudo-inverse of ``level_design``.
    """

    mapping: dict[str, float]
    fit: dict[str, float]
    common_alpha: dict[str, float]
    common_omega: dict[str, float]
    level_design: NDArray[np.float64]
    level_weights: NDArray[np.float64]


def _dot(a: ArrayLike, b: ArrayLike) -> float:
    return float(np.dot(np.asarray(a, float), np.asarray(b, float)))


def _null_q(
    j: dict[str, Floats], fixed: dict[str, float], free: tuple[str, ...]
) -> dict[str, float]:
    """Turns of the ``free`` controls that cancel the q of the ``fixed`` turns (least squares)."""
    rhs = -sum(j[k] * v for k, v in fixed.items())
    a = np.column_stack([j[k] for k in free])
    sol = np.linalg.lstsq(a, rhs, rcond=None)[0]
    return {**fixed, **{k: float(v) for k, v in zip(free, sol, strict=True)}}


def calibrate(run: Run, level_ids: tuple[str, ...]) -> Calibration:
    """The numerical sensitivities of the nominal instrument (sheet f_пр, b_x, b_y; b_z′ = 0;
    units at zero) at the six standard points and at the levelling points.

    Turning each control by a small amount and observing q at the six points gives a column J;
    the element's column g of (5.10) (:func:`y_parallax_first_order` at the photo images of the
    points, f = f′) gives the mapping m = J·g/J·J. A common tilt of the model is a turn of one
    photo's knob with the other photo's knob and b_z′ (α), or the other photo's knob and b_z′ (ω),
    chosen so that q stays zero to first order.
    """
    op, sheet, scene = run.op, run.sheet, run.scene
    inst = op.inst
    bx, by, _ = sheet.base_mm
    setting = InstrumentSetting(sheet.f_instrument_mm, bx, by, 0.0)
    unit = CorrectionUnit(
        sheet.focal_length_corrected_mm, strict_per_axis=inst.variant.strict_per_axis
    )
    linkage = inst.variant.linkage
    imgs = scene.standard  # the standard points' true images, computed once
    f = sheet.focal_length_corrected_mm
    j = {
        c: control_sensitivity(imgs, setting, unit, unit, {c: 1.0}, linkage=linkage)[0]
        for c in _CONTROLS
    }
    mapping, fit = {}, {}
    for k, (element, control) in enumerate(ELEMENTS.items()):
        unit_el = np.eye(5)[k]
        g = y_parallax_first_order(
            imgs[0][:, 0], imgs[0][:, 1], imgs[1][:, 0], imgs[1][:, 1], f, *unit_el
        )
        m = _dot(j[control], g) / _dot(j[control], j[control])
        mapping[element] = m
        fit[element] = float(np.linalg.norm(j[control] * m - g) / np.linalg.norm(g))
    common_alpha = _null_q(
        j, {"k_alpha_left": mapping["alpha1"]}, ("k_alpha_right", "bz", "kappa_left", "kappa_right")
    )
    common_omega = _null_q(
        j, {"k_omega_right": mapping["omega2"]}, ("k_omega_left", "bz", "kappa_left", "kappa_right")
    )
    lp = np.array([control_point_m(run, i) for i in level_ids])
    limgs = scene.images(lp)
    mv = sheet.vertical_scale_denominator
    cols = [np.ones(len(level_ids))]
    for combo in (common_alpha, common_omega):
        _, dd = control_sensitivity(limgs, setting, unit, unit, combo, linkage=linkage)
        cols.append(-dd * mv / 1000.0)
    design = np.column_stack(cols)
    weights = cast(Floats, np.linalg.pinv(design))
    return Calibration(mapping, fit, common_alpha, common_omega, design, weights)
