"""Reference tests: the worked example of §18 of the book, Tables 7–13.

[1] Kushtin & Lyskov, *Фотограмметрия снимка и стереоскопических моделей*, Nedra, 1984, ch. 3,
§18, pp. 80–93 (OCR L1983–2300). True exterior orientation of the example (OCR L2196,
L2240–2242): α = 3°, ω = 2°, κ = −3°, X_S = 2800.000 m, Y_S = 700.000 m, Z_S = 750.000 m;
f = 75 mm, x₀ = y₀ = 0.

Expected values are typed as printed in ``tests/data/resection_table*.csv``. Each chained step
takes the book's *printed* inputs of that step, so that a failure points at one equation.
Where the book is wrong the corrected value is pinned with an ``# ERRATA:`` comment
(``conventions.md`` §11.1, §12 items 26–29).
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from stereoplotter.constants import ARCSEC_PER_RAD
from stereoplotter.geometry.collinearity import object_to_photo
from stereoplotter.geometry.resection import space_resection
from stereoplotter.geometry.resection_book import (
    angular_elements_by_lines,
    angular_normal_equations,
    book_space_resection,
    flying_height_by_lines,
    line_coefficients,
    projection_centre_height,
    projection_centre_plan_by_points,
    solve_angular_normal_equations,
)
from stereoplotter.geometry.rotation import rotation_matrix
from stereoplotter.geometry.transformed import transformed_coordinates

mm = 1.0  # internal length unit of photo coordinates
um = 1e-3 * mm
m = 1.0  # internal length unit of object coordinates
arcsec = 1.0 / ARCSEC_PER_RAD  # radians

DATA = Path(__file__).resolve().parents[1] / "data"


def _load(name: str) -> list[dict[str, str]]:
    with open(DATA / name, encoding="utf-8") as fh:
        return list(csv.DictReader(line for line in fh if not line.startswith("#")))


def _float(value: str) -> float:
    return float(value)


TABLE_7 = _load("resection_table7.csv")
TABLE_8 = _load("resection_table8.csv")
TABLE_9 = _load("resection_table9.csv")
TABLE_10 = _load("resection_table10.csv")
TABLE_11 = _load("resection_table11.csv")
TABLE_12 = _load("resection_table12.csv")
TABLE_13 = _load("resection_table13.csv")

F = 75.0 * mm  # Table 7 header (OCR L2097)
PHOTO = np.array([[_float(r["x_mm"]), _float(r["y_mm"])] for r in TABLE_7])
POINTS = np.array([[_float(r["X_m"]), _float(r["Y_m"]), _float(r["Z_m"])] for r in TABLE_7])
TRUE_ANGLES = np.radians([3.0, 2.0, -3.0])  # OCR L2196
TRUE_CENTRE = np.array([2800.0, 700.0, 750.0])  # OCR L2240-2242
TRUE_PHOTO = object_to_photo(POINTS, TRUE_CENTRE, rotation_matrix(*TRUE_ANGLES), F)

# [1] approximation I (OCR L2123) and approximation III (OCR L2204).
ANGLES_I = np.array([10791.02, 7228.96, -10629.38]) * arcsec
ANGLES_III = np.array([10800.14, 7200.39, -10800.38]) * arcsec
TRANSFORMED_I = np.array([[_float(r["x0_mm"]), _float(r["y0_mm"])] for r in TABLE_9])
TRANSFORMED_III = np.array([[_float(r["x0_mm"]), _float(r["y0_mm"])] for r in TABLE_11])


def _line_index(row: dict[str, str]) -> int:
    """Index of line i-j in the book's order 1-2, 1-3, 1-4, 2-3, 2-4, 3-4."""
    return ["1-2", "1-3", "1-4", "2-3", "2-4", "3-4"].index(row["line"])


# --- Table 7: collinearity (2.50) + (2.53) ------------------------------------------------------


# [1] §18, Table 7 (OCR L2097-2104). Printed to 1e-5 mm; the book's own values deviate from the
# rigorous ones by up to 2 units there (0.018 um), hence 0.025 um instead of the half-unit rule.
@pytest.mark.parametrize("row", TABLE_7, ids=lambda r: f"point{r['point']}")
def test_table7_photo_coordinates_from_true_orientation(row):
    i = int(row["point"]) - 1
    assert_allclose(
        TRUE_PHOTO[i], [_float(row["x_mm"]), _float(row["y_mm"])], rtol=0, atol=0.025 * um
    )


# --- Table 8: working equations (3.23)/(3.24), approximation I -----------------------------------


# [1] §18, Table 8 (OCR L2127-2145), from the printed Table 7 photo coordinates. Half a unit of
# the last printed digit. Every entry reproduces with the corrected (3.24) (conventions.md §12
# item 26) except Q(1-3) and l(1-3).
@pytest.mark.parametrize("row", TABLE_8, ids=lambda r: r["line"])
def test_table8_line_coefficients(row):
    c = line_coefficients(PHOTO, POINTS, F)
    k = _line_index(row)
    assert tuple(c.pairs[k] + 1) == (int(row["i"]), int(row["j"]))
    dx, dy = c.photo_difference_mm[k]
    assert dx == pytest.approx(_float(row["dx_mm"]), abs=0.005 * um)
    assert dy == pytest.approx(_float(row["dy_mm"]), abs=0.005 * um)
    assert_allclose(c.ground_difference_m[k], [_float(row[n]) for n in ("dX_m", "dY_m", "h_m")])
    assert c.K_mm[k] == pytest.approx(_float(row["K_mm"]), abs=0.5e-5 * mm)
    assert c.A[k] == pytest.approx(_float(row["A"]), abs=0.5e-6)
    assert c.B[k] == pytest.approx(_float(row["B"]), abs=0.5e-6)
    assert _float(row["C"]) == 1.0
    q_expected, l_expected = _float(row["Q"]), _float(row["l_arcsec"])
    if row["line"] == "1-3":
        # ERRATA: Table 8 prints Q(1-3) = 393 494.31; (x3 - x1)(X3 - X1) + (y3 - y1)(Y3 - Y1)
        # = 149.3344*1400 + 133.16008*1385 = 393 494.87. The printed l(1-3) = 10 792.67"
        # follows from the wrong Q; the correct value is 10 792.65".
        assert q_expected == 393494.31 and l_expected == 10792.67
        q_expected, l_expected = 393494.87, 10792.65
    assert c.Q[k] == pytest.approx(q_expected, abs=0.005)
    assert c.free_term[k] == pytest.approx(l_expected * arcsec, abs=0.005 * arcsec)


# [1] §18, normal equations I (OCR L2119), formed from the printed Table 8 coefficients (with the
# printed l(1-3)); half a unit of the printed digits.
def test_normal_equations_first_approximation():
    a = np.array([_float(r["A"]) for r in TABLE_8])
    b = np.array([_float(r["B"]) for r in TABLE_8])
    lv = np.array([_float(r["l_arcsec"]) for r in TABLE_8])
    design = np.column_stack([a, b, np.ones(6)])
    n_matrix, n_const = design.T @ design, design.T @ lv
    # ERRATA: the book prints the off-diagonal [AB] = -0.155248; sum(A*B) = -0.151692 (-0.151691
    # from the rounded coefficients).
    expected = np.array(
        [
            [1.955899, -0.151692, -0.119901],
            [-0.151692, 1.965245, 0.153124],
            [-0.119901, 0.153124, 6.000000],
        ]
    )
    assert_allclose(n_matrix, expected, rtol=0, atol=1.5e-6)  # sums of six 6-digit products
    assert_allclose(n_const, [-21258.33, -10903.76, 63963.23], rtol=0, atol=0.005)


# [1] §18, OCR L2121-2125: the book's printed normal equations I solve to its alpha^I, omega^I,
# kappa^I. The book solved with more digits than it prints (the printed system gives
# omega = 7228.950"), hence 0.02".
def test_book_first_approximation_follows_from_its_printed_normal_equations():
    n_matrix = np.array(
        [
            [1.955899, -0.155248, -0.119901],
            [-0.155248, 1.965245, 0.153124],
            [-0.119901, 0.153124, 6.000000],
        ]
    )
    n_const = np.array([-21258.33, -10903.76, 63963.23]) * arcsec
    solution = solve_angular_normal_equations(n_matrix, n_const)
    assert_allclose(solution, ANGLES_I, rtol=0, atol=0.02 * arcsec)
    # The printed degrees (OCR L2121-2125) are the printed seconds converted.
    assert_allclose(np.degrees(ANGLES_I), [2.9975056, 2.0080444, -2.9526056], rtol=0, atol=0.5e-7)


# Independent computation with the corrected N12 and Q(1-3) (conventions.md §11.1): the correct
# first approximation is (10776.28, 7208.26, -10629.15)"; half a unit of 0.01".
def test_correct_first_approximation():
    c = line_coefficients(PHOTO, POINTS, F)
    solution = solve_angular_normal_equations(*angular_normal_equations(c))
    assert_allclose(
        solution, np.array([10776.28, 7208.26, -10629.15]) * arcsec, atol=0.005 * arcsec
    )
    iteration = angular_elements_by_lines(PHOTO, POINTS, F)
    assert_allclose(iteration.approximations[0], solution, rtol=0, atol=1e-9 * arcsec)


# --- Tables 9 and 11: transformed coordinates (3.17) -------------------------------------------


# [1] §18, Table 9 (OCR L2147-2158) and Table 11 (OCR L2248-2256): the book computed with
# direction cosines rounded to 7 digits, which moves x0, y0, Z' by up to 0.03 um: 0.05 um.
# The cosines themselves are printed to 1e-7: half a unit plus the book's own rounding, 1e-7.
@pytest.mark.parametrize(
    ("table", "angles"), [(TABLE_9, ANGLES_I), (TABLE_11, ANGLES_III)], ids=["table9", "table11"]
)
def test_tables_9_and_11_transformed_coordinates(table, angles):
    rot = rotation_matrix(*angles)
    transformed = transformed_coordinates(PHOTO, rot, F)
    z_prime = (rot @ np.column_stack([PHOTO, -F * np.ones(4)]).T)[2]  # Z' of (3.17)
    for k, row in enumerate(table):
        assert_allclose(
            transformed[k], [_float(row["x0_mm"]), _float(row["y0_mm"])], rtol=0, atol=0.05 * um
        )
        assert z_prime[k] == pytest.approx(_float(row["Z_prime_mm"]), abs=0.05 * um)
        if row["a_i"]:  # rows i = 1, 2, 3 of the matrix (2.50): a_i, b_i, c_i
            cosines = [_float(row[n]) for n in ("a_i", "b_i", "c_i")]
            if table is TABLE_9 and k == 0:
                # ERRATA: Table 9 prints c1 = 0.0504205; sin(a)cos(k) + cos(a)sin(w)sin(k)
                # = 0.05042063 (0.0504207 with 7-digit sines and cosines).
                assert cosines[2] == 0.0504205
                cosines[2] = 0.0504206
            assert_allclose(rot[:, k], cosines, rtol=0, atol=1e-7)


# [1] Table 9 and Table 11 headings (OCR L2149, L2248) print sin α and cos α to 7 decimals for the
# book's α^I and α^III; the project's rotation (2.50) with α alone must carry them: cos α on the
# diagonal, sin α in the (3, 1) element (the sign of the book's α). Tolerance: one unit of the
# 7th printed decimal.
@pytest.mark.parametrize(
    ("angles", "sin_printed", "cos_printed"),
    [
        (ANGLES_I, 0.0522924, 0.9986318),
        # ERRATA: Table 11 prints cos α^III = 0.998295; it is 0.9986295 (a dropped digit).
        (ANGLES_III, 0.0523366, 0.9986295),
    ],
    ids=["table9", "table11"],
)
def test_tables_9_and_11_sine_and_cosine_of_alpha_in_the_rotation(angles, sin_printed, cos_printed):
    r = rotation_matrix(angles[0], 0.0, 0.0)
    assert r[0, 0] == pytest.approx(cos_printed, abs=1e-7)
    assert r[2, 2] == pytest.approx(cos_printed, abs=1e-7)
    assert r[2, 0] == pytest.approx(sin_printed, abs=1e-7)
    assert r[0, 2] == pytest.approx(-sin_printed, abs=1e-7)


# --- Table 10: working equations, approximation II ----------------------------------------------


# [1] §18, Table 10 (OCR L2164-2184), from the printed Table 9 transformed coordinates. The book
# truncates rather than rounds in places (K(3-4) = 141.954065 printed 141.95406;
# Q(2-3) = 206 687.954 printed 206 687.9), so one unit of the last digit.
@pytest.mark.parametrize("row", TABLE_10, ids=lambda r: r["line"])
def test_table10_line_coefficients(row):
    c = line_coefficients(TRANSFORMED_I, POINTS, F)
    k = _line_index(row)
    dx, dy = c.photo_difference_mm[k]
    assert dx == pytest.approx(_float(row["dx0_mm"]), abs=0.005 * um)
    assert dy == pytest.approx(_float(row["dy0_mm"]), abs=0.005 * um)
    assert c.K_mm[k] == pytest.approx(_float(row["K_mm"]), abs=1e-5 * mm)
    assert c.Q[k] == pytest.approx(_float(row["Q"]), abs=0.1)
    a_expected = _float(row["A"])
    if row["line"] == "1-2":
        # ERRATA: Table 10 prints A''(1-2) = 0.998105; [K(X2 - X1) + h(y2 - y1)]/Q
        # = (147.80530*1400 + 83*8.88392)/208797.9 = 0.994573.
        assert a_expected == 0.998105
        a_expected = 0.994573
    assert c.A[k] == pytest.approx(a_expected, abs=1e-6)
    assert c.B[k] == pytest.approx(_float(row["B"]), abs=1e-6)
    assert c.free_term[k] == pytest.approx(_float(row["l_arcsec"]) * arcsec, abs=0.001 * arcsec)


# [1] §18, normal equations II (OCR L2162), from the printed Table 10 rows; half a unit.
def test_normal_equations_second_approximation():
    a = np.array([_float(r["A"]) for r in TABLE_10])
    b = np.array([_float(r["B"]) for r in TABLE_10])
    lv = np.array([_float(r["l_arcsec"]) for r in TABLE_10])
    design = np.column_stack([a, b, np.ones(6)])
    n_matrix, n_const = design.T @ design, design.T @ lv
    # The printed matrix is reproduced from the printed Table 10, i.e. with the slip in A''(1-2).
    expected = np.array(
        [
            [1.934460, -0.155244, 0.056366],
            [-0.155244, 1.951514, -0.102740],
            [0.056366, -0.102740, 6.000000],
        ]
    )
    assert_allclose(n_matrix, expected, rtol=0, atol=1.5e-6)
    # ERRATA: the book prints [Bl] = 25.724901; from the printed Table 10 it is 21.863018. The
    # printed value is obtained with B''(1-3) = +0.011255 instead of -0.011255.
    assert_allclose(n_const, [0.7112104, 21.863018, 1028.627], rtol=0, atol=1e-6 + 0.0005)
    b_slipped = b.copy()
    b_slipped[1] = -b_slipped[1]
    assert b_slipped @ lv == pytest.approx(25.724901, abs=1e-5)
    # With A''(1-2) and [Bl] corrected the corrections are (3.04, -20.01, -171.81)"; the book
    # prints (2.88, -22.03, -171.84)" (its own printed system gives (2.87, -22.00, -171.84)").
    a[0] = 0.994573
    design = np.column_stack([a, b, np.ones(6)])
    corrections = solve_angular_normal_equations(design.T @ design, design.T @ lv * arcsec)
    assert_allclose(corrections, np.array([3.04, -20.01, -171.81]) * arcsec, atol=0.005 * arcsec)


# Independent computation (conventions.md §11.1): the clean iteration of the book's method from
# the printed Table 7 coordinates converges to (10800.004, 7199.982, -10800.003)"; the rounding
# of the printed photo coordinates (<= 0.02 um, i.e. 0.05" at f = 75 mm) bounds its distance from
# the true angles: 0.05".
def test_clean_iteration_converges_to_true_angles():
    result = angular_elements_by_lines(PHOTO, POINTS, F)
    assert result.converged
    angles = np.array([result.alpha, result.omega, result.kappa])
    assert_allclose(angles, np.array([10800.0, 7200.0, -10800.0]) * arcsec, atol=0.05 * arcsec)
    assert_allclose(
        angles, np.array([10800.004, 7199.982, -10800.003]) * arcsec, atol=0.0005 * arcsec
    )
    # From error-free photo coordinates the fixed point is the true orientation.
    exact = angular_elements_by_lines(TRUE_PHOTO, POINTS, F, tolerance=1e-6 * arcsec)
    assert_allclose(
        [exact.alpha, exact.omega, exact.kappa], TRUE_ANGLES, rtol=0, atol=1e-4 * arcsec
    )


# --- Table 12: Z_S by (3.26)/(3.27) --------------------------------------------------------------


# [1] §18, Table 12 (OCR L2257-2269), from the printed Table 11 coordinates, with the corrected
# (3.26) (conventions.md §12 item 28). Half a unit of the last digit, except D0, which the book
# computed from its rounded Delta X, Delta Y (D0(1-2) = 1489.93267 printed 1489.9326): 1e-4 m.
@pytest.mark.parametrize("row", TABLE_12, ids=lambda r: r["line"])
def test_table12_flying_height_by_lines(row):
    lines = flying_height_by_lines(TRANSFORMED_III, POINTS, F)
    k = _line_index(row)
    assert tuple(lines.pairs[k] + 1) == (int(row["i"]), int(row["j"]))
    assert_allclose(
        lines.photo_difference_mm[k],
        [_float(row["dx0_mm"]), _float(row["dy0_mm"])],
        rtol=0,
        atol=0.005 * um,
    )
    assert_allclose(
        lines.ground_difference_m[k], [_float(row["dX_m"]), _float(row["dY_m"])], atol=5e-5 * m
    )
    assert lines.ground_distance_m[k] == pytest.approx(_float(row["D0_m"]), abs=1e-4 * m)
    assert lines.height_above_point_m[k] == pytest.approx(
        _float(row["ZS_minus_Zi_m"]), abs=5e-5 * m
    )
    assert lines.projection_centre_height_m[k] == pytest.approx(_float(row["ZS_m"]), abs=5e-5 * m)
    # The weights are ratios of squared *ground* distances D0 (not photo distances).
    assert lines.weight[k] == pytest.approx(_float(row["p"]), abs=0.005)


# [1] §18, Table 12 foot (OCR L2267-2269): weighted mean Z_S = 750.000 m (printed 750.0001 and
# rounded; recomputed 749.99999606). Half a unit of the millimetre.
def test_table12_weighted_mean_height():
    lines = flying_height_by_lines(TRANSFORMED_III, POINTS, F)
    assert projection_centre_height(lines) == pytest.approx(750.000, abs=0.0005 * m)


# --- Table 13: X_S, Y_S by (3.28)/(3.29) ---------------------------------------------------------


# [1] §18, Table 13 (OCR L2271-2276), from the printed Table 11 coordinates and Z_S = 750.000 m.
# Half a unit of the last digit.
@pytest.mark.parametrize("row", TABLE_13, ids=lambda r: f"point{r['point']}")
def test_table13_plan_position_by_points(row):
    plan = projection_centre_plan_by_points(TRANSFORMED_III, POINTS, 750.000, F)
    k = int(row["point"]) - 1
    assert_allclose(plan[k], [_float(row["XS_m"]), _float(row["YS_m"])], rtol=0, atol=5e-5 * m)
    reduction = POINTS[k, :2] - plan[k]  # (Z_S - Z_i) x0/f, (Z_S - Z_i) y0/f
    assert_allclose(reduction, [_float(row["dX_m"]), _float(row["dY_m"])], rtol=0, atol=5e-5 * m)


# [1] §18, Table 13 bottom line and OCR L2240-2242: X_S = 2799.999 m, Y_S = 699.997 m (errors of
# -1 and -3 mm); half a unit of the millimetre.
def test_table13_mean_plan_position():
    plan = projection_centre_plan_by_points(TRANSFORMED_III, POINTS, 750.000, F)
    assert_allclose(plan.mean(axis=0), [2799.999, 699.997], rtol=0, atol=0.0005 * m)


# Independent computation: the whole §18 chain from the printed Table 7 coordinates, iterated to
# convergence, recovers the true projection centre to 1 mm.
def test_book_method_end_to_end():
    result = book_space_resection(PHOTO, POINTS, F)
    assert_allclose(result.projection_centre_m, TRUE_CENTRE, rtol=0, atol=0.001 * m)


# --- Rigorous resection (2.53) on the Table 7 data ------------------------------------------------


# Independent computation: rigorous least squares on (2.53) with the error-free coordinates
# computed from the true orientation. Brief: 0.1" and 1 mm; the solution is exact to ~1e-9.
def test_rigorous_resection_from_error_free_table7():
    result = space_resection(TRUE_PHOTO, POINTS, F)
    assert result.converged
    assert_allclose(result.angles, TRUE_ANGLES, rtol=0, atol=0.1 * arcsec)
    assert_allclose(result.projection_centre_m, TRUE_CENTRE, rtol=0, atol=0.001 * m)
    assert result.rms_residual_mm < 1e-12 * mm


# Rigorous resection from the printed 5-decimal Table 7 coordinates. They deviate from the
# error-free ones by <= 0.018 um (sigma ~ 0.01 um); propagated through the covariance of this
# 4-point geometry that is 0.014" in the angles and 0.11 mm in X_S, Y_S: 4 sigma gives the
# tolerances 0.06" and 0.5 mm. (Observed: 0.02" and 0.03 mm.)
def test_rigorous_resection_from_printed_table7():
    result = space_resection(PHOTO, POINTS, F)
    assert_allclose(result.angles, TRUE_ANGLES, rtol=0, atol=0.06 * arcsec)
    assert_allclose(result.projection_centre_m, TRUE_CENTRE, rtol=0, atol=0.5e-3 * m)
    assert result.rms_residual_mm < 0.02 * um
