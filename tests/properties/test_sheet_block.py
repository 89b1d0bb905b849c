"""The columnar sheet block against an independent per-pair computation.

The pairs of ``jobs/strip8`` with their points thinned differently (2 to all 10 points, so the
pairs' point counts and plan-control counts are unequal, one pair with a single point and no
(6.8) fit) go through :func:`compute_sheet_block` at once. For each pair, independently of the
program: the base azimuth θ from atan2 of the base, the points turned by θ with cos/sin written
out, the (6.8) coefficients by ``numpy.linalg.lstsq`` of the four-unknown linear system (not the
centred normal equations of the program), the sheet corners on the ground from those
coefficients, the depth range and plan extent as min/max of each pair's own arrays. The sheet
each pair gets from the block equals the sheet of that pair computed alone, and a group sum
equals ``numpy.sum`` of the group alone to the bit.
"""

from __future__ import annotations

import math
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np
import pytest

from stereoplotter.geometry.grouped import group_sums
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.job_file import load_job
from stereoplotter.io.job_measured import measured_pair
from stereoplotter.setup.records import SetupOptions, SetupSheet
from stereoplotter.setup.sheet import compute_sheet_from_measurements, sheet_of_block
from stereoplotter.setup.sheet_block import CORNER_ORDER, compute_sheet_block

JOB = Path(__file__).resolve().parents[2] / "jobs" / "strip8" / "job.yaml"
KEEP = (10, 2, 7, 1, 5, 3, 9, 4)  # points kept of each pair, in its order


@pytest.fixture(scope="module")
def pairs():
    job = load_job(JOB)
    out = []
    for pair, keep in zip(job.pairs, KEEP, strict=True):
        arguments = measured_pair(job, pair).sheet_arguments()
        arguments["points"] = tuple(arguments["points"])[:keep]
        out.append(arguments)
    return job, load_instrument(job.instrument), out


@pytest.fixture(scope="module")
def block(pairs):
    job, spec, arguments = pairs
    return compute_sheet_block(arguments, spec=spec, options=SetupOptions(), source=job.source)


def _plan(points):
    return [p for p in points if p.role == "control" and p.kind in ("full", "plan") and p.sk42_m]


def test_the_pairs_have_unequal_point_and_plan_counts(pairs):
    counts = [len(a["points"]) for a in pairs[2]]
    plans = [len(_plan(a["points"])) for a in pairs[2]]
    assert len(set(counts)) == len(counts) and 1 in counts
    assert len(set(plans)) >= 4 and min(plans) < 2 <= max(plans)


def test_frame_and_points_agree_with_an_explicit_turn(pairs, block):
    for i, a in enumerate(pairs[2]):
        c = np.asarray(a["centres_m"], float)
        theta = math.atan2(c[1, 1] - c[0, 1], c[1, 0] - c[0, 0])
        assert block.frame_rotation[i] == pytest.approx(theta, abs=1e-15)
        d = np.array([p.local_m for p in a["points"]]) - c[0]
        cos, sin = math.cos(theta), math.sin(theta)
        turned = np.stack(
            [cos * d[:, 0] + sin * d[:, 1], -sin * d[:, 0] + cos * d[:, 1], d[:, 2]], 1
        )
        assert np.abs(block.points_of(i) - turned).max() < 1e-9  # m


def _lstsq_fit(north, east, x, y):
    """(6.8) X = a·x_г + b·y_г + c_X, Y = −a·y_г + b·x_г + c_Y by lstsq (x_г, y_г reduced to
    the first point for the conditioning; c_X, c_Y moved back)."""
    n0, e0 = north[0], east[0]
    dn, de = north - n0, east - e0
    one, zero = np.ones_like(dn), np.zeros_like(dn)
    design = np.vstack([np.stack([dn, de, one, zero], 1), np.stack([-de, dn, zero, one], 1)])
    (a, b, cx, cy), *_ = np.linalg.lstsq(design, np.concatenate([x, y]), rcond=None)
    return a, b, cx - a * n0 - b * e0, cy + a * e0 - b * n0


def test_similarity_and_corners_agree_with_lstsq(pairs, block):
    fitted = 0
    for i, a in enumerate(pairs[2]):
        plan = _plan(a["points"])
        if len(plan) < 2:
            assert block.fit_row[i] == -1 and np.isnan(block.corners_m[i]).all()
            continue
        fitted += 1
        index = [a["points"].index(p) for p in plan]
        xy = block.points_of(i)[index]
        north = np.array([p.sk42_m[0] for p in plan])
        east = np.array([p.sk42_m[1] for p in plan])
        ref = _lstsq_fit(north, east, xy[:, 0], xy[:, 1])
        fit = block.fits.fit(block.fit_row[i])
        # the same least squares by other arithmetic: 1e-10 of scale is 1 µm over 10 km
        assert fit.a == pytest.approx(ref[0], abs=1e-10)
        assert fit.b == pytest.approx(ref[1], abs=1e-10)
        assert (fit.cx_m, fit.cy_m) == pytest.approx(ref[2:], abs=1e-4)  # m, at ~10⁶ m
        gk = np.array(a["map_sheet"].corners_sk42_m, float)[[CORNER_ORDER[k] for k in "1234"], :2]
        ground = np.stack([ref[0] * gk[:, 0] + ref[1] * gk[:, 1] + ref[2],
                           -ref[0] * gk[:, 1] + ref[1] * gk[:, 0] + ref[3]], 1)  # fmt: skip
        assert np.abs(block.corners_m[i] - ground).max() < 1e-4  # m
        residual = np.stack([ref[0] * north + ref[1] * east + ref[2] - xy[:, 0],
                             -ref[0] * east + ref[1] * north + ref[3] - xy[:, 1]], 1)  # fmt: skip
        assert np.abs(fit.residuals_m - residual).max() < 1e-4
    assert fitted >= 4


def test_depth_range_and_extent_agree_with_each_pairs_own_arrays(pairs, block):
    for i, a in enumerate(pairs[2]):
        c, theta = np.asarray(a["centres_m"], float)[0], block.frame_rotation[i]
        cos, sin = math.cos(theta), math.sin(theta)
        ground = np.vstack([np.asarray(a["working_area_m"], float),
                            [p.local_m for p in a["points"]]]) - c  # fmt: skip
        x, y = cos * ground[:, 0] + sin * ground[:, 1], -sin * ground[:, 0] + cos * ground[:, 1]
        depth = -ground[:, 2]
        assert block.depth_m[i] == pytest.approx([depth.min(), depth.max()], abs=1e-9)
        assert block.depth_mean_m[i] == pytest.approx(depth.mean(), abs=1e-9)
        corners = block.corners_m[i] if block.fit_row[i] >= 0 else np.zeros((0, 2))
        xs, ys = np.concatenate([x, corners[:, 0]]), np.concatenate([y, corners[:, 1]])
        expected = [[xs.min(), xs.max()], [ys.min(), ys.max()]]
        assert np.abs(block.extent_m[i] - expected).max() < 1e-9


def _plain(sheet: SetupSheet) -> dict:
    """The sheet's fields but its Table 24 and (6.8) fit (compared on their own)."""
    return asdict(replace(sheet, table24=None, similarity=None))


def test_each_sheet_of_the_block_is_the_sheet_of_its_pair_alone(pairs, block):
    job, spec, arguments = pairs
    for i, a in enumerate(arguments):
        alone = compute_sheet_from_measurements(
            spec=spec, options=SetupOptions(), source=job.source, **a
        )
        together = sheet_of_block(block, i)
        assert _plain(together) == _plain(alone)
        if alone.similarity is None:
            assert together.similarity is None
        else:
            assert together.similarity.a == alone.similarity.a
            assert np.array_equal(together.similarity.residuals_m, alone.similarity.residuals_m)


def test_group_sums_are_numpys_sum_of_each_group_to_the_bit():
    rng = np.random.default_rng(27)
    sizes = rng.integers(0, 40, size=60)
    values = rng.normal(size=int(sizes.sum())) * 10.0 ** rng.uniform(-3, 6, size=int(sizes.sum()))
    start = np.concatenate([[0], np.cumsum(sizes)])
    expected = [np.sum(values[start[g] : start[g + 1]]) for g in range(len(sizes))]
    assert group_sums(values, start).tolist() == [float(v) for v in expected]
