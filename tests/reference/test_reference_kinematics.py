"""Reference tests of the kinematic acceptance: ``kinematics.md`` §5 and §6.

Reference: the tables of ``/work/shared/design/kinematics.md`` (§5 "[1] Stage 2 in the variants",
§6 "Residual y-parallax of the per-axis approximation", and the §5 sanity checks). They come from
an independent reference implementation of the same model (kinematics.md, preamble and §8), so
they count as an independent computation (style.md §5).

Tolerance (kinematics.md preamble): 0.1 µm or 1 %, whichever is larger, and never tighter than
half a unit of the last printed digit (style.md §5). A printed "0" means < 1e-6° or < 0.1 µm
(kinematics.md §5, below the table).

Where this implementation disagrees with the document beyond that tolerance the test pins our own
value with a ``# DISCREPANCY:`` comment saying why.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from conftest import deg, mm, um
from scipy.optimize import least_squares

from stereoplotter.procedure.selftest import (
    SyntheticPair,
    apply_touch_up,
    format_selftest,
    run_kinematic_selftest,
    sign_combinations,
    touch_up,
    true_units,
    y_parallax,
)


@pytest.fixture(scope="module")
def selftest():
    return run_kinematic_selftest()


# The absolute floor of the tolerance, 0.1 µm, in the unit of each column.
UM_COLUMN = 0.1 * um / um
MM_COLUMN = 0.1 * um / mm
NO_FLOOR = 0.0


def _tolerance(printed: str, floor: float) -> float:
    """max(floor, 1 % of the value, half a unit of the last printed digit)."""
    value = abs(float(printed))
    decimals = len(printed.split(".")[1]) if "." in printed else 0
    half_digit = 0.5 * 10.0**-decimals
    return max(floor, 0.01 * value, half_digit)


def _check(found: float, printed: str, floor: float, what: str) -> None:
    tol = _tolerance(printed, floor)
    assert abs(found - float(printed)) <= tol, (
        f"{what}: kinematics.md prints {printed}, found {found:.6g} (tolerance {tol:.3g})"
    )


# --- §5 sanity checks ------------------------------------------------------------------------


def test_sanity_exact_rectification(selftest):
    # kinematics.md §5 "Sanity checks": q = 3e-11 µm, model = A(ground) to 1e-10 µm; unit round
    # trip 7e-15 mm, instrument round trip 6e-14 mm. Rounding-level numbers: asserted as
    # "at rounding level" (1e-9 mm) rather than digit by digit.
    s = selftest["sanity"]
    assert s["exact_rectification_max_q_um"] < 1e-6
    assert s["affine_model_max_error_um"] < 1e-6
    assert s["unit_round_trip_mm"] < 1e-9
    assert s["instrument_round_trip_mm"] < 1e-9


def test_data_of_the_synthetic_pair(selftest):
    # kinematics.md §5 "Data": n_л = 1.423, M_г = 1:7027, M_в = 1:5405, b_z′ = 2.775 mm
    # (b_z = 2.135 mm at horizontal scale).
    d = selftest["data"]
    assert d["n_left"] == pytest.approx(1.423, abs=0.0005)
    assert d["horizontal_scale_denominator"] == pytest.approx(7027, abs=0.5)
    assert d["vertical_scale_denominator"] == pytest.approx(5405, abs=0.5)
    assert d["base_mm"][2] == pytest.approx(2.775, abs=0.0005)
    assert d["base_mm"][2] / 1.3 == pytest.approx(2.135, abs=0.0005)
    assert d["points"] == 49


# --- §6 table ---------------------------------------------------------------------------------

# (unit, t [°], max|q| [µm], RMS q [µm], after touch-up [µm], height deformation [‰ H])
SECTION6 = [
    ("canonical", 0.5, "0.5", "0.2", "0.1", "0.014"),
    ("canonical", 1.0, "2.2", "0.9", "0.2", "0.057"),
    ("canonical", 3.0, "22.6", "9.7", "3.8", "0.54"),
    ("strict per-axis", 0.5, "610", "347", "75", "7.1"),
    ("strict per-axis", 1.0, "1227", "694", "152", "14"),
    ("strict per-axis", 3.0, "3760", "2090", "497", "43"),
]

# DISCREPANCY: strict per-axis unit, "after touch-up" at 0.5° and 1°. kinematics.md prints 75
# and 152 µm; our touch-up (Levenberg–Marquardt from the set state, cost decreasing monotonically,
# checked against scipy.optimize.least_squares below) gives 80.8 and 162.5 µm. For the strict unit
# the least-squares problem over (κ_п, κ_л, θ_ω,п, b_y, b_z′) has several far-apart local minima,
# all with κ changes of ≈ 0.7 rad and b_y changes of ≈ 80 mm (not a "touch-up" at all). An
# undamped Gauss–Newton from the same start overshoots and lands in another minimum, with
# 75.3 / 151.5 / 496.7 µm: the document's numbers, so its reference evidently used such a solver.
# A multi-start search finds still lower minima (465 µm at 3°). The column is therefore
# solver-dependent for the strict unit; the conclusion (mm-level q before, 10² µm after) is not.
# We pin our local-minimum values; test_strict_touch_up_has_the_documented_minimum shows the
# document's value is a genuine least-squares minimum reached from another start.
STRICT_TOUCH_UP_PINNED = {0.5: "80.8", 1.0: "162.5", 3.0: "496.7"}


@pytest.mark.parametrize(
    ("unit", "tilt", "max_q", "rms_q", "after", "deformation"),
    SECTION6,
    ids=[f"{r[0].split()[0]}-{r[1]}deg" for r in SECTION6],
)
def test_section6_residual_parallax(selftest, unit, tilt, max_q, rms_q, after, deformation):
    rows = [r for r in selftest["residuals"] if r["unit"] == unit and r["tilt_deg"] == tilt]
    assert len(rows) == 1
    r = rows[0]
    what = f"§6 {unit} {tilt}°"
    _check(r["max_q_um"], max_q, UM_COLUMN, f"{what} max|q| [µm]")
    _check(r["rms_q_um"], rms_q, UM_COLUMN, f"{what} RMS q [µm]")
    if unit == "strict per-axis":
        after = STRICT_TOUCH_UP_PINNED[tilt]
    _check(r["max_q_after_touch_up_um"], after, UM_COLUMN, f"{what} after touch-up [µm]")
    # The deformation column is the state before the touch-up (b and κ exact, "after
    # levelling + scaling"); after the touch-up the strict unit gives 15 / 31 / 107 ‰ H.
    _check(r["height_deformation_permille"], deformation, NO_FLOOR, f"{what} deformation [‰ H]")


# --- §5 [1] table -------------------------------------------------------------------------------

# (variant, t [°], α_л error [°], ω_л error [°], mark-4 mismatch [mm], max|q| [µm], RMS [µm],
#  after touch-up [µm]); "0" = < 1e-6° or < 0.1 µm. B2's max|q| / RMS print "as L".
SECTION5 = [
    ("L", 0.5, "0", "0", "0.0000", "0.1", "0.0", "0.0"),
    ("L", 1.0, "0", "0", "0.0000", "0.4", "0.2", "0.0"),
    ("L", 3.0, "0", "0", "0.0000", "6.6", "2.3", "0.0"),
    ("A", 0.5, "-0.0043", "-0.0021", "0.013", "5.1", "2.0", "0.0"),
    ("A", 1.0, "-0.0174", "-0.0086", "0.053", "20.7", "8.0", "0.2"),
    ("A", 3.0, "-0.160", "-0.076", "0.489", "202", "74", "5.7"),
    ("B", 0.5, "0.68", "-0.70", "0.031", "2588", "999", "726"),
    ("B", 1.0, "1.34", "-1.43", "0.123", "5194", "2010", "1433"),
    ("B", 3.0, "3.71", "-4.58", "1.103", "15784", "6128", "3968"),
    ("B2", 0.5, "0", "0", "0", "0.1", "0.0", "0.0"),
    ("B2", 1.0, "0", "0", "0", "0.4", "0.2", "0.1"),
    ("B2", 3.0, "0", "0", "0", "6.6", "2.3", "1.5"),
    ("S", 0.5, "0", "0", "0", "571", "232", "41"),
    ("S", 1.0, "0", "0", "0", "1135", "461", "81"),
    ("S", 3.0, "0", "0", "0", "3325", "1353", "224"),
]


@pytest.mark.parametrize(
    ("variant", "tilt", "d_alpha", "d_omega", "mark4", "max_q", "rms_q", "after"),
    SECTION5,
    ids=[f"{r[0]}-{r[1]}deg" for r in SECTION5],
)
def test_section5_stage2_variants(
    selftest, variant, tilt, d_alpha, d_omega, mark4, max_q, rms_q, after
):
    rows = [r for r in selftest["stage2"] if r["variant"] == variant and r["tilt_deg"] == tilt]
    assert len(rows) == 1
    r = rows[0]
    what = f"§5 {variant} {tilt}°"
    for key, printed in (("alpha_left_error_deg", d_alpha), ("omega_left_error_deg", d_omega)):
        if printed == "0":
            assert abs(r[key]) < 1e-6, f"{what} {key}: {r[key]}"
        else:
            _check(r[key], printed, NO_FLOOR, f"{what} {key} [°]")
    # The mismatch is measured on the photo (what the operator sees at mark 4); as a Y-counter
    # difference it would be n·|Δη| ≈ 1.47 times larger (0.046 mm for B at 0.5°).
    if mark4 == "0":
        assert r["mark4_mismatch_mm"] < 0.1 * um / mm
    else:
        _check(r["mark4_mismatch_mm"], mark4, MM_COLUMN, f"{what} mark-4 mismatch [mm]")
    _check(r["max_q_um"], max_q, UM_COLUMN, f"{what} max|q| [µm]")
    _check(r["rms_q_um"], rms_q, UM_COLUMN, f"{what} RMS q [µm]")
    _check(r["max_q_after_touch_up_um"], after, UM_COLUMN, f"{what} after touch-up [µm]")


def test_mark4_tolerance_verdicts(selftest):
    # kinematics.md §0 item 3 and §4.1: B fails the book's ±0.02·n_л (0.028 mm) at every tilt, A
    # from 1° on; L, B2 and S pass. (§26, OCR L3786: "не должна превышать ±0,02 n_л".)
    fails = {
        (r["variant"], r["tilt_deg"])
        for r in selftest["stage2"]
        if r["mark4_mismatch_mm"] > r["mark4_tolerance_mm"]
    }
    assert fails == {("B", 0.5), ("B", 1.0), ("B", 3.0), ("A", 1.0), ("A", 3.0)}
    assert selftest["stage2"][0]["mark4_tolerance_mm"] == pytest.approx(0.028, abs=0.0005)


def test_fitted_tilt_ratio_in_variant_b(selftest):
    # kinematics.md §4.1 table: "fitted/true (B) ≈ 2.4 / 2.3–2.4 / 2.2–2.5".
    for r in selftest["stage2"]:
        if r["variant"] == "B":
            t = r["tilt_deg"]
            ratio_a = (r["alpha_left_error_deg"] + t) / t
            ratio_w = (r["omega_left_error_deg"] - t) / -t
            assert 2.2 <= ratio_a <= 2.5
            assert 2.2 <= ratio_w <= 2.6


# --- the result as data -----------------------------------------------------------------------


def test_result_is_json_ready_and_formatted(selftest):
    import json

    again = json.loads(json.dumps(selftest))
    assert again["stage2"][0]["variant"] == "L"
    text = format_selftest(selftest)
    assert text.endswith("\n")
    assert "§6 Residual y-parallax" in text and "§5 Stage 2" in text
    # one line per row of each table
    assert sum(line.startswith(("canonical", "strict")) for line in text.splitlines()) == 6
    assert sum(" FAIL" in line for line in text.splitlines()) == 5


def test_instrument_spec_supplies_d_max():
    from stereoplotter.io.instrument_file import load_instrument

    spec = load_instrument("sc1")
    r = run_kinematic_selftest(tilts=[1.0 * deg], variants=("L",), instrument=spec)
    assert r["data"]["projection_distance_max_mm"] == spec.projection_distance_max_mm
    # one row per unit: the canonical, the strict per-axis and the SC-1's own mechanism
    rows = [(row["unit"], row["tilt_deg"]) for row in r["residuals"]]
    assert rows == [
        ("canonical", 1.0),
        ("strict per-axis", 1.0),
        ("sc1_mechanical_projection", 1.0),
    ]


# --- the touch-up solver ---------------------------------------------------------------------


def test_touch_up_agrees_with_scipy():
    # Independent check of the batched Levenberg–Marquardt: scipy.optimize.least_squares on the
    # same residual function, canonical unit, 3°, three sign combinations.
    pair = SyntheticPair()
    setting = pair.setting()
    tilts = sign_combinations()[[0, 5, 10]] * (3.0 * deg)
    pl, pr = pair.photos(tilts)
    left, right = true_units(pair, tilts, strict=False)
    q, _, _ = touch_up(pl, pr, setting, left, right, "L")
    for b in range(3):

        def one(u, b=b):
            return replace(
                u,
                tan_alpha=u.tan_alpha[b],
                tan_omega=u.tan_omega[b],
                decentration_x_mm=u.decentration_x_mm[b],
                decentration_y_mm=u.decentration_y_mm[b],
            )

        lu, ru = one(left), one(right)

        def fun(x, b=b, lu=lu, ru=ru):
            s, l2, r2 = apply_touch_up(x[None, :], setting, lu, ru, "L")
            return y_parallax(pl[b : b + 1], pr[b : b + 1], s, l2, r2).y_parallax_mm.ravel()

        ref = least_squares(fun, np.zeros(5), x_scale=[1e-3, 1e-3, 1e-3, 0.1, 0.1])
        assert np.sum(q[b] ** 2) <= np.sum(ref.fun**2) * (1 + 1e-6)
        assert np.max(np.abs(q[b])) == pytest.approx(np.max(np.abs(ref.fun)), abs=0.01 * um)


def test_strict_touch_up_has_the_documented_minimum():
    # See DISCREPANCY above: starting the touch-up with both κ turned by −0.4 rad (and the
    # settings otherwise unchanged) reaches the minimum behind kinematics.md's 75 µm at 0.5°,
    # whose cost is lower than that of the minimum nearest to the set state.
    pair = SyntheticPair()
    setting = pair.setting()
    tilts = sign_combinations() * (0.5 * deg)
    pl, pr = pair.photos(tilts)
    left, right = true_units(pair, tilts, strict=True)
    q_near, _, _ = touch_up(pl, pr, setting, left, right, "L")
    shifted = (replace(left, kappa=left.kappa - 0.4), replace(right, kappa=right.kappa - 0.4))
    q_far, _, _ = touch_up(pl, pr, setting, *shifted, "L")
    best = np.where(
        np.sum(q_far**2, -1) < np.sum(q_near**2, -1),
        np.max(np.abs(q_far), -1),
        np.max(np.abs(q_near), -1),
    )
    assert np.max(best) / um == pytest.approx(75.0, abs=0.5)
    assert np.max(np.abs(q_near)) / um == pytest.approx(80.8, abs=0.05)
