"""Simulated operator and the setup-data method (procedure.md)."""

from __future__ import annotations

import dataclasses
from types import MappingProxyType

import numpy as np
import pytest
from conftest import um

from stereoplotter.commands.simulation import write_simulation
from stereoplotter.instrument.virtual import Instrument
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.procedure import (
    Noise,
    OperatorModel,
    Transcript,
    simulate,
    simulate_per_trial,
)
from stereoplotter.procedure.relative_equations import (
    relative_orientation_from_standard_points,
    y_parallax_first_order,
)


@pytest.fixture(scope="module")
def pair():
    return load_scenario("scenarios/pair60.yaml"), load_instrument("sc1")


def _canonical(spec):
    """The SC-1 with its gimbal offset set to 0: its mechanism is then the canonical unit."""
    params = dict(spec.parameters)
    key = "correction.gimbal_offset_mm"
    params[key] = dataclasses.replace(params[key], value=0.0)
    return dataclasses.replace(spec, parameters=MappingProxyType(params))


@pytest.fixture(scope="module")
def ideal(pair):
    sc, spec = pair
    spec = _canonical(spec)  # the approximation level of kinematics.md §6 (without h)
    return simulate(
        sc, spec, errors="zero", operator=OperatorModel().zero(), ideal_mechanics=True, seed=1
    )


def test_zero_errors_converge_in_fewest_iterations(ideal):
    # stage 1: (6.9)/(6.10) in their ratio form with the ΔZ coupling (D9) land in one correction,
    # then one confirming look (2 passes; the printed first-order form took 3);
    # stage 2: one k_ω pass, mark 4 exact; κ (D8): one clearing pass and one confirming look
    assert ideal.iterations["1"] == 2
    assert ideal.iterations["2"] == 1
    assert ideal.iterations["2/kappa"] == 2
    for name, c in ideal.checks.items():
        if c.passed is not None:
            assert bool(c.passed), name


def test_zero_errors_reach_the_approximation_level(ideal):
    # kinematics.md §6: the canonical unit leaves a few µm of y-parallax at tilts < 1°
    assert np.max(np.abs(ideal.q_grid_mm)) < 6 * um
    assert np.max(np.abs(ideal.q_standard_mm)) < 6 * um
    assert ideal.checks["stage 5: corner 4"].residual < 1e-9


def test_default_errors_evaluate_every_tolerance(pair):
    sc, spec = pair
    r = simulate(sc, spec, seed=3, evaluate=False)
    names = set(r.checks)
    for expected in (
        "stage 1: |L − L′|",
        "stage 2: mark 4",
        "stage 2: residual y-parallax (6 points)",
        "stage 3: control heights",
        "stage 5: corner 4",
    ):
        assert expected in names
        assert r.checks[expected].passed is not None
    assert any(rec.tolerance is not None for rec in r.transcript.records)


def test_vectorised_equals_per_trial_oracle(pair):
    sc, spec = pair
    vec = simulate(sc, spec, seed=5, trials=3, evaluate=False)
    one = simulate_per_trial(sc, spec, seed=5, trials=3)
    for name, c in vec.checks.items():
        np.testing.assert_array_equal(c.residual, one["checks"][name].residual)
    for name, its in vec.iterations.items():
        np.testing.assert_array_equal(its, one["iterations"][name])
    np.testing.assert_array_equal(vec.q_grid_mm, one["q_grid_mm"])


def test_same_seed_gives_byte_identical_files(pair, tmp_path):
    sc, spec = pair
    out = []
    for k in range(2):
        r = simulate(sc, spec, seed=11, evaluate=True)
        paths = write_simulation(r, tmp_path / str(k))
        out.append({name: p.read_bytes() for name, p in paths.items()})
    assert out[0] == out[1]
    assert set(out[0]) == {
        "transcript.txt",
        "transcript.jsonl",
        "evaluation.yaml",
        "evaluation.md",
        "parallax.png",
    }


def test_noise_streams_are_keyed():
    a = Noise(1, 5).normal("x", 1.0)
    assert np.array_equal(a, Noise(1, 5).normal("x", 1.0))
    assert a[3] == Noise(1, 5, trial=3).normal("x", 1.0)
    assert not np.array_equal(a, Noise(1, 5).normal("y", 1.0))


def test_transcript_renders_text_and_jsonl():
    t = Transcript()
    t.add("1", "check", "Y", reading=1.0, residual=0.01, tolerance=0.02, passed=True)
    assert "pass" in t.to_text()
    assert '"stage": "1"' in t.to_jsonl()


def test_height_scale_reads_and_slips():
    inst = Instrument.error_free(load_instrument("sc1"), 70.0)
    inst.gear_height_counter(8000)
    inst.set("Z", 150.0)
    assert inst.read("H", exact=True) == pytest.approx(2000.0 - 150.0 * 8.0)
    inst.slip_height_scale(100.0)
    inst.set("H", 92.0)
    assert inst.read("Z", exact=True) == pytest.approx(151.0)


def test_equation_511_against_least_squares_of_510():
    # reference: six (5.10) equations solved numerically must give the elements of (5.11)
    f, c, b, a = 100.0, 80.0, 90.0, 5.0
    x11, x22, x12, x21 = -a, a, b + a, -(b + a)
    truth = np.array([2e-3, -1e-3, 1.5e-3, -0.5e-3, 0.8e-3])  # α1 α2 ω2 κ1 κ2
    pts = [
        (x11, 0.0, x21, 0.0),
        (x12, 0.0, x22, 0.0),
        (x11, c, x21, c),
        (x12, c, x22, c),
        (x11, -c, x21, -c),
        (x12, -c, x22, -c),
    ]
    q = np.array([y_parallax_first_order(*p, f, *truth) for p in pts])
    r = relative_orientation_from_standard_points(q, x11, x12, x21, x22, c, f)
    got = np.array([r[k] for k in ("alpha1", "alpha2", "omega2", "kappa1", "kappa2")])
    design = np.array(
        [[-(y_parallax_first_order(*p, f, *np.eye(5)[j])) for j in range(5)] for p in pts]
    )
    lsq = np.linalg.lstsq(design, -q, rcond=None)[0]
    np.testing.assert_allclose(got, truth, atol=1e-15)
    np.testing.assert_allclose(lsq, truth, atol=1e-15)
