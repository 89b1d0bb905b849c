"""The robot trainee's script: an exercise done by page controls, passing on the true values.

:func:`robot_script` is the list of session actions a scripted trainee takes for an exercise —
each one use of one page control (``set`` a value, ``read`` a counter, ``gear``, ``slip``,
``connect``, ``needle``, ``record`` a substitute point, ``claim``) — such that replaying it
through :class:`~stereoplotter.trainer.session.Session` passes the exercise's grade
(``tests/trainer/test_robot_script.py`` replays it for every shipped exercise).

How it is built, per stage of the exercise:

1. **The exact operator.** The simulated operator of the exercise's instrument (same injected
   errors, same seed) with no judgment errors (``OperatorModel.zero()``: exact pointings and
   readings) does the stage; its calls on the instrument are its actions
   (:func:`~stereoplotter.trainer.operator_steps.operator_run`). The operator *with* its judgment
   errors (the grade's par) does not always pass on the true values (e08: control heights 0.51 m
   against 0.46 m, ``docs/trainer.md``), so it is not the robot.
2. **Compacted.** A run of pointing moves (``set`` of X, Y, Z), settings of κ and the
   correction knobs and readings between two other actions is replaced by the last setting of
   each control in the run (a lead screw finished from the side its original last move came
   from, so the carriage takes up the backlash the same way) and the run's last reading: the
   instrument ends in the state the run left it in, in a few page actions instead of hundreds
   (:func:`robot_stats`; e12: 467 actions instead of the exact operator's 6 967).
3. **Finished.** Where the stage's residual y-parallax at the six standard points (stages 2, 3,
   C2, C3) still exceeds half its tolerance, the robot clears it by least squares on the five
   elements of relative orientation (κ_л, κ_п, k_α,л, k_α,п, k_ω,п), Gauss–Newton on the true
   y-parallax with a numerical Jacobian, and sets each control once: the element-by-element
   procedure of the conventional method stops short of the tolerance even for an exact
   operator (e05: 0.029 mm against 0.0125 mm, measured on this module's first run). In stages 3
   and C3 it then levels the model where the heights at the control points exceed half their
   tolerance (Gauss–Newton on the y-parallax and the heights over the relative elements, k_ω,л
   and b_z, then the metre scale slipped by the mean height error): the conventional absolute
   orientation left 3.6 m against 0.57 m on e12 (mountains) for the exact operator.
   The finishing runs inside the exact operator's own run, after each stage (so the next stage
   starts from it), and once more on the session's instrument (whose preset stages are the
   par's).
4. The unusable standard points of an incomplete model get their substitute (the point itself on
   the left photo, what the operator would choose) before the claim.
"""

from __future__ import annotations

import copy
import dataclasses
from typing import Any

import numpy as np

from stereoplotter.instrument.virtual import CASSETTES, DECENTRATIONS, KNOBS, SCREWS, Instrument
from stereoplotter.procedure.run import PreparedRun
from stereoplotter.trainer.actions import apply, control_value
from stereoplotter.trainer.exercise import Exercise
from stereoplotter.trainer.operator_steps import OperatorRun, operator_run
from stereoplotter.trainer.outcome import PARALLAX_STAGES, model_evaluation, standard_q

__all__ = [
    "RELATIVE_ELEMENTS",
    "compact",
    "robot_script",
    "robot_stats",
    "without_sides",
]

#: The five elements of relative orientation the robot clears the y-parallax with (the
#: operator's own least-squares step of stage 2 turns the same five).
RELATIVE_ELEMENTS = ("kappa_left", "kappa_right", "k_alpha_left", "k_alpha_right", "k_omega_right")
#: The elements the robot levels the model with (heights at the control points) while keeping
#: the y-parallax cleared: the five of relative orientation, k_ω,л and b_z.
LEVEL_ELEMENTS = (*RELATIVE_ELEMENTS, "k_omega_left", "bz")
#: Jacobian steps of the levelling other than :data:`_H`: b_z in mm.
_LEVEL_H = {"bz": 1e-3}
#: The robot finishes when the largest true y-parallax exceeds this share of the tolerance
#: (assumed: a margin for the Jacobian's linearisation). [—]
FINISH_SHARE = 0.5
#: Gauss–Newton steps at most (each sets the five elements once).
GAUSS_NEWTON_STEPS = 4
#: Steps of the numerical Jacobian: κ in rad, knobs in tan. [—]
_H = 1e-5
_POINTING = ("X", "Y", "Z")
_ELEMENTS = (*CASSETTES, *KNOBS)


def _exact_q(inst: Instrument, prep: PreparedRun) -> np.ndarray:
    """The true y-parallax at the six standard points, flat (6,). [mm]"""
    return np.asarray(standard_q(inst, prep), float).reshape(-1)


def _copy(inst: Instrument) -> Instrument:
    """A plain copy of an instrument's physical state, without its listener (the twin only
    looks: its actions are nobody's)."""
    memo: dict[int, Any] = {id(inst.spec): inst.spec, id(inst.errors): inst.errors}
    if inst.on_action is not None:
        memo[id(inst.on_action)] = None
    return copy.deepcopy(inst, memo)


def _commanded(actions: list[dict[str, Any]]) -> dict[str, float]:
    """The last value set on each scale-set control (f_пр, κ, knobs) in ``actions``."""
    out: dict[str, float] = {}
    for a in actions:
        if a["kind"] == "set" and a["control"] not in SCREWS and a["control"] not in DECENTRATIONS:
            out[a["control"]] = a["value"]
    return out


def _clear_parallax(
    inst: Instrument, prep: PreparedRun, commanded: dict[str, float], unusable: tuple[int, ...]
) -> list[dict[str, Any]]:
    """Set actions that clear the y-parallax by least squares on :data:`RELATIVE_ELEMENTS`
    (:data:`GAUSS_NEWTON_STEPS` at most) at the usable standard points (the grade
    leaves the unusable ones out); applied to ``inst`` as they are made."""
    tol = float(prep.sheet.tolerances["residual_y_parallax_mm"])
    use = np.array([n not in unusable for n in range(1, 7)])
    out: list[dict[str, Any]] = []
    for _ in range(GAUSS_NEWTON_STEPS):
        q0 = _exact_q(inst, prep)[use]
        if np.max(np.abs(q0)) <= FINISH_SHARE * tol:
            break
        jac = np.empty((int(use.sum()), len(RELATIVE_ELEMENTS)))
        for j, control in enumerate(RELATIVE_ELEMENTS):
            twin, cmd = _copy(inst), dict(commanded)
            value = control_value(twin, control, cmd) + _H
            apply(twin, {"kind": "set", "control": control, "value": value}, cmd)
            jac[:, j] = (_exact_q(twin, prep)[use] - q0) / _H
        step, *_ = np.linalg.lstsq(jac, -q0, rcond=None)
        for control, d in zip(RELATIVE_ELEMENTS, step, strict=True):
            value = round(control_value(inst, control, commanded) + float(d), 9)
            action = {"kind": "set", "control": control, "value": value}
            apply(inst, action, commanded)
            out.append(action)
    return out


def _level(
    inst: Instrument, prep: PreparedRun, commanded: dict[str, float], unusable: tuple[int, ...]
) -> list[dict[str, Any]]:
    """Set actions that bring the heights at the control points within their tolerance while
    keeping the y-parallax cleared: Gauss–Newton on [q / tol_q, (ΔH − mean ΔH) / tol_H] over
    :data:`LEVEL_ELEMENTS` (columns scaled to unit length, the minimum-norm step), then the
    metre height scale slipped by the mean ΔH."""
    tol_q = float(prep.sheet.tolerances["residual_y_parallax_mm"])
    tol_h = float(prep.sheet.tolerances["control_height_m"])
    use = np.array([n not in unusable for n in range(1, 7)])

    def residual(i: Instrument) -> tuple[np.ndarray, float]:
        dh = np.asarray(model_evaluation(i, prep).control.height_error_m, float).reshape(-1)
        q = _exact_q(i, prep)[use]
        return np.concatenate([q / tol_q, (dh - dh.mean()) / tol_h]), float(dh.mean())

    out: list[dict[str, Any]] = []
    for _ in range(GAUSS_NEWTON_STEPS):
        r0, mean = residual(inst)
        if np.max(np.abs(r0)) <= FINISH_SHARE:
            break
        jac = np.empty((r0.size, len(LEVEL_ELEMENTS)))
        for j, control in enumerate(LEVEL_ELEMENTS):
            twin, cmd = _copy(inst), dict(commanded)
            h = _LEVEL_H.get(control, _H)
            value = control_value(twin, control, cmd) + h
            apply(twin, {"kind": "set", "control": control, "value": value}, cmd)
            jac[:, j] = (residual(twin)[0] - r0) / h
        norm = np.linalg.norm(jac, axis=0)
        norm[norm == 0] = 1.0
        step, *_ = np.linalg.lstsq(jac / norm, -r0, rcond=1e-6)
        for control, d in zip(LEVEL_ELEMENTS, step / norm, strict=True):
            value = round(control_value(inst, control, commanded) + float(d), 9)
            action = {"kind": "set", "control": control, "value": value}
            apply(inst, action, commanded)
            out.append(action)
    _, mean = residual(inst)
    if abs(mean) > 0.1 * tol_h:
        value = round(float(np.asarray(inst.read("H", exact=True)).reshape(-1)[0]) - mean, 4)
        action = {"kind": "slip", "value": value}
        apply(inst, action, commanded)
        out.append(action)
    return out


def _finish(
    stage: str,
    inst: Instrument,
    prep: PreparedRun,
    commanded: dict[str, float],
    unusable: tuple[int, ...],
) -> list[dict[str, Any]]:
    """The robot's finishing of a stage (module docstring, 3)."""
    out: list[dict[str, Any]] = []
    if stage in PARALLAX_STAGES:
        out += _clear_parallax(inst, prep, commanded, unusable)
    if stage in ("3", "C3") and inst.height_gear is not None:
        out += _level(inst, prep, commanded, unusable)
    return out


def compact(
    actions: list[dict[str, Any]], readings: dict[str, float], elements: bool = True
) -> list[dict[str, Any]]:
    """The actions with each run of pointing moves and readings replaced by the last setting of
    each lead screw in the run (from the side its original last move finished) and the run's last
    reading (see the module docstring, 2).

    ``readings``: each screw's reading before the first action (updated as the actions go). [mm]
    ``elements``: the settings of κ and the correction knobs belong to a run too (their last
    setting in the run is kept): κ moves nothing else, and a knob drags only its own
    decentration by f′·ΔT, the same in one step as in many; a decentration, f_пр, a base screw,
    the height scale or the coordinatograph ends the run.
    """
    out: list[dict[str, Any]] = []
    run: list[dict[str, Any]] = []

    def flush() -> None:
        last: dict[str, dict[str, Any]] = {}
        read = None
        for a in run:
            if a["kind"] == "read":
                read = a
                continue
            control = a["control"]
            side = a.get("side")
            if control in _ELEMENTS:
                last.pop(control, None)
                last[control] = dict(a)
                continue
            if side is None:
                before = readings.get(control)
                if before is not None and a["value"] != before:
                    side = "below" if a["value"] > before else "above"
            readings[control] = a["value"]
            last.pop(control, None)  # re-inserted: kept in the order of the last settings
            last[control] = {**a, "side": side} if side else dict(a)
        out.extend(last.values())
        if read is not None:
            out.append(read)
        run.clear()

    for a in actions:
        movable = _POINTING + _ELEMENTS if elements else _POINTING
        pointing = a["kind"] == "read" or (a["kind"] == "set" and a["control"] in movable)
        if pointing:
            run.append(a)
            continue
        flush()
        if a["kind"] == "set" and a["control"] in SCREWS:
            readings[a["control"]] = a["value"]
        out.append(a)
    flush()
    return out


def robot_script(session: Any) -> list[dict[str, Any]]:
    """The robot trainee's actions for the session's exercise, each stage ending in its claim
    (see the module docstring). ``session``: a fresh
    :class:`~stereoplotter.trainer.session.Session` (its preset stages applied, nothing done)."""
    ex: Exercise = session.exercise
    run = _robot_run(session)
    inst = _copy(session.inst)
    commanded = dict(session.commanded)
    readings = {s: float(np.asarray(inst.read(s, exact=True)).reshape(-1)[0]) for s in SCREWS}
    # the preset stages are the par's (the session's): the robot starts from the session's state
    script: list[dict[str, Any]] = []
    for stage in ex.stages:
        actions = [{k: v for k, v in a.items() if k != "stage"} for a in run.stage_actions(stage)]
        for a in compact(actions, readings):
            if a["kind"] != "read":
                apply(inst, a, commanded)
            script.append(a)
        script.extend(_finish(stage, inst, session.prep, commanded, ex.unusable_points))
        if stage in ("2", "C2"):
            for n in ex.unusable_points:
                xy = [float(v) for v in session.prep.scene.standard[0][n - 1]]
                script.append({"kind": "record", "name": f"substitute {n}", "value": xy})
        script.append({"kind": "claim", "step": stage})
    return script


def _robot_run(session: Any) -> OperatorRun:
    """The exact operator's run, finished after each y-parallax stage (module docstring, 1, 3)."""
    ex: Exercise = session.exercise
    prep = dataclasses.replace(session.prep, operator=session.prep.operator.zero())

    def finish(stage: str, inst: Instrument, actions: list[dict[str, Any]]) -> None:
        _finish(stage, inst, session.prep, _commanded(actions), ex.unusable_points)

    return operator_run(prep, session.seed, ex.stages[-1], after_stage=finish)


#: The pre-position of :func:`without_sides`: this far beyond the target before the last stroke
#: (assumed: well beyond the backlash of the instruments' screws, 0.005–0.02 mm). [mm]
PRE_POSITION_MM = 0.2


def without_sides(script: list[dict[str, Any]], session: Any) -> list[dict[str, Any]]:
    """The script with each ``side`` of a lead screw's setting replaced by a plain setting
    :data:`PRE_POSITION_MM` beyond the target on that side, then the target (what the side
    does inside the instrument, ``PlayAxis.approach``): for a page without a "finish from"
    choice. A setting whose pre-position would pass a stop, a setting of the height scale H and
    the needle are left plain (their move's own direction finishes them; the grade does not
    read the needle; every shipped exercise still passes, ``tests/trainer``)."""
    out: list[dict[str, Any]] = []
    for a in script:
        side = a.get("side")
        if side is None:
            out.append(a)
            continue
        if a["kind"] != "set" or a["control"] not in SCREWS:  # the needle, the height scale
            out.append({k: v for k, v in a.items() if k != "side"})
            continue
        lo, hi = sorted(
            float(np.asarray(session.inst.reading_of(a["control"], v)).reshape(-1)[0])
            for v in session.inst.travel_mm(a["control"])
        )
        pre = a["value"] - PRE_POSITION_MM if side == "below" else a["value"] + PRE_POSITION_MM
        plain = {k: v for k, v in a.items() if k != "side"}
        out += [{**plain, "value": round(pre, 6)}, plain] if lo <= pre <= hi else [plain]
    return out


def robot_stats(session: Any, script: list[dict[str, Any]]) -> dict[str, int]:
    """Actions of the finished exact operator and of the robot's compacted script over the
    exercise's stages."""
    run = _robot_run(session)
    full = sum(len(run.stage_actions(s)) for s in session.exercise.stages)
    return {"operator_actions": full, "robot_actions": len(script)}
