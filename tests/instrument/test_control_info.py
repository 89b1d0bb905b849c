"""The table of the instrument's controls covers every control once, and each control's kind,
side and axis agree with the Literal group that names it."""

from __future__ import annotations

import math
from typing import get_args

import pytest

from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.virtual import (
    CONTROL_INFO,
    CassetteName,
    Control,
    DecentrationName,
    HeightScaleName,
    Instrument,
    KnobName,
    ScrewName,
    control_axis,
    control_kind,
    control_side,
)
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.procedure.operator import Noise, Operator, OperatorModel
from stereoplotter.procedure.transcript import Transcript
from stereoplotter.spec.range_checks import RangeRefusal
from stereoplotter.trainer.panel import least_count


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


# --- stops, least counts and owners: the values of the instrument file (sc1.yaml) -------------


@pytest.fixture(scope="module")
def sc1():
    return load_instrument("sc1")


def test_stops_and_least_counts_are_the_instrument_files(sc1):
    """sc1.yaml: projection.distance_mm [110, 185], projection.f_instrument_mm [100, 185],
    orientation.kappa_deg [-15, 15], correction.tilt_max_deg 3, correction.decentration_mm
    [-15, 15]; counters: X, Y 0.01 mm, Z 0.01 mm, height scale 0.1 m."""
    deg = math.pi / 180.0
    assert CONTROL_INFO["Z"].range(sc1) == (110.0, 185.0)
    assert CONTROL_INFO["f_instrument"].range(sc1) == (100.0, 185.0)
    assert CONTROL_INFO["kappa_right"].range(sc1) == pytest.approx((-15 * deg, 15 * deg))
    assert CONTROL_INFO["k_omega_left"].range(sc1) == pytest.approx(
        (-math.tan(3 * deg), math.tan(3 * deg))
    )
    assert CONTROL_INFO["dy_left"].range(sc1) == (-15.0, 15.0)
    assert CONTROL_INFO["H"].range(sc1) is None
    assert {n: CONTROL_INFO[n].least_count(sc1) for n in ("X", "Z", "dx_left", "H")} == {
        "X": 0.01, "Z": 0.01, "dx_left": 0.01, "H": 0.1,
    }  # fmt: skip
    # κ and the knobs have no least count in the file: the trainer's wheel steps instead
    assert CONTROL_INFO["kappa_left"].least_count(sc1) is None
    assert CONTROL_INFO["kappa_left"].resolution(sc1) == 1e-4
    assert CONTROL_INFO["k_alpha_right"].resolution(sc1) == 1e-5


@pytest.mark.parametrize(
    ("control", "inside", "outside"),
    [("f_instrument", 184.9, 185.1), ("kappa_left", 0.26, 0.27), ("dx_right", 34.9, 35.1)],
)
def test_the_instrument_refuses_beyond_the_declared_stop(sc1, control, inside, outside):
    """The stop :meth:`ControlInfo.range` declares is the one the instrument refuses at (a
    decentration's scale reads 20 mm at the physical zero: its stop +15 mm reads 35 mm)."""
    inst = Instrument.error_free(sc1, 70.0)
    inst.set(control, inside)
    with pytest.raises(RangeRefusal):
        inst.set(control, outside)


def test_the_knob_refuses_beyond_its_tangent_stop(sc1):
    inst = Instrument.error_free(sc1, 70.0)
    _, high = CONTROL_INFO["k_alpha_left"].range(sc1)
    inst.turn_knob("k_alpha_left", 0.999 * high)
    with pytest.raises(RangeRefusal):
        inst.turn_knob("k_alpha_left", 1.001 * high)


def test_operator_and_trainer_read_the_same_least_counts(sc1):
    """The operator's σ_read, σ_set and rounding and the trainer's ticks use the declared least
    counts (the operator none on κ and the knobs, which the file gives none)."""
    inst = Instrument.error_free(sc1, 70.0)
    op = Operator(inst, OperatorModel(), Noise(0, None), Transcript(enabled=False))
    for name, info in CONTROL_INFO.items():
        assert op.least_count(name) == (info.least_count(sc1) or 0.0), name
        assert least_count(sc1, name) == info.resolution(sc1), name


def test_owner_and_own_name(sc1):
    """The correction unit's controls belong to the instrument's principle and carry its name
    for them (gimbal.py: k_alpha → "photo-carrier tilt α (gimbal)"); the others their part."""
    knob = CONTROL_INFO["k_alpha_left"]
    assert knob.owner(sc1) == sc1.principle
    assert knob.own_name(sc1.principle) == "photo-carrier tilt α (gimbal) (k_alpha_left)"
    assert CONTROL_INFO["dy_right"].own_name(sc1.principle).endswith(" (dy_right)")
    assert CONTROL_INFO["bz"].owner(sc1) == "base carriage"
    assert CONTROL_INFO["kappa_left"].own_name(sc1.principle) == "kappa_left"
    assert knob.own_name("no such principle") == "k_alpha_left"
