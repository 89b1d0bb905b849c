"""What a page shows beside the eyepieces: the photo overview, the stage's checklist, which parts
of the setup sheet an exercise gives, and why a counter moved that was not touched.

All functions return plain JSON data (numbers as floats, ids as text). Units: mm on the photo
(the fiducial system of each photo), m on the ground, µm for parallax.

:func:`overview` ``(session)`` →

.. code-block:: text

    {"format_mm": 180.0, "mark_diameter_mm": 0.04,
     "photos": {"left" | "right": {
         "fiducials": [{"id": "1", "x_mm": …, "y_mm": …}, …],          # the true marks
         "standard_points": [{"id": "1", "x_mm": …, "y_mm": …, "usable": true}, …],   # 1–6
         "control_points": [{"id": "1", "x_mm": …, "y_mm": …, "kind": "full"}, …],
         "check_points": [{"id": "c1", …}],
         "mark": {"x_mm": …, "y_mm": …, "diameter_mm": …} | null}}}     # null before f_пр

:func:`checklist` ``(session)`` →

.. code-block:: text

    {"stage": "2", "done": 3, "total": 21,
     "steps": [{"n": 1, "text": "left mark on the left cassette centre → MO_X",
                "controls": ["X", "Y"], "done": true, "rule": "pointed"}, …]}

A step is the simulated operator's step of the stage (its transcript, each once in the order
first taken). It ticks from the session's own records of the stage in hand (refused actions do
not count; an undo does not untick): ``rule`` ``"controls"`` — the step turns controls other
than the pointing screws X, Y, Z (or gears, slips, connects, lowers the needle): done when the
trainee has used every one of them in the stage; ``"pointed"`` — the step names a standard or
control point and only points and reads: done when the trainee read a counter with the left
mark within :data:`NEAR_MM` of that point's image on the left photo; ``"reading"`` — otherwise:
done when the trainee read any counter the step reads.

:func:`sheet_parts` ``(exercise)`` → ``{"given": [...], "withheld": {part: reason}}``, parts
``certificate`` (the camera: f, principal point, format, fiducials), ``interior`` (f_пр, the
scales, n, b_x: what C1 and C3 need), ``table24`` and ``readings`` (the five stages'
settings). Rule: the setup-data method works from its sheet, so every part is given in every
stage; the conventional method orients by the view — the sheet's orientation values
(decentrations, knob inclinations, the stage readings) would turn C2/C3 into setting numbers, so
only the certificate and the interior part are given.

:func:`coupled_motion` ``(action, before, after)`` → a list of events
``{"kind": "coupled", "control": …, "moved": {counter: [before, after]}, "text": …}`` for
counters that moved although the action did not name them.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from stereoplotter.instrument.virtual import DECENTRATIONS, HEIGHT_SCALE, KNOBS
from stereoplotter.trainer.exercise import Exercise

__all__ = [
    "NEAR_MM",
    "SHEET_PARTS",
    "checklist",
    "checklist_ticks",
    "coupled_motion",
    "note_progress",
    "overview",
    "sheet_parts",
    "show_me_actions",
    "step_rules",
    "step_targets",
]

#: A pointing step ticks when a reading was taken with the left mark this close to its point
#: on the left photo (assumed: a few mark diameters; the operator's pointing is far finer). [mm]
NEAR_MM = 0.5
_POINTING = ("X", "Y", "Z")
_MOVERS = ("gear", "slip", "connect", "needle")
_NAMED = re.compile(r"\b(standard|control) point (\w+)")

#: Each method → the parts of the setup sheet it gives, and why the others are withheld.
SHEET_PARTS: dict[str, dict[str, Any]] = {
    "setup": {"given": ["certificate", "interior", "table24", "readings"], "withheld": {}},
    "conventional": {
        "given": ["certificate", "interior"],
        "withheld": {
            "table24": "the conventional method orients by the view: the sheet's decentrations "
            "and knob inclinations would give the relative orientation away",
            "readings": "the stage readings of the setup-data method set the orientation by "
            "numbers; C2 clears the y-parallax by eye",
        },
    },
}


def _pt(pid: str, xy: Any, **more: Any) -> dict[str, Any]:
    x, y = (float(v) for v in np.asarray(xy, float).reshape(-1)[:2])
    return {"id": str(pid), "x_mm": round(x, 4), "y_mm": round(y, 4), **more}


def overview(session: Any) -> dict[str, Any]:
    """The photos with their fiducials, standard, control and check points and the marks (see
    the module docstring)."""
    ex: Exercise = session.exercise
    scene = session.prep.scene
    points = scene.points
    images = scene.images(np.array([p.local_m for p in points], float)) if points else None
    marks = None
    if "f_instrument" in session.commanded:
        marks = [np.asarray(m, float).reshape(-1) for m in session.inst.marks()]
    diameter = float(ex.spec.mark_diameter_mm)
    photos = {}
    for i, side in enumerate(("left", "right")):
        fid = scene.fiducials_mm[side]
        photo: dict[str, Any] = {
            "fiducials": [_pt(str(k + 1), fid[k]) for k in range(len(fid))],
            "standard_points": [
                _pt(str(n), scene.standard[i][n - 1], usable=n not in ex.unusable_points)
                for n in range(1, 7)
            ],
            "control_points": [],
            "check_points": [],
            "mark": None,
        }
        for j, p in enumerate(points):
            key = "control_points" if p.role == "control" else "check_points"
            photo[key].append(_pt(p.id, images[i][j], kind=p.kind))
        if marks is not None:
            photo["mark"] = {**_pt("mark", marks[i]), "diameter_mm": diameter}
            del photo["mark"]["id"]
        photos[side] = photo
    return {
        "format_mm": float(scene.camera.format_mm),
        "mark_diameter_mm": diameter,
        "photos": photos,
    }


def step_rules(par: Any, stage: str) -> list[dict[str, Any]]:
    """The operator's steps of a stage with the rule each ticks by (see the module docstring):
    ``{"text", "controls": [...], "rule", "needs": [...], "point": (role, id) | None}``."""
    steps: dict[str, dict[str, Any]] = {}
    for action, step in zip(par.actions, par.steps, strict=True):
        if action["stage"] != stage or not step:
            continue
        entry = steps.setdefault(step, {"text": step, "controls": [], "needs": [], "reads": []})
        kind = action["kind"]
        name = action.get("control") or action.get("counter") or kind
        if name not in entry["controls"]:
            entry["controls"].append(name)
        if kind == "read":
            if name not in entry["reads"]:
                entry["reads"].append(name)
        elif kind in _MOVERS or (kind == "set" and name not in _POINTING):
            if name not in entry["needs"]:
                entry["needs"].append(name)
    out = []
    for entry in steps.values():
        named = _NAMED.search(entry["text"])
        if entry["needs"]:
            entry["rule"], entry["point"] = "controls", None
        elif named:
            entry["rule"], entry["point"] = "pointed", (named.group(1), named.group(2))
        else:
            entry["rule"], entry["point"] = "reading", None
        out.append(entry)
    return out


def _point_xy(session: Any, point: tuple[str, str]) -> np.ndarray | None:
    role, pid = point
    if role == "standard":
        n = int(pid) if pid.isdigit() else 0
        return scene_left(session)[n - 1] if 1 <= n <= 6 else None
    scene = session.prep.scene
    for p in scene.points:
        if p.id == pid:
            return np.asarray(scene.images(np.array([p.local_m]))[0][0], float)
    return None


def scene_left(session: Any) -> np.ndarray:
    """The six standard points' images on the left photo, (6, 2). [mm]"""
    return np.asarray(session.prep.scene.standard[0], float)


def note_progress(
    progress: dict[str, Any],
    stage: str,
    action: dict[str, Any],
    left_mark: Any,
    targets: dict[tuple[str, str], np.ndarray],
) -> None:
    """Note a carried-out action in ``progress`` (stage → used controls, read counters, the
    points (role, id) of ``targets`` — their left-photo images [mm] — read within
    :data:`NEAR_MM` of the left mark): what :func:`checklist` ticks from."""
    used, read, near = progress.setdefault(stage, (set(), set(), set()))
    kind = action.get("kind")
    if kind in ("turn", "set"):
        used.add(str(action["control"]))
    elif kind in _MOVERS:
        used.add(kind)
    elif kind == "read":
        read.add(str(action["counter"]))
        if left_mark is not None:
            mark = np.asarray(left_mark, float).reshape(-1)[:2]
            for key, xy in targets.items():
                if key not in near and float(np.hypot(*(mark - xy))) <= NEAR_MM:
                    near.add(key)


def step_targets(session: Any, stage: str) -> dict[tuple[str, str], np.ndarray]:
    """The points the pointing steps of a stage name → their left-photo images. [mm]"""
    out = {}
    for entry in session.step_rules(stage):
        if entry["point"] is not None and entry["point"] not in out:
            xy = _point_xy(session, entry["point"])
            if xy is not None:
                out[entry["point"]] = xy
    return out


def _ticks(session: Any, stage: str) -> list[bool]:
    used, read, near = session.progress_of(stage)
    out = []
    for entry in session.step_rules(stage):
        if entry["rule"] == "controls":
            done = all(c in used for c in entry["needs"])
        elif entry["rule"] == "pointed":
            done = entry["point"] in near
        else:
            done = any(c in read for c in entry["reads"]) if entry["reads"] else bool(read)
        out.append(bool(done))
    return out


def checklist_ticks(session: Any) -> dict[str, Any] | None:
    """The stage in hand's done flags, in the order of :func:`checklist`'s steps (what the
    session state carries on every action: ``{"stage", "done": [bool, …]}``); None when every
    stage is claimed."""
    stage = session.stage
    return None if stage is None else {"stage": stage, "done": _ticks(session, stage)}


def checklist(session: Any) -> dict[str, Any] | None:
    """The stage in hand's steps with done flags (see the module docstring); None when every
    stage is claimed."""
    stage = session.stage
    if stage is None:
        return None
    steps = []
    ticks = _ticks(session, stage)
    for n, (entry, done) in enumerate(zip(session.step_rules(stage), ticks, strict=True), 1):
        steps.append(
            {
                "n": n,
                "text": entry["text"],
                "controls": entry["controls"],
                "done": bool(done),
                "rule": entry["rule"],
            }
        )
    return {
        "stage": stage,
        "done": sum(s["done"] for s in steps),
        "total": len(steps),
        "steps": steps,
    }


def show_me_actions(session: Any, stage: str | None = None) -> list[dict[str, Any]]:
    """The simulated operator's actions of a stage (default: the stage in hand), what a hint of
    level 3 applies at once: a page animates "show me" by sending them one by one at its chosen
    speed instead of asking for the hint (each is one control use; the hint's penalty does not
    apply to actions the trainee sends, so a page that animates should also log a hint 3)."""
    stage = session.stage if stage is None else stage
    if stage is None:
        return []
    return [{k: v for k, v in a.items() if k != "stage"} for a in session.par.stage_actions(stage)]


def sheet_parts(exercise: Exercise) -> dict[str, Any]:
    """The parts of the setup sheet the exercise gives and why the others are withheld."""
    rule = SHEET_PARTS[exercise.method]
    return {"given": list(rule["given"]), "withheld": dict(rule["withheld"])}


def _why(control: str, counter: str) -> str:
    """Why ``counter`` moves when ``control`` turns."""
    if control in KNOBS and counter in DECENTRATIONS and control.split("_")[-1] == counter[3:]:
        axis = "α" if "alpha" in control else "ω"
        return (
            f"{counter} moved with {control}: the photo carrier's decentration is linked to the "
            f"correction knob of {axis} (the dependent decentration, decision D1 in "
            "docs/instruments.md: it follows by f′·ΔT when the knob turns)"
        )
    if control == HEIGHT_SCALE and counter == "Z":
        return "Z moved: the metre height scale is geared to the Z screw, setting H turns Z"
    if control in ("hint", "undo", "redo"):
        return {
            "hint": "the simulated operator did the stage on your instrument (show me)",
            "undo": "undo restored the instrument as it was",
            "redo": "redo restored the instrument as it was",
        }[control]
    return f"{counter} moved with {control} (coupled in the instrument's mechanism)"


def coupled_motion(
    action: dict[str, Any], before: dict[str, Any], after: dict[str, Any]
) -> list[dict[str, Any]]:
    """Events for counters that moved although ``action`` did not name them (``before`` and
    ``after``: the session states' ``counters``)."""
    kind = action.get("kind")
    control = str(action.get("control") or action.get("counter") or kind)
    if kind in ("read", "claim", "record", "lock", "direction"):
        return []
    moved = {}
    for name, c in after.items():
        if name == control or name not in before or (name == "H" and control == "Z"):
            continue
        b, a = before[name]["value"], c["value"]
        if b is not None and a is not None and abs(a - b) >= 0.5 * c["least_count"]:
            moved[name] = [b, a]
    if not moved:
        return []
    if kind == "hint" or kind in ("undo", "redo"):
        return [{"kind": "coupled", "control": kind, "moved": moved, "text": _why(kind, "")}]
    return [
        {
            "kind": "coupled",
            "control": control,
            "moved": moved,
            "text": "; ".join(_why(control, name) for name in moved),
        }
    ]
