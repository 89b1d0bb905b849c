"""Linear Monte Carlo and covariance propagation against the rigorous formulas (style.md §10).

Tolerances are derived from the run's own standard error: |MC − rigorous| < CI half-width at
z = 3.29 (plus the midpoint-grid error of the covariance, < 2·10⁻³ relative at 16 × 32).
"""

import json
import math

import numpy as np
import pytest

from stereoplotter.accuracy import ROW_KEYS, VERDICTS, run_verification, write_verification
from stereoplotter.accuracy import montecarlo as mc

TRIALS = 3000  # per row; CI half-width ≈ 3.29/√(2·3000) = 4.2 % for one source


@pytest.fixture(scope="module")
def rows():
    return run_verification(trials=TRIALS, seed=7)


def test_every_equation_628_to_661_has_a_row(rows):
    eqs = {r["eq"] for r in rows}
    missing = [f"(6.{k})" for k in range(28, 62) if f"(6.{k})" not in eqs]
    assert not missing
    for r in rows:
        assert set(r) == set(ROW_KEYS)
        assert r["verdict"] in VERDICTS and r["note"]


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


def test_plots_have_data(rows):
    from stereoplotter import accuracy_plot as ap

    ax = ap.plot_verification_chart(rows)
    assert len(ax.lines) >= 3
    fig = ap.plot_error_maps(grid=(8, 16))
    assert len(fig.axes) >= 4
    m = mc.least_squares_model(np.eye(1), 1.0, 0)
    assert ap.plot_mc_histogram(m, 1.0, trials=500).patches
    import matplotlib.pyplot as plt

    plt.close("all")
