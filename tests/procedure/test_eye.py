"""The operator's eye (``procedure.eye``): judgement figures derived from stereo acuity
and the observation system, and the six-point check as a detection with a remeasure.

References: the textbook's stereo acuity of the first kind ≈ 30″ and of the second kind 10″
(``docs/procedure.md`` §The operator's eye); the optics of a magnifier referred to 250 mm,
s = d·tan δ / V (computed here with the tangent, the module with the small angle).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from stereoplotter.cli import main
from stereoplotter.errors import ConfigError
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.operator_file import load_operator_model
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.procedure.eye import Eye, ObservationSystem, look_probability
from stereoplotter.procedure.operator import OperatorModel
from stereoplotter.procedure.simulate import simulate

Q3 = "stage 3: residual y-parallax (6 points)"


def _photo_um(arcsec: float, magnification: float, distance_mm: float) -> float:
    return distance_mm * math.tan(math.radians(arcsec / 3600.0)) / magnification * 1000.0


@pytest.mark.parametrize("name", ["sc1", "spr3", "sd3"])
def test_judgement_figures_from_acuity_and_the_instruments_binocular(name):
    spec = load_instrument(name)
    system = ObservationSystem.from_spec(spec)
    # the instrument files give V and d, both assumed (no source documents them)
    assert spec.status("observation.magnification") == "assumed"
    assert spec.status("observation.viewing_distance_mm") == "assumed"
    assert system.magnification_status == system.viewing_distance_status == "assumed"
    v, d = spec.parameter("observation.magnification").value, 250.0
    eye = Eye(system)
    assert eye.y_parallax_sigma_mm * 1000 == pytest.approx(_photo_um(10.0, v, d), rel=1e-8)
    assert eye.stereo_sigma_mm * 1000 == pytest.approx(_photo_um(30.0, v, d), rel=1e-8)
    op = OperatorModel().for_instrument(spec)
    assert op.y_parallax_sigma_mm == eye.y_parallax_sigma_mm
    assert op.stereo_sigma_mm == eye.stereo_sigma_mm
    assert op.eye_figures()["y_parallax_sigma_um"] == pytest.approx(_photo_um(10.0, v, d))


@pytest.mark.parametrize("remeasure", [True, False])
def test_six_point_check_passes_as_the_psychometric_function_predicts(remeasure):
    # The procedure's stage-3 check (book practice: nothing changes the model after it) against
    # (eye 2) evaluated at each trial's true q at the six points: P(pass) = Π (1 − P_look^k),
    # k = 2 looks with the remeasure, 1 without. σ_q = 10 µm (eye="sigma") puts the rates
    # between 0 and 1 (a default eye passes every trial). Tolerance 3 binomial SE.
    sc, spec = load_scenario("pair60"), load_instrument("sc1")
    op = OperatorModel(eye="sigma", remeasure=remeasure)
    r = simulate(
        sc, spec, "setup", seed=7, trials=1000, evaluate=False, practice="book", operator=op
    )
    tol = r.sheet.tolerances["residual_y_parallax_mm"]
    looks = 2 if remeasure else 1
    p_look = np.vectorize(look_probability)(np.asarray(r.q_standard_mm), tol, 0.010)
    p = np.prod(1.0 - p_look**looks, axis=1)
    se = math.sqrt(float(np.sum(p * (1.0 - p)))) / p.size
    assert abs(float(np.mean(r.checks[Q3].passed)) - float(np.mean(p))) <= 3.0 * se


def test_operator_sigma_is_the_free_sigma_single_look_operator(tmp_path):
    legacy = load_operator_model("sigma")
    assert (legacy.eye, legacy.remeasure) == ("sigma", False)
    assert legacy.for_instrument(None).y_parallax_sigma_mm == 0.010
    f = tmp_path / "op.yaml"
    f.write_text("eye: glasses\n", encoding="utf-8")
    with pytest.raises(ConfigError, match="eye"):
        load_operator_model(f)


def test_summary_shows_each_check_with_its_derived_judgement(capsys):
    # the single-run summary of `simulate`, which `demo` prints as its simulated-operator part
    assert main(["simulate", "pair60", "--instrument", "sc1", "-q"]) == 0
    text = capsys.readouterr().out
    rows = [ln for ln in text.splitlines() if ln.startswith("| stage ")]
    assert len(rows) == 7
    sq, sp = _photo_um(10.0, 6.0, 250.0), _photo_um(30.0, 6.0, 250.0)
    for row in rows:
        cells = row.rstrip(" |").split(" | ")
        assert cells[-3] in ("True", "False")  # passed
        assert "µm" in cells[-1]  # judged with
        if "y-parallax" in row:
            assert f"σ_q {sq:.2f} µm" in cells[-1] and "2 looks" in cells[-1]
    assert f"σ_p = 30″·d/V = {sp:.2f} µm" in text and f"σ_q = 10″·d/V = {sq:.2f} µm" in text
    assert "V = 6× (assumed)" in text and "d = 250 mm (assumed)" in text
