"""Remedy R2 stays inside the instrument's ranges: at f = 200 mm, 90 % overlap, α = 2.5° on the
SC-1 its least squares is ill-conditioned (the two k_α and the two κ nearly collinear at a
convergent pair), the damped, bounded turns keep every element inside its stop, and the cell
is run, not refused. The error-free residual that triggers R2 there is D8's κ clearing at
standard points 1, 2 stopped at ¼ mark, with the common κ of both photos almost unseen there."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

pytest.importorskip("xarray")

from stereoplotter.instrument.kinematics import UnitMap, rods_intersection
from stereoplotter.instrument.principles import mechanism_for
from stereoplotter.io.study_file import study_from_mapping
from stereoplotter.procedure.floor import sheet_settings
from stereoplotter.procedure.setup_method import r2_turns
from stereoplotter.procedure.simulate import prepare_run, run_trials_chunk
from stereoplotter.study.cells import cell_run
from stereoplotter.study.runner import run_study, study_checks

RESIDUAL = "stage 2: residual y-parallax (6 points)"


def _design(operator: str, errors: float, trials: int):
    return study_from_mapping(
        {
            "format": "stereoplotter-study/1",
            "name": "r2",
            "base": {"scenario": "pair60"},
            "instrument": "sc1",
            "axes": {
                "f_mm": [200.0],
                "overlap": [0.9],
                "alpha_deg": [2.5],
                "method": ["setup"],
                "operator": [operator],
                "instrument_error_scale": [errors],
            },
            "trials": trials,
            "chunk_trials": trials,
            "measures": ["checks"],
            "seed": 20261126,
        }
    )


@pytest.mark.parametrize(("operator", "errors"), [("eye", 1.0), ("zero", 0.0)])
def test_the_narrow_convergent_cell_is_run_not_refused(operator, errors):
    design = _design(operator, errors, 4)
    cells = design.cells()
    checks = study_checks(design, cells)
    got = {}
    run_study(design, cells, lambda i, v: got.update({i: v}), checks=checks, terms=())
    assert got[0]["status"] == 1, got[0].get("message")
    assert RESIDUAL in checks


def test_r2_turns_are_plain_least_squares_inside_the_bounds_and_damped_beyond():
    rng = np.random.default_rng(1)
    jac = rng.normal(size=(6, 5))
    q = rng.normal(size=6) * 1e-3
    wide = [(-10.0, 10.0)] * 5
    plain = -np.linalg.solve(jac.T @ jac, jac.T @ q)
    np.testing.assert_allclose(r2_turns(jac, q, np.zeros(5), wide), plain, rtol=1e-12)
    # two nearly collinear columns: the plain solution turns them far apart, the bounded one
    # keeps both inside ±0.05
    jac[:, 4] = jac[:, 3] * (1 + 1e-7)
    tight = [(-0.05, 0.05)] * 5
    delta = r2_turns(jac, q, np.zeros(5), tight)
    assert np.all(np.abs(delta) <= 0.05)


def test_the_error_free_residual_is_d8s_kappa_stopped_at_a_quarter_mark():
    """The figures docs/studies.md gives for this cell (§Why R2 is called …), to the decimals it
    prints: a stale figure fails."""
    design = _design("zero", 0.0, 2)
    run = cell_run(design, 0, design.cells()[0])
    prep = prepare_run(run.scenario, run.spec, "setup", run.errors, 1, operator=run.operator)
    result = run_trials_chunk(prep, 0, 1, evaluate=False, transcript=True)
    recs = result.transcript.records
    seen = {
        r.step[-1]: float(r.residual) * 1000.0
        for r in recs
        if r.stage == "2"
        and r.step.startswith("residual y-parallax at standard point")
        and not r.remedy
    }
    # after D8, before R2: points 1, 2 inside ¼ mark (12.5 µm), 3–6 outside
    assert [round(seen[p], 1) for p in "123456"] == [-12.2, -0.0, 15.0, 27.7, 23.9, 35.6]
    kappa = {}
    for r in recs:
        if r.stage == "2" and r.control in ("kappa_left", "kappa_right") and not r.remedy:
            kappa[r.control] = float(r.after)
    setting, units = sheet_settings(prep.sheet, mechanism=mechanism_for(run.spec))

    def q_um(kl, kr):
        m = [UnitMap(replace(units["left"], kappa=kl)), UnitMap(replace(units["right"], kappa=kr))]
        pl, pr = prep.scene.standard
        q = rods_intersection(m[0].rod_from_photo(pl), m[1].rod_from_photo(pr), setting)
        return np.asarray(q.y_parallax_mm) * 1000.0

    arcmin = 180.0 * 60.0 / np.pi
    sheet_k = (float(units["left"].kappa), float(units["right"].kappa))
    d8_k = (kappa["kappa_left"], kappa["kappa_right"])
    assert [round(k * arcmin, 1) for k in sheet_k] == [48.0, -66.0]
    assert [round(k * arcmin, 1) for k in d8_k] == [10.2, -106.1]
    assert round(float(np.mean(np.subtract(d8_k, sheet_k))) * arcmin) == -39
    # the mechanism level at the sheet's own settings
    assert round(float(np.max(np.abs(q_um(*sheet_k)))), 2) == 0.03
    # D8's κ pair in the sheet's otherwise exact settings
    assert [round(v, 1) for v in q_um(*d8_k)[2:]] == [20.1, 32.2, 18.8, 31.1]
    # ∂q/∂κ [mm/rad]: of κ_л at points 1, 2, and of a common turn at points 1–2 and 3–6
    h = 1e-4
    dl = (q_um(sheet_k[0] + h, sheet_k[1]) - q_um(*sheet_k)) / 1000.0 / h
    common = (q_um(sheet_k[0] + h, sheet_k[1] + h) - q_um(*sheet_k)) / 1000.0 / h
    assert [round(float(v), 1) for v in dl[:2]] == [-8.7, 9.2]
    assert round(float(np.mean(np.abs(common[:2]))), 1) == 0.5
    assert round(float(np.mean(np.abs(common[2:]))), 1) == 2.3
