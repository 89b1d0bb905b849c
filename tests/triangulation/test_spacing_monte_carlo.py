"""Monte Carlo of actual strips against the analytic residual variances (control_spacing).

Simulated strips: ε ~ N(0, 1) per base, η by double summation, the polynomial fitted through the
control by least squares, the residual kept. The mean squared residual per point must lie within
its Monte Carlo 99.9 % band (|z| < 3.3 at every point) of var(η − p); the paper's Eq. (1) value
σ_η² − σ_p² must not (it is negative or several times larger at the tested points).
"""

from __future__ import annotations

import numpy as np
import pytest

from stereoplotter.triangulation.control_spacing import (
    choose_control_spacing,
    eta_covariance,
    link_lengths,
    paper_residual_variance,
    residual_variance,
    simulate_residual_variance,
)

Z = 3.3  # two-sided 99.9 % per point; a handful of points per case


@pytest.mark.parametrize(
    ("n_bases", "control", "degree"),
    [(15, (0, 7, 15), 2), (15, (0, 9, 15), 2), (15, (0, 5, 10, 15), 3), (12, (0, 3, 6, 9, 12), 2)],
)
def test_simulated_strips_match_the_residual_variance(n_bases, control, degree):
    rng = np.random.default_rng(2929 + n_bases + sum(control))
    mean, se = simulate_residual_variance(n_bases, np.array(control), degree, 40_000, rng)
    analytic = residual_variance(n_bases, np.array(control), degree)
    free = np.setdiff1d(np.arange(n_bases + 1), control)
    z = (mean[free] - analytic[free]) / se[free]
    assert np.all(np.abs(z) < Z), z
    if len(control) == degree + 1:  # interpolation: exactly zero at the control
        assert np.all(mean[list(control)] < 1e-18)
        paper = paper_residual_variance(n_bases, np.array(control), degree)
        z_paper = (mean[free] - paper[free]) / se[free]
        assert np.all(np.abs(z_paper) > 10)


def test_covariance_matches_simulation():
    rng = np.random.default_rng(7)
    eps = rng.standard_normal((40_000, 6))
    eta = np.concatenate([np.zeros((40_000, 1)), np.cumsum(np.cumsum(eps, 1), 1)], axis=1)
    c = eta_covariance(6)
    emp = eta.T @ eta / len(eta)
    # var of a product estimate: (c_ii c_jj + c_ij²)/T
    se = np.sqrt((np.outer(np.diag(c), np.diag(c)) + c**2) / len(eta))
    assert np.all(np.abs(emp - c) <= 4 * se + 1e-12)
    # the closed form var η(b) = b(b + 1)(2b + 1)/6
    b = np.arange(7)
    np.testing.assert_array_equal(np.diag(c), b * (b + 1) * (2 * b + 1) / 6)


def test_choose_control_spacing_actual_residual():
    """The default criterion splits the strip into links differing by at most one base."""
    for n_bases in range(4, 21):
        control = choose_control_spacing(n_bases, 2)
        assert control[0] == 0 and control[-1] == n_bases
        first, second = link_lengths(control)
        assert first - second in (0, 1)
    assert choose_control_spacing(15, 3) == (0, 5, 11, 15)
    assert choose_control_spacing(12, 3) == (0, 4, 8, 12)


def test_choose_is_the_exhaustive_minimum():
    n_bases = 11
    best = choose_control_spacing(n_bases, 2)
    scores = {}
    for m in range(1, n_bases):
        v = residual_variance(n_bases, np.array([0, m, n_bases]), 2)
        free = np.setdiff1d(np.arange(n_bases + 1), [0, m, n_bases])
        scores[m] = np.mean(v[free] ** 2)
    assert scores[best[1]] == pytest.approx(min(scores.values()), rel=1e-9)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        ((7, (0, 8), 1), "expected values in 0"),
        ((7, (0, 3), 2), "needs ≥ 3 control points"),
        ((7, (0, 3, 3), 2), "distinct"),
        ((0, (0,), 0), "n_bases"),
        ((7, (0.5, 3, 7), 2), "integers"),
    ],
)
def test_bad_input_is_refused(args, message):
    with pytest.raises(ValueError, match=message):
        residual_variance(*args)
