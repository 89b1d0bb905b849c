"""The error-free floor of the conventional method.

Instrument errors zero and operator zero: every check passes on every shipped stereopair and
instrument, by both ways of relative orientation. The instrument's self-test (``instrument
test``, ``selftest.sanity_checks``) gives the correction mechanism's approximation level at the
shipped tilts (≤ 3°): exact rectification leaves q < 1e-6 µm, so with exact settings nothing of
the mechanism stands between the model and the book's tolerances; the conventional operator finds
the settings by looking, so the bounds are the book's: ¼ mark of residual y-parallax "over the
whole stereopair" and H/3000 in the control heights. mountain60 (photo tilts 2.9° against knob
stops at 0.98 × 3°) needed the common tilt that frees a knob at its stop and 2 × max_iterations.
"""

from __future__ import annotations

import numpy as np
import pytest

from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.procedure.conventional import CR1, CR2
from stereoplotter.procedure.operator import OperatorModel
from stereoplotter.procedure.selftest import sanity_checks
from stereoplotter.procedure.simulate import prepare_run, run_trials_chunk


@pytest.mark.parametrize("relative", ["elements", "equations"])
@pytest.mark.parametrize("instrument", ["sc1", "spr3", "sd3"])
@pytest.mark.parametrize("name", ["pair60", "pair80", "mountain60"])
def test_conventional_floor_passes_every_check(name, instrument, relative):
    prep = prepare_run(
        load_scenario(name),
        load_instrument(instrument),
        "conventional",
        "zero",
        3,
        operator=OperatorModel().zero(),
        relative=relative,
    )
    r = run_trials_chunk(prep, 0, None, transcript=False)
    failed = [n for n, c in r.checks.items() if c.passed is not None and not bool(c.passed)]
    assert failed == []
    # the default practice is the operator's: at the floor no check fails, so no remedy is
    # applied (CR1, CR2 recorded, none applied, no rounds)
    assert prep.practice == "operator"
    assert set(r.remedies) == {CR1, CR2}
    assert not any(bool(rem.applied) or int(rem.rounds) for rem in r.remedies.values())
    mechanism_um = sanity_checks(tilt_deg=3.0)["exact_rectification_max_q_um"]
    tol_q = prep.sheet.tolerances["residual_y_parallax_mm"]
    assert np.max(np.abs(r.q_grid_mm)) <= tol_q + mechanism_um * 1e-3
    assert np.max(np.abs(r.q_standard_mm)) <= tol_q + mechanism_um * 1e-3
    tol_h = prep.sheet.tolerances["control_height_m"]
    assert float(r.checks["C3: control heights"].residual) <= tol_h
