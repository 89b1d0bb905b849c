"""What a virtual instrument tells its listener: each operator call as an :class:`Action`.

:class:`~stereoplotter.instrument.virtual.Instrument` calls its ``on_action`` listener (an
:data:`ActionListener`, None by default) once after each successful call of an operator's
method, with the arguments as they were passed; the trainer records the simulated operator's
work this way (:mod:`stereoplotter.trainer.operator_steps`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Final, Literal, get_args

from numpy.typing import ArrayLike

__all__ = ["ACTION_KINDS", "Action", "ActionKind", "ActionListener"]

#: The operator's calls an instrument tells its listener about (:class:`Action`).
ActionKind = Literal["set", "knob", "direction", "read", "gear", "slip", "connect", "needle"]
ACTION_KINDS: Final[tuple[ActionKind, ...]] = get_args(ActionKind)


@dataclass(frozen=True, slots=True)
class Action:
    """One call of an operator's method on an instrument, as it was made: what the
    instrument's listener (``Instrument.on_action``) is told once the call has succeeded.

    Attributes
    ----------
    kind : ActionKind
        The method of :class:`~stereoplotter.instrument.virtual.Instrument`: "set" (``set``),
        "knob" (``turn_knob``), "direction" (``switch_counter``), "read" (``read``), "gear"
        (``gear_height_counter``), "slip" (``slip_height_scale``), "connect"
        (``connect_coordinatograph``) or "needle" (``needle``).
    control : str or None
        The control set, knob turned, counter switched or read (None for the others).
    value : array_like or None
        The value passed: a reading (set, slip; the control's unit), a tilt tangent (knob), the
        counter's sense (direction), M_в (gear), the gear ratio (connect); None (read, needle).
    side : str or None
        The side a setting or the needle finishes from ("below", "above"; None: direct).
    origin_mm : (float, float) or None
        The coordinatograph's origin on the table as passed (connect; None: the default, the
        table centre). [mm]
    """

    kind: ActionKind
    control: str | None = None
    value: Any = None
    side: str | None = None
    origin_mm: ArrayLike | None = None


#: A listener of an instrument's actions (``Instrument.on_action``).
ActionListener = Callable[[Action], None]
