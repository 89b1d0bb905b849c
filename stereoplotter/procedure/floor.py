"""The error-free floor of the setup-data method (decision D9, ``docs/procedure.md``): what the
correction mechanism itself leaves at the sheet's own settings, and the refusal of a pair beyond
it before any trial is run.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from stereoplotter.instrument.kinematics import (
    CorrectionUnit,
    InstrumentSetting,
    UnitMap,
    rods_intersection,
)
from stereoplotter.instrument.knobs import unit_for_orientation
from stereoplotter.procedure.operator import Scene
from stereoplotter.procedure.records import ControlHeight
from stereoplotter.setup.records import SetupRefusal
from stereoplotter.setup.sheet import SetupSheet

__all__ = [
    "ControlHeights",
    "control_heights_of",
    "mechanism_level",
    "refuse_beyond_mechanism",
    "sheet_settings",
]


def sheet_settings(
    sheet: SetupSheet, strict_per_axis: bool = False, mechanism: Any = None
) -> tuple[InstrumentSetting, dict[str, CorrectionUnit]]:
    """The instrument at the sheet's own settings, without any error: f_пр and
    b = (b_x, b_y, b_z′) of the sheet, and the correction units "left", "right" at the sheet's
    α, ω, κ with their decentrations (``unit_for_orientation`` at f′). ``mechanism``: the
    instrument's own correction mechanism
    (:func:`~stereoplotter.instrument.principles.mechanism_for`); None: canonical unit."""
    f = sheet.focal_length_corrected_mm
    units = {
        side: replace(
            unit_for_orientation(p.alpha, p.omega, p.kappa, f, strict_per_axis=strict_per_axis),
            mechanism=mechanism,
        )
        for side, p in zip(("left", "right"), sheet.photos, strict=True)
    }
    bx, by, bz = sheet.base_mm
    return InstrumentSetting(sheet.f_instrument_mm, bx, by, bz), units


@dataclass(frozen=True)
class ControlHeights:
    """The sheet's height control points as a run reads them, built once per run
    (:func:`control_heights_of`, ``procedure.run.prepare_pair``).

    Attributes
    ----------
    rows : tuple of ControlHeight
        Id, the sheet's Z_i of (6.6) and the ground point of each, in the sheet's order.
    ground_m : ndarray, shape (n, 3)
        The ground points (local frame). [m]
    images_mm : (ndarray, ndarray)
        Their true images on the left and right photo, shape (n, 2) each. [mm]
    """

    rows: tuple[ControlHeight, ...]
    ground_m: NDArray[np.float64]
    images_mm: tuple[NDArray[np.float64], NDArray[np.float64]]


def mechanism_level(
    sheet: SetupSheet,
    scene: Scene,
    heights: ControlHeights,
    strict_per_axis: bool = False,
    mechanism: Any = None,
) -> tuple[float, float]:
    """What the correction mechanism itself leaves at the sheet's own settings (the floor).

    The instrument at the sheet's own settings (:func:`sheet_settings`), no error anywhere: the
    largest |q| at the six standard
    points [mm, photo scale], and the largest control-height error relative to the first height
    control point (where stage 3 slips the height scale) [m]. The stages cannot do better: the
    setup-data method sets exactly these values and has no relative orientation or levelling.
    ``mechanism``: the instrument's own correction mechanism
    (:func:`~stereoplotter.instrument.principles.mechanism_for`); None: canonical unit.
    ``heights``: the sheet's height control points (:func:`control_heights_of`).
    """
    setting, exact = sheet_settings(sheet, strict_per_axis, mechanism)
    units = [UnitMap(exact[side]) for side in ("left", "right")]

    def reading(images: tuple[NDArray[np.float64], NDArray[np.float64]]) -> Any:
        pl, pr = images
        return rods_intersection(units[0].rod_from_photo(pl), units[1].rod_from_photo(pr), setting)

    q_max = float(np.max(np.abs(reading(scene.standard).y_parallax_mm)))
    ground = heights.ground_m
    if len(ground) < 2:
        return q_max, 0.0
    depth = reading(heights.images_mm).depth_mm
    # deeper is lower: H_i = H_0 − (D_i − D_0)·M_в/1000 with the scale slipped at point 0
    model_h = ground[0, 2] - (depth - depth[0]) * sheet.vertical_scale_denominator / 1000.0
    return q_max, float(np.max(np.abs(model_h - ground[:, 2])))


def refuse_beyond_mechanism(
    sheet: SetupSheet,
    scene: Scene,
    heights: ControlHeights,
    strict_per_axis: bool = False,
    mechanism: Any = None,
) -> None:
    """Raise :class:`SetupRefusal` when the mechanism's own level (:func:`mechanism_level`)
    already exceeds the residual y-parallax (¼ mark) or the control-height (H/3000) tolerance:
    no operator can then build the model by the setup-data method on this instrument.

    The message names the scenario file and the field that carries the pair beyond the
    mechanism — the largest photo tilt, ``photos[i].exterior.alpha_deg`` or ``omega_deg`` — and
    the §26 tolerances the mechanism level exceeds. ``heights`` as :func:`mechanism_level`.
    """
    q_max, h_max = mechanism_level(sheet, scene, heights, strict_per_axis, mechanism)
    tol_q = sheet.tolerances["residual_y_parallax_mm"]
    tol_h = sheet.tolerances["control_height_m"]
    if q_max <= tol_q and h_max <= tol_h:
        return
    photos = scene.photos
    tilts = [
        (abs(getattr(p.exterior, axis)), i, axis)
        for i, p in enumerate(photos)
        for axis in ("alpha", "omega")
    ]
    _, i, axis = max(tilts, key=lambda t: t[0])  # the first of equal tilts
    found = np.degrees(getattr(photos[i].exterior, axis))
    films = [
        f"photos[{j}].film_deformation_ppm = [{p.film_deformation_ppm[0]:g}, "
        f"{p.film_deformation_ppm[1]:g}]"
        for j, p in enumerate(photos)
        if any(p.film_deformation_ppm)
    ]
    film_note = (
        "; the films' deformation enters this level too ("
        + ", ".join(films)
        + "): the SC complex's correction unit takes it out (--option correction_unit)"
        if films
        else ""
    )
    raise SetupRefusal(
        f"{scene.source}: photos[{i}].exterior.{axis}_deg: expected a tilt the setup-data method "
        f"on {sheet.instrument_title} can carry (§26: at the sheet's exact settings the "
        f"correction mechanism must leave ≤ ¼ mark {tol_q * 1000:.1f} µm of y-parallax at the "
        f"standard points and ≤ H/3000 {tol_h:.2f} m at the control heights), found "
        f"{found:+.1f}° (the largest tilt of the pair): at f′ = "
        f"{sheet.focal_length_corrected_mm:.0f} mm the mechanism leaves {q_max * 1000:.1f} µm "
        f"and {h_max:.2f} m (instrument test, §6); the model needs relative orientation and "
        f"levelling (--method conventional){film_note}"
    )


def control_heights_of(sheet: SetupSheet, scene: Scene) -> ControlHeights:
    """The sheet's height control points with their ground points and their true images (the
    scene's truth), once per run (``procedure.run.prepare_pair``)."""
    rows: list[ControlHeight] = []
    for h in sheet.control_heights:
        p = scene.point(h["id"])
        rows.append(
            ControlHeight(str(h["id"]), float(h["model_height_mm"]), np.asarray(p.local_m, float))
        )
    ground = np.array([h.ground_m for h in rows]).reshape(-1, 3)
    if not rows:
        return ControlHeights((), ground, (np.zeros((0, 2)), np.zeros((0, 2))))
    return ControlHeights(tuple(rows), ground, scene.images(ground))
