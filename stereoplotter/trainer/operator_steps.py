"""The simulated operator's work as a sequence of trainee actions.

The procedure (:mod:`stereoplotter.procedure.setup_method`, ``conventional``) drives the
instrument through :meth:`Instrument.set`, :meth:`~Instrument.turn_knob`, the height counter,
the coordinatograph and reads its counters. :class:`RecordingInstrument` is an instrument that
notes each of these calls as a session action (``set``, ``read``, ``gear``, ``slip``,
``connect``, ``needle``) with the stage in which it happened; :func:`operator_run` runs the
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
    "OperatorRun",
    "RecordingInstrument",
    "new_instrument",
    "operator_run",
    "stage_functions",
]


def _num(value: Any) -> Any:
    """A JSON number (or list) from a scalar or one-trial array."""
    a = np.asarray(value, float)
    if a.size == 1:
        return float(a.reshape(-1)[0])
    return [float(v) for v in a.reshape(-1)]


class RecordingInstrument(Instrument):
    """An instrument that notes every operator call as a session action (``self.actions``)."""

    def __init__(self, *args: Any, **kwargs: Any):
        super().__init__(*args, **kwargs)
        self.actions: list[dict[str, Any]] = []
        self.stage = ""
        self.recording = True
        self._depth = 0
        #: The operator's transcript (set by :func:`operator_run`): each action notes how many
        #: records it held, so that the action's step is the next record's.
        self.transcript: Transcript | None = None
        self.record_index: list[int] = []

    def _note(self, action: dict[str, Any]) -> None:
        if self.recording and self._depth == 0:
            self.actions.append({**action, "stage": self.stage})
            self.record_index.append(len(self.transcript.records) if self.transcript else 0)

    def set(self, control, reading, side=None) -> None:  # type: ignore[override]
        self._depth += 1  # the height scale sets Z: only the outer call is the operator's
        try:
            super().set(control, reading, side)
        finally:
            self._depth -= 1
        action = {"kind": "set", "control": str(control), "value": _num(reading)}
        if side is not None:
            action["side"] = side
        self._note(action)

    def turn_knob(self, knob, tan_tilt) -> None:  # type: ignore[override]
        super().turn_knob(knob, tan_tilt)
        self._note({"kind": "set", "control": str(knob), "value": _num(tan_tilt)})

    def gear_height_counter(self, vertical_scale_denominator: int) -> None:
        super().gear_height_counter(vertical_scale_denominator)
        self._note({"kind": "gear", "value": int(vertical_scale_denominator)})

    def slip_height_scale(self, reading_m) -> None:  # type: ignore[override]
        super().slip_height_scale(reading_m)
        self._note({"kind": "slip", "value": _num(reading_m)})

    def connect_coordinatograph(self, ratio, origin_table_mm=None, enlargement=None) -> None:  # type: ignore[override]
        super().connect_coordinatograph(ratio, origin_table_mm, enlargement)
        action: dict[str, Any] = {"kind": "connect", "value": float(ratio)}
        if origin_table_mm is not None:
            action["origin_mm"] = [float(v) for v in origin_table_mm]
        self._note(action)

    def needle(self, side=None, servo_noise_mm=None):  # type: ignore[override]
        out = super().needle(side, servo_noise_mm)
        action: dict[str, Any] = {"kind": "needle"}
        if side is not None:
            action["side"] = side
        self._note(action)
        return out

    def read(self, control, exact: bool = False):  # type: ignore[override]
        out = super().read(control, exact)
        self._note({"kind": "read", "counter": str(control)})
        return out


def new_instrument(prep: PreparedRun, seed: int, cls: type[Instrument] = Instrument) -> Instrument:
    """The instrument of trial 0 of a run seeded ``seed`` (errors drawn as ``simulate`` does)."""
    return build_instrument(
        prep, injected=prep.model.draw_keyed(seed, 0, None), instrument_cls=cls
    )


@dataclass
class OperatorRun:
    """The simulated operator's run: its actions, its Run and the instrument it left.

    Attributes
    ----------
    actions : list of dict
        Session actions with their ``stage``, in order.
    run : Run
    instrument : RecordingInstrument
    """

    actions: list[dict[str, Any]]
    run: Run
    instrument: RecordingInstrument
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
        state["levels"] = levelling_points(run)
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
    after_stage: Callable[[str, RecordingInstrument], None] | None = None,
) -> OperatorRun:
    """Run the simulated operator (trial 0 of seed ``seed``) stage by stage, noting its actions;
    it stops after stage ``upto`` (default: the method's last). ``after_stage(stage, inst)``
    runs at the end of each stage, its calls on the instrument noted as the stage's actions
    (the robot trainee's finishing, :mod:`stereoplotter.trainer.robot`)."""
    run = build_run(
        prep,
        injected=prep.model.draw_keyed(seed, 0, None),
        noise=Noise(seed, None, None, 0),
        instrument_cls=RecordingInstrument,
    )
    op, inst = run.op, run.op.inst
    assert isinstance(inst, RecordingInstrument)
    inst.transcript = op.log
    ends = {}
    for name, fn in stage_functions(run, prep.method).items():
        inst.stage = name
        fn()
        if after_stage is not None:
            after_stage(name, inst)
        ends[name] = len(inst.actions)
        if name == upto:
            break
    inst.recording = False
    records = op.log.records
    steps = [records[min(i, len(records) - 1)].step if records else "" for i in inst.record_index]
    return OperatorRun(inst.actions, run, inst, ends, steps)
