"""Decomposition of a procedure-MC row: formula → first order of the trial's own errors → procedure.

For an outcome row of §27 the step from the formula to the simulated operator is split into
parts, each computed on the *same* trials as the procedure's value (no extra run):

1. the formula at the book geometry (the row's ``rigorous`` column) → the same formula at the
   simulated geometry (f, l, n_л, p, c of the scenario): ``geometry``;
2. → the first-order x-parallax field of each trial's own errors of the elements of (6.22)
   (b_x, b_y, b_z, α, ω, κ of both photos), propagated with the exact derivatives of the
   instrument model at the error-free setting (central differences, :func:`state_jacobian`):
   ``element_errors`` — the formula's σ's of (6.31)–(6.38) replaced by the scatter the
   procedure actually leaves, and (6.22)'s vertical-photo coefficients by the derivatives at
   the scenario's tilted photos and relief;
3. → + the first order of the trial's error of f_пр, the instrument principal distance the
   procedure sets, which (6.22) does not carry: ``principal_distance``;
4. → + the first order of every other state variable the procedure sets (the photo and plane
   decentrations e, c of both units, the model origin MO), which (6.22) drops:
   ``decentrations``;
5. → the procedure's δp (the instrument model itself, every order): ``non_linear`` (the rest).

Every step is a difference of RMS values of fields on the same trials and grid; its CI is the
delta-method CI (``CI_Z`` standard errors) of the paired per-trial mean squares. The steps add up
to the plain procedure value by construction; the row's procedure value is the control-variate
estimate of the same trials, so the sum agrees with it within the two CIs (the check of
``docs/accuracy.md``).

Units: photo mm inside; the summaries per the row's unit (m_xy or m_p). Pure numpy.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Mapping
from dataclasses import replace
from typing import Any

import numpy as np

from stereoplotter.instrument.kinematics import CorrectionUnit, InstrumentSetting
from stereoplotter.verification.linear_mc import CI_Z, FloatArray

__all__ = [
    "ELEMENTS",
    "LEVELS",
    "OTHER_STATE",
    "PRINCIPAL_DISTANCE",
    "STATE",
    "at_book",
    "linear_fields",
    "paired_step",
    "rms_ci",
    "rms_steps",
    "state_deltas",
    "state_jacobian",
]

#: A variable of the instrument state: (object, field), the object "setting" or a unit side.
StateKey = tuple[str, str]
#: The elements of (6.22): (object, field) of the instrument state; "setting" or a unit side.
ELEMENTS = (
    ("setting", "base_x_mm"),
    ("setting", "base_y_mm"),
    ("setting", "base_z_mm"),
    *((s, f) for s in ("left", "right") for f in ("tan_alpha", "tan_omega", "kappa")),
)
#: f_пр, the instrument principal distance the procedure sets (stage 1-2): not in (6.22).
PRINCIPAL_DISTANCE = (("setting", "f_instrument_mm"),)
#: The rest of the state the procedure sets: decentrations (photo e, plane c) and model origin.
OTHER_STATE = (
    ("setting", "model_origin_x_mm"),
    ("setting", "model_origin_y_mm"),
    *(
        (s, f)
        for s in ("left", "right")
        for f in (
            "decentration_x_mm",
            "decentration_y_mm",
            "plane_decentration_x_mm",
            "plane_decentration_y_mm",
        )
    ),
)
STATE = ELEMENTS + PRINCIPAL_DISTANCE + OTHER_STATE
#: Cumulative first-order fields: name → how many leading variables of :data:`STATE` it takes.
LEVELS = (
    ("elements", len(ELEMENTS)),
    ("principal_distance", len(ELEMENTS) + 1),
    ("first_order", len(STATE)),
)
#: Central-difference steps: tangents and κ [—, rad], lengths [mm]; the field is linear far
#: beyond them at these scales (a procedure error is ≈ 1e-4 rad, 10 µm).
_STEP = {"tan_alpha": 1e-6, "tan_omega": 1e-6, "kappa": 1e-6}
_STEP_MM = 1e-4


def _resolved(unit: CorrectionUnit) -> CorrectionUnit:
    """The unit with its plane decentration written out (c = e under decision D2)."""
    cx, cy = unit.plane_decentration_mm
    return replace(unit, plane_decentration_x_mm=cx, plane_decentration_y_mm=cy)


def _get(
    setting: InstrumentSetting, units: Mapping[str, CorrectionUnit], key: StateKey
) -> FloatArray:
    obj, name = key
    src = setting if obj == "setting" else units[obj]
    return np.asarray(getattr(src, name), float)


def _set(
    setting: InstrumentSetting, units: Mapping[str, CorrectionUnit], key: StateKey, value: float
) -> tuple[InstrumentSetting, dict[str, CorrectionUnit]]:
    obj, name = key
    change: dict[str, Any] = {name: value}
    if obj == "setting":
        return replace(setting, **change), dict(units)
    return setting, {**units, obj: replace(units[obj], **change)}


#: δp at fixed points [photo mm] as a function of an instrument state (setting, left, right).
DpOf = Callable[[InstrumentSetting, CorrectionUnit, CorrectionUnit], FloatArray]


def state_jacobian(
    setting: InstrumentSetting, units: Mapping[str, CorrectionUnit], dp_of: DpOf
) -> FloatArray:
    """∂δp/∂s for every state variable s of :data:`STATE` at the (error-free, scalar) state.

    ``dp_of(setting, left, right)`` → δp at the points (P,) [photo mm]. Returns (len(STATE), P).
    """
    units = {k: _resolved(u) for k, u in units.items()}
    rows = []
    for key in STATE:
        h = _STEP.get(key[1], _STEP_MM)
        v0 = float(np.ravel(_get(setting, units, key))[0])
        out = []
        for sign in (1.0, -1.0):
            s, u = _set(setting, units, key, v0 + sign * h)
            out.append(np.asarray(dp_of(s, u["left"], u["right"]), float).ravel())
        rows.append((out[0] - out[1]) / (2.0 * h))
    return np.array(rows)


def state_deltas(
    setting: InstrumentSetting,
    units: Mapping[str, CorrectionUnit],
    zero_setting: InstrumentSetting,
    zero_units: Mapping[str, CorrectionUnit],
    trials: int,
    rows: slice | None = None,
) -> FloatArray:
    """Each trial's state minus the error-free state, (len(STATE), T); ``rows``: the trials'
    rows of a state of more trials (None: all of it)."""
    units = {k: _resolved(u) for k, u in units.items()}
    zero_units = {k: _resolved(u) for k, u in zero_units.items()}
    out = np.empty((len(STATE), trials))
    for i, key in enumerate(STATE):
        v = _get(setting, units, key)
        if rows is not None and v.ndim:
            v = v[rows]
        z = float(np.ravel(_get(zero_setting, zero_units, key))[0])
        out[i] = np.broadcast_to(v - z, (trials,))
    return out


def linear_fields(jacobian: FloatArray, deltas: FloatArray) -> Iterator[tuple[str, FloatArray]]:
    """The cumulative first-order fields (T, P) of :data:`LEVELS`, one at a time: (name, field)
    for ``elements`` (the (6.22) elements only), ``principal_distance`` (+ f_пр) and
    ``first_order`` (every state variable)."""
    field: FloatArray | float = 0.0
    done = 0
    for name, upto in LEVELS:
        field = field + deltas[done:upto].T @ jacobian[done:upto]
        done = upto
        yield name, np.asarray(field)


def _rms_ci(ms: np.ndarray) -> tuple[float, float]:
    mean = float(np.mean(ms))
    r = math.sqrt(max(mean, 0.0))
    return r, CI_Z * float(np.std(ms, ddof=1)) / math.sqrt(len(ms)) / (2.0 * r)


def _diff_ci(ms_to: np.ndarray, ms_from: np.ndarray) -> tuple[float, float]:
    """RMS(to) − RMS(from) and its delta-method CI from the paired per-trial mean squares."""
    r1, _ = _rms_ci(ms_to)
    r0, _ = _rms_ci(ms_from)
    d = ms_to / (2.0 * r1) - ms_from / (2.0 * r0)
    return r1 - r0, CI_Z * float(np.std(d, ddof=1)) / math.sqrt(len(d))


def paired_step(ms_to: np.ndarray, ms_from: np.ndarray, unit: float) -> tuple[float, float]:
    """RMS(to) − RMS(from) per ``unit`` and its CI from the paired per-trial mean squares of
    two runs on the same trials (a switch step of ``verify --json``)."""
    c, h = _diff_ci(np.asarray(ms_to, float), np.asarray(ms_from, float))
    return c / unit, h / unit


def rms_ci(ms: np.ndarray, unit: float) -> tuple[float, float]:
    """The RMS of per-trial mean squares ``ms`` per ``unit`` and its CI."""
    r, h = _rms_ci(np.asarray(ms, float))
    return r / unit, h / unit


#: Step names in order, with what each adds (the mechanism is named by the caller only where a
#: switch run showed it).
STEPS = (
    ("geometry", "formula at the book geometry → at the simulated geometry"),
    ("element_errors", "→ first order of each trial's own errors of the (6.22) elements"),
    ("principal_distance", "→ + first order of the error of f_пr as set ((6.22) has no f_пр)"),
    ("decentrations", "→ + first order of the decentrations and model origin ((6.22) drops them)"),
    ("non_linear", "→ the procedure (every order of the instrument model)"),
)
#: The levels each step goes between.
_PAIRS = (
    ("simulated_geometry", "elements"),
    ("elements", "principal_distance"),
    ("principal_distance", "first_order"),
    ("first_order", "procedure"),
)


def rms_steps(simulated: float, ms: Mapping[str, FloatArray], unit: float) -> dict[str, Any]:
    """The decomposition block of one reading, without the book-geometry step (:func:`at_book`).

    ``simulated``: the formula per unit at the simulated geometry; ``ms``: per-trial mean
    squares (photo mm²) of "elements", "first_order" and "procedure" (plain) on the same trials;
    ``unit``: the row's unit [photo mm]. Returns ``values`` (each level with its CI) and
    ``steps`` (name, text, contribution, CI, relative to the simulated formula).
    """
    levels = {"simulated_geometry": (simulated, 0.0)}
    for name in (*(n for n, _ in LEVELS), "procedure"):
        r, h = _rms_ci(ms[name])
        levels[name] = (r / unit, h / unit)
    steps: list[dict[str, Any]] = []
    for (name, text), (a, b) in zip(STEPS[1:], _PAIRS, strict=True):
        if a in ms:
            c, h = _diff_ci(ms[b], ms[a])
            c, h = c / unit, h / unit
        else:
            c, h = levels[b][0] - levels[a][0], levels[b][1]
        steps.append(
            {"step": name, "text": text, "contribution": c, "ci": h, "relative": c / simulated}
        )
    return {"values": {k: {"value": v, "ci": h} for k, (v, h) in levels.items()}, "steps": steps}


def at_book(block: Mapping[str, Any], book: float, scale: float = 1.0) -> dict[str, Any]:
    """``block`` of :func:`rms_steps` × ``scale`` with the geometry step from the formula at the
    book geometry ``book`` prepended, and ``sum`` = book + Σ contributions (= the plain
    procedure value)."""
    values = {
        k: {"value": v["value"] * scale, "ci": v["ci"] * scale} for k, v in block["values"].items()
    }
    simulated = values["simulated_geometry"]["value"]
    steps = [
        {
            "step": STEPS[0][0],
            "text": STEPS[0][1],
            "contribution": simulated - book,
            "ci": 0.0,
            "relative": simulated / book - 1.0,
        }
    ]
    steps += [
        {**s, "contribution": s["contribution"] * scale, "ci": s["ci"] * scale}
        for s in block["steps"]
    ]
    return {
        "values": {"book_geometry": {"value": book, "ci": 0.0}, **values},
        "steps": steps,
        "sum": book + sum(s["contribution"] for s in steps),
    }
