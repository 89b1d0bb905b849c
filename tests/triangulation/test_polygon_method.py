"""The polygon method on simulated blocks: iteration → least squares, control, centre elements,
bad input; the inter-strip Monte Carlo (Dorozhinsky's 1.5–2× claim)."""

from __future__ import annotations

import numpy as np
import pytest

from stereoplotter.errors import GeometryError
from stereoplotter.triangulation.polygon import PolygonNetwork, adjust_polygons
from stereoplotter.triangulation.polygon_conditions import find_cells
from stereoplotter.triangulation.polygon_grid import grid_network, grid_sides
from stereoplotter.triangulation.polygon_montecarlo import compare_strips_block, error_map


def _block(a, b, rng, weights=False, control=True):
    """True elements at the centres, side increments with errors, control at the four corners."""
    truth = {f"{k + 1}-{j + 1}": rng.normal(0, 1, 6) * [0.01, 0.01, 0.01, 100, 100, 10]
             for k in range(b) for j in range(a)}  # fmt: skip
    sides = grid_sides(a, b)
    sigma = np.array([1e-4, 1e-4, 1e-4, 0.05, 0.05, 0.05])
    values = (
        np.array([truth[t] - truth[f] for f, t in sides])
        + rng.normal(0, 1, (len(sides), 6)) * sigma
    )
    w = rng.uniform(0.5, 2.0, len(sides)) if weights else None
    corners = ["1-1", f"1-{a}", f"{b}-1", f"{b}-{a}"]
    fixed = {c: truth[c] for c in corners} if control else {}
    return truth, grid_network(a, b, values, weights=w, fixed=fixed)


def adjusted_misclosures(net, v):
    """Misclosures of every condition (polygons and control) with corrections v."""
    result = adjust_polygons(net, method="least_squares")
    out = []
    for c in result.conditions:
        total = np.sum(np.asarray(c.signs)[:, None] * (net.values + v)[list(c.sides)], axis=0)
        out.append(np.where(c.applies, total - c.known, np.nan))
    return np.array(out)


@pytest.mark.parametrize(("a", "b", "weights"), [(6, 4, False), (5, 5, True), (8, 2, True)])
def test_iteration_converges_to_least_squares(a, b, weights):
    _, net = _block(a, b, np.random.default_rng(a * 10 + b), weights=weights)
    ls = adjust_polygons(net, method="least_squares")
    it = adjust_polygons(net, method="iterative", max_iterations=500)
    assert it.converged
    scale = np.abs(ls.corrections).max(axis=0)
    assert np.all(np.abs(it.corrections - ls.corrections).max(axis=0) <= 1e-7 * scale)
    # every condition closes; the control is kept
    assert np.nanmax(np.abs(ls.misclosures_after)) < 1e-9
    for cid, known in net.fixed.items():
        np.testing.assert_allclose(ls.centre_elements[cid], known, rtol=1e-12, atol=1e-9)


def test_least_squares_minimises_weighted_corrections():
    """Any other correction that closes all conditions has a larger Σ w v²."""
    rng = np.random.default_rng(5)
    _, net = _block(5, 3, rng, weights=True)
    ls = adjust_polygons(net, method="least_squares")
    w = net.side_weights()
    best = np.sum(w * ls.corrections**2, axis=0)
    # a closing alternative: move one free centre (every side into it +ε, out of it −ε)
    for eps in (1e-3, -1e-3):
        v = ls.corrections.copy()
        for s_index, (a, b) in enumerate(net.sides):
            if b == "2-2":
                v[s_index] += eps * np.array([1e-3, 1e-3, 1e-3, 1, 1, 1])
            elif a == "2-2":
                v[s_index] -= eps * np.array([1e-3, 1e-3, 1e-3, 1, 1, 1])
        assert np.nanmax(np.abs(adjusted_misclosures(net, v))) < 1e-9
        assert np.all(np.sum(w * v**2, axis=0) > best)


def test_tolerance_bounds_the_residual_misclosures():
    _, net = _block(6, 4, np.random.default_rng(3))
    tol = np.array([1e-5, 1e-5, 1e-5, 0.01, 0.01, 0.01])
    it = adjust_polygons(net, method="iterative", tolerance=tol)
    assert it.converged
    assert np.all(np.nanmax(np.abs(it.misclosures_after), axis=0) <= tol)
    assert np.all(it.iterations >= 1)


def test_adjustment_improves_on_the_measurements():
    rng = np.random.default_rng(11)
    errors_raw, errors_adj = [], []
    for _ in range(20):
        truth, net = _block(6, 4, rng)
        ls = adjust_polygons(net, method="least_squares")
        true_inc = np.array([truth[t] - truth[f] for f, t in net.sides])
        errors_raw.append((net.values - true_inc) ** 2)
        errors_adj.append((ls.side_values - true_inc) ** 2)
    assert np.all(np.mean(errors_adj, axis=(0, 1)) < np.mean(errors_raw, axis=(0, 1)))


def test_no_control_gives_a_datum_at_the_first_centre():
    _, net = _block(4, 3, np.random.default_rng(1), control=False)
    ls = adjust_polygons(net, method="least_squares")
    np.testing.assert_array_equal(ls.centre_elements["1-1"], np.zeros(6))
    assert [c.kind for c in ls.conditions] == ["polygon"] * 6


def test_partly_known_control():
    """NaN in a fixed vector: that element is not controlled there."""
    truth, net = _block(4, 3, np.random.default_rng(2))
    fixed = dict(net.fixed)
    fixed["3-4"] = np.array([np.nan, np.nan, np.nan, *truth["3-4"][3:]])
    net2 = PolygonNetwork(net.centres, net.sides, net.values, fixed=fixed, polygons=net.polygons)
    ls = adjust_polygons(net2, method="least_squares")
    control = [c for c in ls.conditions if c.kind == "control"]
    assert [c.applies.tolist() for c in control][-1] == [False] * 3 + [True] * 3
    np.testing.assert_allclose(ls.centre_elements["3-4"][3:], truth["3-4"][3:], atol=1e-9)


def test_find_cells_on_a_grid():
    sides = grid_sides(5, 4)
    centres = tuple(f"{k + 1}-{j + 1}" for k in range(4) for j in range(5))
    cells = find_cells(centres, sides)
    assert len(cells) == 4 * 3
    assert all(len(c) == 4 for c in cells)
    net = PolygonNetwork(centres, sides, np.zeros((len(sides), 6)))
    assert len(net.cells()) == 12


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"values": np.zeros((3, 6))}, "values: expected shape"),
        ({"sides": (("A", "B"), ("B", "Z"))}, "sides\\[1\\]"),
        ({"sides": (("A", "B"), ("B", "B"))}, "two different centres"),
        ({"weights": np.array([1.0, -1.0])}, "weights"),
        ({"fixed": {"Q": np.zeros(6)}}, "fixed"),
        ({"fixed": {"A": np.zeros(3)}}, "6 elements"),
        ({"polygons": (("A", "B"),)}, "polygons\\[0\\]"),
    ],
)
def test_bad_network_is_refused(kwargs, message):
    base = {
        "centres": ("A", "B", "C"),
        "sides": (("A", "B"), ("B", "C")),
        "values": np.zeros((2, 6)),
    }
    base.update(kwargs)
    with pytest.raises(GeometryError, match=message):
        PolygonNetwork(**base)


def test_dependent_polygons_are_refused():
    centres = ("A", "B", "C")
    sides = (("A", "B"), ("B", "C"), ("C", "A"))
    net = PolygonNetwork(centres, sides, np.ones((3, 6)), polygons=(("A", "B", "C"),) * 2)
    with pytest.raises(GeometryError, match="dependent"):
        adjust_polygons(net, method="least_squares")
    with pytest.raises(GeometryError, match="method"):
        adjust_polygons(net, method="popov")


def test_strip_error_map_is_the_levelling_line():
    """Strips alone: variance at photo i of a line of m sides fixed at both ends is i(m − i)/m."""
    a, b = 7, 2
    g = error_map(a, b, inter_strip=False)
    m = a - 1
    expected = np.array([i * (m - i) / m for i in range(1, m)] * b)
    np.testing.assert_allclose(np.sum(g**2, axis=1), expected, atol=1e-12)


def test_inter_strip_improvement_monte_carlo():
    """Dorozhinsky: inter-strip conditions improve accuracy 1.5–2×. 10 photos × 5 strips,
    control at both ends of every strip: the Monte Carlo ratio agrees with the exact one, and
    lies in the paper's range."""
    result = compare_strips_block(10, 5, 4000, np.random.default_rng(29))
    lo, hi = result.ratio_ci95
    assert lo <= result.exact_ratio <= hi
    assert 1.5 <= result.exact_ratio <= 2.0


def test_irregular_connections_keep_every_closure():
    """Across-strip sides to the nearest photo of a shifted strip make triangles: the default
    polygons still form a complete independent set (sides − centres + 1 conditions), and the
    least-squares adjustment closes every loop of the net."""
    rng = np.random.default_rng(8)
    centres = tuple([f"1-{j}" for j in range(1, 6)] + [f"2-{j}" for j in range(1, 5)])
    sides = [(f"1-{j}", f"1-{j + 1}") for j in range(1, 5)]
    sides += [(f"2-{j}", f"2-{j + 1}") for j in range(1, 4)]
    sides += [("1-1", "2-1"), ("1-2", "2-1"), ("1-3", "2-2"), ("1-4", "2-3"), ("1-5", "2-4")]
    sides += [("1-4", "2-4")]
    net = PolygonNetwork(centres, tuple(sides), rng.normal(0, 1, (len(sides), 6)))
    cells = net.cells()
    assert len(cells) == len(sides) - len(centres) + 1
    assert ("1-1", "1-2", "2-1") in cells  # the triangle
    ls = adjust_polygons(net, method="least_squares")
    # every closed walk closes: the centre elements reproduce every adjusted side
    for s, (a, b) in enumerate(net.sides):
        np.testing.assert_allclose(
            ls.centre_elements[b] - ls.centre_elements[a], ls.side_values[s], atol=1e-9
        )
    it = adjust_polygons(net, method="iterative", max_iterations=1000)
    np.testing.assert_allclose(it.corrections, ls.corrections, atol=1e-8)
