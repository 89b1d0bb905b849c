"""Blunders found and named after Baarda, and the σ of every point, on synthetic blocks."""

from __future__ import annotations

import dataclasses
from functools import cache

import numpy as np
import pytest
from scipy import stats

from stereoplotter.triangulation.bundle import bundle_adjust, problem
from stereoplotter.triangulation.reliability import critical_values, global_test, robust, snoop
from stereoplotter.triangulation.solution import catalogue_residuals
from stereoplotter.triangulation.synth import SynthSpec, synthesize_block


@cache
def block6x15(seed: int):
    """6 strips × 15 photos (the default σ 5 µm, control every 4 bases)."""
    return synthesize_block(
        SynthSpec(strips=6, photos_per_strip=15), np.random.default_rng([seed, 39])
    )


@cache
def _clean_solution(seed: int):
    """The bundle solution of the block without blunders (no covariances needed)."""
    block, _ = block6x15(seed)
    return bundle_adjust(problem(block), covariance=False)


def _with_blunders(block, coordinate: int):
    """+0.5 mm on one coordinate of one measurement of a point of 3 photos of one strip, +2 m on
    the height of one height control point; returns the block and their names."""
    rays = np.bincount(block.obs_point)
    strip = block.strip_of_photo
    three = [
        o
        for o in np.flatnonzero(rays[block.obs_point] == 3)
        if np.unique(strip[block.obs_photo[block.obs_point == block.obs_point[o]]]).size == 1
    ]
    o = three[len(three) // 2]
    comparator = block.comparator_mm.copy()
    comparator[o, coordinate] += 0.5  # the comparator's x, y turned < 2° from the photo's
    cat = list(block.catalogue)
    k = [i for i, c in enumerate(cat) if c.role == "control" and c.kind == "height"][2]
    north, east, h = cat[k].sk42_m
    cat[k] = dataclasses.replace(cat[k], sk42_m=(north, east, h + 2.0))
    bad = dataclasses.replace(block, comparator_mm=comparator, catalogue=tuple(cat))
    names = (block.photos[block.obs_photo[o]], block.point_ids[block.obs_point[o]], cat[k].id)
    return bad, names


def test_critical_values_are_the_normal_quantiles():
    # α₀ = 0.001, β₀ = 0.80: Baarda's k = 3.29 and δ₀ = 4.13
    a0, k, d0 = critical_values(1, alpha0=0.001)
    assert (a0, round(k, 2), round(d0, 2)) == (0.001, 3.29, 4.13)
    # Šidák: n tests at α₀ each have a family-wise rate of 5 %
    a0, _, _ = critical_values(2000, alpha=0.05)
    assert 1 - (1 - a0) ** 2000 == pytest.approx(0.05)


def test_global_test_interval_is_the_chi_square_quantiles():
    g = global_test(1.0, 400)
    assert g.low**2 * 400 == pytest.approx(stats.chi2.ppf(0.025, 400))
    assert g.passed and not global_test(1.2, 400).passed


def test_redundancy_numbers_sum_to_the_redundancy():
    block, _ = block6x15(0)
    p = problem(block)
    r = snoop(p)
    rel = r.reliability_first
    total = rel.photo_r.sum() + np.nansum(rel.control_r)
    assert total == pytest.approx(r.first.redundancy, rel=1e-6)


def test_blunders_on_a_y_coordinate_and_a_control_height_are_named_and_rejected():
    block, _ = block6x15(0)
    bad, (photo, point, control) = _with_blunders(block, 1)
    r = snoop(problem(bad))
    found = {(f.photo, f.point, f.observation) for f in r.flags}
    assert found == {(photo, point, "y_mm"), ("", control, "height_m")}
    assert all(abs(f.w) > r.reliability.k for f in r.flags)
    clean = catalogue_residuals(block, _clean_solution(0)).rms(block, "check")
    rejected = catalogue_residuals(block, r.last.solution).rms(block, "check")
    blundered = catalogue_residuals(block, r.first.solution).rms(block, "check")
    assert np.all(blundered > 1.1 * clean)  # the blunders did spoil the block
    np.testing.assert_allclose(rejected, clean, rtol=0.10)


def test_an_x_blunder_on_a_point_of_one_strip_is_found_but_not_told_from_its_neighbours():
    # three photos of one strip see the point: x holds one condition (the x-parallaxes), so the
    # three w of x are equal up to sign (|ρ| = 1) and all three measurements are removed
    block, _ = block6x15(0)
    bad, (photo, point, _) = _with_blunders(block, 0)
    r = snoop(problem(bad))
    f = r.flags[0]
    assert (f.point, f.observation) == (point, "x_mm")
    named = {f.photo, *(s.split()[0] for s in f.inseparable)}
    assert photo in named and len(named) == 3
    assert {g.observation for g in r.flags[1:]} == {"height_m"}


def test_point_sigma_matches_the_errors_at_check_points():
    # RMS(error/σ) per axis over the check points of 4 blocks of 352: the blocks' values
    # spread by ≈ 0.06 per axis (correlated points), so the mean of 4 has SE ≈ 0.03 and
    # 0.9–1.1 is ± 3.3 SE
    z = []
    for seed in range(4):
        block, truth = block6x15(seed)
        s = bundle_adjust(problem(block))
        check = {c.id for c in block.catalogue if c.role == "check"}
        idx = [
            i
            for i, pid in enumerate(block.point_ids)
            if pid in check and np.isfinite(s.points_m[i, 0])
        ]
        z.append((s.points_m[idx] - truth.points_m[idx]) / s.point_standard_errors[idx])
    rms = np.sqrt(np.mean(np.vstack(z) ** 2, axis=0))
    assert np.all((rms > 0.9) & (rms < 1.1)), rms


def test_danish_reweighting_down_weights_the_two_blunders_only():
    block, _ = block6x15(0)
    bad, (photo, point, control) = _with_blunders(block, 1)
    r = robust(problem(bad), "danish")
    assert [(f.photo, f.point, f.observation) for f in r.flags] == [
        (photo, point, "y_mm"),
        ("", control, "height_m"),
    ]
    assert r.photo_factor.min() < 0.01 and r.control_factor.min() < 0.01  # < 1 % of the weight
    clean = catalogue_residuals(block, _clean_solution(0)).rms(block, "check")
    got = catalogue_residuals(block, r.adjusted.solution).rms(block, "check")
    np.testing.assert_allclose(got, clean, rtol=0.10)
