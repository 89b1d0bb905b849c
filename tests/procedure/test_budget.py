"""The per-part error budget (``verification.budget``): zero terms, linear terms, additivity.

One small run (64 trials per configuration, seed 5) of pair60 on the SC-1, setup method, with
``zero_reading.dy_right`` switched off (σ = 0), serves every test. Tolerances are Monte Carlo
intervals: 3 standard errors of the paired per-trial differences (≈ 99.7 % for a normal mean).
"""

from __future__ import annotations

import numpy as np
import pytest

from stereoplotter.instrument.error_model import error_model_from_spec
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.paths import resolve_data_file
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.procedure.operator import OperatorModel
from stereoplotter.procedure.simulate import simulate
from stereoplotter.verification.budget import MEASURES, OPERATOR_TERMS, run_budget

Z = 3.0  # standard errors of a Monte Carlo interval


def _pair60_sc1():
    spec = load_instrument("sc1")
    scenario = load_scenario(resolve_data_file("scenarios", "pair60"))
    model = error_model_from_spec(spec).with_overrides({"zero_reading.dy_right": 0.0})
    return scenario, spec, model


@pytest.fixture(scope="module")
def budget():
    scenario, spec, model = _pair60_sc1()
    out = run_budget(scenario, spec, "setup", trials=64, seed=5, errors=model)
    return out, {r["name"]: r for r in out["terms"]}


def test_all_on_and_all_off_are_the_ordinary_simulation(budget):
    # The stacked, designed runs of the budget against plain `simulate` (its own keyed draws, one
    # configuration per run): the same 64 trials give the same mean squares to rounding.
    out, _ = budget
    scenario, spec, model = _pair60_sc1()
    for config, kwargs in (
        ("all_on", {"errors": model}),
        ("all_off", {"errors": "zero", "operator": OperatorModel().zero()}),
    ):
        r = simulate(scenario, spec, "setup", seed=5, trials=64, **kwargs)
        ev = r.evaluation
        per_h = 1000.0 / ev.flying_height_m
        per_map = 1000.0 / ev.map_scale_denominator
        expected = {
            "residual_y_parallax_rms_um": np.mean((np.asarray(r.q_grid_mm) * 1000.0) ** 2),
            "height_error_rms_permille": np.mean((ev.grid.height_error_m * per_h) ** 2),
            "plan_error_rms_map_mm": np.mean(
                (ev.grid.x_error_m * per_map) ** 2 + (ev.grid.y_error_m * per_map) ** 2
            ),
        }
        for m, v in expected.items():
            assert out["totals"][m][config]["ms"] == pytest.approx(v, rel=1e-12)


def test_every_term_is_listed_with_three_contributions(budget):
    out, rows = budget
    spec = load_instrument("sc1")
    expected = [*error_model_from_spec(spec).names, *OPERATOR_TERMS, "operator.rounding"]
    assert list(rows) == expected
    for r in rows.values():
        for kind in ("one_at_a_time", "all_but_one", "linear"):
            assert set(r[kind]) == set(MEASURES)
    assert out["configurations"] == 2 * len(expected) + 2


def test_a_term_at_zero_sigma_contributes_zero(budget):
    # zero_reading.dy_right adds 1.45 ± 0.04 µm to the residual y-parallax and 0.069 ‰ H to the
    # height error at its default σ = 0.2 mm (pair60/sc1 budget, docs/accuracy.md); at σ = 0 the
    # configurations with and without it are the same trials with the same draws.
    _, rows = budget
    r = rows["zero_reading.dy_right"]
    assert r["scale"] == 0.0 and r["linear_model"] == "zero (σ = 0)"
    for kind in ("one_at_a_time", "all_but_one"):
        for m in MEASURES:
            c = r[kind][m]
            assert abs(c["delta_ms"]) <= Z * c["delta_ms_se"]
            assert c["delta_ms"] == 0.0
        assert all(r["linear"][m]["delta_ms"] == 0.0 for m in MEASURES)


@pytest.mark.parametrize(
    ("term", "measure"),
    [
        # a decentration zero-reading error displaces a photo in its plane: the built points move
        # in plan (left photo) and in height through the x-parallax (right photo) in proportion
        ("zero_reading.dx_left", "plan_error_rms_map_mm"),
        ("zero_reading.dx_right", "height_error_rms_permille"),
    ],
)
def test_linear_term_agrees_with_its_linear_prediction(budget, term, measure):
    # the prediction is independent of the Monte Carlo: a deterministic central difference of
    # the error-free procedure at ±0.1 σ, times σ²; the Monte Carlo draws the term at full σ
    _, rows = budget
    c = rows[term]["one_at_a_time"][measure]
    lin = rows[term]["linear"][measure]["delta_ms"]
    assert rows[term]["linear_model"] == "numerical linearisation"
    assert lin > 10 * c["delta_ms_se"] / 64**0.5  # a real effect, not noise
    assert abs(c["delta_ms"] - lin) <= Z * c["delta_ms_se"]


def test_one_at_a_time_contributions_add_up_to_the_total_in_plan(budget):
    # For terms acting linearly and independently (zero-mean, independent draws), the mean square
    # of their sum is the sum of their mean squares: E[gap] = 0, and the gap of the same trials
    # has a paired standard error. Tolerance Z·SE of that gap. Asserted for the plan error only:
    # in this run the height gap is 0.023 ± 0.008 ‰² (2.9 SE) and the y-parallax terms are far
    # from linear (the linear and Monte Carlo contributions of operator.pointing differ in sign).
    out, _ = budget
    add = out["totals"]["plan_error_rms_map_mm"]["additivity"]
    total = out["totals"]["plan_error_rms_map_mm"]["total_delta"]["delta_ms"]
    assert abs(add["gap_ms"]) <= Z * add["gap_ms_se"]
    assert abs(add["sum_one_at_a_time_ms"] - total) <= 0.05 * total


def test_totals_all_off_is_the_error_free_floor(budget):
    # all off: no trial-to-trial scatter (every error is zero, the same procedure each trial)
    out, _ = budget
    for m in MEASURES:
        assert out["totals"][m]["all_off"]["ms_se"] == pytest.approx(0.0, abs=1e-12)


def test_operator_zero_gives_zero_operator_terms():
    spec = load_instrument("sc1")
    scenario = load_scenario(resolve_data_file("scenarios", "pair60"))
    out = run_budget(
        scenario,
        spec,
        trials=2,
        seed=1,
        errors=error_model_from_spec(spec).zero(),
        operator=OperatorModel().zero(),
    )
    for r in out["terms"]:
        for m in MEASURES:
            assert r["one_at_a_time"][m]["delta_ms"] == 0.0
            assert r["all_but_one"][m]["delta_ms"] == 0.0
