"""The coordinatograph: bridge (X) and pen carriage (Y) as two independent chains (§5).

The bridge cannot yaw, so X (the bridge, pen carriage included) and Y (the pen carriage on the
bridge) are two independent 1-DOF lead-screw chains in one pymunk space, driven at the same time
by merged handwheel programs. The pen is at (X carriage, Y carriage). Putting the Y rail on the
moving bridge and re-synchronising its nut in Python every step costs ten times more and gives the
same result within 0.3 µm (``mechanics.md`` §5), so it is not done.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.mechanics.base import (
    N_PER_UM,
    AxisParams,
    Side,
    check_travel,
    pre_position,
)
from stereoplotter.instrument.mechanics.play import PlayAxis
from stereoplotter.instrument.mechanics.pymunk_axis import PymunkAxis, new_space, run_programs

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = ["BRIDGE", "PEN_CARRIAGE", "Coordinatograph", "CoordinatographParams"]

#: The bridge of ``mechanics.md`` §5: 9.5 kg with the pen carriage, b = 30 µm, k = 2 N/µm
#: (**assumed** values). Dead band ±19.66 µm.
BRIDGE = AxisParams(
    name="coordinatograph X", backlash_mm=0.030, mass_kg=9.5, stiffness_kg_s2=2.0 * N_PER_UM,
    range_mm=(0.0, 800.0),
)  # fmt: skip
#: The pen carriage of §5: 1.5 kg, b = 20 µm, k = 1 N/µm (**assumed**). Dead band ±11.47 µm.
PEN_CARRIAGE = AxisParams(
    name="coordinatograph Y", backlash_mm=0.020, mass_kg=1.5, stiffness_kg_s2=1.0 * N_PER_UM,
    range_mm=(0.0, 800.0),
)  # fmt: skip


@dataclass(frozen=True, slots=True)
class CoordinatographParams:
    """The two chains of a coordinatograph.

    Parameters
    ----------
    x, y : AxisParams
        Bridge and pen carriage. They must share ``dt_s`` and ``iterations``.
    """

    x: AxisParams = BRIDGE
    y: AxisParams = PEN_CARRIAGE

    def __post_init__(self) -> None:
        if (self.x.dt_s, self.x.iterations) != (self.y.dt_s, self.y.iterations):
            raise StereoplotterError(
                "coordinatograph: X and Y share one space, so dt_s and iterations must agree, "
                f"found X {self.x.dt_s, self.x.iterations} and Y {self.y.dt_s, self.y.iterations}"
            )
        if self.x.vertical or self.y.vertical:
            raise StereoplotterError("coordinatograph: the table axes are horizontal")

    @classmethod
    def from_instrument(cls, spec: InstrumentSpec, **overrides: object) -> CoordinatographParams:
        """The chains of an instrument's coordinatograph.

        Travel from ``coordinatograph.table_mm``; masses from ``mechanics.bridge_mass_kg`` and
        ``mechanics.pen_carriage_mass_kg``; μ from ``mechanics.friction_coefficient``. Backlash
        and stiffness have no instrument key and stay as in :data:`BRIDGE` and
        :data:`PEN_CARRIAGE` (``mechanics.md`` §5, assumed).

        Parameters
        ----------
        spec : InstrumentSpec
            The instrument.
        **overrides
            :class:`AxisParams` fields applied to both chains (``dt_s``, ``friction``, …).

        Examples
        --------
        >>> from stereoplotter.io.instrument_file import load_instrument
        >>> CoordinatographParams.from_instrument(load_instrument("sc1")).x.range_mm
        (0.0, 800.0)
        """
        key = spec.key_of("coordinatograph_table_mm")
        parameter = spec.parameters[key]
        source = f"{parameter.file}: {key} ({parameter.status})"
        width, height = spec.coordinatograph_table_mm
        common = {"range_source": source, "friction": spec.friction_coefficient}
        x = replace(BRIDGE, range_mm=(0.0, float(width)), mass_kg=spec.bridge_mass_kg, **common)
        y = replace(
            PEN_CARRIAGE, range_mm=(0.0, float(height)), mass_kg=spec.pen_carriage_mass_kg,
            **common,
        )  # fmt: skip
        if overrides:
            x, y = replace(x, **overrides), replace(y, **overrides)
        return cls(x, y)


class Coordinatograph:
    """A coordinatograph with pymunk drives (or, with ``fast=True``, the play operator).

    Parameters
    ----------
    params : CoordinatographParams, optional
        Default: :data:`BRIDGE` and :data:`PEN_CARRIAGE` on an 800 × 800 mm table.
    start_mm : (float, float), optional
        Initial pen position, at rest. Default: the table centre. [mm]
    fast : bool
        Use :class:`~.play.PlayAxis` for both chains (quasi-static, no time domain).

    Attributes
    ----------
    x, y : PymunkAxis or PlayAxis
        The bridge and the pen carriage.

    Examples
    --------
    >>> c = Coordinatograph()
    >>> c.place((100.0, 200.0), "below")
    >>> err = (c.move_pen((101.0, 201.0)) - (101.0, 201.0)) * 1e3  # µm
    >>> [round(float(e), 1) for e in err]  # dead bands ±19.66, ±11.47 µm, less relaxation
    [-19.3, -11.2]
    """

    def __init__(
        self,
        params: CoordinatographParams | None = None,
        *,
        start_mm: tuple[float, float] | None = None,
        fast: bool = False,
    ):
        self.params = CoordinatographParams() if params is None else params
        if start_mm is None:
            start_mm = (
                0.5 * sum(self.params.x.range_mm),
                0.5 * sum(self.params.y.range_mm),
            )
        self.fast = fast
        if fast:
            self.space = None
            self.x: PymunkAxis | PlayAxis = PlayAxis(self.params.x)
            self.y: PymunkAxis | PlayAxis = PlayAxis(self.params.y)
            self.place(start_mm)
        else:
            self.space = new_space(self.params.x.iterations)
            self.x = PymunkAxis(self.params.x, self.space, offset_mm=0.0, start_mm=start_mm[0])
            self.y = PymunkAxis(self.params.y, self.space, offset_mm=-1.0e4, start_mm=start_mm[1])

    @property
    def pen(self) -> np.ndarray:
        """Pen position (X carriage, Y carriage). [mm]"""
        return np.array([float(np.squeeze(self.x.position)), float(np.squeeze(self.y.position))])

    @property
    def counters(self) -> np.ndarray:
        """Nut settings (X, Y): what the counters read. [mm]"""
        return np.array([float(np.squeeze(self.x.nut)), float(np.squeeze(self.y.nut))])

    def place(self, nut_mm: ArrayLike, side: Side = None) -> None:
        """Put both chains at rest as long monotone moves from ``side`` leave them. [mm]"""
        sx, sy = np.asarray(nut_mm, float)
        self.x.place(float(sx), side)
        self.y.place(float(sy), side)

    def move_pen(self, target_mm: ArrayLike, side: Side = None) -> np.ndarray:
        """Drive both handwheels at once to ``target_mm``; return the settled pen position.

        Parameters
        ----------
        target_mm : (float, float)
            Counter targets (X, Y). [mm]
        side : {None, "below", "above"}
            ``None``: the direct strategy. ``"below"``/``"above"``: the unidirectional one
            (both chains finish from that side), which turns backlash into a constant index
            error (``mechanics.md`` §5).

        Returns
        -------
        numpy.ndarray
            Pen position (X, Y) after ``settle_s`` at rest. [mm]

        Raises
        ------
        TravelRefusal
            A target or pre-position beyond the table's stops (nothing moves).
        """
        tx, ty = (float(v) for v in np.asarray(target_mm, float))
        if isinstance(self.x, PlayAxis) and isinstance(self.y, PlayAxis):
            for axis, t in ((self.x, tx), (self.y, ty)):  # refuse before anything moves
                check_travel(axis.params, t, "target")
                pre = pre_position(axis.nut, t, side, axis.params.overtravel_mm)
                check_travel(axis.params, pre[~np.isnan(pre)], "pre-position")
            self.x.approach(tx, side)
            self.y.approach(ty, side)
            return self.pen
        if not (isinstance(self.x, PymunkAxis) and isinstance(self.y, PymunkAxis)):
            raise TypeError("coordinatograph: both chains must use the same back-end")
        programs = [(self.x, self.x.program(tx, side)), (self.y, self.y.program(ty, side))]
        settle = max(
            round(self.params.x.settle_s / self.params.x.dt_s),
            round(self.params.y.settle_s / self.params.y.dt_s),
        )
        steps = run_programs(self.x.space, self.params.x.dt_s, programs, settle)
        self.x.steps += steps
        self.y.steps += steps
        return self.pen

    @property
    def dead_band_mm(self) -> np.ndarray:
        """Quasi-static half dead bands (h_X, h_Y) of the two chains. [mm]"""
        return np.array([self.params.x.half_play_mm, self.params.y.half_play_mm])
