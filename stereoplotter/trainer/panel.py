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
                "controls": ["X", "Y"], "done": true, "rule": "pointed", "shown": true,
                "conditional": false, "targets": {}, "control_names": ["X", "Y"],
                "sheet_rows": [], "note": null, "condition": null}, …]}

A step is the simulated operator's step of the stage (its transcript, each once in the order
first taken; a gear or a zero place the operator set beside another step's record gets its own
step or the zero-place step). It is ticked when its target is met on the instrument as it stands,
recomputed after every action, hint and show-me: ``rule`` ``"target"`` — the step sets controls
from the sheet (not by looking): done when each shows the operator's value within the least
count of its scale (:func:`least_count`; the gear: the same ratio), or, for a value a later
correction of the stage changes (ΔZ, Δb_z, f_пр), where the correction left it once the L-check
holds; ``"parallax"`` — the step clears the y-parallax at standard point n: done when the true
|q| there is within the residual y-parallax tolerance and its element was turned; ``"controls"``
— the step finds its value by looking (a place of zero, a levelling turn): done when the
trainee has used every control it sets; ``"pointed"`` — the step names a standard or control
point and only points and reads: done when the trainee read a counter with the left mark within
:data:`NEAR_MM` of that point's image on the left photo; ``"reading"`` — otherwise: done when
the trainee read any counter the step reads. After hint 3 (the operator did the stage on this
instrument) every step but a target is done. A ``conditional`` step (the L-check's corrections)
is ``shown`` only while its condition holds (|L − L′| outside its tolerance) and is not counted
otherwise. Each step also carries its words (:func:`~stereoplotter.trainer.step_words.step_words`:
the page's control names, the sheet rows its values come from, a note, its condition).

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
import weakref
from typing import Any

import numpy as np

from stereoplotter.instrument.virtual import CONTROL_INFO, DECENTRATIONS, HEIGHT_SCALE, KNOBS
from stereoplotter.procedure.step_values import BOTTOM_STOP, L_CHECK_FAILED
from stereoplotter.trainer.actions import control_value
from stereoplotter.trainer.exercise import Exercise
from stereoplotter.trainer.outcome import stage_measures, standard_q
from stereoplotter.trainer.step_words import step_words

__all__ = [
    "MOVER_TEXT",
    "NEAR_MM",
    "SHEET_PARTS",
    "SHOWN",
    "checklist",
    "checklist_ticks",
    "coupled_motion",
    "least_count",
    "note_progress",
    "overview",
    "sheet_parts",
    "show_me_actions",
    "span_fails",
    "standard_q_now",
    "step_rules",
    "step_targets",
]

#: A pointing step ticks when a reading was taken with the left mark this close to its point
#: on the left photo (assumed: a few mark diameters; the operator's pointing is far finer). [mm]
NEAR_MM = 0.5
_POINTING = ("X", "Y", "Z")
#: Noted among a stage's used controls when hint 3 had the operator do the stage.
SHOWN = "hint 3"
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
    shown = session.shown_marks()  # as the state gives them (where the read-out is hidden:
    marks = None  # to the counters' least count)
    if shown is not None:
        marks = [np.array([shown[s]["x_mm"], shown[s]["y_mm"]], float) for s in ("left", "right")]
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


#: Steps whose values are the operator's own judgment (clearing the y-parallax, levelling by
#: common tilts, the least-squares clearing): their controls have no fixed target; the
#: y-parallax steps tick on the true y-parallax instead (:func:`_ticks`).
_JUDGED = re.compile(r"clear(ing)? (of )?the (y-parallax|six q)|common tilt|level|fuse|turn \w+ by")
#: A standard point whose y-parallax a step clears.
_CLEARS_AT = re.compile(r"standard point (\d): clear the y-parallax")
#: Controls that follow from the sheet in a step that names another control: the zero places
#: of the correction mechanisms and decentrations (set together in the step that names them).
_ZERO_PLACE_FAMILY = tuple(KNOBS) + tuple(DECENTRATIONS)
#: What a mover action does, as a step of its own when the operator's record of the step names
#: something else (the gear is set with f_пр but recorded later).
MOVER_TEXT = {
    "gear": "gear the height counter to the vertical scale 1:M_в",
    "connect": "connect the coordinatograph",
}


def _step_of(action: dict[str, Any], step: str, texts: list[str]) -> str:
    """The step an action belongs to: its record's, but a mover that record does not name
    gets a step of its own, and a zero place set beside another cassette goes to the stage's
    zero-place step."""
    kind = action["kind"]
    if kind in MOVER_TEXT and kind not in step:
        return MOVER_TEXT[kind]
    name = action.get("control")
    if kind == "set" and name in _ZERO_PLACE_FAMILY and "cassette" in step:
        home = next((t for t in texts if "zero places" in t), None)
        if home is not None:
            return home
    return step


#: The declared conditions the page judges by the trainee's L-check (its corrections, and the
#: carriage's bottom stop they may reach): steps under them are shown when the L-check fails.
#: A knob at its stop in C2 is the operator's own instrument's: shown as the operator took it.
_SHOWN_WHEN_THE_L_CHECK_FAILS = frozenset({L_CHECK_FAILED.name, BOTTOM_STOP.name})


def _operator_log(par: Any) -> Any:
    """The simulated operator's transcript of ``par``
    (:class:`~stereoplotter.trainer.operator_steps.OperatorRun`), or None."""
    return getattr(getattr(getattr(par, "run", None), "op", None), "log", None)


def _conditional_steps(par: Any) -> set[str]:
    """The steps the operator took only where the L-check's conditions held (each transcript
    record carries its step's declared condition, ``procedure.step_values.CONDITIONS``)."""
    log = _operator_log(par)
    if log is None:
        return set()
    return {r.step for r in log.records if r.condition in _SHOWN_WHEN_THE_L_CHECK_FAILS}


def _add_silent_records(par: Any, stage: str, steps: dict[str, dict[str, Any]]) -> None:
    """Steps of the operator's transcript that no action of its own precedes (the right photo's
    L′, measured together with the left one before either is written down), placed after the
    step written before them; a measurement of L′ reads Y."""
    records = _operator_log(par)
    if records is None:
        return
    order = list(dict.fromkeys(r.step for r in records.records if r.stage == stage and r.step))
    for i, text in enumerate(order):
        if text in steps:
            continue
        entry = {"text": text, "controls": [], "needs": [], "reads": [], "targets": {}}
        if text.startswith("measure L′"):
            entry["controls"], entry["reads"] = ["Y"], ["Y"]
        before = next((t for t in reversed(order[:i]) if t in steps), None)
        items = list(steps.items())
        at = next((j + 1 for j, (t, _) in enumerate(items) if t == before), len(items))
        items.insert(at, (text, entry))
        steps.clear()
        steps.update(items)


def least_count(spec: Any, control: str) -> float:
    """The least count of a control's scale, as the session's controls give it
    (:meth:`ControlInfo.resolution`; a name that is no control: the X, Y counters'). [its unit]"""
    info = CONTROL_INFO.get(control)
    return info.resolution(spec) if info is not None else float(spec.xy_least_count_mm)


def step_rules(par: Any, stage: str) -> list[dict[str, Any]]:
    """The operator's steps of a stage with the rule each ticks by (see the module docstring):
    ``{"text", "controls": [...], "rule", "needs": [...], "point": (role, id) | None,
    "targets": {control: value}, "conditional": bool}``."""
    texts = [s for a, s in zip(par.actions, par.steps, strict=True) if a["stage"] == stage and s]
    steps: dict[str, dict[str, Any]] = {}
    for action, step in zip(par.actions, par.steps, strict=True):
        if action["stage"] != stage or not step:
            continue
        step = _step_of(action, step, texts)
        entry = steps.setdefault(
            step, {"text": step, "controls": [], "needs": [], "reads": [], "targets": {}}
        )
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
        if kind == "gear":
            entry["targets"]["gear"] = float(action["value"])
        elif kind == "set" and isinstance(action.get("value"), (int, float)):
            entry["targets"][name] = float(action["value"])
    _add_silent_records(par, stage, steps)
    conditional = _conditional_steps(par)
    out = []
    looked: set[str] = set()  # controls set by looking: later values are relative to them
    for entry in steps.values():
        named = _NAMED.search(entry["text"])
        judged = bool(_JUDGED.search(entry["text"]))
        measuring = any(c in ("X", "Y") for c in entry["reads"])
        if judged or measuring:
            looked.update(entry["needs"])
        entry["targets"] = {
            c: v
            for c, v in entry["targets"].items()
            if not judged and not measuring and c not in ("X", "Y") and c not in looked
        }
        clears = _CLEARS_AT.search(entry["text"])
        entry["conditional"] = entry["text"] in conditional
        entry["clears_point"] = int(clears.group(1)) if clears else None
        if entry["clears_point"] is not None:
            entry["rule"], entry["point"] = "parallax", None
        elif entry["targets"] and not entry["conditional"]:
            entry["rule"], entry["point"] = "target", None
        elif entry["needs"]:
            entry["rule"], entry["point"] = "controls", None
        elif named:
            entry["rule"], entry["point"] = "pointed", (named.group(1), named.group(2))
        else:
            entry["rule"], entry["point"] = "reading", None
        out.append(entry)
    for i, entry in enumerate(out):  # a target a later correction changes: met once corrected
        later = {c for e in out[i + 1 :] if e["conditional"] for c in [*e["needs"], *e["targets"]]}
        entry["corrected"] = sorted(later & set(entry["targets"]))
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
    if kind == "hint" and action.get("level") == 3:
        used.add(SHOWN)
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


def _target_met(
    session: Any, targets: dict[str, float], corrected: frozenset[str] = frozenset()
) -> bool:
    """Every control of ``targets`` shows its target within the least count of its scale (the
    gear: the same ratio); a control of ``corrected`` (a later correction of the stage changes
    it) may instead stand where the correction left it."""
    inst = session.inst
    for control, target in targets.items():
        if control in corrected:
            continue
        if control == "gear":
            if inst.height_gear is None or float(inst.height_gear) != target:
                return False
            continue
        value = control_value(inst, control, session.commanded)
        if value is None or not np.isfinite(value):
            return False
        if abs(float(value) - target) > least_count(inst.spec, control) * (1 + 1e-9):
            return False
    return True


#: Session → (the settings the L-check depends on, its last answer): X and Y do not change the
#: span (the check puts the mark on the fiducials itself), so a run of pointings asks once; the
#: same for the y-parallax at the standard points (X, Y, Z do not change it).
_SPAN_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_SPAN_SCALES = ("bx", "by", "bz", *DECENTRATIONS)


_Q_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _settings_key(session: Any, *more: str) -> tuple:
    """What the model's shape depends on: every setting but the pointing screws X, Y, Z (the
    y-parallax is taken at the points themselves, wherever the mark is), and the screws
    ``more`` (the span of the L-check depends on Z, the projection distance)."""
    inst = session.inst
    return (
        tuple(sorted(session.commanded.items())),
        tuple(control_value(inst, c, session.commanded) for c in (*_SPAN_SCALES, *more)),
        inst.height_gear,
    )


def standard_q_now(session: Any) -> np.ndarray:
    """|q| at the six standard points on the instrument as it stands (cached while only X, Y,
    Z move). [mm]"""
    key = _settings_key(session)
    hit = _Q_CACHE.get(session)
    if hit is not None and hit[0] == key:
        return hit[1]
    q = np.abs(np.asarray(standard_q(session.inst, session.prep), float).reshape(-1))
    _Q_CACHE[session] = (key, q)
    return q


def span_fails(session: Any) -> bool:
    """The L-check's condition: |L − L′| (true) outside its tolerance on the instrument as it
    stands (False before f_пр is set: nothing to check yet)."""
    if "f_instrument" not in session.commanded:
        return False
    inst = session.inst
    key = _settings_key(session, "Z")
    hit = _SPAN_CACHE.get(session)
    if hit is not None and hit[0] == key:
        return hit[1]
    fails = False
    for m in stage_measures(inst, session.prep, "1"):
        if m.name.startswith("scale coefficient"):
            fails = bool(np.max(m.value) > m.tolerance)
    _SPAN_CACHE[session] = (key, fails)
    return fails


def _ticks(
    session: Any, stage: str, blind: bool = False, rules: list[dict[str, Any]] | None = None
) -> tuple[list[bool], list[bool]]:
    """(done, shown) per step of the stage: done when its target is met (see the module
    docstring); shown unless it is conditional and its condition does not hold. ``blind``
    or ``rules`` given: :func:`_blind_ticks`."""
    if blind or rules is not None:
        return _blind_ticks(session, stage, rules)
    used, read, near = session.progress_of(stage)
    rules = session.step_rules(stage)
    q = None
    if any(e["rule"] == "parallax" for e in rules) and "f_instrument" in session.commanded:
        q = standard_q_now(session)
    tol_q = float(session.prep.sheet.tolerances["residual_y_parallax_mm"])
    fails = span_fails(session) if any(e["conditional"] for e in rules) else False
    done, shown = [], []
    for entry in rules:
        if entry["rule"] == "target":
            ok = _target_met(session, entry["targets"])
            touched = all(c in used for c in entry["corrected"]) or SHOWN in used
            if not ok and entry["corrected"] and touched and not fails:
                ok = _target_met(session, entry["targets"], frozenset(entry["corrected"]))
        elif entry["rule"] == "parallax":
            n = entry["clears_point"]
            ok = q is not None and bool(q[n - 1] <= tol_q) and entry["needs"][0] in used
        elif SHOWN in used:  # the operator did the stage on this instrument (hint 3)
            ok = True
        elif entry["rule"] == "controls":
            ok = all(c in used for c in entry["needs"])
        elif entry["rule"] == "pointed":
            ok = entry["point"] in near
        else:
            ok = any(c in read for c in entry["reads"]) if entry["reads"] else bool(read)
        see = not entry["conditional"] or fails
        done.append(bool(ok) and see)
        shown.append(see)
    return done, shown


def _blind_ticks(
    session: Any, stage: str, rules: list[dict[str, Any]] | None
) -> tuple[list[bool], list[bool]]:
    """(done, shown) of ``rules`` (default the session's own steps) with no tick on a hidden
    quantity (the read-out hidden, or steps not of this instrument): a target, parallax or
    controls step is done once its controls were used, a pointed or reading step as
    :func:`_ticks` ticks it, every step after hint 3; every step is shown (whether a
    conditional step's condition holds is the trainee's to judge)."""
    used, read, near = session.progress_of(stage)
    done = []
    for entry in session.step_rules(stage) if rules is None else rules:
        if SHOWN in used:
            ok = True
        elif entry["rule"] in ("target", "parallax", "controls"):
            ok = all(c in used for c in [*entry["targets"], *entry["needs"]])
        elif entry["rule"] == "pointed":
            ok = entry["point"] in near
        else:
            ok = any(c in read for c in entry["reads"]) if entry["reads"] else bool(read)
        done.append(bool(ok))
    return done, [True] * len(done)


def checklist_ticks(
    session: Any, blind: bool = False, rules: list[dict[str, Any]] | None = None
) -> dict[str, Any] | None:
    """The stage in hand's done and shown flags, in the order of :func:`checklist`'s steps
    (what the session state carries on every action: ``{"stage", "done": [bool, …], "shown":
    [bool, …]}``); None when every stage is claimed. ``blind``, ``rules``: see :func:`_ticks`."""
    stage = session.stage
    if stage is None:
        return None
    done, shown = _ticks(session, stage, blind, rules)
    return {"stage": stage, "done": done, "shown": shown}


def checklist(session: Any, blind: bool = False, reference: bool = False) -> dict[str, Any] | None:
    """The stage in hand's steps with done flags (see the module docstring); None when every
    stage is claimed. ``blind`` (the read-out hidden): ticks as :func:`_ticks` gives them
    blind, and no step carries its targets (the operator's values on this instrument).
    ``reference``: the steps of the operator's run on the exercise's error-free instrument
    (:meth:`~stereoplotter.trainer.session.Session.reference_rules`), not on this one (whose
    steps follow from its hidden errors: a clearing the check made necessary, a pass more)."""
    stage = session.stage
    if stage is None:
        return None
    steps = []
    rules = session.reference_rules(stage) if reference else session.step_rules(stage)
    ticks, shown = _ticks(session, stage, blind, rules if reference else None)
    given = sheet_parts(session.exercise)["given"]
    for n, (entry, done, see) in enumerate(zip(rules, ticks, shown, strict=True), 1):
        steps.append(
            {
                "n": n,
                "text": entry["text"],
                "controls": entry["controls"],
                "done": bool(done),
                "rule": entry["rule"],
                "shown": bool(see),
                "conditional": entry["conditional"],
                "targets": {} if blind else dict(entry["targets"]),
                **step_words(session, entry, given),
            }
        )
    return {
        "stage": stage,
        "done": sum(s["done"] for s in steps if s["shown"]),
        "total": sum(s["shown"] for s in steps),
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
    knob, dec = CONTROL_INFO.get(control), CONTROL_INFO.get(counter)
    if knob and dec and knob.kind == "knob" and dec.kind == "decentration" and (
        knob.side == dec.side
    ):
        axis = "α" if knob.axis == "alpha" else "ω"
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
