"""The injected-error model of the instruments."""

from __future__ import annotations

import numpy as np
import pytest

from stereoplotter.errors import ConfigError
from stereoplotter.instrument.error_model import error_model_from_spec
from stereoplotter.io.instrument_file import load_instrument


@pytest.fixture(scope="module")
def model():
    return error_model_from_spec(load_instrument("sc1"))


def test_every_error_term_is_there(model):
    # zero readings, gear/scale ratio errors, backlash per axis, setting errors of f_пр,
    # b, κ, decentrations and corrections, coordinatograph non-orthogonality, pen play, sheet
    # placement
    groups = {n.split(".")[0] for n in model.names}
    assert groups == {"zero_reading", "counter_scale", "backlash", "setting", "coordinatograph"}
    for name in (
        "setting.f_instrument",
        "setting.bz",
        "setting.kappa_right",
        "setting.dx_left",
        "setting.correction_omega_right",
        "coordinatograph.nonorthogonality",
        "coordinatograph.pen_play",
        "coordinatograph.sheet_placement_y",
        "backlash.Z",
        "counter_scale.X",
    ):
        assert name in model.names
    assert all(t.assumed for t in model.terms)  # no data sheet: every default is assumed


def test_units_are_internal(model):
    assert model.term("setting.kappa_left").scale == pytest.approx(np.radians(1 / 60))
    assert model.term("counter_scale.Y").scale == pytest.approx(30e-6)
    assert model.term("coordinatograph.nonorthogonality").scale == pytest.approx(
        np.radians(20 / 3600)
    )


def test_same_seed_same_draw_and_trials_vectorise(model):
    a = model.draw(np.random.default_rng(3), trials=1000)
    b = model.draw(np.random.default_rng(3), trials=1000)
    assert all(np.array_equal(a[k], b[k]) for k in a)
    s = a["zero_reading.X"]
    # sample σ within 4/sqrt(2(N−1)) relative of the configured 0.2 mm (style.md §10)
    assert abs(s.std() / 0.2 - 1) < 4 / np.sqrt(2 * 999)
    assert np.all(a["backlash.X"] == 0.005)
    assert np.all(np.abs(a["coordinatograph.pen_play"]) <= 0.01)


def test_zero_and_overrides(model):
    zero = model.zero().draw(np.random.default_rng(1), trials=5)
    assert all(np.all(v == 0) for v in zero.values())
    changed = model.with_overrides({"backlash": 0.02, "setting.bx": {"scale": 0.0}}, "e.yaml")
    assert changed.term("backlash.bz").scale == 0.02 and changed.term("setting.bx").scale == 0
    with pytest.raises(
        ConfigError,
        match=r"e\.yaml: backlash\.W: expected an error term or "
        r"group",
    ):
        model.with_overrides({"backlash.W": 0.1}, "e.yaml")
    with pytest.raises(ConfigError, match=r"e\.yaml: backlash: expected a finite number ≥ 0"):
        model.with_overrides({"backlash": -1}, "e.yaml")
