"""The common interface of a handwheel-driven linear axis, and its parameters.

Every linear axis of the plotters (X, Y, Z carriages) and of the coordinatograph (bridge X, pen
carriage Y) is a lead screw: the handwheel turns the screw, the nut moves the carriage through an
axial play (backlash) b and an axial compliance k, and the carriage slides on its rail against
Coulomb friction F = μ·m·g (``docs/design/mechanics.md`` §4). Two back-ends implement
:class:`LinearAxis`:

* :class:`~stereoplotter.instrument.mechanics.play.PlayAxis`: the closed-form play operator,
vectorised over
  trials (the test oracle and the fast path for bulk Monte Carlo);
* :class:`~stereoplotter.instrument.mechanics.pymunk_axis.PymunkAxis`: the time-domain pymunk model.

Units (``mechanics.md`` §3): mm, s, kg. Hence force in mN (kg·mm/s²), stiffness in kg/s²
(1 N/µm = 10⁶ kg/s², :data:`N_PER_UM`), torque in kg·mm²/s² (1 N·m = 10⁶, :data:`N_M`).

Side convention: ``side="below"`` finishes every setting with a monotone stroke of the nut in the
increasing direction, ``"above"`` in the decreasing direction (the *unidirectional* strategy);
``None`` drives the nut straight to the target (the *direct* strategy).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal, Protocol, runtime_checkable

import numpy as np

from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.controls import CONTROL_INFO
from stereoplotter.instrument.mechanics.dead_band import G_MM_S2, half_play_mm, play_offset_mm

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = [
    "G_MM_S2",
    "N_M",
    "N_PER_UM",
    "AxisParams",
    "LinearAxis",
    "Side",
    "TravelRefusal",
    "check_side",
    "check_travel",
    "detour_start",
    "pre_position",
]

#: One N/µm in the mechanics stiffness unit. [kg/s² per N/µm]
N_PER_UM: float = 1.0e6
#: One N·m in the mechanics torque unit. [kg·mm²/s² per N·m]
N_M: float = 1.0e6

#: Which side a setting is finished from: ``"below"``, ``"above"`` or ``None`` (direct).
Side = Literal["below", "above"] | None


class TravelRefusal(StereoplotterError):
    """A nut setting lies beyond an axis' range stops: the stop refuses it, nothing is clipped.

    Attributes
    ----------
    axis : str
        The axis name (``"X"``, ``"coordinatograph Y"``).
    value : float
        The refused setting. [mm]
    low, high : float
        The range stops of the axis. [mm]
    """

    def __init__(self, message: str, *, axis: str, value: float, low: float, high: float):
        super().__init__(message)
        self.axis = axis
        self.value = value
        self.low = low
        self.high = high


@dataclass(frozen=True, slots=True)
class AxisParams:
    """Parameters of one handwheel-driven lead-screw axis.

    Defaults are the reference axis of ``mechanics.md`` §8 (b = 20 µm, μ = 0.1, 2 kg,
    k = 1 N/µm); instrument values are **assumed** (``instruments.md``).

    Parameters
    ----------
    name : str
        Axis name used in messages (``"X"``).
    backlash_mm : float
        Axial play b between nut and carriage. [mm]
    friction : float
        Coulomb friction coefficient μ of the carriage on its rail. [—]
    mass_kg : float
        Carriage mass m (the moving part the friction acts on). [kg]
    stiffness_kg_s2 : float
        Axial stiffness k of screw and nut; ``math.inf`` for a rigid screw.
        1 N/µm = :data:`N_PER_UM` = 10⁶. [kg/s²]
    range_mm : tuple of float
        Range stops (lo, hi) of the nut setting. [mm]
    range_source : str
        Where the range is set (``"instruments/sc1.yaml: model.x_offset_mm (assumed)"``), quoted
        by :class:`TravelRefusal`; empty when the range was given directly.
    vertical : bool
        A vertical column under gravity (Z, ``mechanics.md`` §7): the load keeps the carriage on
        the lower flank, so the play shows as a constant sag.
    follower_mass_kg : float
        Mass of the compliance follower between spring and play (pymunk only). [kg]
    dt_s : float
        Fixed time step (pymunk). [s]
    iterations : int
        Solver iterations per step (pymunk). [—]
    slew_mm_s, creep_mm_s : float
        Handwheel slewing speed and final creep speed. [mm/s]
    creep_distance_mm : float
        Length of the final creep. [mm]
    accel_mm_s2 : float
        Mean acceleration of the handwheel staircase; keep it below μ·g. [mm/s²]
    stair_s : float
        Duration of one level of the acceleration staircase. [s]
    settle_s : float
        Time waited after the nut stops before the carriage is read. [s]
    overtravel_mm : float
        Length of the final monotone stroke of the unidirectional strategy; must exceed the dead
        band 2h. [mm]
    simulate_last_mm : float
        pymunk only: a monotone stroke longer than this starts with :meth:`place` at this
        distance before its end (the state a long move leaves) and only the rest is simulated
        (``mechanics.md`` §4: 0.012 µm from the full simulation). ``math.inf``: simulate all.
        [mm]
    """

    name: str = "axis"
    backlash_mm: float = 0.020
    friction: float = 0.1
    mass_kg: float = 2.0
    stiffness_kg_s2: float = 1.0 * N_PER_UM
    range_mm: tuple[float, float] = (-1000.0, 1000.0)
    range_source: str = ""
    vertical: bool = False
    follower_mass_kg: float = 0.5
    dt_s: float = 1.0e-3
    iterations: int = 10
    slew_mm_s: float = 20.0
    creep_mm_s: float = 0.2
    creep_distance_mm: float = 0.2
    accel_mm_s2: float = 200.0
    stair_s: float = 0.01
    settle_s: float = 0.05
    overtravel_mm: float = 0.5
    simulate_last_mm: float = 2.0

    def __post_init__(self) -> None:
        def need(ok: bool, what: str, value: object) -> None:
            if not ok:
                raise StereoplotterError(f"axis {self.name}: {what}, found {value!r}")

        need(self.backlash_mm >= 0.0 and math.isfinite(self.backlash_mm), "backlash_mm ≥ 0",
             self.backlash_mm)  # fmt: skip
        need(self.friction >= 0.0 and math.isfinite(self.friction), "friction μ ≥ 0", self.friction)
        need(not self.vertical or self.friction < 1.0, "friction μ < 1 on a vertical axis "
             "(the load must keep the carriage on its lower flank)", self.friction)  # fmt: skip
        need(0.0 < self.mass_kg < math.inf, "mass_kg > 0", self.mass_kg)
        need(self.stiffness_kg_s2 > 0.0, "stiffness_kg_s2 > 0 (inf: rigid)", self.stiffness_kg_s2)
        need(0.0 < self.follower_mass_kg < math.inf, "follower_mass_kg > 0", self.follower_mass_kg)
        lo, hi = self.range_mm
        need(lo < hi, "range_mm (lo, hi) with lo < hi", self.range_mm)
        need(self.dt_s > 0.0, "dt_s > 0", self.dt_s)
        need(self.iterations >= 1, "iterations ≥ 1", self.iterations)
        need(0.0 < self.creep_mm_s <= self.slew_mm_s, "0 < creep_mm_s ≤ slew_mm_s",
             (self.creep_mm_s, self.slew_mm_s))  # fmt: skip
        need(self.creep_distance_mm >= 0.0, "creep_distance_mm ≥ 0", self.creep_distance_mm)
        need(self.accel_mm_s2 > 0.0, "accel_mm_s2 > 0", self.accel_mm_s2)
        need(self.stair_s > 0.0 and self.settle_s >= 0.0, "stair_s > 0 and settle_s ≥ 0",
             (self.stair_s, self.settle_s))  # fmt: skip
        need(self.simulate_last_mm > self.creep_distance_mm, "simulate_last_mm > creep_distance_mm",
             self.simulate_last_mm)  # fmt: skip
        need(self.overtravel_mm > 2.0 * self.dead_band_mm, "overtravel_mm > the dead band 2h",
             (self.overtravel_mm, 2.0 * self.dead_band_mm))  # fmt: skip

    @property
    def friction_force(self) -> float:
        """Coulomb friction force F = μ·m·g on the carriage. [mN]"""
        return self.friction * self.mass_kg * G_MM_S2

    @property
    def rigid(self) -> bool:
        """True for a rigid screw (k = ∞)."""
        return math.isinf(self.stiffness_kg_s2)

    @property
    def half_play_mm(self) -> float:
        """Half-width h of the play operator's dead band (:func:`~.dead_band.half_play_mm`). [mm]"""
        return float(
            half_play_mm(
                self.backlash_mm,
                self.friction,
                self.mass_kg,
                self.stiffness_kg_s2,
                vertical=self.vertical,
            )
        )

    @property
    def offset_mm(self) -> float:
        """Centre offset c of the dead band (:func:`~.dead_band.play_offset_mm`). [mm]"""
        return float(
            play_offset_mm(
                self.backlash_mm,
                self.mass_kg,
                self.stiffness_kg_s2,
                self.follower_mass_kg,
                vertical=self.vertical,
            )
        )

    @property
    def dead_band_mm(self) -> float:
        """Full width 2h of the dead band. [mm]"""
        return 2.0 * self.half_play_mm

    @classmethod
    def from_instrument(
        cls, spec: InstrumentSpec, axis: Literal["X", "Y", "Z"], **overrides: object
    ) -> AxisParams:
        """The plotter axis X, Y or Z of an instrument: backlash, travel and ``mechanics.*``.

        Parameters
        ----------
        spec : InstrumentSpec
            The instrument (``load_instrument("sc1")``).
        axis : {"X", "Y", "Z"}
            X and Y take ``errors.backlash_xy_mm``, the model offset ranges and
            ``mechanics.carriage_mass_kg``; Z takes ``errors.backlash_z_mm``, the
            projection-distance range, ``mechanics.z_carriage_mass_kg`` and ``vertical=True``.
            All take ``mechanics.friction_coefficient`` and ``mechanics.screw_stiffness_N_per_um``.
        **overrides
            Any other :class:`AxisParams` field (friction, mass_kg, …; all **assumed**).

        Returns
        -------
        AxisParams

        Examples
        --------
        >>> from stereoplotter.io.instrument_file import load_instrument
        >>> p = AxisParams.from_instrument(load_instrument("sc1"), "X")
        >>> p.backlash_mm, p.range_mm, p.friction, p.mass_kg, p.stiffness_kg_s2
        (0.005, (-250.0, 450.0), 0.1, 2.0, 1000000.0)
        """
        if axis not in ("X", "Y", "Z"):
            raise StereoplotterError(f"axis must be 'X', 'Y' or 'Z', found {axis!r}")
        attribute = CONTROL_INFO[axis].range_attribute  # the stops of the axis's screw
        if attribute is None:
            raise StereoplotterError(f"axis {axis!r} has no stops in the instrument file")
        backlash = "backlash_z_mm" if axis == "Z" else "backlash_xy_mm"
        key = spec.key_of(attribute)
        parameter = spec.parameters[key]
        fields: dict[str, object] = {
            "name": f"{spec.key} {axis}",
            "backlash_mm": getattr(spec, backlash),
            "range_mm": tuple(float(v) for v in getattr(spec, attribute)),
            "range_source": f"{parameter.file}: {key} ({parameter.status})",
            "vertical": axis == "Z",
            "friction": spec.friction_coefficient,
            "mass_kg": spec.z_carriage_mass_kg if axis == "Z" else spec.carriage_mass_kg,
            "stiffness_kg_s2": spec.screw_stiffness_N_per_um * N_PER_UM,
        }
        fields.update(overrides)
        return cls(**fields)  # type: ignore[arg-type]


def check_travel(params: AxisParams, value: ArrayLike, what: str = "setting") -> None:
    """Refuse a nut setting beyond the range stops of an axis, as the stop would.

    Parameters
    ----------
    params : AxisParams
        The axis.
    value : float or array_like
        The nut setting(s). [mm]
    what : str
        What the value is, for the message (``"target"``, ``"pre-position"``).

    Raises
    ------
    TravelRefusal
        Naming the axis, the (first) refused value and the range. Nothing is clipped.

    Examples
    --------
    >>> check_travel(AxisParams(name="X", range_mm=(-150.0, 150.0)), 120.0)
    >>> check_travel(AxisParams(name="X", range_mm=(-150.0, 150.0)), 151.0)
    Traceback (most recent call last):
    ...
    stereoplotter.instrument.mechanics.base.TravelRefusal: axis X: setting 151.000000 mm is beyond the range stops [-150, 150] mm (the stop refuses it; nothing is clipped)
    """  # noqa: E501
    lo, hi = params.range_mm
    v = np.asarray(value, dtype=float)
    if v.size == 0 or (v.min() >= lo and v.max() <= hi):  # NaN fails both: refused below
        return
    bad = ~((v >= lo) & (v <= hi))  # NaN is refused too
    if not bad.any():
        return
    first = float(v[bad].flat[0]) if v.ndim else float(v)
    where = f" of {params.range_source}" if params.range_source else ""
    raise TravelRefusal(
        f"axis {params.name}: {what} {first:.6f} mm is beyond the range stops "
        f"[{lo:g}, {hi:g}] mm{where} (the stop refuses it; nothing is clipped)",
        axis=params.name,
        value=first,
        low=lo,
        high=hi,
    )


def check_side(side: object) -> None:
    """Refuse anything but ``None``, ``"below"`` and ``"above"``."""
    if side not in (None, "below", "above"):
        raise StereoplotterError(f"side must be None, 'below' or 'above', found {side!r}")


def pre_position(nut_mm: ArrayLike, target_mm: ArrayLike, side: Side, overtravel_mm: float):
    """Where the unidirectional strategy first drives the nut, or NaN where no detour is needed.

    Finishing from ``"below"`` means the last stroke is monotone upward and at least
    ``overtravel_mm`` long: a nut above ``target − overtravel`` first goes down to it.
    ``"above"`` mirrors this; ``None`` never detours.

    Parameters
    ----------
    nut_mm, target_mm : float or array_like
        Current nut setting and target, broadcast together. [mm]
    side : {None, "below", "above"}
    overtravel_mm : float
        Length of the final stroke. [mm]

    Returns
    -------
    numpy.ndarray
        The pre-position, NaN where the nut can go straight to the target. [mm]

    Examples
    --------
    >>> pre_position([0.0, 20.0], 10.0, "below", 0.5)
    array([nan, 9.5])
    """
    check_side(side)
    nut, target = np.broadcast_arrays(
        np.asarray(nut_mm, dtype=float), np.asarray(target_mm, dtype=float)
    )
    if side is None:
        return np.full(nut.shape, np.nan)
    start, detour = detour_start(nut, target, side, overtravel_mm)
    return np.where(detour, start, np.nan)


def detour_start(nut, target, side: str, overtravel_mm: float):
    """(start, detour) of :func:`pre_position` for ``side`` "below"/"above": the start of the
    final stroke and where the nut must first go there (arrays of one shape, no checks)."""
    sign = 1.0 if side == "below" else -1.0
    start = target - sign * overtravel_mm
    # sign·(nut − start) > 0 to the bit: nut − start is ±0 only where nut = start
    return start, (nut > start) if side == "below" else (nut < start)


@runtime_checkable
class LinearAxis(Protocol):
    """A handwheel-driven lead-screw axis: nut (command) and carriage.

    Implemented by :class:`~.play.PlayAxis` (closed form, vectorised: positions are arrays of
    shape (T,)) and :class:`~.pymunk_axis.PymunkAxis` (time domain: positions are floats).
    """

    params: AxisParams

    @property
    def nut(self) -> float | np.ndarray:
        """Nut (command) position: the counter value. [mm]"""
        ...

    @property
    def position(self) -> float | np.ndarray:
        """Carriage position. [mm]"""
        ...

    def approach(self, target: ArrayLike, side: Side = None) -> float | np.ndarray:
        """Drive the nut to ``target`` (finishing from ``side``); return the carriage. [mm]"""
        ...

    def place(self, nut_mm: ArrayLike, side: Side = None) -> None:
        """Put the axis at rest as a long monotone move from ``side`` would leave it. [mm]"""
        ...
