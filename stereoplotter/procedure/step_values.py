"""Steps as values: what a step of either method sets or reads, its line in the transcript, its
noise identity and its condition, declared once; :func:`perform` is the one interpreter that
does the mechanics (through the operator) and writes the transcript from the declaration.

A method is a sequence of steps (:data:`Step`): :class:`SetStep` sets a computed value on a
control's scale, :class:`DriveStep` turns a control while looking, :class:`ReadStep` reads a
scale into a zero reading of the run, :class:`Note` is the line of steps done together, and
:class:`Act` hands a step whose mechanics are a loop or a look (the L-check, a fit) to its
function. Every step declares its :class:`~stereoplotter.procedure.noise_key.NoiseKey`, so a
step inserted, removed or moved leaves the draws of every other step as they were.
:class:`Line` is a step's line in the transcript (its wording a template whose fields the
interpreter fills); :class:`Condition` marks a step taken only where its condition holds (the
L-check's corrections, the carriage at its bottom stop, a knob at its stop), recorded with
each of its transcript records (:attr:`~stereoplotter.procedure.transcript.Record.condition`).
:func:`turn_common_tilt` is the one "turn each control of a combination by rate·φ and log it"
of both methods (the setup method's levelling, the conventional method's levelling and its
common tilt at a knob's stop).

Units: mm on the instrument, m on the height scale, rad for the cassettes, tan for the knobs
(each control's own, :data:`~stereoplotter.instrument.virtual.CONTROL_INFO`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any, TypeAlias

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.instrument.virtual import CONTROL_INFO
from stereoplotter.procedure.noise_key import NoiseKey

if TYPE_CHECKING:  # typing only: run.py builds the operator this module drives
    from stereoplotter.procedure.operator import Operator
    from stereoplotter.procedure.run import Run

__all__ = [
    "BOTTOM_STOP",
    "CONDITIONS",
    "KNOB_AT_STOP",
    "L_CHECK_FAILED",
    "Act",
    "Condition",
    "DriveStep",
    "Line",
    "Note",
    "ReadStep",
    "SetStep",
    "Step",
    "perform",
    "perform_all",
    "turn_common_tilt",
]


@dataclass(frozen=True, slots=True)
class Condition:
    """The condition of a conditional step: the step is taken (and in the transcript) only
    where it holds.

    Attributes
    ----------
    name : str
        Its name, as the transcript records it.
    holds : str
        When it holds, in words.
    """

    name: str
    holds: str


#: The L-check's corrections ΔZ (6.9) and Δb_z (6.10): a photo's |L − L′| over 0.03/n_л.
L_CHECK_FAILED = Condition(
    "L-check failed", "|L − L′| > 0.03/n_л on a photo after the L-check's measurement"
)
#: f_пр changed for n = D/f_пр: a ΔZ that would take the carriage past its bottom stop (or,
#: with f_пр short of the sheet's, a shallower carriage).
BOTTOM_STOP = Condition(
    "carriage at its bottom stop",
    "the ΔZ would take the carriage past its bottom stop D_max, or f_пр is short of the "
    "sheet's value and the carriage rises",
)
#: The conventional method's common tilt that centres a pair of knobs: a knob at its stop.
KNOB_AT_STOP = Condition(
    "knob at its stop", "a correction knob of the axis is at its stop during C2"
)
#: Every condition a step declares.
CONDITIONS = (L_CHECK_FAILED, BOTTOM_STOP, KNOB_AT_STOP)


@dataclass(frozen=True, slots=True)
class Line:
    """A step's line in the transcript.

    Attributes
    ----------
    stage : str
        "1" … "5" (setup-data method), "C1" … "C4" (conventional method).
    text : str
        What the operator does; a template whose ``{fields}`` the step fills at run time.
    equation : str
        The book equation or design decision behind the act.
    unit : str or None
        The unit of the values logged; None: the control's own (``CONTROL_INFO``), "mm" for
        a line without a control.
    condition : Condition or None
        The step's condition (None: every run takes it).
    """

    stage: str
    text: str
    equation: str = ""
    unit: str | None = None
    condition: Condition | None = None

    def in_stage(self, stage: str, equation: str | None = None) -> Line:
        """This line written in ``stage`` (a step both stages or methods take), ``equation``
        where that stage's basis differs."""
        return replace(self, stage=stage, equation=self.equation if equation is None else equation)

    def log(
        self,
        op: Operator,
        control: str = "",
        fields: Mapping[str, Any] | None = None,
        unit: str | None = None,
        **values: Any,
    ) -> None:
        """Write the line for ``control``: its text with ``fields`` filled, ``values`` the
        record's numbers (:meth:`~stereoplotter.procedure.transcript.Transcript.add`);
        ``unit`` overrides the line's."""
        unit = unit or self.unit or (CONTROL_INFO[control].unit if control else "mm")
        op.log.add(
            self.stage,
            self.text.format(**fields) if fields else self.text,
            control,
            unit=unit,
            equation=self.equation,
            condition=self.condition.name if self.condition else "",
            **values,
        )


@dataclass(frozen=True, slots=True)
class SetStep:
    """Set a computed value on a control's scale (σ_set; backlash and scale errors stay in)
    and log it as the reading.

    Attributes
    ----------
    control : str
    value : callable
        ``value(run)``: the reading to set (from the sheet or the run's zero readings).
    key : NoiseKey
        The identity of the setting's draw.
    line : Line or None
        Its line (None: set together with a step that has one).
    fields : callable or None
        ``fields(run)``: the values of the line's template fields.
    """

    control: str
    value: Callable[[Run], ArrayLike]
    key: NoiseKey
    line: Line | None = None
    fields: Callable[[Run], Mapping[str, Any]] | None = None


@dataclass(frozen=True, slots=True)
class DriveStep:
    """Turn a control while looking until it is physically at a value (no scale read: no
    draw) and log the value as the reading.

    Attributes
    ----------
    control : str
    value : callable
        ``value(run)``: where the control is turned to.
    line : Line or None
    """

    control: str
    value: Callable[[Run], ArrayLike]
    line: Line | None = None


@dataclass(frozen=True, slots=True)
class Note:
    """A line for steps done together just before it (each declared silent)."""

    line: Line


@dataclass(frozen=True, slots=True)
class ReadStep:
    """Read a control's scale (σ_read, rounded to the least count) into the run's zero reading
    ``zero`` and log what is recorded.

    Attributes
    ----------
    control : str
    key : NoiseKey
        The identity of the reading's draw.
    zero : str
        The zero reading recorded (``run.zero``).
    line : Line or None
        Its line (None: recorded silently).
    recorded : callable or None
        ``recorded(run, reading)``: what is recorded from the reading (None: the reading).
    """

    control: str
    key: NoiseKey
    zero: str
    line: Line | None = None
    recorded: Callable[[Run, NDArray[np.float64]], NDArray[np.float64]] | None = None


@dataclass(frozen=True, slots=True)
class Act:
    """A step whose mechanics are its own function (a tolerance loop, a look, a fit): its
    identity declared here, its draws below it.

    Attributes
    ----------
    name : str
        What the step does (a name for the reader; its lines are the function's).
    key : NoiseKey
        The identity its draws hang below.
    does : callable
        ``does(run, key)``.
    condition : Condition or None
    """

    name: str
    key: NoiseKey
    does: Callable[[Run, NoiseKey], object]
    condition: Condition | None = None


#: A step of a method.
Step: TypeAlias = SetStep | DriveStep | ReadStep | Note | Act


def perform(run: Run, step: Step) -> None:
    """Do ``step`` on the run's instrument through its operator and write its line."""
    op = run.op
    if isinstance(step, SetStep):
        value = step.value(run)
        op.set(step.control, value, step.key)  # type: ignore[arg-type]
        if step.line is not None:
            fields = step.fields(run) if step.fields is not None else None
            step.line.log(op, step.control, fields, reading=value)
    elif isinstance(step, DriveStep):
        value = step.value(run)
        op.drive(step.control, value)  # type: ignore[arg-type]
        if step.line is not None:
            step.line.log(op, step.control, reading=value)
    elif isinstance(step, Note):
        step.line.log(op)
    elif isinstance(step, ReadStep):
        reading = op.read(step.control, step.key)  # type: ignore[arg-type]
        value = reading if step.recorded is None else step.recorded(run, reading)
        run.zero[step.zero] = value
        if step.line is not None:
            step.line.log(op, step.control, reading=value)
    else:
        step.does(run, step.key)


def perform_all(run: Run, steps: Sequence[Step]) -> None:
    """Do ``steps`` in order (:func:`perform`)."""
    for step in steps:
        perform(run, step)


#: Controls a common tilt sets on their scale (read, then set to reading + rate·φ) rather than
#: turning them while looking: the base screws.
_ON_SCALE = ("by", "bz")


def turn_common_tilt(
    run: Run,
    combo: Mapping[str, float],
    phi: ArrayLike,
    key: NoiseKey,
    active: NDArray[np.bool_],
    line: Line,
    *,
    fields: Mapping[str, Any] | None = None,
    scale_sense: float = 1.0,
    turn: Callable[[str, NDArray[np.float64], NDArray[np.bool_]], None] | None = None,
    unit_of: Callable[[str], str] | None = None,
    **values: Any,
) -> None:
    """Turn each control of ``combo`` (control → rate per radian of the tilt) by rate·φ and
    log it (``line``; ``{control}`` in its text is the control's name).

    b_y, b_z are read (draw ``key``/control) and set to reading + ``scale_sense``·rate·φ (draw
    ``key``/set‹control›) on the ``active`` trials; every other control is turned while
    looking to where it is + rate·φ (``turn``, default :meth:`Operator.drive`). ``unit_of``:
    the unit a control's record shows (default the line's). ``values``: the record's other
    fields (iteration, remedy, when). [control units, rad]
    """
    op = run.op
    phi = np.asarray(phi, float)
    for control, rate in combo.items():
        if control in _ON_SCALE:
            before = op.read(control, key.at(control))  # type: ignore[arg-type]
            after = before + scale_sense * rate * phi
            op.set(control, after, key.at(f"set{control}"), active)  # type: ignore[arg-type]
        else:
            before = op.physical(control)  # type: ignore[arg-type]
            if turn is None:
                op.drive(control, before + rate * phi, active)  # type: ignore[arg-type]
            else:
                turn(control, before + rate * phi, active)
            after = op.physical(control)  # type: ignore[arg-type]
        unit = unit_of(control) if unit_of is not None else None
        text = {**(fields or {}), "control": control}
        line.log(op, control, text, unit, before=before, after=after, **values)
