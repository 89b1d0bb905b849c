"""Remedy R3's levelling design: the common tilts that level a setup-data model without
disturbing its y-parallax, and their height sensitivities at the sheet's control heights.

The design is the operator's knowledge of the instrument at the sheet's own settings, the same
for every trial: :func:`~stereoplotter.procedure.run.prepare_pair` computes it once per run and
:func:`~stereoplotter.procedure.setup_method.refine_scale_and_level` reads it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.instrument.kinematics import (
    CorrectionUnit,
    InstrumentSetting,
    counters_from_homologous_points,
)
from stereoplotter.instrument.knobs import turn_correction_knob
from stereoplotter.instrument.virtual import control_axis, control_kind, control_side
from stereoplotter.procedure.floor import ControlHeights, sheet_settings
from stereoplotter.procedure.operator import Scene
from stereoplotter.setup.sheet import SetupSheet

__all__ = ["LEVEL_FREE", "LEVEL_TILTS", "LevelDesign", "level_design"]

#: Remedy R3 (stage 3, control heights beyond H/3000): the common tilts that level the model on
#: a setup-data instrument. §26 refines only the *scaling* "by the heights of control points"
#: (stage 3, b_x) and has no levelling step; the levelling here is an assumption (the §26 intro:
#: the set orientation "most often is not accurate enough and its correction takes additional
#: time"). A common tilt of the model turns both correction units by the same angle — k_α,л and
#: k_α,п about the Y axis (along the base), k_ω,л and k_ω,п about the X axis — and moves the
#: right pivot with the turned base: by the rigid rotation of b = (b_x, b_y, b_z′), Δb_z′ =
#: −b_x·φ_α (the tilt along the base needs b_z′), and Δb_z′ = b_y·φ_ω, Δb_y = −b_z′·φ_ω, both
#: second order here (b_y ≈ 0, b_z′ ≈ 1 mm). :data:`LEVEL_FREE` (b_z′, κ_л, κ_п) are solved by
#: least squares on the instrument model so that q at the six standard points is unchanged to
#: first order (:func:`level_design`; the solved Δb_z′/φ_α = −b_x within 1 % and the κ's small
#: are tested in ``tests/procedure/test_heights_remedy.py``).
LEVEL_TILTS = {
    "alpha": ("k_alpha_left", "k_alpha_right"),
    "omega": ("k_omega_left", "k_omega_right"),
}
LEVEL_FREE = ("bz", "kappa_left", "kappa_right")


@dataclass(frozen=True)
class LevelDesign:
    """What the operator knows of levelling a model on this instrument (one table per sheet).

    Attributes
    ----------
    combos : dict
        "alpha"/"omega" → control → turn per radian of the common tilt (knobs in T, κ in rad,
        ``bz`` in mm of b_z′): :data:`LEVEL_TILTS` by 1 each, :data:`LEVEL_FREE` solved so that
        q at the six standard points is unchanged to first order.
    q_misfit : dict
        "alpha"/"omega" → the largest |∂q/∂φ| left at the six standard points by the combo,
        against the largest |∂q/∂φ| of the knobs alone. [—]
    design : ndarray, shape (n, 3)
        Columns 1, ∂H/∂φ_α, ∂H/∂φ_ω at the sheet's control heights. [m, m/rad]
    """

    combos: dict[str, dict[str, float]]
    q_misfit: dict[str, float]
    design: NDArray[np.float64]


def _turned(
    setting: InstrumentSetting,
    units: dict[str, CorrectionUnit],
    changes: Mapping[str, float],
    linkage: str,
) -> tuple[InstrumentSetting, dict[str, CorrectionUnit]]:
    units = dict(units)
    for control, d in changes.items():
        if control == "bz":
            setting = replace(setting, base_z_mm=np.asarray(setting.base_z_mm) + d)
        elif control_kind(control) == "cassette":
            side = control_side(control)
            units[side] = replace(units[side], kappa=np.asarray(units[side].kappa) + d)
        else:
            axis, side = control_axis(control), control_side(control)
            now = units[side].tan_alpha if axis == "alpha" else units[side].tan_omega
            units[side] = turn_correction_knob(
                units[side], axis, np.asarray(now) + d, linkage=linkage
            )
    return setting, units


def _response(
    images: tuple[ArrayLike, ArrayLike],
    setting: InstrumentSetting,
    units: dict[str, CorrectionUnit],
    changes: Mapping[str, float],
    linkage: str,
    step: float = 1e-5,
) -> tuple[Any, Any]:
    """∂q [mm, photo] and ∂D [mm, model] per unit of a combined turn (central differences)."""
    out = []
    for sign in (1.0, -1.0):
        ch = {k: sign * step * v for k, v in changes.items()}
        s, u = _turned(setting, units, ch, linkage)
        out.append(counters_from_homologous_points(images[0], images[1], s, u["left"], u["right"]))
    dq = (out[0].y_parallax_mm - out[1].y_parallax_mm) / (2.0 * step)
    dd = (out[0].depth_mm - out[1].depth_mm) / (2.0 * step)
    return dq, dd


def level_design(
    sheet: SetupSheet,
    scene: Scene,
    heights: ControlHeights,
    linkage: str = "L",
    strict_per_axis: bool = False,
) -> LevelDesign:
    """The q-neutral common tilts of remedy R3 and their height sensitivities, on the
    instrument model at the sheet's own settings
    (:func:`~stereoplotter.procedure.floor.sheet_settings`): the operator's knowledge, the same
    for every trial, which a prepared run holds (``procedure.run.prepare_pair``). ``heights``:
    the sheet's height control points (:func:`~stereoplotter.procedure.floor.control_heights_of`).
    """
    setting, units = sheet_settings(sheet, strict_per_axis)
    std = scene.standard
    j = {
        c: _response(std, setting, units, {c: 1.0}, linkage)[0]
        for c in (*LEVEL_FREE, *LEVEL_TILTS["alpha"], *LEVEL_TILTS["omega"])
    }
    combos, misfit = {}, {}
    for name, knobs in LEVEL_TILTS.items():
        fixed = {k: 1.0 for k in knobs}
        rhs = -sum(j[k] for k in knobs)
        a = np.column_stack([j[k] for k in LEVEL_FREE])
        sol = np.linalg.lstsq(a, rhs, rcond=None)[0]
        combos[name] = {**fixed, **{k: float(v) for k, v in zip(LEVEL_FREE, sol, strict=True)}}
        left = _response(std, setting, units, combos[name], linkage)[0]
        misfit[name] = float(np.max(np.abs(left)) / np.max(np.abs(rhs)))
    imgs = heights.images_mm
    cols = [np.ones(len(heights.rows))]
    for name in LEVEL_TILTS:
        _, dd = _response(imgs, setting, units, combos[name], linkage)
        cols.append(-dd * sheet.vertical_scale_denominator / 1000.0)  # deeper is lower
    return LevelDesign(combos, misfit, np.column_stack(cols))
