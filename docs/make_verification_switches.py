"""The switch runs of the decomposition of the procedure rows (issue 25, ``docs/accuracy.md``).

Run from the repository root::

    python3 docs/make_verification_switches.py

Prints, on the book's scenarios pair60/pair80 and the SC-1:

0. the scatter and mean of f_пр as set by the setup method, against the error-free run (pair60,
   monocular σ = 10 µm only, ideal mechanics, 500 trials, seed 3);
1. the setup rows' decomposition (δp on the (6.27) domain) as built and with every loop at a
   fixed 2 and 4 passes (3 000 trials, seed 5, 8 × 16 grid): the f_пр step and the element step;
2. the conventional σ_q part at 3, 6 and 10 passes (1 500 trials, seed 21) against the formula
   with the plane at the procedure's levelling points;
3. the same σ_q part on the scenario with vertical photos over flat terrain
   (``idealised_geometry``), also re-levelled at Fig. 39's points against (5.54).

The rows of ``verify`` itself (both linkages) are printed by ``stereoplotter verify -o DIR``
and ``stereoplotter verify --linkage independent -o DIR``.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from stereoplotter.io.book_setting import book_instrument, book_scenarios
from stereoplotter.procedure.operator import OperatorModel
from stereoplotter.procedure.simulate import simulate
from stereoplotter.verification.procedure_mc import idealised_geometry, procedure_mc


def principal_distance_scatter() -> str:
    """f_пр of the setup method's trials minus the error-free run's: mean and σ [µm]."""
    sc, spec = book_scenarios()["60"], book_instrument()
    zero = OperatorModel().zero()
    kw = dict(errors="zero", ideal_mechanics=True, practice="book", seed=3)
    r0 = simulate(sc, spec, operator=zero, trials=1, **kw)
    r = simulate(sc, spec, operator=replace(zero, monocular_sigma_mm=0.01), trials=500, **kw)
    f0 = float(np.ravel(r0.instrument.setting.f_instrument_mm)[0])
    d = (np.asarray(r.instrument.setting.f_instrument_mm, float) - f0) * 1000.0
    return f"mean {np.mean(d):+.1f} µm, σ {np.std(d):.1f} µm"


def _steps(r: dict) -> str:
    d = r["fields"]["parallax"]["decomposition"]
    ref = d["values"]["simulated_geometry"]["value"]
    return "  ".join(
        f"{s['step']} {100 * s['relative']:+.1f} ± {100 * s['ci'] / ref:.1f} %" for s in d["steps"]
    )


def main() -> None:
    scenarios, spec = book_scenarios(), book_instrument()
    print(f"0. f_пр as set minus the error-free run's, pair60: {principal_distance_scatter()}")
    print("1. setup rows, δp on the (6.27) domain: steps as shares of the formula")
    for slot in ("60", "80"):
        for passes in (None, 2, 4):
            r = procedure_mc(
                scenarios[slot],
                "setup",
                spec=spec,
                trials=3000,
                seed=5,
                grid=(8, 16),
                passes=passes,
            )
            f = r["fields"]["parallax"]
            label = "as built" if passes is None else f"{passes} passes"
            print(f"  {slot} % {label:9s} {f['coefficient']:.4f} ± {f['ci']:.4f}  {_steps(r)}")
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
