"""Linear Monte Carlo and covariance propagation against the rigorous formulas (style.md §10).

Tolerances are derived from the run's own standard error: |MC − rigorous| < CI half-width at
z = 3.29 (plus the midpoint-grid error of the covariance, < 2·10⁻³ relative at 16 × 32).
"""

import json
import math

import numpy as np
import pytest

from stereoplotter.commands.verification import write_verification
from stereoplotter.verification import ROW_KEYS, run_verification
from stereoplotter.verification import linear_mc as mc
from stereoplotter.verification.verdicts import is_verdict

TRIALS = 3000  # per row; CI half-width ≈ 3.29/√(2·3000) = 4.2 % for one source


@pytest.fixture(scope="module")
def rows():
    return run_verification(trials=TRIALS, seed=7, procedure_trials=0)


def test_every_equation_628_to_661_has_a_row(rows):
    eqs = {r["eq"] for r in rows}
    missing = [f"(6.{k})" for k in range(28, 62) if f"(6.{k})" not in eqs]
    assert not missing
    for r in rows:
        assert set(r) == set(ROW_KEYS)
        assert is_verdict(r["verdict"]) and r["note"], (r["eq"], r["verdict"])


def test_mc_and_covariance_agree_with_rigorous(rows):
    for r in rows:
        tol = r["mc_linear_ci"] + 2e-3 * r["rigorous"]
        assert abs(r["mc_linear"] - r["rigorous"]) < tol, r["eq"]
        assert abs(r["covariance"] - r["rigorous"]) < 2e-3 * r["rigorous"], r["eq"]


def test_half_width_scales_as_derived():
    m = mc.least_squares_model(np.eye(1), 1.0, 0)
    _, h, _ = mc.mc_rms(m, 20000, np.random.default_rng(3))
    assert h == pytest.approx(mc.CI_Z / math.sqrt(2 * 20000), rel=0.05)


def test_seeded_and_reproducible():
    a = run_verification(trials=200, seed=11)
    b = run_verification(trials=200, seed=11)
    assert [r["mc_linear"] for r in a] == [r["mc_linear"] for r in b]


def test_statistic_is_rms_not_mean_of_sigmas():
    # field with a pointwise σ varying over the grid: RMS² = mean σ², not (mean σ)²
    m = mc.setup_model(70.0, 70.0, 0.0, 70.0, {"kappa_left": 1e-3}, levelled=False)
    r, h, _ = mc.mc_rms(m, 4000, np.random.default_rng(5))
    assert abs(r - 1e-3 * 70 / math.sqrt(3)) < h + 1e-3 * 70 * 2e-3


def test_write_verification(tmp_path, rows):
    paths = write_verification(rows, tmp_path, trials=TRIALS, seed=7)
    assert {p.name for p in paths} >= {"verification.md", "verification.csv", "verification.json"}
    data = json.loads((tmp_path / "verification.json").read_text())
    assert len(data) == len(rows) and data[0]["mc_procedure"] is None
    assert "Closing comparison" in (tmp_path / "verification.md").read_text()


def test_geometry_override_rejects_unknown_key():
    with pytest.raises(ValueError, match="geometry keys"):
        run_verification(trials=10, geometry={"focal": 100})


def test_plots_draw_against_the_rigorous_reference(rows):
    from stereoplotter.plotting import accuracy as ap

    ax = ap.plot_verification_chart(rows)
    assert ax.get_yscale() == "log"
    # each series is value / rigorous: the book-formula points of (6.43) and (6.44)
    by_label = {line.get_label(): line.get_ydata() for line in ax.lines}
    i43 = [r["eq"] for r in rows].index("(6.43)")
    assert by_label["book formula"][i43] == pytest.approx(1.2604 / 1.2143, abs=1e-3)
    # histograms: the red line is the rigorous value at the table's geometry (here a user one)
    g = {
        "f": 100.0,
        "l": 90.0,
        "n": 1.6,
        "c": 80.0,
        "p60": 80.0,
        "a60": 0.0,
        "p80": 40.0,
        "a80": 40.0,
    }
    other = run_verification(trials=100, seed=1, geometry=g, procedure_trials=0)
    fig = ap.plot_mc_histograms(other, trials=300, geometry=g)
    ref = {r["eq"]: r["rigorous"] for r in other}
    for axh, eq in zip(fig.axes, ("(6.43)", "(6.44)"), strict=False):
        red = next(ln for ln in axh.lines if ln.get_color() == "r")
        assert red.get_xdata()[0] == pytest.approx(ref[eq])
        blue = next(ln for ln in axh.lines if ln.get_color() == "b")
        # the linear MC of the rigorous model agrees with it (300 trials, 99.9 % CI ≈ 14 %)
        assert blue.get_xdata()[0] == pytest.approx(ref[eq], rel=0.15)
    import matplotlib.pyplot as plt

    plt.close("all")


# --- procedure MC, --geometry, histograms (issue 6 items 1-3) ---------------------------------


def test_procedure_mc_setup_matches_formula_at_simulated_geometry():
    from stereoplotter.accuracy import setup_accuracy as sa
    from stereoplotter.io.book_setting import book_instrument, book_scenarios
    from stereoplotter.verification.procedure_mc import procedure_mc

    sc = book_scenarios()["60"]
    r = procedure_mc(sc, "setup", spec=book_instrument(), trials=3000, seed=3)
    # the unit-consistent (6.39) at the simulated geometry (derived with sympy in
    # tests/reference/test_reference_accuracy.py); the procedure agrees within its 99.9 % CI
    # (≈ 4 % at T = 3 000; the note's first-order difference is +1.6 %), no added margin
    ref = sa.setup_parallax_rms_from_pointing(
        r["f"], r["p"], r["c"], r["l"], r["n"], 1.0, mode="rigorous"
    )
    assert r["ci"] < 0.05 * ref
    assert abs(r["coefficient"] - ref) < r["ci"]
    assert r["n"] == pytest.approx(1.69, abs=0.01)  # our SC-1 sheet, not the book's 1.42


def test_procedure_columns_filled_and_disabled():
    """Issue 10 (3, 4): every outcome row of §27 at the slot that was simulated gets the
    procedure value, its CI, the formula at the simulated geometry and the value with instrument
    errors; the other slot's rows and every other row stay empty."""
    from stereoplotter.io.book_setting import book_instrument, book_scenarios
    from stereoplotter.verification.table import (
        PROCEDURE_ROWS,
        attach_procedure_mc,
        run_procedure_mc,
    )

    proc = run_procedure_mc(100, 2, {"60": book_scenarios()["60"]}, instrument=book_instrument())
    rows = attach_procedure_mc(run_verification(trials=200, seed=2, procedure_trials=0), proc)
    outcome = {f"(6.{i})" for i in range(39, 62)}
    assert set(PROCEDURE_ROWS) == outcome
    keys = ("mc_procedure", "mc_procedure_ci", "mc_procedure_formula", "mc_procedure_instrument")
    for r in rows:
        filled = r["eq"] in outcome and PROCEDURE_ROWS[r["eq"]][0] == "60"
        assert all((r[k] is not None) == filled for k in keys), r["eq"]
        assert ("procedure MC (pair60" in r["note"]) == filled
    off = run_verification(trials=200, seed=2, procedure_trials=0)
    assert all(r["mc_procedure"] is None for r in off)


def test_procedure_mc_needs_loaded_inputs():
    # the verification layer reads no files: no scenarios, no procedure MC; a scenario without
    # its instrument is refused
    from stereoplotter.io.book_setting import book_scenarios
    from stereoplotter.verification.table import run_procedure_mc

    rows = run_verification(trials=50, seed=2, procedure_trials=50)
    assert all(r["mc_procedure"] is None for r in rows)
    with pytest.raises(ValueError, match="instrument"):
        run_procedure_mc(50, 2, book_scenarios())


def test_geometry_book_explicit_equals_default():
    from stereoplotter.verification.table import BOOK

    a = run_verification(trials=300, seed=4, procedure_trials=0)
    b = run_verification(trials=300, seed=4, geometry=dict(BOOK), procedure_trials=0)
    for x, y in zip(a, b, strict=True):
        assert {k: x[k] for k in x if k != "note"} == {k: y[k] for k in y if k != "note"}


@pytest.mark.parametrize(
    "geometry",
    [
        {"f": 100.0, "l": 90.0, "n": 1.6, "c": 80.0, "p60": 80.0, "p80": 40.0},
        {"c": 75.0, "p60": 72.0, "p80": 36.0},
    ],
)
def test_other_geometry_rigorous_and_mc_agree(geometry):
    rows = run_verification(trials=TRIALS, seed=8, geometry=geometry, procedure_trials=0)
    for r in rows:
        assert abs(r["mc_linear"] - r["rigorous"]) < r["mc_linear_ci"] + 2e-3 * r["rigorous"], (
            r["eq"],
            r["quantity"],
        )


def test_geometry_from_scenario_file():
    from stereoplotter.io.geometry_file import geometry_from_file

    g, scen = geometry_from_file("scenarios/pair80.yaml")
    assert g["p80"] == pytest.approx(36.1, abs=0.1) and g["c"] == pytest.approx(2 * g["p80"])
    assert scen["60"] is None and scen["80"].source == "scenarios/pair80.yaml"


def test_cli_verify_geometry_and_histograms(tmp_path):
    from stereoplotter.cli import main

    rc = main(
        [
            "verify",
            "--trials",
            "300",
            "--procedure-trials",
            "100",
            "--geometry",
            "scenarios/pair60.yaml",
            "-o",
            str(tmp_path),
        ]
    )
    assert rc == 0
    assert (tmp_path / "mc_histograms.png").stat().st_size > 1000
    data = json.loads((tmp_path / "verification.json").read_text())
    by = {r["eq"]: r for r in data}
    assert by["(6.43)"]["mc_procedure"] is not None and by["(6.44)"]["mc_procedure"] is None
    # the verdicts are recomputed for the file's geometry: no printed number, no book arithmetic
    assert by["(6.43)"]["printed"] is None and by["(6.45)"]["from_printed_inputs"] is None
    assert "geometry differs from the book's" in by["(6.43)"]["note"]
    import matplotlib.pyplot as plt

    plt.close("all")


@pytest.mark.parametrize("slot", ["60", "80"])
def test_procedure_mc_conventional_heights_datum_mechanisms(slot):
    """Issue 9 (2): the total M_p of the conventional method (6.60)/(6.61) by the simulated
    operator (T = 20 000, seed 20240601, docs/accuracy.md): the old quantity δp at the ideal
    model position 1.058 / 1.170; heights as read with the height scale slipped at one levelling
    point 1.453 / 1.529 (2.0x); with the book's datum 0.723 / 0.766. The remaining +5.4 % /
    +5.9 % over the rigorous 0.686 / 0.724 is the levelling points: the procedure levels on the
    scenario's control points nearest standard points 3-6 (x_п -83...12 / -80...46, y ±78), not
    at Fig. 39's x_п ∈ {-c, a}, y = ±c; the same rigorous model with the plane at those points
    gives 0.7210 / 0.7632. Pinned here at T = 4 000 (CI ≈ ±2.5 %)."""
    from stereoplotter.accuracy.chapter5 import relative_orientation_parallax_rms
    from stereoplotter.io.book_setting import book_instrument, book_scenarios
    from stereoplotter.verification.procedure_mc import procedure_mc

    r = procedure_mc(
        book_scenarios()[slot], "conventional", spec=book_instrument(), trials=4000, seed=11
    )
    by, formula = r["by_datum"], r["formula"]
    ro = relative_orientation_parallax_rms(r["a"], r["c"], r["p"], 1.0, "rigorous")
    book = {"60": 0.6862, "80": 0.7235}[slot]
    assert math.hypot(ro, {"60": 0.6455, "80": 0.6310}[slot]) == pytest.approx(book, abs=1e-3)
    assert formula["book"] == pytest.approx(book, abs=1e-3)
    # the mechanism: the plane at the procedure's levelling points raises the formula itself
    # by 5.1 % / 5.5 % (its (5.54) part 0.2325 -> 0.3877 / 0.3539 -> 0.4607)
    assert formula["procedure"] / formula["book"] == pytest.approx(
        {"60": 1.0513, "80": 1.0552}[slot], abs=2e-3
    )
    plane, ci = by["plane"]
    assert abs(plane - formula["procedure"]) <= ci  # mechanism on: the formula at its points
    levelled, ci_book = by["book"]
    assert abs(levelled - formula["book"]) <= ci_book  # off: re-levelled at Fig. 39's points
    # the one-point slip of the height scale: ≈ 2.0× the book's datum (measured 2.01 / 2.00)
    assert by["slip"][0] / plane == pytest.approx(2.0, rel=0.08)
    assert r["coefficient"] == pytest.approx(plane)


@pytest.mark.parametrize("slot", ["60", "80"])
def test_procedure_mc_conventional_relative_part_is_the_levelling_points(slot):
    """The σ_q part alone (sources="y_parallax"): 0.38 / 0.46 of the full procedure was the
    unexplained remainder against (5.54) 0.2327 / 0.3540. It is (5.54) with the plane at the
    procedure's levelling points (0.3877 / 0.4607; T = 20 000: 0.3879 ± 0.0058 / 0.4673 ± 0.0067);
    re-levelled at Fig. 39's points the
    same trials give (5.54) (the shipped tilts and relief lower it by 0-6 %, as in
    test_conventional_relative.py)."""
    from stereoplotter.io.book_setting import book_instrument, book_scenarios
    from stereoplotter.verification.procedure_mc import procedure_mc

    r = procedure_mc(
        book_scenarios()[slot],
        "conventional",
        spec=book_instrument(),
        trials=4000,
        seed=11,
        sources="y_parallax",
    )
    formula = r["formula"]
    assert formula["book"] == pytest.approx({"60": 0.2327, "80": 0.3540}[slot], abs=5e-4)
    assert formula["procedure"] == pytest.approx({"60": 0.3877, "80": 0.4607}[slot], abs=5e-4)
    plane, ci = r["by_datum"]["plane"]
    # within CI; at 80 % the σ_q part runs +1.4 % (T = 20 000: 0.4673 ± 0.0067, the CI's edge;
    # C2's stopping rule, docs/accuracy.md), so up to +3 % is allowed above
    assert formula["procedure"] - ci <= plane <= 1.03 * formula["procedure"] + ci
    levelled, ci_book = r["by_datum"]["book"]
    assert 0.94 * formula["book"] - ci_book <= levelled <= formula["book"] + ci_book
