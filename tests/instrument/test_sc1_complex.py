"""Issue 11, deliverable 4: the SC complex options (off by default), Monte Carlo within CI."""

from __future__ import annotations

import numpy as np
import pytest

from stereoplotter.instrument.sc1_complex import (
    AutomaticCoordinatograph,
    ErrorCorrectionUnit,
    SC1Options,
)
from stereoplotter.instrument.spec import RangeRefusal
from stereoplotter.io.instrument_file import load_instrument


def test_options_off_by_default():
    assert SC1Options() == SC1Options(False, False)


def test_correction_unit_rms_3um_and_range_100um():
    unit = ErrorCorrectionUnit.from_spec(load_instrument("sc1"))
    assert (unit.range_um, unit.rms_um) == (100.0, 3.0)  # SCX, documented
    rng = np.random.default_rng(11)
    res = unit.residual_um(np.full((20000, 2), 60.0), rng)
    rms = float(np.sqrt(np.mean(np.sum(res**2, axis=-1))))
    # vector RMS 3 µm; the MC standard error of the RMS is ≈ 3/√(2n) = 0.015 µm: 4 of them
    assert rms == pytest.approx(3.0, abs=4 * 3.0 / np.sqrt(2 * 20000))
    with pytest.raises(RangeRefusal, match=r"±100 µm"):
        unit.residual_um([[101.0, 0.0]], rng)


def test_no_correction_unit_on_sd3():
    with pytest.raises(RangeRefusal):
        ErrorCorrectionUnit.from_spec(load_instrument("sd3"))


def test_automatic_coordinatograph_lag_and_enlargement():
    coord = AutomaticCoordinatograph.from_spec(load_instrument("sc1"))
    coord.check_enlargement(10.0)
    with pytest.raises(RangeRefusal, match=r"10 ×"):
        coord.check_enlargement(10.5)
    # straight track at 2 mm/s: the pen lags by v·τ = 0.1 mm on average (closed form)
    t = np.arange(0, 10, 0.01)
    track = np.column_stack([2.0 * t, np.zeros_like(t)])
    pen = coord.pen_mm(track, 0.01, np.random.default_rng(3))
    lag = float(np.mean(track[:, 0] - pen[:, 0]))
    assert lag == pytest.approx(2.0 * 0.05, abs=4 * 0.02 / np.sqrt(len(t)))
