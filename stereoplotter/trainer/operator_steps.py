"""The simulated operator's work as a sequence of trainee actions.

The procedure (:mod:`stereoplotter.procedure.setup_method`, ``conventional``) drives the
instrument through :meth:`Instrument.set`, :meth:`~Instrument.turn_knob`, the height counter,
the coordinatograph and reads its counters. An :class:`ActionRecorder`, the instrument's
listener (:attr:`Instrument.on_action`), notes each of these calls as a session action
(``set``, ``read``, ``gear``, ``slip``, ``connect``, ``needle``) with the stage in which it
happened; :func:`operator_run` runs the
method once (trial 0 of ``simulate(..., seed=seed)``, the same instrument, errors and judgments)
and returns those actions. They are what a hint of level 3 replays ("show me") and what presets
the stages before an exercise's first stage; replayed through a
:class:`~stereoplotter.trainer.session.Session` they reproduce the operator's instrument state.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from stereoplotter.instrument.action_listener import Action
from stereoplotter.instrument.virtual import Instrument
from stereoplotter.procedure.conventional import (
    c1_interior,
    c2_relative_by_elements,
    c3_absolute,
    c4_sheet,
    calibrate,
    levelling_points,
)
from stereoplotter.procedure.operator import Noise
from stereoplotter.procedure.run import PreparedRun, Run, build_instrument, build_run
from stereoplotter.procedure.setup_method import (
    stage1_scale_coefficient,
    stage2_transform,
    stage3_scale_model,
)
from stereoplotter.procedure.sheet_stages import stage4_orient_sheet, stage5_check
from stereoplotter.procedure.transcript import Transcript

__all__ = [
    "ActionRecorder",
    "OperatorRun",
    "new_instrument",
    "operator_run",
    "session_action",
    "stage_functions",
]


def _num(value: Any) -> Any:
    """A JSON number (or list) from a scalar or one-trial array."""
    a = np.asarray(value, float)
    if a.size == 1:
        return float(a.reshape(-1)[0])
    return [float(v) for v in a.reshape(-1)]


class ActionRecorder:
    """Notes each operator action on an instrument as a session action: the instrument's
    listener (``inst.on_action = recorder``, :attr:`Instrument.on_action`).

    Attributes
    ----------
    actions : list of dict
        The session actions (``set``, ``read``, ``gear``, ``slip``, ``connect``, ``needle``,
        ``direction``; a correction knob's turn is a ``set``), each with its ``stage``.
    stage : str
        The stage the next actions belong to.
    recording : bool
        False: actions are not noted.
    transcript : Transcript or None
        The operator's transcript: each action notes how many records it held
        (:attr:`record_index`), so that the action's step is the next record's.
    """

    def __init__(self, transcript: Transcript | None = None):
        self.actions: list[dict[str, Any]] = []
        self.stage = ""
        self.recording = True
        self.transcript = transcript
        self.record_index: list[int] = []

    def __call__(self, action: Action) -> None:
        """Note ``action`` (see :func:`session_action`) unless not :attr:`recording`."""
        if self.recording:
            self.actions.append({**session_action(action), "stage": self.stage})
            self.record_index.append(len(self.transcript.records) if self.transcript else 0)


def session_action(action: Action) -> dict[str, Any]:
    """The session action (:mod:`stereoplotter.trainer.actions`) an instrument's action is."""
    out: dict[str, Any]
    if action.kind in ("set", "knob"):
        out = {"kind": "set", "control": str(action.control), "value": _num(action.value)}
        if action.side is not None:
            out["side"] = action.side
    elif action.kind == "read":
        out = {"kind": "read", "counter": str(action.control)}
    elif action.kind == "direction":
        out = {"kind": "direction", "counter": str(action.control), "sign": int(action.value)}
    elif action.kind == "gear":
        out = {"kind": "gear", "value": int(action.value)}
    elif action.kind == "slip":
        out = {"kind": "slip", "value": _num(action.value)}
    elif action.kind == "connect":
        out = {"kind": "connect", "value": float(action.value)}
        if action.origin_mm is not None:
            out["origin_mm"] = [float(v) for v in np.asarray(action.origin_mm, float)]
    else:  # needle
        out = {"kind": "needle"}
        if action.side is not None:
            out["side"] = action.side
    return out


def new_instrument(prep: PreparedRun, seed: int) -> Instrument:
    """The instrument of trial 0 of a run seeded ``seed`` (errors drawn as ``simulate`` does)."""
    return build_instrument(prep, injected=prep.model.draw_keyed(seed, 0, None))


@dataclass
class OperatorRun:
    """The simulated operator's run: its actions, its Run and the instrument it left.

    Attributes
    ----------
    actions : list of dict
        Session actions with their ``stage``, in order.
    run : Run
    instrument : Instrument
        The instrument the run left (its listener removed).
    """

    actions: list[dict[str, Any]]
    run: Run
    instrument: Instrument
    stage_ends: dict[str, int] = field(default_factory=dict)
    #: Per action, the step of the transcript it belongs to (the first record written after it).
    steps: list[str] = field(default_factory=list)

    def stage_actions(self, stage: str) -> list[dict[str, Any]]:
        """The actions of one stage."""
        return [a for a in self.actions if a["stage"] == stage]

    def stage_steps(self, stage: str) -> list[str]:
        """The steps of one stage in the operator's order (repeats of a step in a row once)."""
        out: list[str] = []
        for action, step in zip(self.actions, self.steps, strict=True):
            if action["stage"] == stage and step and (not out or out[-1] != step):
                out.append(step)
        return out


def _conventional_stages(run: Run):
    state: dict[str, Any] = {}

    def c1() -> None:
        c1_interior(run)

    def c2() -> None:
        state["levels"] = levelling_points(run.scene, run.sheet)
        state["cal"] = calibrate(run, state["levels"])
        run.calibration = state["cal"]
        its, worst = c2_relative_by_elements(run, state["cal"])
        run.record_stage("C2", its)
        tol = run.sheet.tolerances["residual_y_parallax_mm"]
        run.check("C2: residual y-parallax (6 points)", worst, tol, iterations=its)

    def c3() -> None:
        c3_absolute(run, state["cal"], state["levels"], c2_relative_by_elements)

    def c4() -> None:
        c4_sheet(run)

    return {"C1": c1, "C2": c2, "C3": c3, "C4": c4}


def stage_functions(run: Run, method: str) -> dict[str, Callable[[], None]]:
    """The method's stages as callables on ``run``, in order (the conventional method's
    relative orientation element by element, ``RELATIVE_OPTIONS[0]``, as ``simulate`` does)."""
    if method == "setup":
        return {
            "1": lambda: stage1_scale_coefficient(run),
            "2": lambda: stage2_transform(run),
            "3": lambda: stage3_scale_model(run),
            "4": lambda: stage4_orient_sheet(run),
            "5": lambda: stage5_check(run),
        }
    return _conventional_stages(run)


def operator_run(
    prep: PreparedRun,
    seed: int,
    upto: str | None = None,
    after_stage: Callable[[str, Instrument, list[dict[str, Any]]], None] | None = None,
) -> OperatorRun:
    """Run the simulated operator (trial 0 of seed ``seed``) stage by stage, noting its actions;
    it stops after stage ``upto`` (default: the method's last). ``after_stage(stage, inst,
    actions)`` runs at the end of each stage (``actions``: those noted so far), its calls on the
    instrument noted as the stage's actions (the robot trainee's finishing,
    :mod:`stereoplotter.trainer.robot`)."""
    run = build_run(
        prep, injected=prep.model.draw_keyed(seed, 0, None), noise=Noise(seed, None, None, 0)
    )
    op, inst = run.op, run.op.inst
    recorder = ActionRecorder(op.log)
    inst.on_action = recorder
    ends = {}
    for name, fn in stage_functions(run, prep.method).items():
        recorder.stage = name
        fn()
        if after_stage is not None:
            after_stage(name, inst, recorder.actions)
        ends[name] = len(recorder.actions)
        if name == upto:
            break
    inst.on_action = None
    records = op.log.records
    steps = [
        records[min(i, len(records) - 1)].step if records else "" for i in recorder.record_index
    ]
    return OperatorRun(recorder.actions, run, inst, ends, steps)
