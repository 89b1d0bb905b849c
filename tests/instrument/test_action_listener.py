"""The instrument's action listener is told each operator call once, as it was made, after it
succeeded; with a listener the vectorised screw drive declines so nothing goes untold; a
listener changes nothing the instrument does."""

from __future__ import annotations

import numpy as np
import pytest

from stereoplotter.instrument.action_listener import Action
from stereoplotter.instrument.virtual import Instrument
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.spec.range_checks import RangeRefusal


@pytest.fixture(scope="module")
def spec():
    return load_instrument("sc1")


def _calls(inst: Instrument) -> None:
    inst.set("f_instrument", 140.0)
    inst.set("X", 10.0, "below")
    inst.turn_knob("k_alpha_left", 0.01)
    inst.gear_height_counter(8000)
    inst.slip_height_scale(143.4)
    inst.set("H", 135.4)
    inst.switch_counter("Y", -1)
    inst.read("H")
    inst.connect_coordinatograph(1.0, (300.0, 400.0))
    inst.needle("above")


def test_each_call_is_told_once_as_made(spec):
    inst = Instrument.error_free(spec, 70.0)
    told: list[Action] = []
    inst.on_action = told.append
    _calls(inst)
    assert told == [
        Action("set", "f_instrument", 140.0),
        Action("set", "X", 10.0, "below"),
        Action("knob", "k_alpha_left", 0.01),
        Action("gear", value=8000),
        Action("slip", value=143.4),
        Action("set", "H", 135.4),  # not also the setting of Z it makes
        Action("direction", "Y", -1),
        Action("read", "H"),
        Action("connect", value=1.0, origin_mm=(300.0, 400.0)),
        Action("needle", side="above"),
    ]


def test_a_refused_call_is_not_told(spec):
    inst = Instrument.error_free(spec, 70.0)
    told: list[Action] = []
    inst.on_action = told.append
    with pytest.raises(RangeRefusal):
        inst.gear_height_counter(7)
    assert told == []


def test_a_listener_changes_nothing(spec):
    plain, heard = Instrument.error_free(spec, 70.0), Instrument.error_free(spec, 70.0)
    heard.on_action = lambda action: None
    _calls(plain)
    _calls(heard)
    for name in ("X", "Y", "Z"):
        assert heard.read(name, exact=True) == plain.read(name, exact=True)
    assert np.array_equal(heard.needle(), plain.needle())


def test_the_vectorised_drive_declines_with_a_listener(spec):
    inst = Instrument(spec, 70.0, rng=np.random.default_rng(3), trials=4)
    target = np.full(4, 12.0)
    active = np.ones(4, bool)
    args = (target, active, 1, lambda r: r)
    inst.on_action = lambda action: None
    assert inst.drive_screw("X", *args) is False
    inst.on_action = None
    assert inst.drive_screw("X", *args) is True
