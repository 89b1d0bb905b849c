"""Hand-driven mechanics: lead-screw axes, the coordinatograph and the sheet on its table.

Two back-ends behind one interface, :class:`LinearAxis` (``docs/design/mechanics.md``):

* :class:`PlayAxis`: the closed-form play operator x = clip(x_prev, s − h, s + h),
  h = b/2 + μ·m·g/k, vectorised over trials; the test oracle and the bulk Monte Carlo path;
* :class:`PymunkAxis`: the time-domain lead screw (kinematic nut, spring, SlideJoint backlash,
  friction joint) in pymunk; reproduces the play operator to ≈ 0.5 µm for slow approaches and
  adds the speed-dependent effects.

Built on them: :class:`Coordinatograph` (two independent chains) and :func:`orient_sheet` (the
sheet turned about a pinned corner). Units: mm, s, kg; randomness only through an explicit
``numpy.random.Generator``.
"""

from stereoplotter.instrument.mechanics.base import (
    G_MM_S2,
    N_M,
    N_PER_UM,
    AxisParams,
    LinearAxis,
    Side,
    TravelRefusal,
    check_travel,
)
from stereoplotter.instrument.mechanics.coordinatograph import (
    BRIDGE,
    PEN_CARRIAGE,
    Coordinatograph,
    CoordinatographParams,
)
from stereoplotter.instrument.mechanics.dead_band import half_play_mm, play_offset_mm
from stereoplotter.instrument.mechanics.play import PlayAxis, play
from stereoplotter.instrument.mechanics.pymunk_axis import PymunkAxis, new_space, velocity_plan
from stereoplotter.instrument.mechanics.sheet import (
    OperatorParams,
    SheetOnTable,
    SheetOrientation,
    SheetParams,
    orient_sheet,
    pin_radial_residual,
)

__all__ = [
    "BRIDGE",
    "G_MM_S2",
    "N_M",
    "N_PER_UM",
    "PEN_CARRIAGE",
    "AxisParams",
    "Coordinatograph",
    "CoordinatographParams",
    "LinearAxis",
    "OperatorParams",
    "PlayAxis",
    "PymunkAxis",
    "SheetOnTable",
    "SheetOrientation",
    "SheetParams",
    "Side",
    "TravelRefusal",
    "check_travel",
    "half_play_mm",
    "new_space",
    "orient_sheet",
    "pin_radial_residual",
    "play",
    "play_offset_mm",
    "velocity_plan",
]
