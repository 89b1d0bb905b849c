"""The polygon network built from the strips (runs once triangulation/polygon.py is present)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import arcsec, m
from synthetic_blocks import exact_block

from stereoplotter.triangulation.polygon_block import polygon_block, polygon_sides
from stereoplotter.triangulation.strip import oriented_strips


def test_sides_of_an_error_free_block_close_every_polygon():
    # along-strip sides are the strips' increments, cross sides corrected by the common points:
    # error-free, the increments around any cell of four photos sum to zero
    block, truth = exact_block()
    strips, _ = oriented_strips(block)
    sides, values = polygon_sides(block, strips)
    index = {p: j for j, p in enumerate(block.photos)}
    for (a, b), v in zip(sides, values, strict=True):
        d = truth.orientations[index[b]] - truth.orientations[index[a]]
        assert np.max(np.abs(v[:3] - d[:3])) < 0.01 * arcsec
        assert np.max(np.abs(v[3:] - d[3:])) < 1e-3 * m


def test_polygon_method_returns_the_truth_on_an_error_free_block():
    pytest.importorskip("stereoplotter.triangulation.polygon")
    block, truth = exact_block()
    s = polygon_block(block)
    err = s.orientations - truth.orientations
    assert np.max(np.abs(err[:, :3])) < 0.01 * arcsec
    assert np.max(np.abs(err[:, 3:])) < 1e-3 * m


def test_polygon_point_sigma_by_its_empirical_rule_matches_the_check_points():
    # the rule: σ = RMS residual at the control points per axis. Against the truth at the check
    # points of 4 blocks of 4 × 10, pooled over the axes: the blocks' ratios spread by ≈ 0.15,
    # so 0.75–1.25 is more than ± 3 SE about 1
    from stereoplotter.triangulation.synth import SynthSpec, synthesize_block

    z = []
    for seed in range(4):
        block, truth = synthesize_block(SynthSpec(), np.random.default_rng([seed, 7]))
        s = polygon_block(block)
        se = s.point_standard_errors
        check = {c.id for c in block.catalogue if c.role == "check"}
        idx = [
            i
            for i, pid in enumerate(block.point_ids)
            if pid in check and np.all(np.isfinite(s.points_m[i]))
        ]
        z.append((s.points_m[idx] - truth.points_m[idx]) / se[idx])
    rms = float(np.sqrt(np.mean(np.vstack(z) ** 2)))
    assert 0.75 < rms < 1.25, rms
