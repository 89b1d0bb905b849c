"""One operator everywhere: a one-cell study of pair60 (no geometry axis, SC-1, setup data) runs
the operator of ``simulate`` — the same check pass rates within 4 standard errors — and the
``operator`` axis gives the free-σ operator for whoever asks for it."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import pytest

pytest.importorskip("xarray")

from stereoplotter.errors import ConfigError
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.study_file import study_from_mapping
from stereoplotter.procedure.operator import OperatorModel
from stereoplotter.study.cells import cell_run
from stereoplotter.study.runner import run_study, study_checks

TRIALS = 100
SEED = 20261122  # pair60's own seed, the one `simulate` uses without --seed


def one_cell(operator=None) -> dict:
    axes = {"method": ["setup"]}
    if operator is not None:
        axes["operator"] = operator
    return {
        "format": "stereoplotter-study/1",
        "name": "one-cell",
        "base": {"scenario": "pair60"},
        "instrument": "sc1",
        "axes": axes,
        "trials": TRIALS,
        "chunk_trials": TRIALS,
        "measures": ["checks"],
        "seed": SEED,
    }


def test_study_cell_and_simulate_give_the_same_pass_rates():
    design = study_from_mapping(one_cell())
    cells = design.cells()
    checks = study_checks(design, cells)
    got = {}
    run_study(design, cells, lambda i, v: got.update({i: v}), checks=checks, terms=())
    study = dict(zip(checks, got[0]["pass_rate"], strict=True))
    study_se = dict(zip(checks, got[0]["pass_rate_se"], strict=True))
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "stereoplotter",
            "simulate",
            "pair60",
            "--instrument",
            "sc1",
            "--trials",
            str(TRIALS),
            "--json",
            "--workers",
            "1",
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    sim = json.loads(out.stdout)["checks"]
    compared = 0
    for name, entry in sim.items():
        if "pass_rate" not in entry or name not in study:
            continue
        rate, se = entry["pass_rate"]["rate"], entry["pass_rate"]["rate_se"]
        # SE of the difference of two independent rates; a floor of one trial in T where both
        # rates are 0 or 1 (the binomial SE is then 0)
        sd = max(math.hypot(se, study_se[name]), 1.0 / TRIALS)
        assert abs(study[name] - rate) <= 4 * sd, (name, study[name], rate)
        compared += 1
    assert compared >= 5


def test_operator_axis_defaults_to_the_simulate_operator_and_offers_the_free_sigma():
    sc1 = load_instrument("sc1")
    design = study_from_mapping(one_cell(["eye", "sigma", "zero"]))
    cells = design.cells()
    assert [c["operator"] for c in cells] == ["eye", "sigma", "zero"]
    eye, sigma, zero = (cell_run(design, i, c).operator for i, c in enumerate(cells))
    assert eye == OperatorModel().for_instrument(sc1)
    assert (sigma.stereo_sigma_mm, sigma.y_parallax_sigma_mm, sigma.remeasure) == (
        0.010,
        0.010,
        False,
    )
    assert zero.y_parallax_sigma_mm == 0.0 and zero.reading_sigma_lc == 0.0


def test_a_bad_operator_name_is_one_line_naming_the_axis():
    with pytest.raises(ConfigError) as exc:
        study_from_mapping(one_cell(["eyes"]), "s.yaml")
    assert "axes.operator" in str(exc.value) and "\n" not in str(exc.value)
