"""The typed names of the controls the procedure picks by photo and axis.

A step that works on "the knob of axis α of the left photo" looks its control up here, so the
name it passes to the operator is one of the instrument's declared controls
(:data:`~stereoplotter.instrument.virtual.CONTROL_INFO`), never one assembled from parts.
"""

from __future__ import annotations

from typing import Final, Literal

from stereoplotter.instrument.virtual import CassetteName, DecentrationName, KnobName, Side

__all__ = ["CASSETTE", "DECENTRATION", "KNOB", "Tilt"]

#: A correction knob's axis.
Tilt = Literal["alpha", "omega"]

#: The cassette (κ) of a photo.
CASSETTE: Final[dict[Side, CassetteName]] = {"left": "kappa_left", "right": "kappa_right"}
#: The correction knob of a photo and axis.
KNOB: Final[dict[tuple[Tilt, Side], KnobName]] = {
    ("alpha", "left"): "k_alpha_left",
    ("omega", "left"): "k_omega_left",
    ("alpha", "right"): "k_alpha_right",
    ("omega", "right"): "k_omega_right",
}
#: The decentration of a photo along x ("dx") or y ("dy").
DECENTRATION: Final[dict[tuple[str, Side], DecentrationName]] = {
    ("dx", "left"): "dx_left",
    ("dy", "left"): "dy_left",
    ("dx", "right"): "dx_right",
    ("dy", "right"): "dy_right",
}
