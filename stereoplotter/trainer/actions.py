"""The actions a trainee can take and how each acts on the virtual instrument.

An action is a dict ``{"kind": ..., ...}`` (JSON). :data:`ACTION_FIELDS` lists each kind's
fields; :func:`check_action` refuses a malformed action with one line; :func:`apply` carries an
instrument action out (``turn``, ``set``, ``direction``, ``read``, ``gear``, ``slip``,
``connect``, ``needle``). ``lock``, ``record``, ``claim``, ``undo``, ``redo`` and ``hint`` act on
the session, not the instrument (:mod:`stereoplotter.trainer.session`).

Units: readings in the control's own unit — lead screws and decentrations in mm of their
counter, the height scale H in m, κ in rad, the correction knobs k_α, k_ω in the tilt tangent
they represent (—), f_пр in mm.
"""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np

from stereoplotter.errors import StereoplotterError, TrainerError
from stereoplotter.instrument.virtual import (
    CASSETTES,
    CONTROL_INFO,
    DECENTRATIONS,
    HEIGHT_SCALE,
    KNOBS,
    SCREWS,
    Instrument,
)

__all__ = [
    "ACTION_CATALOGUE",
    "ACTION_FIELDS",
    "COUNTERS",
    "INSTRUMENT_KINDS",
    "TURNABLE",
    "apply",
    "check_action",
    "control_value",
    "refusal_text",
]

#: Each action kind → its required fields (optional ones: ``side`` of set/turn/needle, ``t``).
ACTION_FIELDS: dict[str, tuple[str, ...]] = {
    "turn": ("control", "delta"),
    "set": ("control", "value"),
    "direction": ("counter", "sign"),
    "lock": ("control",),
    "read": ("counter",),
    "record": ("name", "value"),
    "claim": ("step",),
    "undo": (),
    "redo": (),
    "hint": ("level",),
    "gear": ("value",),
    "slip": ("value",),
    "connect": ("value",),
    "needle": (),
}
#: Kinds that act on the instrument.
INSTRUMENT_KINDS = ("turn", "set", "direction", "read", "gear", "slip", "connect", "needle")
#: Counters and scales a trainee reads (the metre height scale H once geared).
COUNTERS = (*SCREWS, *DECENTRATIONS, HEIGHT_SCALE)
#: Every control a trainee turns or sets.
TURNABLE = (*SCREWS, HEIGHT_SCALE, "f_instrument", *CASSETTES, *DECENTRATIONS, *KNOBS)


def _field(name: str, type_: str, unit: str | None = None, **more: Any) -> dict[str, Any]:
    return {"name": name, "type": type_, "unit": unit, "optional": False, **more}


_SIDE = _field("side", "choice", None, choices=["below", "above"], optional=True)
#: Each control → its unit (:data:`~stereoplotter.instrument.virtual.CONTROL_INFO`), for a field
#: in the control's own unit.
_UNITS = {name: CONTROL_INFO[name].unit for name in TURNABLE}
#: Every action the core accepts, with its fields, for a page to make one control per kind
#: (JSON). Field ``type``: ``choice`` (one of ``choices``), ``number``, ``integer``, ``text``,
#: ``point`` ([x_mm, y_mm] on the left photo) or ``number-or-point``; ``unit`` in the control's
#: own unit where the field is a number (``"control"``: mm of a counter, m of the height scale,
#: rad of κ, tangent of a correction knob, mm of f_пр; each control's in ``units``).
#: ``acts_on``: ``instrument`` or ``session``; ``assist``: the exercise assist that must allow
#: it (exam: never undo nor hints).
ACTION_CATALOGUE: list[dict[str, Any]] = [
    {
        "kind": "turn",
        "label": "turn a handwheel, knob or scale by a step",
        "fields": [
            _field("control", "choice", None, choices=list(TURNABLE)),
            _field("delta", "number", "control", units=_UNITS),
            _SIDE,
        ],
        "acts_on": "instrument",
        "assist": None,
    },
    {
        "kind": "set",
        "label": "turn a control until its scale shows a value",
        "fields": [
            _field("control", "choice", None, choices=list(TURNABLE)),
            _field("value", "number", "control", units=_UNITS),
            _SIDE,
        ],
        "acts_on": "instrument",
        "assist": None,
    },
    {
        "kind": "direction",
        "label": "switch a counter's direction",
        "fields": [
            _field("counter", "choice", None, choices=[*SCREWS, *DECENTRATIONS]),
            _field("sign", "choice", None, choices=[1, -1]),
        ],
        "acts_on": "instrument",
        "assist": None,
    },
    {
        "kind": "read",
        "label": "read a counter to its least count",
        "fields": [_field("counter", "choice", None, choices=list(COUNTERS))],
        "acts_on": "instrument",
        "assist": None,
    },
    {
        "kind": "lock",
        "label": "lock a control (a later turn is refused)",
        "fields": [_field("control", "choice", None, choices=list(TURNABLE))],
        "acts_on": "session",
        "assist": None,
    },
    {
        "kind": "record",
        "label": "write a value on the sheet: a zero reading, or 'substitute N' as a point "
        "clicked on the left photo",
        "fields": [
            _field("name", "text", None, examples=["MO_X", "substitute 5"]),
            _field("value", "number-or-point", "mm"),
        ],
        "acts_on": "session",
        "assist": None,
    },
    {
        "kind": "gear",
        "label": "gear the height counter for the vertical scale M_в",
        "fields": [_field("value", "integer", "—")],
        "acts_on": "instrument",
        "assist": None,
    },
    {
        "kind": "slip",
        "label": "slip the metre height scale to show a height now",
        "fields": [_field("value", "number", "m")],
        "acts_on": "instrument",
        "assist": None,
    },
    {
        "kind": "connect",
        "label": "connect the coordinatograph at a ratio M_г/M_map",
        "fields": [
            _field("value", "number", "—"),
            _field("origin_mm", "point", "mm", optional=True),
        ],
        "acts_on": "instrument",
        "assist": None,
    },
    {
        "kind": "needle",
        "label": "lower the coordinatograph's needle (mark the sheet)",
        "fields": [_SIDE],
        "acts_on": "instrument",
        "assist": None,
    },
    {
        "kind": "claim",
        "label": "claim the stage in hand done",
        "fields": [_field("step", "choice", None, choices=[*"12345", "C1", "C2", "C3", "C4"])],
        "acts_on": "session",
        "assist": None,
    },
    {"kind": "undo", "label": "undo", "fields": [], "acts_on": "session", "assist": "undo"},
    {"kind": "redo", "label": "redo", "fields": [], "acts_on": "session", "assist": "undo"},
    {
        "kind": "hint",
        "label": "a hint: 1 what to do, 2 which control, 3 show me",
        "fields": [_field("level", "choice", None, choices=[1, 2, 3])],
        "acts_on": "session",
        "assist": "hints",
    },
]


def _number(action: dict[str, Any], key: str) -> float:
    value = action[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise TrainerError(
            f"action {action['kind']}: {key}: expected a finite number, found {value!r}"
        )
    return float(value)


def check_action(action: Any) -> dict[str, Any]:
    """The action if it is well formed, else :class:`TrainerError` naming the field."""
    if not isinstance(action, dict):
        raise TrainerError(f"action: expected a mapping with a kind, found {action!r}")
    kind = action.get("kind")
    if kind not in ACTION_FIELDS:
        raise TrainerError(
            f"action kind: expected one of {', '.join(ACTION_FIELDS)}, found {kind!r}"
        )
    for key in ACTION_FIELDS[kind]:
        if key not in action:
            raise TrainerError(f"action {kind}: missing field {key!r}")
    if kind in ("turn", "set", "lock") and action["control"] not in TURNABLE:
        raise TrainerError(
            f"action {kind}: control: expected one of {', '.join(TURNABLE)}, "
            f"found {action['control']!r}"
        )
    if kind in ("read", "direction") and action["counter"] not in COUNTERS:
        raise TrainerError(
            f"action {kind}: counter: expected one of {', '.join(COUNTERS)}, "
            f"found {action['counter']!r}"
        )
    if kind == "direction" and action["sign"] not in (1, -1):
        raise TrainerError(f"action direction: sign: expected 1 or -1, found {action['sign']!r}")
    if kind == "direction" and action["counter"] == HEIGHT_SCALE:
        raise TrainerError("action direction: the height scale H has no direction switch")
    if kind == "hint" and action["level"] not in (1, 2, 3):
        raise TrainerError(f"action hint: level: expected 1, 2 or 3, found {action['level']!r}")
    if kind == "turn":
        _number(action, "delta")
    if kind in ("set", "slip", "connect", "gear"):
        _number(action, "value")
    if kind == "connect" and action.get("origin_mm") is not None:
        o = action["origin_mm"]
        if (
            not isinstance(o, list)
            or len(o) != 2
            or not all(
                isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
                for v in o
            )
        ):
            raise TrainerError(f"action connect: origin_mm: expected [x_mm, y_mm], found {o!r}")
    if "side" in action and action["side"] not in ("below", "above", None):
        raise TrainerError(
            f"action {kind}: side: expected below, above or null, found {action['side']!r}"
        )
    return action


#: A file path in an instrument's refusal (``…/data/instruments/sd3.yaml``): a trainee is told
#: the instrument, never where the server keeps its files.
_PATH = re.compile(r"(?:[^\s:]*[/\\])?([\w.-]+)\.ya?ml\b")


def refusal_text(message: str) -> str:
    """An instrument's refusal without file paths (the file named by its stem, "sd3") and
    without the advice to edit the file (the trainee cannot)."""
    text = _PATH.sub(lambda m: f"instrument {m.group(1)}", message)
    return text.replace("; widen the range in the YAML if your instrument allows it", "")


def control_value(inst: Instrument, control: str, commanded: dict[str, float]) -> float:
    """What a control's own scale shows now (exact), in the control's unit.

    Knobs have no usable zero place (stage 2 fits them): their value is the tilt tangent last
    set on them (0 at the start).
    """
    if control in SCREWS or control in DECENTRATIONS or control == HEIGHT_SCALE:
        return float(np.asarray(inst.read(control, exact=True)).reshape(-1)[0])
    return commanded.get(control, 0.0)


def apply(inst: Instrument, action: dict[str, Any], commanded: dict[str, float]) -> Any:
    """Carry out an instrument action; returns what it shows (a reading) or None.

    ``commanded`` holds the last value set on each scale-set control (f_пр, κ, knobs) and is
    updated. An instrument refusal (a stop, a gear that does not exist) becomes
    :class:`TrainerError` with the instrument's words.
    """
    kind = action["kind"]
    try:
        if kind in ("turn", "set"):
            control = action["control"]
            value = (
                control_value(inst, control, commanded) + _number(action, "delta")
                if kind == "turn"
                else _number(action, "value")
            )
            if control in KNOBS:
                inst.turn_knob(control, value)
            else:
                inst.set(control, value, action.get("side"))
            if control not in SCREWS and control not in DECENTRATIONS and control != HEIGHT_SCALE:
                commanded[control] = value
            return None
        if kind == "direction":
            inst.switch_counter(action["counter"], int(action["sign"]))
            return None
        if kind == "read":
            return float(np.asarray(inst.read(action["counter"])).reshape(-1)[0])
        if kind == "gear":
            inst.gear_height_counter(int(_number(action, "value")))
            return None
        if kind == "slip":
            inst.slip_height_scale(_number(action, "value"))
            return None
        if kind == "connect":
            origin = action.get("origin_mm")
            inst.connect_coordinatograph(_number(action, "value"), origin)
            return None
        if kind == "needle":
            return [float(v) for v in np.asarray(inst.needle(action.get("side"))).reshape(-1)]
    except TrainerError:
        raise
    except StereoplotterError as exc:
        raise TrainerError(f"action {kind}: refused: {refusal_text(str(exc))}") from None
    raise TrainerError(f"action {kind}: not an instrument action")
