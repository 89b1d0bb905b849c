"""What a stage achieved on the instrument, against the ground truth and the book's tolerances.

:func:`stage_measures` reads the physical state of an instrument (one, or T of them at once)
after a stage and returns that stage's measures, each with the tolerance of the setup sheet
(``SetupSheet.tolerances``, the book's ch. 6 values): the same function grades a trainee, the
simulated operator ("par") and the population of simulated operators, so they are compared on
equal terms. No judgment enters: these are true values (the scene's ground truth).

Measures by stage (setup-data method 1–5; conventional C1–C4):

* ``1``, ``C1`` — f_пр as set against the sheet's f_пр (tolerance: one least count of the
  scales, assumed: the sheet prints f_пр to it); the height counter geared for the sheet's M_в
  (stage 1 only; 0 or 1, must be 0).
* ``2``, ``C2`` and again ``3``, ``C3`` — the largest true residual y-parallax at the six standard
  points (Fig. 39) against ``residual_y_parallax_mm`` (Eq. (5.11)'s 0.0125 mm at photo scale).
* ``3``, ``C3`` — the largest height error of the built model at the control points against
  ``control_height_m`` (:func:`~stereoplotter.procedure.evaluation.evaluate_against`, heights read
  on the slipped metre scale).
* ``4``, ``5``, ``C4`` — the largest plan error of the built model at the control points on the
  map against ``corner_mm`` (0.3 mm on the sheet, §27 stage 5), and the coordinatograph connected.

Units: y-parallax in mm at photo scale, heights in m on the ground, plan errors in mm on the map.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from stereoplotter.instrument.virtual import Instrument
from stereoplotter.procedure.evaluation import evaluate_against
from stereoplotter.procedure.operator import Noise, Operator, OperatorModel
from stereoplotter.procedure.records import SheetReadings
from stereoplotter.procedure.run import PreparedRun
from stereoplotter.procedure.transcript import Transcript

__all__ = [
    "PARALLAX_STAGES",
    "Measure",
    "model_evaluation",
    "rigid_residuals_m",
    "stage_measures",
    "standard_q",
]

#: Stages graded on the residual y-parallax at the six standard points.
PARALLAX_STAGES = ("2", "3", "C2", "C3")


@dataclass(frozen=True)
class Measure:
    """One outcome of a stage: value (float, or (T,) array), tolerance, unit; lower is better."""

    name: str
    value: Any
    tolerance: float
    unit: str

    @property
    def ratio(self) -> Any:
        """value / tolerance (≤ 1 passes)."""
        return np.asarray(self.value, float) / self.tolerance


def _f_error(inst: Instrument, prep: PreparedRun) -> NDArray[np.float64]:
    """|f_пр as set − the sheet's f_пр| (inf before f_пр is set). [mm]"""
    f_set = np.asarray(inst.state()["f_instrument_mm"], float)
    target = SheetReadings.of(prep.sheet)["f_пр"].value
    return np.abs(np.nan_to_num(f_set, nan=np.inf) - target)


def _f_scale_error(inst: Instrument, prep: PreparedRun) -> NDArray[np.float64]:
    """|f_пр on its scale − the sheet's f_пр|: what the trainee set, without the scale's hidden
    setting error (the instrument's, not the trainee's: an exact operator on e09 sets the scale
    to the sheet's value and leaves 0.0155 mm of true error). [mm]"""
    return np.abs(_f_error_signed(inst, prep) - inst.injected["setting.f_instrument"])


def _f_error_signed(inst: Instrument, prep: PreparedRun) -> NDArray[np.float64]:
    f_set = np.asarray(inst.state()["f_instrument_mm"], float)
    return np.nan_to_num(f_set, nan=np.inf) - SheetReadings.of(prep.sheet)["f_пр"].value


def _exact_operator(inst: Instrument) -> Operator:
    """An operator without judgment errors at a copy of the instrument (to look, not to act)."""
    memo = {id(inst.spec): inst.spec, id(inst.errors): inst.errors}
    twin = copy.deepcopy(inst, memo)
    return Operator(
        twin, OperatorModel().zero(), Noise(0, inst.trials, None, 0), Transcript(enabled=False)
    )


def _span_error(inst: Instrument, prep: PreparedRun) -> NDArray[np.float64]:
    """max over the photos of |L − L′|, L′ the true Y span of fiducials 3, 4 at the present
    depth (the mark put exactly on each, Y read exactly) and L = n·(y₃ − y₄) of the sheet's
    measured marks (decision D5, as the stage-1 check). [mm]"""
    op = _exact_operator(inst)
    worst = np.zeros(inst.trials) if inst.trials else np.zeros(())
    for i, side in enumerate(("left", "right")):
        fid = prep.scene.fiducials_mm[side]
        ys = []
        for mark in (3, 4):
            op.mark_on(side, fid[mark - 1], f"grade/{side}/{mark}")
            ys.append(np.asarray(op.inst.read("Y", exact=True), float))
        photo = prep.sheet.photos[i]
        m = photo.marks_measured_mm
        span = photo.n * (m["3"][1] - m["4"][1])
        worst = np.maximum(worst, np.abs(span - (ys[0] - ys[1])))
    return worst


def standard_q(inst: Instrument, prep: PreparedRun) -> NDArray[np.float64]:
    """The true y-parallax at the six standard points, shape (6,) or (T, 6). [mm]"""
    op = Operator(inst, OperatorModel(), Noise(0, inst.trials, None, 0), Transcript(enabled=False))
    scene = prep.scene
    return np.asarray(op.y_parallax(scene.standard_points_m, scene.standard), float)


def _q_max(
    inst: Instrument, prep: PreparedRun, unusable: tuple[int, ...] = ()
) -> NDArray[np.float64]:
    """The largest |q| over the usable standard points (an unusable one, on water or outside
    the overlap, cannot be seen: its substitute is graded instead). [mm]"""
    q = np.abs(np.nan_to_num(standard_q(inst, prep), nan=np.inf))
    keep = [n - 1 for n in range(1, 7) if n not in unusable]
    return np.max(q[..., keep], axis=-1)


def model_evaluation(inst: Instrument, prep: PreparedRun):
    """The built model against the prepared run's ground truth (``evaluate_against`` on
    ``prep.truth``, computed once per session), heights read on the slipped metre scale once the
    height counter is geared."""
    units = inst.state()["units"]
    zero = None
    if inst.height_gear is not None:
        zero = (
            np.asarray(inst.read("H", exact=True))
            + np.asarray(inst.state()["carriages_mm"]["Z"])
            * prep.sheet.vertical_scale_denominator
            / 1000.0
        )
    return evaluate_against(
        prep.truth, inst.setting, units["left"], units["right"], height_zero=zero
    )


def rigid_residuals_m(points) -> NDArray[np.float64]:
    """The plan residual at each point after the best rotation and shift of the built plan onto
    the true one (what orienting the sheet on the control points removes; the coordinatograph's
    gear fixes the scale). Closed-form 2-D Procrustes, per trial; shape (n,) or (T, n). [m]"""
    true = np.asarray(points.ground_m, float)[:, :2]
    built = true + np.stack(
        [np.asarray(points.x_error_m, float), np.asarray(points.y_error_m, float)], axis=-1
    )
    t0 = true - true.mean(axis=0)
    b0 = built - built.mean(axis=-2, keepdims=True)
    cross = np.sum(b0[..., 0] * t0[:, 1] - b0[..., 1] * t0[:, 0], axis=-1)
    dot = np.sum(b0[..., 0] * t0[:, 0] + b0[..., 1] * t0[:, 1], axis=-1)
    theta = np.arctan2(cross, dot)[..., None]
    c, s = np.cos(theta), np.sin(theta)
    rx = c * b0[..., 0] - s * b0[..., 1] - t0[:, 0]
    ry = s * b0[..., 0] + c * b0[..., 1] - t0[:, 1]
    return np.hypot(rx, ry)


def _rigid_residual_m(points) -> NDArray[np.float64]:
    """The largest of :func:`rigid_residuals_m`. [m]"""
    return np.max(rigid_residuals_m(points), axis=-1)


def _worst(values: Any) -> NDArray[np.float64]:
    return np.max(np.abs(np.nan_to_num(np.asarray(values, float), nan=np.inf)), axis=-1)


def stage_measures(
    inst: Instrument, prep: PreparedRun, stage: str, unusable: tuple[int, ...] = ()
) -> list[Measure]:
    """The measures of ``stage`` on the instrument as it stands (see the module docstring);
    ``unusable``: the standard points (1–6) of an incomplete model, left out of the
    y-parallax."""
    tol = prep.sheet.tolerances
    lc = prep.spec.xy_least_count_mm
    out: list[Measure] = []
    f_unset = bool(np.all(np.isinf(_f_error(inst, prep))))
    if f_unset:  # nothing is projected yet: the stage's measures cannot be taken
        out.append(Measure("f_пр not set", 1.0, 0.5, "—"))
    if stage == "1" and not f_unset:
        span = _span_error(inst, prep)
        out.append(Measure("scale coefficient |L − L′| (true)", span, tol["mark_span_mm"], "mm"))
    if stage == "C1" and not f_unset:
        out.append(Measure("f_пр as set − sheet f_пр", _f_scale_error(inst, prep), lc, "mm"))
    if stage == "1":
        geared = inst.height_gear == float(prep.sheet.vertical_scale_denominator)
        value = np.zeros(inst.trials) if inst.trials else 0.0
        out.append(Measure("height counter not geared for M_в", value + (not geared), 0.5, "—"))
    if stage in ("1", "C1"):
        return out
    if f_unset:
        return out
    if stage not in ("2", "C2", "3", "C3", "4", "5", "C4"):
        raise ValueError(f"no stage {stage!r}")
    if stage in PARALLAX_STAGES:
        out.append(
            Measure(
                "residual y-parallax at the 6 standard points (true)",
                _q_max(inst, prep, unusable),
                float(tol["residual_y_parallax_mm"]),
                "mm",
            )
        )
    if stage in ("3", "C3"):
        ev = model_evaluation(inst, prep)
        out.append(
            Measure(
                "height error at the control points",
                _worst(ev.control.height_error_m),
                float(tol["control_height_m"]),
                "m",
            )
        )
    if stage in ("4", "5", "C4"):
        ev = model_evaluation(inst, prep)
        m_map = ev.map_scale_denominator or prep.sheet.horizontal_scale_denominator
        plan = _rigid_residual_m(ev.control) * 1000.0 / m_map
        out.append(
            Measure(
                "plan error at the control points on the map (sheet fitted)",
                plan,
                float(tol["corner_mm"]),
                "mm",
            )
        )
        connected = inst.coordinatograph_connected
        value = np.zeros(inst.trials) if inst.trials else 0.0
        out.append(Measure("coordinatograph not connected", value + (not connected), 0.5, "—"))
    return out
