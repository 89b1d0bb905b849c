"""A trainee's session on the virtual instrument: actions, their log, undo/redo, hints, replay.

:meth:`Session.start` builds what the simulated operator would get for the exercise — the setup
sheet, the instrument with its injected errors (trial 0 of the exercise's seed, or of the
trainee's seed), the scene — runs the simulated operator once on an identical instrument (the
"par" of grading and the source of level-3 hints) and presets the stages before the
exercise's first stage with the operator's own actions. :meth:`Session.act` carries out one
action (:mod:`stereoplotter.trainer.actions`) and appends a log record with the digests of the
session state before and after. :meth:`Session.replay` runs a log again; the new log is equal to
the old one, record for record (so written again, byte for byte).

Time: an action may carry ``t`` (seconds since the start, from the client); otherwise the
session's monotonic clock gives it. The log keeps it, and a replay uses the logged ``t``.
"""

from __future__ import annotations

import copy
import hashlib
import hmac
import json
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from stereoplotter.errors import TrainerError
from stereoplotter.instrument.virtual import (
    CASSETTES,
    CONTROL_INFO,
    DECENTRATIONS,
    HEIGHT_SCALE,
    KNOBS,
    SCREWS,
    ControlInfo,
    Instrument,
)
from stereoplotter.procedure.control_names import CASSETTE
from stereoplotter.procedure.operator import Noise, Operator
from stereoplotter.procedure.run import PreparedRun
from stereoplotter.procedure.simulate import prepare_run
from stereoplotter.procedure.transcript import Transcript
from stereoplotter.trainer.actions import (
    ACTION_FIELDS,
    INSTRUMENT_KINDS,
    apply,
    check_action,
    control_value,
)
from stereoplotter.trainer.exercise import ASSISTS, STAGES, Exercise, resolve_exercise
from stereoplotter.trainer.hints import hint_text
from stereoplotter.trainer.operator_steps import OperatorRun, new_instrument, operator_run
from stereoplotter.trainer.outcome import stage_measures
from stereoplotter.trainer.panel import (
    checklist_ticks,
    coupled_motion,
    note_progress,
    step_rules,
    step_targets,
)
from stereoplotter.trainer.texts import announced_row, claim_text, hint_lines

__all__ = [
    "LOG_FORMAT",
    "SUBSTITUTE_STAGES",
    "UNDO_DEPTH",
    "Session",
    "check_stage",
    "json_finite",
    "secret_seed",
    "state_digest",
]

LOG_FORMAT = "stereoplotter-session/1"
#: The stages that use the six standard points: an incomplete model's substitutes are recorded
#: before they are claimed.
SUBSTITUTE_STAGES = ("2", "C2")
#: Undo steps kept (each about 8 kB: a copy of the instrument's state, measured on e08 with
#: tracemalloc; frozen values shared with the instrument); older ones are dropped (assumed: a
#: trainee undoes a few moves, not a stage's hundreds).
UNDO_DEPTH = 500


def state_digest(state: dict[str, Any]) -> str:
    """SHA-256 (first 16 hex digits) of the canonical JSON of a state."""
    text = json.dumps(state, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _f(value: Any) -> float:
    return float(np.asarray(value, float).reshape(-1)[0])


@dataclass
class _Undoable:
    """What undo restores: the instrument and the session's own state."""

    instrument: Instrument
    commanded: dict[str, float]
    locked: list[str]
    records: dict[str, Any]
    stage_index: int
    claimed: list[str]
    at_claim: dict[str, Instrument]


class Session:
    """One trainee at one exercise (build with :meth:`start` or :meth:`replay`)."""

    def __init__(self, exercise: Exercise, trainee: str, seed: int, clock: bool = True):
        self.exercise = exercise
        self.trainee = trainee
        self.seed = int(seed)
        errors = "zero" if exercise.errors == "off" else None
        self.prep: PreparedRun = prepare_run(
            exercise.scenario, exercise.spec, exercise.method, errors, self.seed
        )
        self.par: OperatorRun = operator_run(self.prep, self.seed, exercise.stages[-1])
        self.inst = new_instrument(self.prep, self.seed)
        self.commanded: dict[str, float] = {}
        self.locked: list[str] = []
        self.records: dict[str, Any] = {}
        self.claimed: list[str] = []
        #: Stage → a copy of the instrument when the trainee claimed it (graded on it).
        self.at_claim: dict[str, Instrument] = {}
        self.stage_index = 0
        self.log: list[dict[str, Any]] = []
        self.hints_used: list[int] = []
        self._undo: list[_Undoable] = []
        self._redo: list[_Undoable] = []
        self._t0 = time.monotonic() if clock else None
        #: Stage → (controls used, counters read, points read at): the checklist's
        #: ticks (:func:`~stereoplotter.trainer.panel.checklist`; an undo does not untick).
        self.progress: dict[str, Any] = {}
        #: What the last action moved that it did not name (coupled motions), with a reason.
        self.events: list[dict[str, Any]] = []
        #: The state after the last action and its digest, keyed by the log's length: the next
        #: action's "before" (the state changes only by acting; building it twice per action
        #: was half the time).
        self._last_state: tuple[int, dict[str, Any], str] | None = None
        self._rules: dict[str, list[dict[str, Any]]] = {}  # stage → its steps' tick rules
        self._target_points: dict[str, dict[Any, Any]] = {}  # stage → the points its steps read
        for stage in exercise.preset_stages:
            for action in self.par.stage_actions(stage):
                apply(self.inst, action, self.commanded)

    # --- construction ----------------------------------------------------------------------

    @classmethod
    def start(
        cls, exercise: Exercise, *, trainee: str = "trainee", seed: int | None = None
    ) -> Session:
        """A new session: the exercise's seed, else ``seed``, else the trainee's own seed."""
        if exercise.seed is not None:
            use = exercise.seed
        elif seed is not None:
            use = int(seed)
        else:
            use = exercise.seed_for(trainee)
        return cls(exercise, trainee, use)

    def header(self) -> dict[str, Any]:
        """The first line of the session log: format, exercise (file content), trainee, seed."""
        return {
            "format": LOG_FORMAT,
            "exercise": self.exercise.source,
            "exercise_name": self.exercise.name,
            "trainee": self.trainee,
            "seed": self.seed,
            "preset_stages": list(self.exercise.preset_stages),
        }

    @classmethod
    def replay(
        cls,
        records: list[dict[str, Any]],
        exercise: Exercise | None = None,
        *,
        read_exercise: Callable[[dict[str, Any]], Exercise] | None = None,
    ) -> Session:
        """Run a session log (header + action records) again.

        The exercise is ``exercise``, or the header's file content read by ``read_exercise``
        (:func:`~stereoplotter.trainer.exercise.resolve_exercise`).

        Raises
        ------
        TrainerError
            The log is not a session log, or an action's outcome differs from the log (the
            digest of the state after it, or a refusal).
        """
        if not records or records[0].get("format") != LOG_FORMAT:
            raise TrainerError(f"session log: expected a first line with format {LOG_FORMAT}")
        head = records[0]
        if exercise is None:
            exercise = resolve_exercise(head["exercise"], read_exercise)
        session = cls(exercise, str(head["trainee"]), int(head["seed"]), clock=False)
        for rec in records[1:]:
            action = dict(rec["action"])
            action["t"] = rec["t"]
            try:
                session.act(action)
            except TrainerError:
                if rec.get("refused") is None:
                    raise
            mine = session.log[-1]
            if mine != rec:
                raise TrainerError(
                    f"session log: record {rec.get('n')} does not replay "
                    f"(state {mine.get('state_after')} against {rec.get('state_after')})"
                )
        return session

    # --- what the trainee sees -----------------------------------------------------------------

    @property
    def stages(self) -> tuple[str, ...]:
        return self.exercise.stages

    @property
    def stage(self) -> str | None:
        """The stage in hand (None when every stage is claimed)."""
        if self.stage_index >= len(self.stages):
            return None
        return self.stages[self.stage_index]

    def _counters(self) -> dict[str, Any]:
        spec = self.inst.spec
        out: dict[str, Any] = {}
        geared = self.inst.height_gear is not None  # the metre scale shows once geared
        shown = (*SCREWS, *DECENTRATIONS, *([HEIGHT_SCALE] if geared else []))
        for name in shown:
            info = CONTROL_INFO[name]
            out[name] = {
                "value": _f(self.inst.read(name)),
                "unit": info.unit,
                "least_count": info.resolution(spec),
                "direction": 1 if name == HEIGHT_SCALE else self.inst.counter_sense(name),
            }
        return out

    def _controls(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for name in (*SCREWS, "f_instrument", *CASSETTES, *DECENTRATIONS, *KNOBS):
            info = CONTROL_INFO[name]
            if info.kind in ("screw", "decentration"):
                value = control_value(self.inst, name, self.commanded)
            else:  # f_пр unset until the operator sets it; κ and the knobs start at zero
                value = self.commanded.get(name, None if info.kind == "principal_distance" else 0.0)
            low, high = self._stops(info)
            out[name] = {
                "value": value,
                "unit": info.unit,
                "min": low,
                "max": high,
                "step": info.resolution(self.inst.spec),
            }
        return out

    def _stops(self, info: ControlInfo) -> tuple[float | None, float | None]:
        """A control's stops as its scale reads them (:meth:`ControlInfo.range`): a lead
        screw's counter readings at the ends of its travel; none shown for a decentration,
        whose stop limits the physical decentration its scale reads with its zero-reading
        error. [the control's unit]"""
        if info.kind == "screw":
            ends = (_f(self.inst.reading_of(info.name, v)) for v in self.inst.travel_mm(info.name))
            lo, hi = ends
            return min(lo, hi), max(lo, hi)
        stops = info.range(self.inst.spec)
        if stops is None or info.kind == "decentration":
            return None, None
        return stops

    def control_range(self, name: str) -> tuple[float, float] | None:
        """The values a control can be set to (its stops, as its scale reads), or None for a
        control without stops. [the control's unit]"""
        got = self._controls().get(name)
        if got is None or got["min"] is None or got["max"] is None:
            return None
        return float(got["min"]), float(got["max"])

    def hides_readout(self) -> bool:
        """Whether the exercise hides the parallax read-out (an exam, or practice with the
        read-out off): then the trainee's state gives the marks only as the eyepieces show
        them (:meth:`shown_marks`) and the checklist ticks nothing on a hidden quantity."""
        return not self.exercise.allows("parallax_readout")

    def mark_quantum_mm(self) -> float:
        """The step in which the trainee's state gives a mark's photo position where the
        read-out is hidden: the least count of the X, Y counters (0.01 mm on all three
        instruments), the finest position the instrument shows in numbers. A parallax taken
        from two marks so given is uncertain by ±1 step (σ = step/√6 = 4.1 µm), twice the
        eye's σ_q = 10″·d/V = 2.0 µm at the binocular's 6× (``procedure.eye``): the numbers
        tell no more than one look. [mm]"""
        return float(self.exercise.spec.xy_least_count_mm)

    def shown_marks(self) -> dict[str, Any] | None:
        """The marks as the trainee's state gives them: exact where the read-out is shown;
        where it is hidden, each position rounded to :meth:`mark_quantum_mm` and the field
        turned by the cassette's scale (the κ set, without its hidden setting error: at most
        10⁻⁴ rad, a hundredth of a screen pixel at the eyepiece's edge)."""
        marks = self._marks()
        if marks is None or not self.hides_readout():
            return marks
        step = self.mark_quantum_mm()
        out = {}
        for side, mark in marks.items():
            out[side] = {
                "x_mm": _on_step(mark["x_mm"], step),
                "y_mm": _on_step(mark["y_mm"], step),
                "kappa_rad": float(self.commanded.get(CASSETTE[side], 0.0)),
            }
        return out

    def _marks(self) -> dict[str, Any] | None:
        """Where each mark stands on its photo; None before f_пр is set (no projection yet)."""
        if "f_instrument" not in self.commanded:
            return None
        pl, pr = self.inst.marks()
        left, right = (np.asarray(p, float).reshape(-1) for p in (pl, pr))
        return {
            "left": {
                "x_mm": float(left[0]),
                "y_mm": float(left[1]),
                "kappa_rad": _f(self.inst.unit("left").kappa),
            },
            "right": {
                "x_mm": float(right[0]),
                "y_mm": float(right[1]),
                "kappa_rad": _f(self.inst.unit("right").kappa),
            },
        }

    def _parallax(self) -> dict[str, float] | None:
        """y- and x-parallax at the standard point nearest the left mark. [µm]

        y: the model's true y-parallax there (what the eye judges, no judgment error); x: the
        right mark's x offset from that point's image less the left mark's.
        """
        if not self.exercise.allows("parallax_readout") or "f_instrument" not in self.commanded:
            return None
        il, ir = self.prep.scene.standard
        pl, pr = (np.asarray(p, float).reshape(-1) for p in self.inst.marks())
        distance = np.hypot(*(il - pl).T)
        for n in self.exercise.unusable_points:  # on water or outside the overlap: no reading
            distance[n - 1] = np.inf
        i = int(np.argmin(distance))
        op = Operator(
            self.inst, self.prep.operator, Noise(0, None, None, 0), Transcript(enabled=False)
        )
        q = op.y_parallax(
            self.prep.scene.standard_points_m[i : i + 1], (il[i : i + 1], ir[i : i + 1])
        )
        x = (pr[0] - ir[i, 0]) - (pl[0] - il[i, 0])
        return {
            "y_um": round(_f(q) * 1000.0, 3),
            "x_um": round(float(x) * 1000.0, 3),
            "point": i + 1,
        }

    def _checks(self) -> list[dict[str, Any]]:
        """The stage's checks with their tolerances: the procedure's own (the conventional
        method's C4 names its checks "stage 5"), else what the grade measures (``graded``)."""
        stage = self.stage
        if stage is None:
            return []
        own = ("C4", "5") if stage == "C4" else (stage,)
        out = []
        for name, check in self.par.run.results.items():
            if check_stage(name) in own and check.tolerance is not None:
                out.append({"name": name, "tolerance": _f(check.tolerance), "unit": check.unit})
        if not out:
            tol = self.prep.sheet.tolerances
            if stage == "C1":
                out.append(
                    {
                        "name": "C1: f_пр on its scale against the sheet",
                        "tolerance": CONTROL_INFO["f_instrument"].resolution(self.exercise.spec),
                        "unit": "mm",
                        "graded": True,
                    }
                )
            elif stage in ("4", "C4"):
                out.append(
                    {
                        "name": f"{'stage 4' if stage == '4' else 'C4'}: plan error at the "
                        "control points on the map (sheet fitted), coordinatograph connected",
                        "tolerance": float(tol["corner_mm"]),
                        "unit": "mm",
                        "graded": True,
                    }
                )
        return out

    def _announced(self) -> dict[str, float] | None:
        """The injected errors when the exercise announces them (internal units: mm, rad,
        relative), else None."""
        if self.exercise.errors != "announced":
            return None
        return {k: _f(v) for k, v in sorted(self.inst.injected.items()) if _f(v) != 0.0}

    def step_rules(self, stage: str) -> list[dict[str, Any]]:
        """The operator's steps of a stage with their tick rules (cached)."""
        if stage not in self._rules:
            self._rules[stage] = step_rules(self.par, stage)
        return self._rules[stage]

    def reference_rules(self, stage: str) -> list[dict[str, Any]]:
        """The steps of a stage with their tick rules as the simulated operator takes them on
        the exercise's instrument without errors (the same for every trainee: what an exam's
        checklist lists, :func:`~.panel.checklist` ``reference``)."""
        return _reference_rules(self.exercise, stage)

    def shows_reference_steps(self) -> bool:
        """Whether the trainee's checklist lists :meth:`reference_rules` (an exercise without
        hints: the steps of the operator's run on this instrument follow from its errors)."""
        return not self.exercise.allows("hints")

    def _targets(self, stage: str) -> dict[Any, Any]:
        """The points a stage's steps read at (cached; :func:`~.panel.step_targets`)."""
        if stage not in self._target_points:
            self._target_points[stage] = step_targets(self, stage)
        return self._target_points[stage]

    def progress_of(self, stage: str) -> tuple[set[str], set[str], set[Any]]:
        """(controls used, counters read, points (role, id) read at) in a stage."""
        return self.progress.get(stage, (set(), set(), set()))

    def allowed(self) -> list[str]:
        """The action kinds allowed now."""
        if self.stage is None:
            return ["read"]
        kinds = [k for k in ACTION_FIELDS if k not in ("undo", "redo", "hint")]
        if self.exercise.allows("undo"):
            if self._undo:
                kinds.append("undo")
            if self._redo:
                kinds.append("redo")
        if self.exercise.allows("hints"):
            kinds.append("hint")
        return kinds

    def state(self) -> dict[str, Any]:
        """What the trainee sees (JSON-serialisable; the contract's keys; a value that is not
        finite, e.g. a range without a stop, is null): :meth:`full_state` with, where the
        read-out is hidden, the marks as the eyepieces show them (:meth:`shown_marks`) and
        the checklist's ticks blind to hidden quantities."""
        return self.trainee_view(self.full_state())

    def trainee_view(self, full: dict[str, Any]) -> dict[str, Any]:
        """``full`` (:meth:`full_state` of the session as it stands) as the trainee sees it."""
        reference = self.shows_reference_steps()
        if not self.hides_readout() and not reference:
            return full
        rules = self.reference_rules(self.stage) if reference and self.stage else None
        view = full | {
            "marks": self.shown_marks(),
            "checklist_ticks": checklist_ticks(self, blind=True, rules=rules),
        }
        if self.hides_readout():
            view["controls"] = _scales_as_shown(full["controls"])
        return view

    def full_state(self, counters: dict[str, Any] | None = None) -> dict[str, Any]:
        """The session's whole state, the exact marks included: what the log's digests and
        its claim records hold (the log is given once every stage is claimed). ``counters``:
        :meth:`_counters` of the session as it stands, when the caller has it already."""
        return json_finite(
            {
                "instrument": self.exercise.spec.key,
                "stage": self.stage,
                "step": self.stage,
                "counters": self._counters() if counters is None else counters,
                "controls": self._controls(),
                "marks": self._marks(),
                "parallax": self._parallax(),
                "checks": self._checks(),
                "allowed": self.allowed(),
                "mode": self.exercise.mode,
                "done": self.stage is None,
                "locked": list(self.locked),
                "records": dict(self.records),
                "injected_errors": self._announced(),
                "injected_errors_list": self._announced_list(),
                "events": list(self.events),
                "assists": {k: self.exercise.allows(k) for k in ASSISTS},
            }
        ) | {"checklist_ticks": checklist_ticks(self)}

    def _announced_list(self) -> list[dict[str, Any]] | None:
        """The announced injected errors as readable rows (``name``, ``value``, ``unit``,
        ``text``), or None when the exercise does not announce them."""
        errors = self._announced()
        if errors is None:
            return None
        return [announced_row(name, value) for name, value in errors.items()]

    # --- acting ------------------------------------------------------------------------------

    def _now(self, action: dict[str, Any]) -> float:
        if "t" in action:
            return float(action["t"])
        if self._t0 is None:
            return 0.0
        return round(time.monotonic() - self._t0, 3)

    def _snapshot(self) -> _Undoable:
        return _Undoable(
            _copy_instrument(self.inst),
            dict(self.commanded),
            list(self.locked),
            _state_copy(self.records, {}),
            self.stage_index,
            list(self.claimed),
            dict(self.at_claim),
        )

    def _restore(self, snap: _Undoable) -> None:
        self.inst = snap.instrument
        self.commanded = snap.commanded
        self.locked = snap.locked
        self.records = snap.records
        self.stage_index = snap.stage_index
        self.claimed = snap.claimed
        self.at_claim = snap.at_claim

    def act(self, action: dict[str, Any]) -> dict[str, Any]:
        """Carry out one action; returns the new state (see :meth:`state`).

        Raises
        ------
        TrainerError
            The action is malformed, not allowed now, or refused by the instrument (the refusal
            is logged too).
        """
        t = self._now(action) if isinstance(action, dict) else 0.0
        last = self._last_state
        if last is not None and last[0] == len(self.log):
            before, before_digest = last[1], last[2]
        else:
            before = self.full_state()
            before_digest = state_digest(before)
        clean = {k: v for k, v in action.items() if k != "t"} if isinstance(action, dict) else {}
        record: dict[str, Any] = {
            "n": len(self.log) + 1,
            "t": t,
            "stage": self.stage,
            "action": clean,
            "state_before": before_digest,
        }
        self.events = []
        try:
            check_action(action)
            record["result"] = json_finite(self._do(clean, before))
            if record["stage"] is not None:
                marks = self._marks() if clean["kind"] == "read" else None
                xy = None if marks is None else [marks["left"]["x_mm"], marks["left"]["y_mm"]]
                targets = self._targets(record["stage"])
                note_progress(self.progress, record["stage"], clean, xy, targets)
            counters = self._counters()
            self.events = coupled_motion(clean, before["counters"], counters)
        except TrainerError as exc:
            record["refused"] = str(exc)
            after = self.full_state()
            record["state_after"] = state_digest(after)
            self.log.append(record)
            self._last_state = (len(self.log), dict(after), record["state_after"])
            raise
        after = self.full_state(counters)
        record["state_after"] = state_digest(after)
        if clean["kind"] == "claim":
            record["state"] = after
        self.log.append(record)
        self._last_state = (len(self.log), dict(after), record["state_after"])
        return self.trainee_view(after)

    def _do(self, action: dict[str, Any], before: dict[str, Any]) -> Any:
        kind = action["kind"]
        if kind not in before["allowed"]:
            raise TrainerError(
                f"action {kind}: not allowed now (allowed: {', '.join(before['allowed'])})"
            )
        if kind == "undo":
            self._redo.append(self._snapshot())
            self._restore(self._undo.pop())
            return None
        if kind == "redo":
            self._undo.append(self._snapshot())
            self._restore(self._redo.pop())
            return None
        if kind == "hint":
            return self._hint(int(action["level"]), animated=action.get("animated") is True)
        if kind in ("turn", "set") and action["control"] in self.locked:
            raise TrainerError(f"action {kind}: {action['control']} is locked")
        undoable = self.exercise.allows("undo") and kind != "read"
        snap = self._snapshot() if undoable else None
        if kind in INSTRUMENT_KINDS:
            result = apply(self.inst, action, self.commanded)
        elif kind == "lock":
            if action["control"] not in self.locked:
                self.locked.append(action["control"])
            result = None
        elif kind == "record":
            self.records[str(action["name"])] = action["value"]
            result = None
        else:  # claim
            result = self._claim(str(action["step"]))
        if snap is not None:
            self._undo.append(snap)
            del self._undo[:-UNDO_DEPTH]
            self._redo.clear()
        return result

    def _claim(self, step: str) -> dict[str, Any]:
        if step != self.stage:
            raise TrainerError(
                f"action claim: step: the stage in hand is {self.stage}, found {step!r}"
            )
        if step in SUBSTITUTE_STAGES:
            for n in self.exercise.unusable_points:
                value = self.records.get(f"substitute {n}")
                if not _is_point(value):
                    raise TrainerError(
                        f"action claim: standard point {n} is unusable: record 'substitute {n}' "
                        "as [x_mm, y_mm] on the left photo first"
                    )
        self.claimed.append(step)
        self.at_claim[step] = _copy_instrument(self.inst)
        self.stage_index += 1
        out: dict[str, Any] = {"claimed": step, "text": f"stage {step} claimed"}
        if self.exercise.mode == "practice":  # feedback: the stage's true outcome
            out["measures"] = [
                {
                    "name": m.name,
                    "value": _f(m.value),
                    "tolerance": float(m.tolerance),
                    "unit": m.unit,
                    "passed": bool(_f(m.value) <= m.tolerance),
                }
                for m in stage_measures(self.inst, self.prep, step, self.exercise.unusable_points)
            ]
            out["text"] = claim_text(step, out["measures"])
        return out

    def _hint(self, level: int, animated: bool = False) -> dict[str, Any]:
        """A hint of the stage in hand. Level 3 with ``animated``: "show me" played by the page
        (it sends the operator's actions itself, one by one): charged as level 3, nothing
        applied here."""
        stage = self.stage
        assert stage is not None
        self.hints_used.append(level)
        actions = self.par.stage_actions(stage)
        out: dict[str, Any] = {
            "level": level,
            "text": hint_text(self.exercise.method, stage, level),
        }
        # the operator's steps of the stage, each once, in the order first taken
        out["steps"] = list(dict.fromkeys(self.par.stage_steps(stage)))
        if level == 3 and animated:  # the page plays the actions: charged, not applied
            out["animated"] = len(actions)
        elif level == 3:  # show me: the simulated operator does the stage on this instrument
            for a in actions:
                apply(self.inst, a, self.commanded)
            out["applied"] = len(actions)
        elif level == 2:
            controls = []
            for a in actions:
                c = a.get("control") or a.get("counter") or a["kind"]
                if c not in controls:
                    controls.append(c)
            out["controls"] = controls
        out["lines"] = hint_lines(out)
        out["text"] = "\n".join(out["lines"])
        return out

    # --- the operator's actions as a script -----------------------------------------------------

    def operator_script(self) -> list[dict[str, Any]]:
        """The simulated operator's actions for the exercise's stages, each stage followed by
        its claim: the acceptance test's scripted trainee."""
        script: list[dict[str, Any]] = []
        for stage in self.stages:
            for a in self.par.stage_actions(stage):
                script.append({k: v for k, v in a.items() if k != "stage"})
            if stage in SUBSTITUTE_STAGES:  # the operator's substitute: the standard point itself
                for n in self.exercise.unusable_points:
                    xy = [float(v) for v in self.prep.scene.standard[0][n - 1]]
                    script.append({"kind": "record", "name": f"substitute {n}", "value": xy})
            script.append({"kind": "claim", "step": stage})
        return script


def secret_seed(key: bytes, exercise: str, trainee: str, attempt: int) -> int:
    """A trainee's seed known only to whoever holds ``key`` (the server's secret): HMAC-SHA-256
    of exercise, trainee and attempt number, its first 8 bytes as a non-negative int below
    2**63. Nothing public (the names) gives it: an exam cannot be answered offline."""
    message = "\x00".join((exercise, trainee, str(int(attempt)))).encode("utf-8")
    digest = hmac.new(key, message, hashlib.sha256).digest()
    return int.from_bytes(digest[:8], "big") >> 1


#: Exercise (its file content) → stage → the reference run's step rules (one run per exercise
#: and process, about a second; every trainee of the exercise shares it).
_REFERENCE: dict[str, dict[str, list[dict[str, Any]]]] = {}


def _reference_rules(exercise: Exercise, stage: str) -> list[dict[str, Any]]:
    key = json.dumps(exercise.source, sort_keys=True, default=str)
    if key not in _REFERENCE:
        prep = prepare_run(exercise.scenario, exercise.spec, exercise.method, "zero", 0)
        par = operator_run(prep, 0, exercise.stages[-1])
        _REFERENCE[key] = {s: step_rules(par, s) for s in exercise.stages}
    return _REFERENCE[key][stage]


def _scales_as_shown(controls: dict[str, Any]) -> dict[str, Any]:
    """The controls with the scales the instrument reads (the screws' and decentrations'
    values and stops) to their least count, the control's ``step``: read exactly, the stops
    give a counter's hidden zero and scale errors, and a decentration's follow of a knob turn
    the true f′ (what the counters show to the least count anyway)."""
    out = dict(controls)
    for name in (*SCREWS, *DECENTRATIONS):
        if name in out:
            c = dict(out[name])
            for key in ("value", "min", "max"):
                if c.get(key) is not None:
                    c[key] = _on_step(float(c[key]), float(c["step"]))
            out[name] = c
    return out


def _on_step(value: float, step: float) -> float:
    """``value`` rounded to a multiple of ``step`` (to 9 decimals: no binary residue)."""
    return round(round(value / step) * step, 9)


def _is_point(value: Any) -> bool:
    return (
        isinstance(value, list)
        and len(value) == 2
        and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
        and all(math.isfinite(v) for v in value)
    )


def json_finite(value: Any) -> Any:
    """``value`` with every non-finite float replaced by None (JSON has no inf, nan)."""
    if isinstance(value, dict):
        return {k: json_finite(v) for k, v in value.items()}
    if isinstance(value, list):
        return [json_finite(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _copy_instrument(inst: Instrument) -> Instrument:
    """A copy of the instrument's physical state (the spec and error model shared: frozen)."""
    memo: dict[int, Any] = {id(inst.spec): inst.spec, id(inst.errors): inst.errors}
    return _state_copy(inst, memo)


#: Values :func:`_state_copy` hands on as they are (immutable).
_ATOMIC = frozenset(
    {type(None), bool, int, float, complex, str, bytes, np.float64, np.int64, np.bool_}
)
#: Type → how :func:`_state_copy` copies its instances: "shared" (a frozen dataclass, a value:
#: the instrument changes one by building a new one, :func:`dataclasses.replace`), "plain" (its
#: state is its ``__dict__`` alone) or "other" (``copy.deepcopy``); only this package's own
#: types are shared or copied as plain.
_HOW: dict[type, str] = {}


def _state_copy(obj: Any, memo: dict[int, Any]) -> Any:
    """``copy.deepcopy(obj, memo)`` for the plain state a session holds (dicts, lists, tuples,
    arrays, objects with a ``__dict__``), an order of magnitude faster: what ``deepcopy``
    reaches there through its generic reconstruction is built directly, and a frozen
    dataclass of this package is shared instead of copied (nothing changes it in place).
    Anything else (another package's type, an object with ``__slots__`` or its own copy or
    pickling hooks, an array of objects) goes to
    ``copy.deepcopy`` with the same memo, so aliasing inside ``obj`` is kept as ``deepcopy``
    keeps it."""
    cls = type(obj)
    if cls in _ATOMIC:
        return obj
    done = memo.get(id(obj))
    if done is not None:
        return done
    if cls is np.ndarray and obj.dtype != object:
        out: Any = obj.copy()
    elif cls is dict:
        out = memo[id(obj)] = {}
        for k, v in obj.items():
            out[k] = _state_copy(v, memo)
        return out
    elif cls is list:
        out = memo[id(obj)] = []
        out.extend(_state_copy(v, memo) for v in obj)
        return out
    elif cls is tuple:
        items = [_state_copy(v, memo) for v in obj]
        out = obj if all(a is b for a, b in zip(items, obj, strict=True)) else tuple(items)
    elif (how := _HOW.get(cls) or _how(cls)) == "shared":
        out = obj
    elif how == "plain":
        out = memo[id(obj)] = object.__new__(cls)
        out.__dict__.update({k: _state_copy(v, memo) for k, v in obj.__dict__.items()})
        return out
    else:
        return copy.deepcopy(obj, memo)
    memo[id(obj)] = out
    return out


def _how(cls: type) -> str:
    params = getattr(cls, "__dataclass_params__", None)
    hooks = ("__deepcopy__", "__copy__", "__reduce_ex__", "__reduce__", "__getstate__",
             "__setstate__")
    ours = cls.__module__.split(".")[0] == "stereoplotter"  # others' types: deepcopy
    if ours and params is not None and params.frozen:
        how = "shared"
    elif ours and "__slots__" not in cls.__dict__ and all(
        getattr(cls, h, None) is getattr(object, h, None) for h in hooks
    ) and "__dict__" in dir(cls):
        how = "plain"
    else:
        how = "other"
    _HOW[cls] = how
    return how


def check_stage(name: str) -> str | None:
    """The stage a check of the procedure belongs to, by its name ("stage 5: …", "C2: …")."""
    head = name.split(":", 1)[0].strip()
    if head.startswith("stage "):
        return head.split()[1].split("/")[0]
    for stages in STAGES.values():
        if head in stages:
            return head
    return None
