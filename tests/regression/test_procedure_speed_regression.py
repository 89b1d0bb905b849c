"""Work on the simulated operator's speed must not change its results.

The values below are those of a seeded vectorised run (T = 50, seed 3, pair60 on the SC-1,
closed-form back-end), recorded with numpy 2.4.6 and scipy 1.17.1, for the setup-data method and
the conventional method with the operator's practice and with the book's (``practice="book"``).
They are compared within a relative tolerance of 1e-9: bit identity across numpy versions and
processors is not promised (the SIMD paths of the elementary functions may differ in the last
bit), only the same seed twice in one environment (``test_same_seed_gives_byte_identical_files``).

The runs fix what the defaults would otherwise move: the SC-1's gimbal offset h = 0 (the
canonical correction unit), the free-σ operator ``OperatorModel(eye="sigma", remeasure=False)``
(σ_p = σ_q = 10 µm, one look; ``simulate --operator sigma``) and a 0.2 mm zero-reading scatter of
b_x and the decentration scales (:data:`RECORDED_ZERO_SCATTER`; the default is the calibration
error ``known_zero_error_mm``).
"""

from __future__ import annotations

import dataclasses
from types import MappingProxyType

import numpy as np
import pytest

from stereoplotter.instrument.error_model import error_model_from_spec
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.procedure import simulate
from stereoplotter.procedure.operator import OperatorModel

#: The recorded runs' zero-reading scatter of b_x and the decentrations (module docstring). [mm]
RECORDED_ZERO_SCATTER = {
    f"zero_reading.{s}": 0.2 for s in ("bx", "dx_left", "dy_left", "dx_right", "dy_right")
}


@pytest.fixture(scope="module")
def runs():
    sc, spec = load_scenario("scenarios/pair60.yaml"), load_instrument("sc1")
    params = dict(spec.parameters)
    key = "correction.gimbal_offset_mm"  # h = 0: the canonical unit of the recorded runs
    params[key] = dataclasses.replace(params[key], value=0.0)
    spec = dataclasses.replace(spec, parameters=MappingProxyType(params))
    op = OperatorModel(eye="sigma", remeasure=False)  # the recorded runs' operator
    errors = error_model_from_spec(spec).with_overrides(RECORDED_ZERO_SCATTER)
    out = {
        m: simulate(
            sc, spec, method=m, seed=3, trials=50, evaluate=False, operator=op, errors=errors
        )
        for m in ("setup", "conventional")
    }
    out["conventional/book"] = simulate(
        sc,
        spec,
        method="conventional",
        seed=3,
        trials=50,
        evaluate=False,
        practice="book",
        operator=op,
        errors=errors,
    )
    return out


PINNED = {
    "setup": {
        "q_standard[7, 2]": -0.013712294385312837,
        "q_grid[13, 40]": -0.004815305799054293,
        "sum q_grid": 2.4002274760142965,
        "MO_by[11]": 50.17,
        "MO_Z[11]": 519.9,
        "stage 1: |L − L′|[29]": 0.016605343177729992,
        "stage 2: mark 4[29]": 0.0047085915789559715,
        "stage 2: residual y-parallax (6 points)[29]": 0.023438988764950243,
        "stage 3: control heights[29]": 0.1467620104841103,
        "stage 3: residual y-parallax (6 points)[29]": 0.01230639861154506,
        "stage 5: corner 4[29]": 0.0027624631174676508,
        "stage 5: plan control points (needle − plotted)[29]": 0.13462978807541742,
        "kappa_right[5]": -0.02989823975500832,
        "Z[17]": 175.69083617353027,
    },
    "conventional": {
        "q_standard[7, 2]": -0.07514670709550975,
        "q_grid[13, 40]": -0.014317345333774415,
        "sum q_grid": -4.900152922367263,
        "MO_by[11]": 50.230000000000004,
        "MO_X[11]": 200.32,
        "C2: residual y-parallax (6 points)[29]": 0.016300012835496445,
        "C3: levelling points (against the first)[29]": 3.2797900538959652,
        "C3: control heights[29]": 0.5467620104840876,
        "C3: residual y-parallax (6 points)[29]": 0.04614504998113353,
        "stage 5: plan control points (needle − plotted)[29]": 0.26731374231660715,
        "kappa_right[5]": -0.028972131824376465,
        "Z[17]": 175.64456185929782,
    },
    "conventional/book": {
        "q_standard[7, 2]": -0.05894315445359279,
        "q_grid[13, 40]": -0.0060969470544427005,
        "sum q_grid": -5.043255405119347,
        "MO_by[11]": 50.230000000000004,
        "MO_X[11]": 200.32,
        "C2: residual y-parallax (6 points)[29]": 0.016300012835496445,
        "C3: levelling points (against the first)[29]": 3.2797900538959652,
        "C3: control heights[29]": 0.3930706613532493,
        "C3: residual y-parallax (6 points)[29]": 0.03908462919148619,
        "stage 5: plan control points (needle − plotted)[29]": 0.15112608329025004,
        "kappa_right[5]": -0.029990038695095072,
        "Z[17]": 175.70223034173316,
    },
}

#: Relative tolerance of the regression values (module docstring).
RTOL = 1e-9

ITERATION_SUMS = {
    "setup": {"stage 1: |L − L′|": 338, "stage 2: mark 4": 58},
    "conventional": {
        "C2: residual y-parallax (6 points)": 166,
        "C3: levelling points (against the first)": 533,
    },
    "conventional/book": {
        "C2: residual y-parallax (6 points)": 166,
        "C3: levelling points (against the first)": 533,
    },
}


def _value(r, name: str) -> float:
    if name == "q_standard[7, 2]":
        return float(r.q_standard_mm[7, 2])
    if name == "q_grid[13, 40]":
        return float(r.q_grid_mm[13, 40])
    if name == "sum q_grid":
        return float(np.sum(r.q_grid_mm))
    if name == "kappa_right[5]":
        return float(r.instrument.state()["units"]["right"].kappa[5])
    if name == "Z[17]":
        return float(r.instrument.state()["carriages_mm"]["Z"][17])
    base, index = name[:-1].rsplit("[", 1)
    if base in r.zero_readings:
        return float(r.zero_readings[base][int(index)])
    return float(r.checks[base].residual[int(index)])


@pytest.mark.parametrize("method", ["setup", "conventional", "conventional/book"])
def test_seeded_vectorised_run_matches_the_recorded_values(runs, method):
    r = runs[method]
    for name, want in PINNED[method].items():
        assert _value(r, name) == pytest.approx(want, rel=RTOL, abs=1e-12), name
    for name, total in ITERATION_SUMS[method].items():
        assert int(r.checks[name].iterations.sum()) == total, name


@pytest.mark.parametrize("control", ["kappa_left", "kappa_right", "k_alpha_left", "k_omega_right"])
def test_q_turning_equals_the_plain_kinematics(runs, control):
    """The operator's cached 1-D look (one rod computed once, cos κ kept) gives the same bits as
    ``counters_from_homologous_points`` on the units with the control turned."""
    from dataclasses import replace

    from stereoplotter.instrument.kinematics import counters_from_homologous_points
    from stereoplotter.instrument.knobs import turn_correction_knob
    from stereoplotter.procedure import Noise, OperatorModel, Transcript
    from stereoplotter.procedure.operator import Operator

    r = runs["setup"]
    inst = r.instrument
    op = Operator(inst, OperatorModel(), Noise(0, inst.trials), Transcript(enabled=False))
    pts = r.scene.standard_points_m
    imgs = r.scene.images(pts)
    img = (imgs[0][3], imgs[1][3])
    side = control.split("_")[-1]
    value = op.physical(control) + np.linspace(-1e-3, 1e-3, inst.trials)
    units = {"left": inst.unit("left"), "right": inst.unit("right")}
    if control.startswith("kappa_"):
        units[side] = replace(units[side], kappa=value)
    else:
        axis = control.split("_")[1]
        units[side] = turn_correction_knob(units[side], axis, value, inst.variant.linkage)
    want = counters_from_homologous_points(
        img[0], img[1], inst.setting, units["left"], units["right"]
    ).y_parallax_mm
    got = op.q_turning(control, img)(value)
    assert got.tobytes() == np.asarray(want, float).tobytes()
