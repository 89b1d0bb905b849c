"""The controls of the virtual instrument, declared once: their names by group, and each
control's kind, unit, side, axis, owning part, stops and least count (:data:`CONTROL_INFO`).

The instrument, the operator, the procedure's steps, the transcript and the trainer read a
control's facts here, never from its name's spelling. Stops and least counts depend on the
instrument file: :meth:`ControlInfo.range` and :meth:`ControlInfo.least_count` read the
:class:`~stereoplotter.spec.instrument_spec.InstrumentSpec` attribute each control declares.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final, Literal, get_args

import numpy as np

from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.principles import PRINCIPLES
from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = [
    "CASSETTES",
    "CONTROLS",
    "CONTROL_INFO",
    "DECENTRATIONS",
    "KNOBS",
    "SCREWS",
    "SET_CONTROLS",
    "CassetteName",
    "Control",
    "ControlInfo",
    "ControlKind",
    "ControlPart",
    "DecentrationName",
    "HeightScaleName",
    "KnobName",
    "ScaleName",
    "ScrewName",
    "SetControl",
    "Side",
    "control_axis",
    "control_kind",
    "control_side",
]

#: The two photos / projectors.
Side = Literal["left", "right"]
#: Lead-screw axes with a counter or scale: the carriages and the base carriage.
ScrewName = Literal["X", "Y", "Z", "bx", "by", "bz"]
#: Cassette rotations κ, set on their scales [rad].
CassetteName = Literal["kappa_left", "kappa_right"]
#: Decentration scales of the correction units [mm].
DecentrationName = Literal["dx_left", "dy_left", "dx_right", "dy_right"]
#: Correction knobs k_α, k_ω, turned to the tilt tangent they represent (:meth:`turn_knob`).
KnobName = Literal["k_alpha_left", "k_omega_left", "k_alpha_right", "k_omega_right"]
#: The metre height scale geared to the Z screw.
HeightScaleName = Literal["H"]
#: Controls set on a scale: f_пр, the cassette rotations and the decentrations.
SetControl = Literal["f_instrument", CassetteName, DecentrationName]
#: Every counter or scale that can be read (:meth:`Instrument.read`).
ScaleName = Literal[ScrewName, DecentrationName, HeightScaleName]
#: Every control of the instrument (what an operator turns or sets).
Control = Literal[ScrewName, SetControl, KnobName, HeightScaleName]

SCREWS: Final[tuple[ScrewName, ...]] = get_args(ScrewName)
CASSETTES: Final[tuple[CassetteName, ...]] = get_args(CassetteName)
DECENTRATIONS: Final[tuple[DecentrationName, ...]] = get_args(DecentrationName)
KNOBS: Final[tuple[KnobName, ...]] = get_args(KnobName)
#: Controls set on a scale (f_пр, κ, decentrations).
SET_CONTROLS: Final[tuple[SetControl, ...]] = get_args(SetControl)
#: Every control an operator can turn to a reading.
CONTROLS = SCREWS + SET_CONTROLS

#: What a control is: a lead screw with its counter, the principal-distance scale, a cassette
#: rotation, a decentration scale, a correction knob or the height scale.
ControlKind = Literal[
    "screw", "principal_distance", "cassette", "decentration", "knob", "height_scale"
]


#: The part of the instrument a control belongs to: the carriages (X, Y, Z), the base carriage
#: (b_x, b_y, b_z′), the projector (f_пр), a cassette (κ), a correction unit (its k_α, k_ω knobs
#: and decentrations: built by the instrument's correction principle,
#: :mod:`stereoplotter.instrument.principles`) or the height counter (its metre scale).
ControlPart = Literal[
    "carriage", "base carriage", "projector", "cassette", "correction unit", "height counter"
]


@dataclass(frozen=True, slots=True)
class ControlInfo:
    """One control of the instrument, declared once (:data:`CONTROL_INFO`).

    Attributes
    ----------
    name : str
        The control's name (:data:`Control`).
    kind : ControlKind
    unit : str
        Unit of its setting: "mm" (screws, f_пр, decentrations), "rad" (cassettes), "tan" (a
        knob: the tangent of the tilt it represents), "m" (the height scale).
    side : {"left", "right"} or None
        The photo it acts on (None: both, the carriages and the base).
    axis : str or None
        A decentration's "x" or "y", a knob's "alpha" or "omega" (None: none).
    part : ControlPart
        The part of the instrument it belongs to; "correction unit": the instrument's
        correction principle owns it (:meth:`owner`) and gives it its own name
        (:meth:`own_name`).
    range_attribute : str or None
        The :class:`~stereoplotter.spec.instrument_spec.InstrumentSpec` attribute of its stops
        (:func:`~stereoplotter.spec.range_checks.check_in_range`); None: no stop (the height
        scale follows Z).
    least_count_attribute : str or None
        The spec attribute of its scale's least count; None: the instrument file gives none
        (κ, the knobs: set by what they represent, their setting error is the instrument's
        injected one, the operator adds none in least counts).
    family : str or None
        A correction unit's control without its side (``"k_alpha"``, ``"dx"``): the key the
        principles name it by (:attr:`~stereoplotter.instrument.principles.Principle.controls`).
    step : float or None
        The step a trainee's wheel turns a control without a least count by (κ: 10⁻⁴ rad, a
        knob: 10⁻⁵ of the tangent; assumed, finer than the setting errors of 1′ = 2.9·10⁻⁴).
    """

    name: str
    kind: ControlKind
    unit: str
    side: Side | None = None
    axis: str | None = None
    part: ControlPart = "carriage"
    range_attribute: str | None = None
    least_count_attribute: str | None = None
    family: str | None = None
    step: float | None = None

    def least_count(self, spec: InstrumentSpec) -> float | None:
        """The least count of its scale in ``spec`` (None: none given). [its unit]

        Examples
        --------
        >>> from stereoplotter.io.instrument_file import load_instrument
        >>> sc1 = load_instrument("sc1")
        >>> CONTROL_INFO["Z"].least_count(sc1), CONTROL_INFO["dx_left"].least_count(sc1)
        (0.01, 0.01)
        >>> CONTROL_INFO["kappa_left"].least_count(sc1) is None
        True
        """
        if self.least_count_attribute is None:
            return None
        return float(getattr(spec, self.least_count_attribute))

    def resolution(self, spec: InstrumentSpec) -> float:
        """The finest step a trainee sets or reads it to: its least count, else its
        :attr:`step`. [its unit]"""
        least = self.least_count(spec)
        return least if least is not None else float(self.step or 0.0)

    def range(self, spec: InstrumentSpec) -> tuple[float, float] | None:
        """Its stops in ``spec``, in the quantity the stop limits (a screw's nut travel, the
        physical decentration, f_пр, κ, a knob's tangent); None: no stop. [its unit]

        Examples
        --------
        >>> from stereoplotter.io.instrument_file import load_instrument
        >>> CONTROL_INFO["Z"].range(load_instrument("sc1"))
        (110.0, 185.0)
        """
        if self.range_attribute is None:
            return None
        limit = getattr(spec, self.range_attribute)
        if self.kind == "knob":  # |tilt| ≤ tilt_max, turned as its tangent
            t_max = float(np.tan(limit))
            return -t_max, t_max
        lo, hi = limit
        return float(lo), float(hi)

    def owner(self, spec: InstrumentSpec) -> str:
        """Who owns it on ``spec``'s instrument: its correction principle (``spec.principle``)
        for a correction unit's control, else its :attr:`part`."""
        return spec.principle if self.part == "correction unit" else self.part

    def own_name(self, principle: str) -> str:
        """Its name with the instrument's own added for a correction unit's control
        (``"plate α (k_alpha_left)"``); unchanged otherwise or for an unknown principle."""
        p = PRINCIPLES.get(principle)
        if p is None or self.family is None:
            return self.name
        own = p.controls.get(self.family)
        return self.name if own is None else f"{own} ({self.name})"


_SCREW_RANGES: dict[str, str] = {
    "X": "model_x_offset_range_mm",
    "Y": "model_y_offset_range_mm",
    "Z": "projection_distance_range_mm",
    "bx": "base_x_range_mm",
    "by": "base_y_range_mm",
    "bz": "base_z_range_mm",
}


def _control_table() -> dict[str, ControlInfo]:
    xy, z = "xy_least_count_mm", "z_least_count_mm"
    out = {
        name: ControlInfo(
            name,
            "screw",
            "mm",
            part="carriage" if name in ("X", "Y", "Z") else "base carriage",
            range_attribute=_SCREW_RANGES[name],
            least_count_attribute=z if name == "Z" else xy,
        )
        for name in SCREWS
    }
    out["f_instrument"] = ControlInfo(
        "f_instrument", "principal_distance", "mm", None, None, "projector",
        "f_instrument_range_mm", xy,
    )  # fmt: skip
    out["H"] = ControlInfo(
        "H", "height_scale", "m", None, None, "height counter", None, "height_scale_least_count_m"
    )
    sides: tuple[Side, ...] = ("left", "right")
    for side in sides:
        name = f"kappa_{side}"
        out[name] = ControlInfo(
            name, "cassette", "rad", side, part="cassette", range_attribute="kappa_range", step=1e-4
        )
        for axis in ("x", "y"):
            family = f"d{axis}"
            name = f"{family}_{side}"
            out[name] = ControlInfo(
                name, "decentration", "mm", side, axis, "correction unit",
                "decentration_range_mm", xy, family,
            )  # fmt: skip
        for axis in ("alpha", "omega"):
            family = f"k_{axis}"
            name = f"{family}_{side}"
            out[name] = ControlInfo(
                name, "knob", "tan", side, axis, "correction unit", "tilt_max", None, family, 1e-5
            )
    return out


#: Every control → its :class:`ControlInfo`: the instrument and the operator dispatch on its
#: ``kind`` and take its ``side`` and ``axis`` from here, never from the name's spelling.
CONTROL_INFO: Final[dict[str, ControlInfo]] = _control_table()


def control_kind(control: str) -> ControlKind | None:
    """The kind of ``control`` (None: not a control of the instrument)."""
    info = CONTROL_INFO.get(control)
    return None if info is None else info.kind


def control_side(control: str) -> Side:
    """The photo a cassette, decentration or knob acts on."""
    side = CONTROL_INFO[control].side
    if side is None:
        raise StereoplotterError(f"{control!r} acts on no single photo")
    return side


def control_axis(control: str) -> str:
    """A decentration's "x" or "y", a knob's "alpha" or "omega"."""
    axis = CONTROL_INFO[control].axis
    if axis is None:
        raise StereoplotterError(f"{control!r} has no axis")
    return axis
