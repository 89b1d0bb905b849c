"""The setup-data procedure's mechanism switches (``procedure.fidelity``): each switch isolates
its mechanism, against the book's own error formulas (6.32)–(6.38) and the book's stage texts.

Element checks run the procedure MC's setup configuration (only the operator's monocular σ,
ideal mechanics, no instrument error, §27 task 1) with every other switch at the formula's
assumption, and compare the RMS error of one element over T trials with the formula: the
99.9 % CI of an RMS from T normal draws is ±3.29/√(2T) relative (±6 % at T = 1 500).
"""

from __future__ import annotations

import argparse
import math
import re
from dataclasses import replace

import numpy as np
import pytest

from stereoplotter.accuracy.setup_accuracy import setup_element_sigmas
from stereoplotter.commands.arguments import add_fidelity_arguments, fidelity_from_args
from stereoplotter.io.book_setting import book_instrument, book_scenarios
from stereoplotter.procedure.fidelity import MECHANISMS, Fidelity
from stereoplotter.procedure.operator import OperatorModel
from stereoplotter.procedure.run import build_run
from stereoplotter.procedure.setup_method import stage1_scale_coefficient
from stereoplotter.procedure.simulate import prepare_run, simulate
from stereoplotter.report.form_fields import correction_rows
from stereoplotter.verification.procedure_mc import procedure_mc

T = 1500
RMS_CI = 3.29 / math.sqrt(2 * T)  # relative 99.9 % CI of an RMS of T normal draws


def _elements(fidelity: Fidelity, slot: str = "60") -> tuple[dict, dict]:
    """Element RMS errors of a setup procedure MC run (instrument units) and the formula's
    σ's (photo scale, ``mode="rigorous"``) with the run's geometry."""
    r = procedure_mc(
        book_scenarios()[slot], "setup", spec=book_instrument(), trials=T, seed=3,
        fidelity=fidelity, grid=(4, 8), control_variate=False,
    )  # fmt: skip
    sig = setup_element_sigmas(r["f"], r["l"], r["n"], r["n"] * r["sigma_mm"], mode="rigorous")
    return r, sig


def test_every_switch_is_declared_once_with_its_basis_and_the_formulas_setting():
    """One declaration: a field of :class:`Fidelity` per mechanism, each with a basis that
    cites a book line or equation, its default among its choices, and --as-formula sets them
    all (a flag overrides one)."""
    names = [m.name for m in MECHANISMS]
    assert len(set(names)) == len(names)
    assert set(names) == set(Fidelity.__dataclass_fields__)
    for m in MECHANISMS:
        assert re.search(r"OCR L\d{4}|\(6\.\d\d\)|assumed", m.basis), m.name
        assert m.default in m.choices and (m.as_formula in m.choices or m.name == "passes")
    assert Fidelity.as_formula().departures() == ()
    p = argparse.ArgumentParser()
    add_fidelity_arguments(p)
    args = p.parse_args(["--as-formula", "--kappa", "y_parallax"])
    assert fidelity_from_args(args) == replace(Fidelity.as_formula(), kappa="y_parallax")
    assert fidelity_from_args(p.parse_args([])) == Fidelity()
    with pytest.raises(ValueError, match="--kappa"):
        Fidelity(kappa="sideways")


def test_tilts_switch_gives_the_least_squares_m_omega_of_6_35():
    """(6.33): with the zero reading at the centre and marks 3, 4 at y = ±l (the same
    coefficient a = l²/f), the least squares give σ_ω² = (3/2)·σ²/a²; one fit at mark 3
    against the centre gives 2σ²/a², √(4/3) = 1.155 times the RMS. The counters' n exact
    (fit_scale) so the fits carry only their own pointings."""
    formula = Fidelity.as_formula()
    r_ls, sig = _elements(formula)
    r_one, _ = _elements(replace(formula, tilts="knob_fit"))
    for side in ("left", "right"):
        ls = r_ls["element_rms"][f"{side}.tan_omega"] / sig["omega"]
        one = r_one["element_rms"][f"{side}.tan_omega"] / sig["omega"]
        assert abs(ls - 1.0) < RMS_CI, side
        assert abs(one / math.sqrt(4.0 / 3.0) - 1.0) < RMS_CI, side


def test_kappa_switch_gives_6_36_and_bx_zero_gives_6_38():
    """κ from the fiducials: m_κ = m_x/(√2·l·n) (6.36); b_x's zero place from two pointings
    and no stage-3 fusing: m_bx = √2·m_x/n (6.38) at photo scale (b_x in instrument mm / n);
    with MO_bx exact and no stage 3 b_x carries no error at all."""
    formula = Fidelity.as_formula()
    r, sig = _elements(formula)
    n = r["n"]
    for side in ("left", "right"):
        assert abs(r["element_rms"][f"{side}.kappa"] / sig["kappa"] - 1.0) < RMS_CI, side
    assert abs(r["element_rms"]["setting.base_x_mm"] / n / sig["base_x"] - 1.0) < RMS_CI
    exact, _ = _elements(replace(formula, bx_zero="exact"))
    assert exact["element_rms"]["setting.base_x_mm"] == 0.0


def test_bottom_stop_corrects_both_ways():
    """The book's (6.11), O′_Z = O_Z + ΔZ either way: f_пр is short of the sheet's value only
    while the carriage stands at its bottom stop (n = D/f_пр reached by f_пр there), so after
    stage 1's L-check loop every trial has f_пр = the sheet's or Z at the stop. The one-way
    rule leaves trials with f_пр shortened and the carriage raised off the stop."""
    sc, spec = book_scenarios()["60"], book_instrument()
    op = replace(OperatorModel().zero(), monocular_sigma_mm=0.01)
    out = {}
    for mode in ("both_ways", "one_way"):
        prep = prepare_run(
            sc, spec, "setup", "zero", 3, operator=op, ideal_mechanics=True, practice="book",
            fidelity=Fidelity(bottom_stop=mode),
        )  # fmt: skip
        run = build_run(prep, 0, 300, transcript=False)
        stage1_scale_coefficient(run)
        inst = run.op.inst
        f = np.asarray(inst.setting.f_instrument_mm, float)
        stop = inst.reading_of("Z", inst.travel_mm("Z")[1])
        z = np.asarray(inst.read("Z", exact=True), float)
        short = f < prep.sheet.f_instrument_mm - 1e-9
        off_stop = z < stop - spec.z_least_count_mm
        out[mode] = (short, off_stop)
    short, off_stop = out["both_ways"]
    assert short.any() and not (short & off_stop).any()
    short, off_stop = out["one_way"]
    assert (short & off_stop).any()


def test_stage1_compares_with_the_L_the_sheet_and_the_form_print():
    """Stage 1 (units at zero) compares L′ with L⁰ = n·(y₃ − y₄) of the sheet's measured marks
    (D5): the sheet prints that number as the stage-1 reading, the form's correction worksheet
    shows it, and the transcript's "compare with L_л = …" is it."""
    sc, spec = book_scenarios()["60"], book_instrument()
    r = simulate(sc, spec, "setup", "zero", 1, evaluate=False)
    sheet = r.sheet
    printed = {row["reading"]: row for row in sheet.readings}
    for photo, side in zip(sheet.photos, "лп", strict=True):
        m = photo.marks_measured_mm
        span = photo.n * (m["3"][1] - m["4"][1])  # independent: from the measured marks
        row = printed[f"L⁰_{side}"]
        assert row["stage"] == 1 and row["value"] == pytest.approx(span, abs=1e-12)
        said = [
            rec.step for rec in r.transcript.records
            if rec.stage == "1" and f"compare with L_{side} = " in rec.step
        ]  # fmt: skip
        assert said and all(f"= {span:.3f} mm" in s for s in said)
        form = [c for c in correction_rows(sheet, "en") if c[0] == f"L′_{side}"]
        assert form and f"= {span:.3f} mm" in form[0][2]
