"""The virtual instrument: an SC-1, SPR-3 or SD-3 an operator can work on.

:class:`Instrument` holds the physical state — carriages, base carriage, cassettes, correction
mechanisms, decentration scales, counters with their zero readings, the coordinatograph — and
exposes only what an operator can do: turn a control to a scale reading (:meth:`set`), turn a
correction knob (:meth:`turn_knob`), read a scale (:meth:`read`), and look through the eyepieces
(:meth:`marks`, :meth:`mark_offsets`). Every formula it needs lives in the pure layer:
the kinematics in :mod:`stereoplotter.instrument.kinematics`, the backlash in
:mod:`stereoplotter.instrument.mechanics`.

Frames (``kinematics.md`` §3.1): X, Y, D are physical model coordinates [mm] with the left pivot's
plumb at X = Y = 0; a counter reads ``zero + (1 + e)·nut`` (its zero reading, место нуля, is
the reading at the plumb, the book's MO; ``e`` its gear/scale ratio error). The carriage follows the
nut through the backlash of its screw. Injected errors come from an
:class:`~stereoplotter.instrument.error_model.ErrorModel`, drawn once per instrument (or per trial,
vectorised: every state is an array of shape (T,) when ``trials`` is given).
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any, Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.errors import ConfigError, StereoplotterError
from stereoplotter.instrument.action_listener import Action, ActionListener
from stereoplotter.instrument.controls import (
    CASSETTES,
    CONTROL_INFO,
    CONTROLS,
    DECENTRATIONS,
    KNOBS,
    SCREWS,
    CassetteName,
    Control,
    ControlInfo,
    ControlKind,
    ControlPart,
    DecentrationName,
    HeightScaleName,
    KnobName,
    ScaleName,
    ScrewName,
    SetControl,
    Side,
    control_axis,
    control_kind,
    control_side,
)
from stereoplotter.instrument.decentration_variants import decentration_variant
from stereoplotter.instrument.error_model import ErrorModel, error_model_from_spec
from stereoplotter.instrument.kinematics import (
    CorrectionUnit,
    InstrumentSetting,
    UnitMap,
    marks_from_counters,
)
from stereoplotter.instrument.knobs import turn_correction_knob
from stereoplotter.instrument.mechanics.base import N_PER_UM, AxisParams
from stereoplotter.instrument.mechanics.coordinatograph import (
    Coordinatograph,
    CoordinatographParams,
)
from stereoplotter.instrument.mechanics.play import PlayAxis
from stereoplotter.instrument.mechanics.pymunk_axis import PymunkAxis
from stereoplotter.instrument.principles import mechanism_for
from stereoplotter.instrument.sc1_complex import AutomaticCoordinatograph, SC1Options
from stereoplotter.spec.instrument_spec import InstrumentSpec
from stereoplotter.spec.range_checks import check_in_range

__all__ = [
    "BACKENDS",
    "CASSETTES",
    "CONTROLS",
    "CONTROL_INFO",
    "DECENTRATIONS",
    "HEIGHT_SCALE",
    "KNOBS",
    "NOMINAL_ZERO",
    "SCREWS",
    "CassetteName",
    "Control",
    "ControlInfo",
    "ControlKind",
    "ControlPart",
    "DecentrationName",
    "HeightScaleName",
    "Instrument",
    "KnobName",
    "Scale",
    "ScaleName",
    "ScrewName",
    "SetControl",
    "Side",
    "control_axis",
    "control_kind",
    "control_side",
]

#: Mechanics back-ends of the lead-screw axes.
BACKENDS = ("closed-form", "pymunk")

#: The metre height scale geared to the Z screw: reading = slip − D·M_в/1000 [m].
HEIGHT_SCALE: Final[HeightScaleName] = "H"
#: Reading of the height scale at D = 0 before the operator slips it (arbitrary constant). [m]
_HEIGHT_SLIP_NOMINAL = 2000.0
#: Nominal zero readings of the scales (arbitrary instrument constants). [mm]
_NOMINAL_ZERO = {
    "X": 200.0,
    "Y": 200.0,
    "Z": 0.0,
    "bx": 0.0,
    "by": 50.0,
    "bz": 50.0,
    "dx_left": 20.0,
    "dy_left": 20.0,
    "dx_right": 20.0,
    "dy_right": 20.0,
}
#: The nominal zero readings an operator finds on the instrument's scales (the place of zero
#: engraved; the injected zero-reading error is what differs from it). [mm]
NOMINAL_ZERO = dict(_NOMINAL_ZERO)


@dataclass(frozen=True, slots=True)
class Scale:
    """A counter or scale: reading = zero + sense·(1 + ratio_error)·position.

    Attributes
    ----------
    name : str
    zero : float or ndarray
        Reading at position 0 (the place of zero, место нуля, including its error). [mm]
    ratio_error : float or ndarray
        Relative gear/scale ratio error e. [—]
    least_count : float
        Resolution of the reading (vernier). [mm]
    sense : int
        Direction switch: +1 readings grow with the position (the book's setting, L3779).
    """

    name: str
    zero: Any
    ratio_error: Any
    least_count: float
    sense: int = 1
    #: sense·(1 + ratio_error), the scale's gain, computed once (per trial when the ratio error is)
    gain: Any = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "gain", self.sense * (1.0 + self.ratio_error))

    def reading(self, position: ArrayLike) -> NDArray[np.float64]:
        """The exact reading of a position. [mm]"""
        return np.asarray(self.zero + self.gain * np.asarray(position, float))

    def position(self, reading: ArrayLike) -> NDArray[np.float64]:
        """The position that shows a reading. [mm]"""
        return (np.asarray(reading, float) - self.zero) / self.gain

    def rounded(self, reading: ArrayLike) -> NDArray[np.float64]:
        """A reading as the operator sees it: to the least count."""
        return np.round(np.asarray(reading, float) / self.least_count) * self.least_count


def _scales(
    spec: InstrumentSpec, injected: dict[str, Any], full: Callable[[Any], NDArray[np.float64]]
) -> dict[str, Scale]:
    """The counters' scales with their injected zero-reading and ratio errors (least counts of
    the spec, each control's own: :meth:`ControlInfo.least_count`)."""
    return {
        name: Scale(
            name,
            full(nominal + injected[f"zero_reading.{name}"]),
            full(injected.get(f"counter_scale.{name}", 0.0)),
            CONTROL_INFO[name].resolution(spec),
        )
        for name, nominal in _NOMINAL_ZERO.items()
    }


class Instrument:
    """A virtual SC-1, SPR-3 or SD-3.

    Parameters
    ----------
    spec : InstrumentSpec
    focal_length_mm : float
        f′ of the photos in the cassettes (decision D3: the units work with it). [mm]
    errors : ErrorModel, optional
        Injected errors; default the instrument's own (:func:`error_model_from_spec`).
        ``errors.zero()`` gives an error-free instrument.
    rng : numpy.random.Generator, optional
        Draws the injected errors; required unless the error model is all zero.
    variant : str
        Decentration variant of the correction mechanisms: "L" (default), "A", "B", "B2", "S".
    backend : {"closed-form", "pymunk"}
        Mechanics of the lead-screw axes X, Y, Z.
    trials : int, optional
        Vectorise over T independent instruments (closed-form back-end only).
    ideal_mechanics : bool
        Rigid, frictionless screws without backlash (the kinematic instrument); otherwise the
        friction, compliance and masses of the YAML ``mechanics.*`` apply.
    injected : mapping, optional
        Already drawn injected errors (``ErrorModel.draw`` output, or one trial of it) instead of
        drawing them from ``rng``: lets a per-trial loop rebuild trial t of a vectorised run.
    options : SC1Options, optional
        Options of the SC complex (SC-1 only, off by default): with ``automatic_coordinatograph``
        the needle is driven by the tracking servo (:mod:`stereoplotter.instrument.sc1_complex`)
        instead of the geared screws. The error-correction unit acts on the image coordinates
        before they reach the instrument (``procedure.simulate``).
    options_checked : bool
        ``options`` are fitted to ``spec`` already (:meth:`SC1Options.fitted_to`, done once per
        run by ``procedure.simulate.prepare_run``): not checked again.

    Attributes
    ----------
    on_action : callable or None
        The listener of the operator's actions (:mod:`~stereoplotter.instrument.action_listener`):
        told an ``Action`` after each successful call of :meth:`set`, :meth:`turn_knob`,
        :meth:`switch_counter`, :meth:`read`, :meth:`gear_height_counter`,
        :meth:`slip_height_scale`, :meth:`connect_coordinatograph` and :meth:`needle` (one per
        call: the height scale's setting of Z is not told again). With a listener,
        :meth:`drive_screw` declines, so that its caller's reads and settings are told too.
        None (default): nobody listens.

    Notes
    -----
    Ranges are stops: a setting outside the instrument's range raises
    :class:`~stereoplotter.spec.range_checks.RangeRefusal` or
    :class:`~stereoplotter.instrument.mechanics.base.TravelRefusal`; nothing is clipped.
    """

    def __init__(
        self,
        spec: InstrumentSpec,
        focal_length_mm: float,
        *,
        errors: ErrorModel | None = None,
        rng: np.random.Generator | None = None,
        variant: str = "L",
        backend: str = "closed-form",
        trials: int | None = None,
        ideal_mechanics: bool = False,
        injected: dict[str, Any] | None = None,
        options: SC1Options | None = None,
        options_checked: bool = False,
    ):
        if backend not in BACKENDS:
            raise StereoplotterError(
                f"backend: expected one of {', '.join(BACKENDS)}, found {backend!r}"
            )
        if backend == "pymunk" and trials is not None:
            raise StereoplotterError(
                "the pymunk back-end runs single instruments; use backend='closed-form' for trials"
            )
        self.spec = spec
        # checked against the instrument file (only the SC-1 of the SC complex has them) unless
        # the caller fitted them to this spec already (a prepared run checks them once)
        if options is None:
            options = SC1Options()
        self.options = options if options_checked else options.fitted_to(spec)
        self._servo: AutomaticCoordinatograph | None = None
        self.variant = decentration_variant(variant)
        self.backend = backend
        self.trials = trials
        self.ideal_mechanics = ideal_mechanics
        self.errors = errors if errors is not None else error_model_from_spec(spec)
        if injected is not None:
            rng = np.random.default_rng(0)
        elif rng is None:
            if any(t.scale for t in self.errors.terms if t.distribution != "constant"):
                raise StereoplotterError(
                    "an instrument with random injected errors needs an "
                    "explicit numpy.random.Generator (rng)"
                )
            rng = np.random.default_rng(0)
        self.injected = dict(injected) if injected is not None else self.errors.draw(rng, trials)
        e = self.injected
        shape = () if trials is None else (trials,)

        def full(v: Any) -> NDArray[np.float64]:
            return np.broadcast_to(np.asarray(v, float), shape).copy()

        self._scales = _scales(spec, e, full)
        self._axes = {name: self._make_axis(name) for name in SCREWS}
        self.focal_length_mm = float(focal_length_mm)
        self._f_instrument = full(math.nan)
        self._kappa = {"left": full(0.0), "right": full(0.0)}
        self._height_gear: float | None = None
        self._height_slip = full(_HEIGHT_SLIP_NOMINAL)
        self._units = {
            side: CorrectionUnit(
                self.focal_length_mm,
                full(0.0),
                full(0.0),
                full(0.0),
                full(0.0),
                full(0.0),
                strict_per_axis=self.variant.strict_per_axis,
                mechanism=mechanism_for(spec),
            )
            for side in ("left", "right")
        }
        #: Per side, the UnitMap of the present unit (rebuilt when the unit is replaced).
        self._unit_maps: dict[str, UnitMap] = {}
        #: The last :attr:`setting` and the arrays it was built from (f_пр, the base carriages).
        self._setting_cache: tuple[tuple[Any, ...], InstrumentSetting] | None = None
        self._travel: dict[str, tuple[float, float]] = {}
        self.on_action: ActionListener | None = None

    # --- construction --------------------------------------------------------------------

    @classmethod
    def error_free(cls, spec: InstrumentSpec, focal_length_mm: float, **kwargs: Any) -> Instrument:
        """The kinematic instrument: no injected errors, ideal screws."""
        return cls(
            spec,
            focal_length_mm,
            errors=error_model_from_spec(spec).zero(),
            ideal_mechanics=True,
            **kwargs,
        )

    def _axis_params(self, name: str) -> AxisParams:
        spec = self.spec
        info = CONTROL_INFO[name]
        travel = info.range(spec)
        assert info.range_attribute is not None and travel is not None  # every screw has stops
        key = spec.key_of(info.range_attribute)
        parameter = spec.parameters[key]
        ideal = self.ideal_mechanics
        backlash = 0.0 if ideal else float(np.mean(self.injected[f"backlash.{name}"]))
        try:
            return AxisParams(
                name=f"{spec.key} {name}",
                backlash_mm=backlash,
                friction=0.0 if ideal else spec.friction_coefficient,
                mass_kg=spec.z_carriage_mass_kg if name == "Z" else spec.carriage_mass_kg,
                stiffness_kg_s2=math.inf if ideal else spec.screw_stiffness_N_per_um * N_PER_UM,
                range_mm=travel,
                range_source=f"{parameter.file}: {key} ({parameter.status})",
                vertical=name == "Z",
            )
        except StereoplotterError as exc:
            # the instrument file passed the same check when loaded
            # (io.instrument_file._check_mechanics): the backlash comes from the error model,
            # i.e. from an --errors file
            backlash_key = spec.key_of("backlash_z_mm" if name in ("Z", "bz") else "backlash_xy_mm")
            raise ConfigError(
                spec.parameters[backlash_key].file,
                f"{backlash_key}.value",
                "a backlash that leaves the axis a dead band below its 0.5 mm overtravel",
                f"{backlash:g} mm: {exc}",
                "the backlash in use may come from the overrides of an --errors file",
            ) from None

    def _make_axis(self, name: str) -> Any:
        """A lead-screw axis at rest at its start: 0 (the plumb, no base) when 0 is inside its
        range, else the middle of the range (Z: half-way down)."""
        params = self._axis_params(name)
        lo, hi = params.range_mm
        start = 0.0 if lo <= 0.0 <= hi else 0.5 * (lo + hi)
        if self.backend == "pymunk" and name in ("X", "Y", "Z"):
            return PymunkAxis(params, start_mm=start)
        axis = PlayAxis(params, trials=self.trials if self.trials is not None else 1)
        axis.place(start)
        return axis

    # --- what an operator can do ---------------------------------------------------------------

    def read(self, control: ScaleName, exact: bool = False) -> NDArray[np.float64] | float:
        """The reading of a counter or scale (X, Y, Z (= D), bx, by, bz, dx/dy_left/right).

        Parameters
        ----------
        control : str
        exact : bool
            Return the exact reading instead of the one rounded to the least count.
        """
        out = self._read(control, exact)
        if self.on_action is not None:
            self.on_action(Action("read", str(control)))
        return out

    def _read(self, control: ScaleName, exact: bool) -> NDArray[np.float64] | float:
        """:meth:`read` without telling the listener."""
        if control == HEIGHT_SCALE:
            reading = self._height_reading()
            out = reading if exact else self._round_height(reading)
            return self._out(out)
        if control not in self._scales:
            raise StereoplotterError(f"no scale {control!r}; scales: {', '.join(self._scales)}")
        scale = self._scales[control]
        if control in self._axes:
            reading = scale.reading(_nut(self._axes[control]))
        else:
            unit = self._units[control_side(control)]
            x = control_axis(control) == "x"
            value = unit.decentration_x_mm if x else unit.decentration_y_mm
            reading = scale.reading(value)
        out = reading if exact else scale.rounded(reading)
        return self._out(out)

    def set(
        self,
        control: ScrewName | SetControl | HeightScaleName,
        reading: ArrayLike,
        side: str | None = None,
    ) -> None:
        """Turn a control until its scale shows ``reading``.

        Lead screws (X, Y, Z, bx, by, bz) move their nut there; the carriage follows through the
        backlash, finishing from ``side`` ("below", "above" or None). f_пр and κ are set on their
        scales with their setting errors [mm, rad]; a decentration is set on its scale (the
        scale's zero-reading error stays in the physical decentration).

        Raises
        ------
        RangeRefusal, TravelRefusal
            A setting beyond the instrument's range: refused like the real stop.
        """
        self._set(control, reading, side)
        if self.on_action is not None:
            self.on_action(Action("set", str(control), reading, side))

    def _set(
        self,
        control: ScrewName | SetControl | HeightScaleName,
        reading: ArrayLike,
        side: str | None,
    ) -> None:
        """:meth:`set` without telling the listener (the height scale sets Z through it)."""
        if control == HEIGHT_SCALE:
            gear = self._gear()
            depth_reading = (self._height_slip - np.asarray(reading, float)) * 1000.0 / gear
            self._set("Z", depth_reading, side)
            return
        if control in self._axes:
            nut = self._scales[control].position(reading)
            axis = self._axes[control]
            if isinstance(axis, PlayAxis):  # the same move, its carriages not copied out
                axis.move(self._arg(nut), side, owned=nut.shape == axis.h.shape)
            else:
                axis.approach(self._arg(nut), side)
            return
        value = np.asarray(reading, float)
        info = CONTROL_INFO.get(control)
        kind = None if info is None else info.kind
        stops = None if info is None else info.range_attribute
        if kind == "principal_distance" and stops is not None:
            check_in_range(self.spec, stops, float(np.max(value)), "f_пр")
            check_in_range(self.spec, stops, float(np.min(value)), "f_пр")
            self._f_instrument = value + self.injected["setting.f_instrument"]
        elif kind == "cassette" and stops is not None:
            side_name = control_side(control)
            for v in (np.min(value), np.max(value)):
                check_in_range(self.spec, stops, float(v), f"κ_{side_name}")
            self._kappa[side_name] = value + self.injected[f"setting.{control}"]
            self._units[side_name] = _replace(self._units[side_name], kappa=self._kappa[side_name])
        elif kind == "decentration" and stops is not None:
            axis, side_name = control_axis(control), control_side(control)
            d = self._scales[control].position(value) + self.injected[f"setting.{control}"]
            for v in (np.min(d), np.max(d)):
                check_in_range(
                    self.spec, stops, float(v), f"decentration {info.family},{side_name}"
                )
            unit = self._units[side_name]
            cx, cy = unit.plane_decentration_mm
            if axis == "x":
                unit = _replace(
                    unit, decentration_x_mm=d, plane_decentration_x_mm=d, plane_decentration_y_mm=cy
                )
            else:
                unit = _replace(
                    unit, decentration_y_mm=d, plane_decentration_y_mm=d, plane_decentration_x_mm=cx
                )
            self._units[side_name] = unit
        else:
            raise StereoplotterError(f"no control {control!r}; controls: {', '.join(CONTROLS)}")

    def turn_knob(self, knob: KnobName, tan_tilt: ArrayLike) -> None:
        """Turn a correction mechanism (k_α or k_ω of the left or right photo) to represent the
        tilt tangent ``tan_tilt`` (T = tan θ / k, ``kinematics.md`` §3.2).

        The knob has no usable zero place (it is fitted on the fiducials, stage 2), so it is set
        by what it represents; its setting error is added. Under variant L the decentration
        follows (D1); "A" drags only the photo decentration; "B", "B2" none.

        Raises
        ------
        RangeRefusal
            |tilt| beyond the correction range.
        """
        info = CONTROL_INFO.get(knob)
        if info is None or info.kind != "knob" or info.range_attribute is None:
            raise StereoplotterError(f"no correction knob {knob!r}; knobs: {', '.join(KNOBS)}")
        axis, side = control_axis(knob), control_side(knob)
        t = np.asarray(tan_tilt, float) + np.tan(self.injected[f"setting.correction_{axis}_{side}"])
        for v in (np.min(t), np.max(t)):
            check_in_range(
                self.spec, info.range_attribute, math.atan(float(v)), f"{info.family},{side}"
            )
        self._units[side] = turn_correction_knob(
            self._units[side], axis, t, linkage=self.variant.linkage
        )
        if self.on_action is not None:
            self.on_action(Action("knob", str(knob), tan_tilt))

    def switch_counter(self, control: ScrewName | DecentrationName, sense: int) -> None:
        """Switch a counter's direction (+1: readings grow with the position, the book's
        setting, L3779; −1: they fall). The reading at the present position stays; the zero
        reading (место нуля) follows from it."""
        if control not in self._scales:
            raise StereoplotterError(f"no counter {control!r}; counters: {', '.join(self._scales)}")
        if sense not in (1, -1):
            raise StereoplotterError(f"counter direction: expected +1 or -1, found {sense!r}")
        scale = self._scales[control]
        if control in self._axes:
            position = np.asarray(self._axes[control].nut, float).reshape(np.shape(scale.zero))
        else:
            unit = self._units[control_side(control)]
            x = control_axis(control) == "x"
            position = unit.decentration_x_mm if x else unit.decentration_y_mm
        now = scale.reading(position)
        zero = now - sense * (1.0 + scale.ratio_error) * np.asarray(position, float)
        self._scales[control] = replace(scale, zero=zero, sense=sense)
        if self.on_action is not None:
            self.on_action(Action("direction", str(control), sense))

    def counter_sense(self, control: ScrewName | DecentrationName) -> int:
        """The direction of a counter (+1 or −1)."""
        return self._scales[control].sense

    def drive_screw(
        self,
        control: ScrewName,
        target: NDArray[np.float64],
        active: NDArray[np.bool_],
        passes: int,
        limit: Callable[[NDArray[np.float64]], NDArray[np.float64]],
        side: str | None = None,
    ) -> bool:
        """Look-and-correct passes of a lead screw over T trials: each pass reads the counter
        exactly, adds the carriage's error from ``target`` on the ``active`` trials, passes the
        reading through ``limit`` (the caller's stop rule) and sets it from ``side`` — the
        arithmetic of :meth:`read` (exact) and :meth:`set`, on the axis's own (T,) arrays
        without the copies and checks of each call. False (nothing done) for a pymunk axis or a
        single instrument or an instrument with a listener (:attr:`on_action`), which the caller
        drives by :meth:`read` and :meth:`set`. [mm]"""
        axis = self._axes[control]
        if not self.trials or not isinstance(axis, PlayAxis) or self.on_action is not None:
            return False
        scale = self._scales[control]
        zero, gain = scale.zero, scale.gain
        every = bool(np.all(active))  # then the error is the difference itself (no np.where)
        for _ in range(passes):
            err = target - axis.position_view
            if not every:
                err = np.where(active, err, 0.0)
            reading = np.asarray(zero + gain * axis.nut_view) + err  # the exact reading + error
            cmd = limit(reading)
            nut = (cmd - zero) / gain  # Scale.position
            axis.move(nut, side, owned=nut.shape == axis.h.shape)
        return True

    def travel_mm(self, control: ScrewName) -> tuple[float, float]:
        """The range stops of a lead-screw axis (nut positions). [mm]

        Examples
        --------
        >>> from stereoplotter.io.instrument_file import load_instrument
        >>> Instrument.error_free(load_instrument("sc1"), 70.0).travel_mm("Z")
        (110.0, 185.0)
        """
        travel = self._travel.get(control)
        if travel is None:
            travel = tuple(float(v) for v in self._axis_params(control).range_mm)
            self._travel[control] = travel
        return travel

    def reading_of(
        self, control: ScrewName | DecentrationName, nut_mm: ArrayLike
    ) -> NDArray[np.float64]:
        """The exact reading a counter shows with its nut at ``nut_mm`` (counter arithmetic)."""
        return np.asarray(self._scales[control].reading(nut_mm))

    # --- the metre height scale (stage 1 MO_Z, stage 3 (6.15)) ----------------------------------

    def gear_height_counter(self, vertical_scale_denominator: int) -> None:
        """Put the height-counter gear for M_в: the metre scale then moves D·M_в/1000.

        Raises
        ------
        RangeRefusal
            An M_в that is not one of the instrument's gears.

        Examples
        --------
        >>> from stereoplotter.io.instrument_file import load_instrument
        >>> inst = Instrument.error_free(load_instrument("sc1"), 70.0)
        >>> inst.gear_height_counter(8000)
        >>> inst.set("Z", 175.0)
        >>> round(inst.read("H", exact=True), 6)  # 2000 m − 175 mm · 8000 / 1000
        600.0
        >>> inst.slip_height_scale(143.4)
        >>> inst.set("H", 135.4)  # 8 m lower: 1 mm deeper
        >>> round(inst.read("Z", exact=True), 6)
        176.0
        """
        check_in_range(
            self.spec, "vertical_scale_denominators", float(vertical_scale_denominator), "M_в"
        )
        self._height_gear = float(vertical_scale_denominator)
        if self.on_action is not None:
            self.on_action(Action("gear", value=vertical_scale_denominator))

    def slip_height_scale(self, reading_m: ArrayLike) -> None:
        """Slip the metre height scale (friction coupling) so that it shows ``reading_m`` now."""
        self._height_slip = self._height_slip + (
            np.asarray(reading_m, float) - self._height_reading()
        )
        if self.on_action is not None:
            self.on_action(Action("slip", value=reading_m))

    @property
    def height_gear(self) -> float | None:
        """M_в the height counter is geared for (:meth:`gear_height_counter`); None: not geared."""
        return self._height_gear

    def _gear(self) -> float:
        if self._height_gear is None:
            raise StereoplotterError(
                "the height counter is not geared (gear_height_counter(M_в) first)"
            )
        return self._height_gear

    def _height_reading(self) -> NDArray[np.float64]:
        depth = np.asarray(self._scales["Z"].reading(_nut(self._axes["Z"])), float)
        return self._height_slip - depth * self._gear() / 1000.0

    def _round_height(self, reading: NDArray) -> NDArray[np.float64]:
        lc = CONTROL_INFO[HEIGHT_SCALE].resolution(self.spec)
        return np.round(np.asarray(reading, float) / lc) * lc

    # --- looking through the eyepieces ---------------------------------------------------------

    @property
    def setting(self) -> InstrumentSetting:
        """The physical setting: f_пр, base and the plumb of S_л at X = Y = 0."""
        axes = [self._axes[n] for n in ("bx", "by", "bz")]
        key = (
            self._f_instrument,
            *(a.position_view if isinstance(a, PlayAxis) else None for a in axes),
        )
        cached = self._setting_cache
        if cached is not None and all(map(operator.is_, key, cached[0])) and key[-1] is not None:
            return cached[1]  # f_пр and the base carriages as they were (arrays are replaced)
        if np.any(np.isnan(self._f_instrument)):
            raise StereoplotterError("f_пр has not been set (set('f_instrument', …) first)")
        setting = InstrumentSetting(
            self._f_instrument, self._pos("bx"), self._pos("by"), self._pos("bz"), 0.0, 0.0
        )
        self._setting_cache = (key, setting)
        return setting

    def _pos(self, name: str) -> NDArray[np.float64]:
        return self._out(self._axes[name].position)

    def position(self, name: ScrewName) -> NDArray[np.float64] | float:
        """Physical position of a lead-screw axis (X, Y, Z, bx, by, bz): ``state()`` for one
        axis (not an operator's view). [mm]"""
        return self._pos(name)

    def unit(self, side: Side) -> CorrectionUnit:
        """The present correction unit of ``side`` ("left"/"right"): ``state()["units"][side]``."""
        return self._units[side]

    def unit_map(self, side: Side) -> UnitMap:
        """The :class:`~stereoplotter.instrument.kinematics.UnitMap` of the present unit of
        ``side``, kept until the unit changes (cos κ, sin κ kept while κ stays)."""
        unit = self._units[side]
        cached = self._unit_maps.get(side)
        if cached is not None and cached.unit is unit:
            return cached
        trig = cached.trig if cached is not None and cached.unit.kappa is unit.kappa else None
        cached = UnitMap(unit, trig)
        self._unit_maps[side] = cached
        return cached

    def marks(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Photo points under the left and right measuring marks for the present carriages. [mm]

        ``kinematics.md`` §3.3 through
        :func:`~stereoplotter.instrument.kinematics.marks_from_counters`.
        """
        return marks_from_counters(
            self._pos("X"),
            self._pos("Y"),
            self._pos("Z"),
            self.setting,
            self._units["left"],
            self._units["right"],
        )

    def mark_offsets(
        self, left_point_mm: ArrayLike | None = None, right_point_mm: ArrayLike | None = None
    ) -> dict[str, NDArray[np.float64]]:
        """Where each mark sits relative to a photo point, as seen in the eyepieces. [photo mm]

        Returns ``{"left": mark − point, "right": mark − point}`` for the points given.
        """
        pl, pr = self.marks()
        out = {}
        if left_point_mm is not None:
            out["left"] = pl - np.asarray(left_point_mm, float)
        if right_point_mm is not None:
            out["right"] = pr - np.asarray(right_point_mm, float)
        return out

    # --- the coordinatograph ------------------------------------------------------------------

    def connect_coordinatograph(
        self,
        ratio: float,
        origin_table_mm: tuple[float, float] | None = None,
        enlargement: float | None = None,
    ) -> None:
        """Couple the coordinatograph to the X, Y carriages through the gear ``ratio``.

        Parameters
        ----------
        ratio : float
            r = M_г / M_map, one of the instrument's coordinatograph gears: the needle moves
            r·ΔX, r·ΔY on the table. [—]
        origin_table_mm : (float, float), optional
            Table position of the needle when the carriages are on the plumb of S_л
            (X = Y = 0). Default: the table centre. [mm]
        enlargement : float, optional
            Photo → map enlargement M_photo/M_map of this setting; with the automatic
            coordinatograph it is checked against the documented 10 ×. [—]

        Raises
        ------
        RangeRefusal
            A ratio that is not one of the gears; with the automatic coordinatograph an
            enlargement beyond its documented limit.
        """
        check_in_range(self.spec, "coordinatograph_ratios", float(ratio), "coordinatograph ratio")
        if self.options.automatic_coordinatograph:
            self._servo = AutomaticCoordinatograph.from_spec(self.spec)
            if enlargement is not None:
                self._servo.check_enlargement(float(enlargement))
        params = CoordinatographParams.from_instrument(self.spec)
        if self.ideal_mechanics:
            ideal = {"backlash_mm": 0.0, "friction": 0.0, "stiffness_kg_s2": math.inf}
            params = CoordinatographParams(replace(params.x, **ideal), replace(params.y, **ideal))
        origin_given = origin_table_mm
        if origin_table_mm is None:
            origin_table_mm = (0.5 * sum(params.x.range_mm), 0.5 * sum(params.y.range_mm))
        self._cg_ratio = float(ratio)
        self._cg_origin = np.asarray(origin_table_mm, float)
        if self.trials is None:
            self._cg = Coordinatograph(
                params, start_mm=tuple(self._cg_origin), fast=self.backend == "closed-form"
            )
            self._cg_axes = (self._cg.x, self._cg.y)
        else:
            self._cg_axes = (
                PlayAxis(params.x, trials=self.trials),
                PlayAxis(params.y, trials=self.trials),
            )
            for axis, start in zip(self._cg_axes, self._cg_origin, strict=True):
                axis.place(start)
        if self.on_action is not None:
            self.on_action(Action("connect", value=ratio, origin_mm=origin_given))

    def table_position_mm(self, model_xy_mm: ArrayLike) -> NDArray[np.float64]:
        """Ideal table position of a model position (X, Y): origin + r·(X, Y), the gears
        without the mechanics' errors (where a sheet point belongs on the table). [mm]

        Raises
        ------
        StereoplotterError
            The coordinatograph is not connected.
        """
        if not hasattr(self, "_cg_axes"):
            raise StereoplotterError(
                "the coordinatograph is not connected (connect_coordinatograph(ratio) first)"
            )
        return self._cg_origin + self._cg_ratio * np.asarray(model_xy_mm, float)

    @property
    def coordinatograph_connected(self) -> bool:
        """The coordinatograph is coupled to the carriages (:meth:`connect_coordinatograph`)."""
        return hasattr(self, "_cg_axes")

    @property
    def servo_sigma_mm(self) -> float:
        """σ_s of the automatic coordinatograph's settled pen (0 without it; ASSUMED). [mm]"""
        return 0.0 if self._servo is None else self._servo.sigma_mm

    def needle(
        self, side: str | None = None, servo_noise_mm: ArrayLike | None = None
    ) -> NDArray[np.float64]:
        """Table position of the needle for the present carriages. [mm]

        The bridge and pen-carriage screws follow r·(X, Y) (gears), finishing from ``side``; the
        rails' non-orthogonality ε turns the pen carriage's axis (x += y·sin ε) and the needle has
        its play in the holder (``errors.*``). With the automatic coordinatograph the servo
        holds the pen on r·(X, Y) at rest (the lag term v·τ vanishes when the carriages stop):
        the screws' backlash and the pen play are replaced by the servo noise ``servo_noise_mm``
        (a draw of N(0, σ_s²) per axis by the caller's generator, shape (..., 2); None: 0); ε stays.
        """
        if not hasattr(self, "_cg_axes"):
            raise StereoplotterError(
                "the coordinatograph is not connected (connect_coordinatograph(ratio) first)"
            )
        target_x = self._cg_origin[0] + self._cg_ratio * np.asarray(self._pos("X"))
        target_y = self._cg_origin[1] + self._cg_ratio * np.asarray(self._pos("Y"))
        eps = self.injected["coordinatograph.nonorthogonality"]
        if self._servo is not None:
            noise = np.zeros(2) if servo_noise_mm is None else np.asarray(servo_noise_mm, float)
            x = target_x + noise[..., 0]
            y = target_y + noise[..., 1]
            play = 0.0
        else:
            x_axis, y_axis = self._cg_axes
            x = np.asarray(x_axis.approach(self._arg(target_x), side), float)
            y = np.asarray(y_axis.approach(self._arg(target_y), side), float)
            play = self.injected["coordinatograph.pen_play"]
        x = x + (y - self._cg_origin[1]) * np.sin(eps) + play
        out = (
            self._out(np.stack([x, y], axis=-1))
            if self.trials
            else np.array([float(np.squeeze(x)), float(np.squeeze(y))])
        )
        if self.on_action is not None:
            self.on_action(Action("needle", side=side))
        return out

    # --- state for tests and reports (not an operator's view) ---------------------------------

    def state(self) -> dict[str, Any]:
        """The physical state (what the operator cannot see): for tests, transcripts, reports."""
        return {
            "carriages_mm": {n: self._pos(n) for n in ("X", "Y", "Z")},
            "base_mm": {n: self._pos(n) for n in ("bx", "by", "bz")},
            "f_instrument_mm": self._out(self._f_instrument),
            "units": {side: u for side, u in self._units.items()},
            "zero_readings": {n: self._out(s.zero) for n, s in self._scales.items()},
        }

    def _arg(self, value: NDArray) -> Any:
        if self.backend == "pymunk":
            return float(value)
        return np.broadcast_to(np.asarray(value, float), (self.trials or 1,))

    def _out(self, value: Any) -> Any:
        v = np.asarray(value, float)
        if self.trials is None and v.size == 1:
            return float(v.reshape(-1)[0])
        return v


def _nut(axis: Any) -> Any:
    """The nut positions of an axis to compute with (not to keep): a PlayAxis's own array,
    which it replaces and never writes into, instead of the copy of ``axis.nut``."""
    return axis.nut_view if isinstance(axis, PlayAxis) else axis.nut


def _replace(unit: CorrectionUnit, **changes: Any) -> CorrectionUnit:
    return replace(unit, **changes)
