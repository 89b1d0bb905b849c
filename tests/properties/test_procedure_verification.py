"""Issue 10 (2-4): the procedure Monte Carlo of every outcome row of §27 — the linear control
variate, setup data refined on control (task 2) and the runs with instrument errors — against
independent derivations."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stereoplotter.accuracy.chapter5 import geodetic_orientation_parallax_rms
from stereoplotter.instrument.error_model import ErrorModel, ErrorTerm
from stereoplotter.io.book_setting import book_instrument, book_scenarios
from stereoplotter.procedure.fidelity import MECHANISMS, Fidelity
from stereoplotter.verification import control_variate as cvar
from stereoplotter.verification.linear_mc import CI_Z
from stereoplotter.verification.procedure_mc import procedure_mc
from stereoplotter.verification.table import procedure_rows


def _term(name, distribution, scale):
    return ErrorTerm(name, distribution, scale, "mm", "test", True, "test")


def test_control_variate_unbiased_on_a_known_non_linear_field():
    """v(x) = b(x) + g₁(x)·z + g₂(x)·u + k·z² over three points, z standard normal (an operator
    act), u uniform on [−a, a] (an instrument term). Exact, from E z² = 1, E z³ = 0, E z⁴ = 3,
    E u² = a²/3: E[mean v²] = mean over x of b² + g₁² + g₂²a²/3 + 3k² + 2bk. The controlled
    estimate is within its 99.9 % CI of it, with a CI far narrower than the plain mean's; a field
    linear in the draws is estimated exactly."""
    b = np.array([0.1, -0.2, 0.05])
    g1 = np.array([1.0, 0.5, -0.3])
    g2 = np.array([0.2, -0.4, 0.6])
    a, k = 0.5, 0.05
    model = ErrorModel("test", (_term("t.u", "uniform", a), _term("t.c", "constant", 0.0)))

    def run(injected, noise, trials):
        z = noise.normal("mono/z", 1.0)
        u = np.asarray(injected["t.u"], float)
        v = b + np.outer(z, g1) + np.outer(u, g2) + k * (z**2)[:, None]
        return {"v": v, "linear": b + np.outer(z, g1) + np.outer(u, g2)}

    # E[(b + g1 z + g2 u + k z²)²] = b² + g1² + g2² a²/3 + 3k² + 2bk
    exact = float(np.mean(b**2 + g1**2 + g2**2 * a**2 / 3 + 3 * k**2 + 2 * b * k))
    lin = cvar.linear_control(run, model)
    trials = 4000
    injected = model.draw_keyed(7, 0, trials)
    noise = cvar.RecordingNoise(7, trials)
    fields = run(injected, noise, trials)
    cv = cvar.per_trial_controlled(fields, lin, noise, injected, model)
    plain = np.mean(fields["v"] ** 2, axis=1)
    se_cv = np.std(cv["v"], ddof=1) / math.sqrt(trials)
    se_plain = np.std(plain, ddof=1) / math.sqrt(trials)
    assert abs(np.mean(cv["v"]) - exact) < CI_Z * se_cv
    # the remainder is the k·z² part only: measured s.e. ratio 0.23 (k = 0.05)
    assert se_cv < 0.3 * se_plain
    linear_exact = float(np.mean(b**2 + g1**2 + g2**2 * a**2 / 3))
    assert np.allclose(cv["linear"], linear_exact, rtol=1e-9)


@pytest.fixture(scope="module")
def setup80():
    return procedure_mc(
        book_scenarios()["80"], "setup", spec=book_instrument(), trials=3000, seed=5
    )


def test_setup_control_observed_is_the_residual_and_the_levelling_in_quadrature(setup80):
    """(6.59) by the procedure: the control parallaxes observed with m_p = m_xy/√2 add the
    levelling plane's error, independent of the procedure's residual: observed² = 2·levelled²
    (per m_p = m_xy/√2) + (5.55)² with the plane at Fig. 39's points (the rigorous (6.55) term,
    exact integral; the run's midpoint grid adds ≤ 0.5 %)."""
    f = setup80["fields"]
    lev, obs = f["levelled"], f["observed"]
    g = setup80
    geodetic = geodetic_orientation_parallax_rms(g["a"], g["c"], g["p"], g["f"], 1.0, "rigorous")
    expected = math.hypot(math.sqrt(2.0) * lev["coefficient"], geodetic)
    ci = obs["ci"] + math.sqrt(2.0) * lev["ci"]
    assert abs(obs["coefficient"] - expected) < ci + 5e-3 * expected
    # both below 1 % relative at T = 3 000 thanks to the control variate (levelled 0.7 % at
    # 45 000 without: the plain mean's CI here is ≈ 5 %)
    assert obs["ci"] < 0.02 * obs["coefficient"]


def test_setup_parallax_decomposition_is_first_order_in_the_trials_own_errors(setup80):
    """(6.40)/(6.44) by the procedure, decomposed on its own trials (verification/
    decomposition.py): the formula at the simulated geometry is the unit-consistent (6.40) at
    p, c, l, n of the scenario, 0.9589 (derived with sympy in tests/reference); the first-order
    field of each trial's own state errors (central differences of the instrument model at the
    error-free setting, an independent computation) reproduces the procedure's δp: the
    non-linear rest is below 0.1 % of the value at σ = 10 µm (errors ≈ 1e-4 rad, 20 µm: second
    order ≈ 1e-4 relative). The computed decentrations are set from the sheet, so their step
    is exactly zero; the steps add up to the plain value, which agrees with the controlled
    value within the two CIs."""
    f = setup80["fields"]["parallax"]
    assert f["formula"] == pytest.approx(0.9589, abs=5e-4)
    d = f["decomposition"]
    steps = {s["step"]: s for s in d["steps"]}
    value = d["values"]["procedure"]["value"]
    assert abs(steps["non_linear"]["contribution"]) < 1e-3 * value
    assert steps["decentrations"]["contribution"] == 0.0
    total = f["formula"] + sum(s["contribution"] for s in d["steps"])
    assert total == pytest.approx(value, rel=1e-12)
    assert abs(value - f["coefficient"]) < f["ci"] + d["values"]["procedure"]["ci"]


def test_independent_linkage_acts_in_the_setup_method():
    """B2 (linkage "independent"): the computed decentrations are set before the k_ω, k_α fits
    in the setup method itself. The
    error-free run then builds the model to
    well within the book's residual y-parallax check, ¼ of the mark (SC-1 sheet tolerance):
    its RMS δp is below that tolerance, as the dragging linkage's is."""
    sc, spec = book_scenarios()["60"], book_instrument()
    tol = spec.residual_q_fraction_of_mark * spec.mark_diameter_mm
    for linkage in ("drag", "independent"):
        r = procedure_mc(sc, "setup", spec=spec, trials=2, seed=1, linkage=linkage)
        assert r["linkage"] == linkage
        assert r["bias_mm"] < tol, linkage


def test_control_variate_agrees_with_the_plain_mean_with_instrument_errors():
    """With every instrument error term at its σ (normal, uniform pen play, constant backlash,
    real mechanics) the controlled and the plain estimates of the same trials agree within
    their CIs: the control variate adds no bias (the plain mean is the independent estimate)."""
    r = procedure_mc(
        book_scenarios()["60"],
        "conventional",
        spec=book_instrument(),
        trials=600,
        seed=3,
        sources="stereo",
        passes=3,
        instrument=True,
    )
    plain, plain_ci = r["plain"]
    assert abs(r["coefficient"] - plain) < plain_ci + r["ci"]
    assert r["ci"] < 0.2 * plain_ci


def test_stereo_part_is_the_levelling_formula_at_fig39_points():
    """(6.54) by the procedure, the σ_p part alone, re-levelled at Fig. 39's four points
    (``by_datum["book"]``): the rigorous (5.55) at the simulated geometry, 0.6452, within its CI
    and 0.3 % (tilted photos and relief of the scenario; measured +0.09 %)."""
    r = procedure_mc(
        book_scenarios()["60"],
        "conventional",
        spec=book_instrument(),
        trials=300,
        seed=11,
        sources="stereo",
        passes=3,
    )
    value, ci = r["by_datum"]["book"]
    assert r["formula"]["book"] == pytest.approx(0.6452, abs=5e-4)
    assert abs(value - r["formula"]["book"]) < ci + 3e-3 * r["formula"]["book"]
    assert ci < 0.005 * value


def test_cli_verify_instrument_unknown_is_refused(capsys):
    """``verify --instrument NAME`` loads NAME for the procedure MC; an unknown name is one clear
    line before any run."""
    from stereoplotter.cli import main

    rc = main(["verify", "--trials", "50", "--procedure-trials", "10", "--instrument", "sc9"])
    err = capsys.readouterr().err
    assert rc != 0 and "sc9" in err and len(err.strip().splitlines()) == 1


def test_levelled_setup_rows_are_the_formula_at_the_procedures_own_tilt_errors(setup80):
    """(6.48) by the procedure is 36 % below the rigorous formula at the simulated geometry, and
    the decomposition puts it in the first-order step of the trials' own element errors
    ((6.47) depends only on m_α, m_ω). Independent check: the integral of (6.47) taken with the
    variances of α_л − α_п and ω_л − ω_п measured on a separate run of the same operator
    (monocular σ only, §27 task 1, ideal mechanics, 6 000 trials) agrees with the procedure's
    levelled value within the two CIs (99.9 %: the levelled value's, and 3.29·√(1/(2T)) of a
    standard deviation estimated from T trials). Which mechanism makes the tilt errors small
    is shown by the linkage switch (docs/accuracy.md, ``verify --linkage independent``)."""
    from dataclasses import replace

    from stereoplotter.accuracy.chapter5 import mean_shifted_square
    from stereoplotter.procedure.operator import OperatorModel
    from stereoplotter.procedure.simulate import simulate

    sc, spec = book_scenarios()["80"], book_instrument()
    sigma = 0.010
    op = replace(OperatorModel().zero(), monocular_sigma_mm=sigma)
    kw = dict(errors="zero", ideal_mechanics=True, practice="book", seed=3)
    trials = 6000
    r0 = simulate(sc, spec, operator=OperatorModel().zero(), trials=1, **kw)
    r = simulate(sc, spec, operator=op, trials=trials, **kw)
    f, n = r.sheet.focal_length_corrected_mm, r.sheet.n_left

    def errors(attr):
        out = []
        for side in ("left", "right"):
            now = np.arctan(np.asarray(getattr(r.instrument.unit(side), attr)))
            ideal = np.arctan(np.ravel(getattr(r0.instrument.unit(side), attr))[0])
            out.append(now - ideal)
        return out

    al, ar = errors("tan_alpha")
    wl, wr = errors("tan_omega")
    g = setup80
    a, c = g["a"], g["c"]
    mean_w = c**2 / 3.0 * mean_shifted_square((c - a) / 2.0, c)
    mean_a = c**2 * (10 * a**2 + 5 * a * c + c**2) / 30.0
    var = (mean_w * np.var(wl - wr) + mean_a * np.var(al - ar)) / f**2
    at_measured = math.sqrt(var) / (n * sigma)  # per m_xy = n_л·σ
    lev = setup80["fields"]["levelled"]
    ci_measured = CI_Z * at_measured / math.sqrt(2.0 * trials)
    assert abs(lev["coefficient"] - at_measured) < lev["ci"] + ci_measured
    elements = lev["decomposition"]["values"]["elements"]
    assert abs(elements["value"] - at_measured) < elements["ci"] + ci_measured


def test_decentration_linkage_is_a_stated_parameter_and_bad_values_get_one_line(tmp_path):
    """``correction.decentration_linkage`` of every shipped instrument: a leaf with its status
    and basis (``drag``, assumed: no construction drawing); any other value is refused in one
    line naming the file and the field, before any run."""
    import yaml

    from stereoplotter.errors import ConfigError
    from stereoplotter.io.instrument_file import instrument_from_mapping, load_instrument
    from stereoplotter.io.paths import data_dir

    for name in ("sc1", "spr3", "sd3"):
        spec = load_instrument(name)
        leaf = spec.parameters["correction.decentration_linkage"]
        assert spec.decentration_linkage == "drag" and leaf.is_assumed and "D1" in leaf.basis
    data = yaml.safe_load((data_dir("instruments") / "sc1.yaml").read_text(encoding="utf-8"))
    data["correction"]["decentration_linkage"]["value"] = "sticky"
    with pytest.raises(ConfigError) as exc:
        instrument_from_mapping(data, "bad.yaml")
    text = str(exc.value)
    assert "bad.yaml" in text and "correction.decentration_linkage" in text
    assert "sticky" in text and len(text.strip().splitlines()) == 1


def test_verify_decomposes_every_procedure_row():
    """The rows of ``verify --linkage independent``: every procedure row carries a
    decomposition under the linkage asked for; its steps add up to the procedure's value
    within the CIs (``closes``), and on the setup rows the non-linear rest is ≤ 1 % of the
    value (measured ≤ 0.02 % at 45 000 trials). The runs without instrument errors, 200
    trials each. Every row also carries the as-formula and switch blocks
    (:func:`_check_switch_blocks`)."""
    from stereoplotter.verification.as_formula import switch_chain
    from stereoplotter.verification.table import (
        attach_procedure_mc,
        run_procedure_mc,
        run_verification,
    )

    proc = run_procedure_mc(
        200,
        2,
        book_scenarios(),
        instrument=book_instrument(),
        with_instrument=False,
        linkage="independent",
    )
    rows = attach_procedure_mc(run_verification(trials=50, seed=2, procedure_trials=0), proc)
    rows = [r for r in rows if r["mc_procedure"] is not None]
    assert len(rows) == 23
    for r in rows:
        d = r["decomposition"]["first_order"]
        assert d["linkage"] == "independent" and d["closes"], r["eq"]
        steps = {s["step"]: s for s in d["steps"]}
        if "non_linear" in steps:
            assert abs(steps["non_linear"]["contribution"]) <= 0.01 * r["mc_procedure"], r["eq"]
    _check_switch_blocks(rows, switch_chain(Fidelity(linkage="independent")))


def _check_switch_blocks(rows, chain):
    """``as_formula`` (value, CI, ratio to the formula at the simulated geometry; setup rows
    also the twin on vertical photos over flat terrain) and a ``decomposition`` from it to the
    row's run, one step per switch of the chain, each named by its flag, on paired trials: the
    as-formula value plus the steps is the row's run on those trials exactly, and agrees with
    the row's value within the CIs."""
    flags = {m.name: m.flag for m in MECHANISMS}
    for r in rows:
        a, d = r["as_formula"], r["decomposition"]
        assert a["ratio"] == pytest.approx(a["value"] / a["formula"]), r["eq"]
        assert a["agrees"] == (abs(a["value"] - a["formula"]) <= a["ci"]), r["eq"]
        assert a["agrees"] or a["mechanism"], r["eq"]
        if procedure_rows()[r["eq"]].field is None:  # conventional: the run is the as-formula one
            assert d["steps"] == [] and a["value"] == r["mc_procedure"]
            continue
        assert "vertical_flat" in a
        assert [s["step"] for s in d["steps"]] == chain
        assert all(s["switch"].startswith(flags[s["step"]] + " ") for s in d["steps"])
        total = d["as_formula"]["value"] + sum(s["contribution"] for s in d["steps"])
        assert total == pytest.approx(d["sum"], rel=1e-12)
        assert d["closes"], r["eq"]


@pytest.mark.parametrize("slot", ["60", "80"])
def test_as_formula_reproduces_the_formula_on_vertical_photos_over_flat_terrain(slot):
    """The setup method with every mechanism switch at the formula's assumption, on the
    scenario's twin with vertical photos over flat terrain (the geometry (6.22) is derived
    for): the levelled and observed rows ((6.47)–(6.50), (6.58), (6.59)) are the formula, and
    the unlevelled rows ((6.39)–(6.44)) are it with b_x's coefficient taken at the terrain's
    model depth D_t = H̄/M_в instead of the carriage's D = n_л·f_пр (δp/δb_x = f_пр/D_t). The
    run is linear in its pointings (control-variate CI < 1e-4); the tolerance 0.5 % is that of
    the elements' RMS errors against (6.32)–(6.38) in such a run (b_z by the L-check's ratio
    form, D9, 1–2 % above (6.37), a term ≤ 10 % of the variance)."""
    from stereoplotter.verification.as_formula import vertical_flat_block
    from stereoplotter.verification.procedure_mc import idealised_geometry

    sc = idealised_geometry(book_scenarios()[slot])
    r = procedure_mc(
        sc, "setup", spec=book_instrument(), trials=600, seed=4,
        fidelity=Fidelity.as_formula(), grid=(8, 16),
    )  # fmt: skip
    for field in ("parallax", "levelled", "observed"):
        b = vertical_flat_block(r, field, False)
        ratio = b.get("ratio_at_depth", b["ratio"])
        assert abs(ratio - 1.0) < 0.005, (field, ratio)
    # the depth ratio is the sheet's D_max over the terrain's model depth
    assert r["n"] * r["f_instrument"] / r["terrain_depth_mm"] == pytest.approx(185 / 175)
