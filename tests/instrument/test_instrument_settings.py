"""Issue 11, deliverable 2: each instrument's own φ, ω-dependent settings on the sheet.

The counts are the documented ones (SD stereograph 8, SPR-2 12; the instrument files'
``facts.phi_omega_dependent_settings``); the values are checked against the geometry they come
from: the decentration is the value that makes the plane correction exact on the axis
(kinematics §2.4), the inclination satisfies Drobyshev's ΔF/Δf_k = x·tan θ / (x·tan α) = k.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from stereoplotter.instrument.principles import sequence_for, setting_values
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.report.sheet import sheet_to_dict
from stereoplotter.setup.sheet import compute_setup_sheet

PAIR60 = Path(__file__).parents[2] / "stereoplotter" / "data" / "scenarios" / "pair60.yaml"


@pytest.mark.parametrize(("name", "counted_kinds"), [("sd3", ("primary", "derived")),
                                                     ("spr3", ("derived",))])  # fmt: skip
def test_count_is_the_documented_one(name, counted_kinds):
    """SD: 8 setting elements (plates primary, photo decentrations mediated); SPR-2: 12
    decentrations (photo, correction mechanism, follower), after dφ, dω are introduced."""
    spec = load_instrument(name)
    seq = sequence_for(spec.principle)
    documented = spec.parameters["facts.phi_omega_dependent_settings"].value
    assert seq.phi_omega_dependent == documented
    per_pair = 2 * sum(s.kind in counted_kinds for s in seq.settings)
    assert per_pair == documented


def test_sc1_count_is_labelled_assumed():
    seq = sequence_for(load_instrument("sc1").principle)
    assert seq.count_status == "assumed" and seq.phi_omega_dependent == 8


@pytest.mark.parametrize("alpha_deg", [-3.0, -0.7, 0.4, 2.5])
def test_decentration_makes_the_plane_correction_exact(alpha_deg):
    """x = τξ − e with τ = (f + c·tan α)/(f + ξ·tan α) equals the exact single-tilt relation
    x = (ξ − f·tan α)/(1 + ξ·tan α/f) for every ξ when c = e = the printed decentration."""
    f, k, a = 100.0, 1.4, math.radians(alpha_deg)
    seq = sequence_for("transformed_bundle_lens_shift_correction")
    values = dict(zip((s.key for s in seq.settings), setting_values(seq, f, k, a, 0.0),
                      strict=True))  # fmt: skip
    e, c, u = values["photo_dx"], values["mechanism_dx"], values["follower_dx"]
    assert e == c == u
    xi = np.linspace(-120.0, 120.0, 25)
    ta = math.tan(a)
    exact = (xi - f * ta) / (1.0 + xi * ta / f)
    tau = (f + c * ta) / (f + xi * ta)
    np.testing.assert_allclose(tau * xi - e, exact, atol=1e-12)


def test_inclination_is_drobyshev_k_ratio():
    f, k, a, w = 70.0, 1.9, math.radians(1.3), math.radians(-2.2)
    seq = sequence_for("transformed_bundle_correction_planes")
    v = dict(zip((s.key for s in seq.settings), setting_values(seq, f, k, a, w), strict=True))
    x = 37.0  # any photo abscissa: ΔF/Δf_k = x·tan θ / (x·tan α) = k (DRO60 eq. (4))
    assert x * math.tan(math.radians(v["plate_alpha"])) / (x * math.tan(a)) == pytest.approx(k)
    assert math.tan(math.radians(v["plate_omega"])) / math.tan(w) == pytest.approx(k)
    # the derived photo decentration from the plate: (f′/k)·tan θ
    assert v["photo_dx"] == pytest.approx(f / k * math.tan(math.radians(v["plate_alpha"])))


def test_sheets_print_each_instruments_own_settings():
    scenario = load_scenario(PAIR60)
    data = {
        name: sheet_to_dict(
            compute_setup_sheet(scenario, load_instrument(name), rng=np.random.default_rng(1))
        )
        for name in ("sc1", "spr3", "sd3")
    }
    symbols = {n: [s["symbol"] for s in d["instrument_settings"]["settings"]]
               for n, d in data.items()}  # fmt: skip
    assert symbols["spr3"] == ["θ_α", "θ_ω", "e_x", "e_y", "c_x", "c_y", "u_x", "u_y"]
    assert symbols["sd3"] == ["θ_α", "θ_ω", "d_x", "d_y"]
    assert data["sd3"]["instrument_settings"]["settings"][0]["name"].startswith("correction-plate")
    assert data["sc1"]["instrument_settings"]["settings"][0]["name"].startswith("photo-carrier")
    # the settings agree with the sheet's own decentrations and plane inclinations
    for d in data.values():
        s = {x["key"]: x for x in d["instrument_settings"]["settings"]}
        dx = next(v for k, v in s.items() if k.endswith("_dx"))
        assert dx["left"] == pytest.approx(d["decentrations_mm"]["left"]["x"], abs=1e-6)
        first = d["instrument_settings"]["settings"][0]
        assert first["right"] == pytest.approx(
            d["correction_inclinations_deg"]["right"]["alpha"], abs=1e-6
        )
