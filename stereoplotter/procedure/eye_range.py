"""Pass rates of the book's checks across the published range of the operator's judgement.

The operator's σ_q (y-parallax judged) and σ_p (the fused mark, x-parallax judged) are the two
figures the checks of §26 depend on most; the defaults come from the eye model
(:mod:`stereoplotter.procedure.eye`), the literature gives a range (``docs/procedure.md``,
§The operator's eye: sources). :func:`pass_rate_table` runs the simulated procedure of each
(scenario, method) at each (σ_q, σ_p) of :data:`SETTINGS`, everything else the default operator
and instrument, and reports per setting the rate at which *every* check with a tolerance passed
and the rate of the check that failed most, each with its binomial standard error.

``stereoplotter study eye-range --trials 500`` prints the table of ``docs/procedure.md`` (SC-1,
pair60 and pair80, both methods, the scenarios' own seeds).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from stereoplotter.procedure.operator import OperatorModel
from stereoplotter.procedure.simulate import prepare_run, run_trials_chunk
from stereoplotter.procedure.trials import trial_columns
from stereoplotter.scenario.model import Scenario
from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = ["SETTINGS", "PassRates", "pass_rate_table", "pass_rates", "table_markdown"]

#: (label, σ_q, σ_p) of the table [mm]; None: the eye model's value for the instrument.
SETTINGS: tuple[tuple[str, float | None, float | None], ...] = (
    ("eye model (default): σ_q 2.02, σ_p 6.06 µm", None, None),
    ("σ_q 5 µm", 0.005, None),
    ("σ_q 10 µm (precision plotters, published)", 0.010, None),
    ("σ_q 15 µm (the book's m_q)", 0.015, None),
    ("σ_q 10, σ_p 4 µm (published setting σ)", 0.010, 0.004),
    ("σ_q 10, σ_p 10 µm", 0.010, 0.010),
)


@dataclass(frozen=True)
class PassRates:
    """Of one run: T, the rate at which every check passed and its SE, the check that passed
    least and its rate."""

    trials: int
    all_checks: float
    all_checks_se: float
    weakest: str
    weakest_rate: float


def pass_rates(
    scenario: Scenario, spec: InstrumentSpec, method: str, operator: OperatorModel, trials: int
) -> PassRates:
    """Run ``trials`` trials (the scenario's seed, default errors) and summarise the checks."""
    prep = prepare_run(scenario, spec, method, None, scenario.seed, operator=operator)
    result = run_trials_chunk(prep, 0, trials, evaluate=False, transcript=False)
    cols = trial_columns(result)
    flags = {
        name: cols[f"check/{name}/passed"].astype(bool)
        for name, c in result.checks.items()
        if c.tolerance is not None
    }
    every = np.logical_and.reduce(list(flags.values()))
    rate = float(every.mean())
    weakest = min(flags, key=lambda n: float(flags[n].mean()))
    return PassRates(
        trials,
        rate,
        math.sqrt(rate * (1.0 - rate) / trials),
        weakest,
        float(flags[weakest].mean()),
    )


def pass_rate_table(
    scenarios: Sequence[Scenario],
    spec: InstrumentSpec,
    trials: int,
    methods: tuple[str, ...] = ("setup", "conventional"),
) -> dict[tuple[str, str, str], PassRates]:
    """{(setting label, scenario name, method): PassRates} over :data:`SETTINGS`."""
    out = {}
    for label, sq, sp in SETTINGS:
        operator = OperatorModel(y_parallax_sigma_mm=sq, stereo_sigma_mm=sp)
        for sc in scenarios:
            for method in methods:
                out[(label, sc.name, method)] = pass_rates(sc, spec, method, operator, trials)
    return out


def table_markdown(
    rows: Mapping[tuple[str, str, str], PassRates],
    scenarios: Sequence[Scenario],
    methods: tuple[str, ...] = ("setup", "conventional"),
) -> str:
    """The table: one row per setting of ``rows`` (in their order), per (scenario, method)
    'all checks ± SE (weakest check, its rate)'."""
    heads = [f"{s.name} {m}" for s in scenarios for m in methods]
    lines = [
        "| operator | " + " | ".join(heads) + " |",
        "|---|" + "---:|" * len(heads),
    ]
    short = {
        "stage 1: |L − L′|": "L",
        "stage 2: mark 4": "mark 4",
        "stage 2: residual y-parallax (6 points)": "q₂",
        "stage 3: control heights": "heights",
        "stage 3: residual y-parallax (6 points)": "q₃",
        "stage 5: corner 4": "corner 4",
        "stage 5: plan control points (needle − plotted)": "plan",
        "C2: residual y-parallax (6 points)": "C2",
        "C3: levelling points (against the first)": "C3 lev.",
        "C3: control heights": "C3 heights",
        "C3: residual y-parallax (6 points)": "C3 q",
    }
    for label in dict.fromkeys(k[0] for k in rows):
        cells = []
        for s in scenarios:
            for m in methods:
                r = rows[(label, s.name, m)]
                cells.append(
                    f"{r.all_checks:.2f} ± {r.all_checks_se:.2f} "
                    f"({short.get(r.weakest, r.weakest)} {r.weakest_rate:.2f})"
                )
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
