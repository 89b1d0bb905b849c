"""The design of a study: cells, samples, tasks, the moments of a cell, the normal case."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stereoplotter import load_instrument, load_scenario
from stereoplotter.geometry.collinearity import object_to_photo
from stereoplotter.study.cells import Moments, combine_chunks
from stereoplotter.study.design import Axis, Sample, StudyDesign, Task
from stereoplotter.study.geometry import base_geometry, normal_case


@pytest.fixture(scope="module")
def pair60():
    return load_scenario("pair60")


def design(pair60, axes, sample=None, trials=100, chunk=30):
    return StudyDesign(
        name="t",
        base=pair60,
        instruments={"sc1": load_instrument("sc1")},
        axes=tuple(axes),
        trials=trials,
        chunk_trials=chunk,
        measures=("checks", "procedure"),
        seed=1,
        procedure_trials=10,
        sample=sample,
    )


def test_grid_cells_are_the_product_last_axis_fastest(pair60):
    d = design(pair60, [Axis("f_mm", None, 70, 210, 3), Axis("method", ("setup", "conventional"))])
    cells = d.cells()
    assert len(cells) == 6
    assert [c["f_mm"] for c in cells] == [70.0, 70.0, 140.0, 140.0, 210.0, 210.0]
    assert [c["method"] for c in cells[:2]] == ["setup", "conventional"]


def test_tasks_cover_every_trial_once_then_the_procedure_mc(pair60):
    tasks = design(pair60, [Axis("f_mm", (70.0,))]).tasks(0)
    chunks = [t for t in tasks if t.kind == "chunk"]
    covered = np.concatenate([np.arange(t.first, t.first + t.trials) for t in chunks])
    assert np.array_equal(covered, np.arange(100))
    assert [t.kind for t in tasks[len(chunks) :]] == ["procedure"]


def test_latin_hypercube_puts_one_point_in_each_stratum_of_each_axis(pair60):
    n = 16
    axes = [
        Axis("overlap", None, 0.56, 0.9),
        Axis("relief", None, 0.0, 0.35),
        Axis("method", ("setup", "conventional")),
    ]
    cells = design(pair60, axes, Sample("lhs", n, 3)).cells()
    assert len(cells) == 2 * n
    for name, lo, hi in (("overlap", 0.56, 0.9), ("relief", 0.0, 0.35)):
        v = np.array([c[name] for c in cells if c["method"] == "setup"])
        strata = np.floor((v - lo) / (hi - lo) * n).astype(int)
        assert sorted(strata) == list(range(n))


def test_sobol_sample_is_seeded_and_inside_the_ranges(pair60):
    axes = [Axis("f_mm", None, 70, 200), Axis("alpha_deg", None, 0, 3)]
    a = design(pair60, axes, Sample("sobol", 8, 5)).cells()
    b = design(pair60, axes, Sample("sobol", 8, 5)).cells()
    assert a == b
    f = np.array([c["f_mm"] for c in a])
    assert f.min() >= 70 and f.max() <= 200 and len(set(f)) == 8


def test_moments_of_chunks_in_order_are_the_mean_and_se_of_all_trials():
    rng = np.random.default_rng(0)
    values = rng.normal(3.0, 2.0, (2, 103))
    values[1, [5, 60]] = np.nan  # a check not evaluated in two trials
    parts = [
        (Task("chunk", 0, first, 0), Moments.of(values[:, first : first + 25]))
        for first in range(0, 103, 25)
    ]
    m = combine_chunks(parts[::-1])  # arrival order does not matter
    for row in range(2):
        v = values[row][np.isfinite(values[row])]
        assert m.n[row] == v.size
        assert m.mean[row] == pytest.approx(np.mean(v), rel=1e-13)
        se = np.std(v, ddof=1) / math.sqrt(v.size)
        assert m.standard_error()[row] == pytest.approx(se, rel=1e-12)


def test_normal_case_has_the_asked_overlap_and_the_base_photo_scale(pair60):
    base = base_geometry(pair60)
    for f, overlap in ((70.0, 0.6), (200.0, 0.9), (140.0, 0.56)):
        sc = normal_case(pair60, {"f_mm": f, "overlap": overlap})
        left, right = sc.photo("left").exterior, sc.photo("right").exterior
        z0 = sc.points[0].local_m[2]  # flat terrain: every point at z0
        assert all(p.local_m[2] == pytest.approx(z0) for p in sc.points)
        height = left.centre[2] - z0
        assert height / f == pytest.approx(base["flying_height_m"] / base["f_mm"], rel=1e-12)
        # the right nadir on the left photo: the photo base b = (1 − overlap)·format (vertical)
        nadir = np.array([[right.centre[0], right.centre[1], z0]])
        xy = object_to_photo(nadir, left.centre, left.rotation, f, (0.0, 0.0))[0]
        assert 1 - np.hypot(*xy) / sc.camera.format_mm == pytest.approx(overlap, abs=1e-9)
