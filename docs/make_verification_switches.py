"""The switch runs behind the decomposition of the procedure rows (``docs/accuracy.md``).

Run from the repository root::

    python3 docs/make_verification_switches.py

Prints, on the book's scenarios pair60/pair80 and the SC-1:

0. f_пр as set by the setup method minus the sheet's, under the bottom-stop rule both ways (the
   book's (6.11), the default) and one way (f_пр shortened at the stop, never lengthened),
   pair60, monocular σ = 10 µm only, ideal mechanics, 500 trials, seed 3;
1. stage 3's part of the setup rows (δp on the (6.27) domain, paired on 2 000 trials, seed 5,
   8 × 16 grid): stage 3 off → b_x fused on control point 1 → + κ cleared again (D10), at the
   default switches and at the switches where the decomposition of ``verify --json`` flips
   stage 3 (κ by y-parallax, one pass, linkage independent), with the RMS error of b_x;
2. the conventional σ_q part at 3, 6 and 10 passes (1 500 trials, seed 21) against the formula
   with the plane at the procedure's levelling points;
3. the same σ_q part on the scenario with vertical photos over flat terrain
   (``idealised_geometry``), also re-levelled at Fig. 39's points against (5.54).

The rows of ``verify`` itself, with their ``as_formula`` blocks and the decomposition from it
to the default one switch a step, are printed by ``stereoplotter verify -o DIR`` (and
``--json``).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from stereoplotter.io.book_setting import book_instrument, book_scenarios
from stereoplotter.procedure.fidelity import Fidelity
from stereoplotter.procedure.operator import OperatorModel
from stereoplotter.procedure.simulate import simulate
from stereoplotter.verification import decomposition as dc
from stereoplotter.verification.procedure_mc import idealised_geometry, procedure_mc


def principal_distance_scatter(rule: str) -> str:
    """f_пр of the setup method's trials minus the sheet's under bottom-stop ``rule``: mean and
    σ [µm]."""
    sc, spec = book_scenarios()["60"], book_instrument()
    zero = OperatorModel().zero()
    kw = dict(errors="zero", ideal_mechanics=True, practice="book", seed=3, evaluate=False)
    r = simulate(
        sc, spec, operator=replace(zero, monocular_sigma_mm=0.01), trials=500,
        fidelity=Fidelity(bottom_stop=rule), **kw,
    )  # fmt: skip
    d = (np.asarray(r.instrument.setting.f_instrument_mm, float) - r.sheet.f_instrument_mm) * 1e3
    return f"mean {np.mean(d):+.1f} µm, σ {np.std(d):.1f} µm"


def stage3_trace(base: Fidelity, label: str) -> None:
    """Stage 3 off → b_x fused → + κ cleared again, paired, at switches ``base``."""
    scenarios, spec = book_scenarios(), book_instrument()
    for slot in ("60", "80"):
        runs = {
            s: procedure_mc(
                scenarios[slot],
                "setup",
                spec=spec,
                trials=2000,
                seed=5,
                grid=(8, 16),
                fidelity=replace(base, stage3=s),
            )
            for s in ("none", "bx_only", "fuse")
        }
        f = runs["fuse"]["fields"]["parallax"]
        ref, unit = f["formula"], f["unit"]
        parts = []
        for a, b in (("none", "bx_only"), ("bx_only", "fuse")):
            c, h = dc.paired_step(
                runs[b]["fields"]["parallax"]["mean_squares"],
                runs[a]["fields"]["parallax"]["mean_squares"],
                unit,
            )
            parts.append(f"{a} → {b} {100 * c / ref:+.1f} ± {100 * h / ref:.1f} %")
        bx = "  ".join(f"{s} {runs[s]['element_rms']['setting.base_x_mm'] * 1e3:.1f}" for s in runs)
        print(f"  {label}, {slot} %: {'; '.join(parts)} of the formula; b_x RMS [µm] {bx}")


def main() -> None:
    print("0. f_пр as set minus the sheet's, pair60:")
    for rule in ("both_ways", "one_way"):
        print(f"  {rule}: {principal_distance_scatter(rule)}")
    print("1. stage 3's part of the setup rows (δp on the (6.27) domain):")
    stage3_trace(Fidelity(), "default switches")
    chain = replace(
        Fidelity.as_formula(),
        bottom_stop="both_ways",
        kappa="y_parallax",
        tilts="knob_fit",
        fit_scale="as_set",
    )
    stage3_trace(chain, "the decomposition's stage-3 step (one pass, linkage independent)")
    scenarios, spec = book_scenarios(), book_instrument()
    print("2. conventional σ_q part against the formula at the procedure's levelling points")
    for slot in ("60", "80"):
        for passes in (3, 6, 10):
            r = procedure_mc(
                scenarios[slot],
                "conventional",
                spec=spec,
                trials=1500,
                seed=21,
                sources="y_parallax",
                passes=passes,
            )
            ratio = r["coefficient"] / r["formula"]["procedure"] - 1.0
            print(
                f"  {slot} % {passes:2d} passes {r['coefficient']:.4f} ± {r['ci']:.4f} "
                f"against {r['formula']['procedure']:.4f}: {100 * ratio:+.1f} %"
            )
    print("3. the same on vertical photos over flat terrain (3 passes)")
    for slot in ("60", "80"):
        r = procedure_mc(
            idealised_geometry(scenarios[slot]),
            "conventional",
            spec=spec,
            trials=1500,
            seed=21,
            sources="y_parallax",
            passes=3,
        )
        ratio = r["coefficient"] / r["formula"]["procedure"] - 1.0
        book, ci = r["by_datum"]["book"]
        print(
            f"  {slot} % {r['coefficient']:.4f} ± {r['ci']:.4f} against "
            f"{r['formula']['procedure']:.4f}: {100 * ratio:+.1f} %; re-levelled at Fig. 39's "
            f"points {book:.4f} ± {ci:.4f} against (5.54) {r['formula']['book']:.4f}"
        )


if __name__ == "__main__":
    main()
