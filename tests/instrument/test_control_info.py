"""The table of the instrument's controls covers every control once, and each control's kind,
side and axis agree with the Literal group that names it."""

from __future__ import annotations

from typing import get_args

import pytest

from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.virtual import (
    CONTROL_INFO,
    CassetteName,
    Control,
    DecentrationName,
    HeightScaleName,
    KnobName,
    ScrewName,
    control_axis,
    control_kind,
    control_side,
)


def _flat(literal) -> set[str]:
    out: set[str] = set()
    for a in get_args(literal):
        out |= _flat(a) if get_args(a) else {a}
    return out


def test_every_control_has_one_entry():
    assert set(CONTROL_INFO) == _flat(Control)
    assert all(info.name == name for name, info in CONTROL_INFO.items())


@pytest.mark.parametrize(
    ("group", "kind", "unit"),
    [
        (ScrewName, "screw", "mm"),
        (CassetteName, "cassette", "rad"),
        (DecentrationName, "decentration", "mm"),
        (KnobName, "knob", "tan"),
        (HeightScaleName, "height_scale", "m"),
    ],
)
def test_each_group_has_its_kind_and_unit(group, kind, unit):
    for name in _flat(group):
        assert (control_kind(name), CONTROL_INFO[name].unit) == (kind, unit), name


def test_side_and_axis():
    assert (control_side("k_alpha_left"), control_axis("k_alpha_left")) == ("left", "alpha")
    assert (control_side("dy_right"), control_axis("dy_right")) == ("right", "y")
    assert control_side("kappa_right") == "right"
    assert control_kind("not a control") is None
    with pytest.raises(StereoplotterError, match="no single photo"):
        control_side("bx")
