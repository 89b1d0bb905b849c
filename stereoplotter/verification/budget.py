"""Per-part error budget of a simulated procedure.

For every named instrument error term (:mod:`stereoplotter.instrument.error_model`, at its
configured σ) and every operator error (:class:`~stereoplotter.procedure.operator.OperatorModel`:
pointing, x- and y-parallax clearing, reading, setting, rounding to the least count), its
contribution to three measures of the built model on the working-area grid
(:data:`MEASURES`): the true residual y-parallax RMS [µm, photo scale], the height error RMS
[‰ H̄] and the plan error RMS [mm at map scale].

Contributions are differences of mean squares (MS, over the grid points and the trials) between
configurations of the same simulated procedure (``procedure.simulate``):

* one at a time: Δᵢ = MS(only i on) − MS(all off), the floor "all off" being the error-free
  procedure (its residue is the sheet's own approximations);
* all but one: Δᵢ = MS(all on) − MS(all on except i).

Common random numbers: every configuration runs the same N base trials — trial j draws the same
instrument errors (keyed streams, ``ErrorModel.draw_keyed``) and the same operator judgments
(keyed by act, :class:`_BudgetNoise`) whichever terms are on — so Δᵢ is the mean of paired
per-trial differences and its standard error comes from their scatter. Many configurations run
stacked in one vectorised procedure run (trial block k = configuration k); the backlash terms and
the rounding are properties of a whole run (the screws' dead band, the operator's habit), so they
are varied run by run.

The contribution is reported as an RMS, sign(Δ)·√|Δ| (a negative Δ: switching the term on made
the measure smaller), with SE = half the width of √ over Δ ± SE(Δ).

Predicted column ("linear"): the σ² order of Δ from a smooth expansion of the
error-free procedure with its decisions held fixed. Differences at ±ε, ±2ε with ε = 0.001 σ
(:data:`LINEARISATION_STEP`, far inside every loop's pass/fail jump of the error-free run) give
the derivative g and the curvature h at each grid point p; for a zero-mean error of variance
var, Δ_pred = var · mean_p (gₚ² + y₀ₚ·hₚ) — the linear term and the floor's curvature term
(the error-free floor y₀ is not zero, so the curvature enters Δ at the same order σ²); var = σ²
for a normal term, a²/3 for a uniform one of half-width a; for an operator error, the sum over
every judgment act of the error-free procedure (each act an independent draw). The same at
ε = 0.01 σ (:data:`CHECK_STEP`) must agree within 1 %, else the response is not smooth about
zero error and the prediction is dropped. Each prediction is validated against the simulated
one-at-a-time Δ: kept where |Δ_sim − Δ_pred| ≤ 2 SE (:data:`Z_AGREE`), else dropped with the
measured reason (the z, and the fraction of trials whose decisions — loop passes, checks,
remedies — differ from the error-free run's with that term alone). The backlash (a dead band)
and the rounding to the least count (a step) have no smooth model. Additivity: Σ one-at-a-time
Δ against Δ(all on − all off) within 2 SE, else the interacting terms are listed with their
interaction Δ(all but one) − Δ(one at a time) and its SE.

Pure: no file, no plot (``report.budget`` and ``plotting.budget`` render the result).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from stereoplotter.constants import MM_PER_M, UM_PER_MM
from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.error_model import ErrorModel, error_model_from_spec
from stereoplotter.procedure.operator import Noise, OperatorModel
from stereoplotter.procedure.run import PreparedRun
from stereoplotter.procedure.simulate import prepare_run, run_trials_chunk
from stereoplotter.procedure.trials import DEFAULT_MEMORY_BUDGET_MB, chunk_trials_for
from stereoplotter.random_streams import keyed_draws
from stereoplotter.scenario.model import Scenario
from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = [
    "DEFAULT_BUDGET_TRIALS",
    "LINEARISATION_STEP",
    "MEASURES",
    "OPERATOR_TERMS",
    "BudgetTerm",
    "budget_terms",
    "budget_work",
    "run_budget",
]

#: Base trials per configuration by default: `budget pair60 --instrument sc1` takes 34.8 s on
#: two cores (setup method; conventional 57.8 s), under the 60 s goal with room for a busy machine;
#: 3 000 took 52 s (``benchmarks/bench_budget.py``). SE of the largest contributions ≈ 1 %.
DEFAULT_BUDGET_TRIALS = 2000

#: Step of the numerical linearisation, in σ of the term (central differences). Small enough
#: that no decision of the error-free procedure (a loop's pass count, a check's pass/fail, a
#: remedy) changes within it: the derivative is the procedure's with its decisions held fixed
#: (a step of 0.1 σ crosses the loops' pass/fail jumps). [—]
LINEARISATION_STEP = 1e-3
#: A second step: a term whose predicted Δ differs between the two steps by more than
#: :data:`STEP_AGREEMENT` (relative) is not smooth about zero error — a branch or a kink within
#: the steps (a smooth response changes by O(ε²) ≈ 1e-4 between them); its prediction is
#: dropped. [—]
CHECK_STEP = 1e-2
STEP_AGREEMENT = 1e-2
#: A contribution below this fraction of the all-on mean square, simulated and predicted, is
#: negligible (numerical noise of the procedure's solves): no validation asked. [—]
NEGLIGIBLE = 1e-6
#: Agreement of the linear and the simulated one-at-a-time Δ: |Δ_sim − Δ_lin| ≤ Z·SE(Δ_sim);
#: of Σ one-at-a-time Δ and Δ(all on − all off): |gap| ≤ Z·SE(gap) (2 SE). [—]
Z_AGREE = 2.0

#: The three measures: key → (unit, what).
MEASURES = {
    "residual_y_parallax_rms_um": ("µm", "true residual y-parallax RMS on the grid, photo scale"),
    "height_error_rms_permille": ("‰ H", "height error RMS on the grid, ‰ of the flying height"),
    "plan_error_rms_map_mm": ("mm", "plan error RMS on the grid, mm at map scale"),
}

#: Operator errors: term name → (noise family = key prefix of the act, OperatorModel field,
#: unit of the field, meaning).
OPERATOR_TERMS = {
    "operator.pointing": (
        "mono",
        "monocular_sigma_mm",
        "mm",
        "pointing the mark on a point of one photo (monocular), per axis",
    ),
    "operator.x_parallax_clearing": (
        "stereo",
        "stereo_sigma_mm",
        "mm",
        "x-parallax judged zero (mark set on the ground)",
    ),
    "operator.y_parallax_clearing": (
        "q",
        "y_parallax_sigma_mm",
        "mm",
        "y-parallax judged cleared",
    ),
    "operator.reading": ("read", "reading_sigma_lc", "least count", "reading a counter or scale"),
    "operator.setting": ("set", "setting_sigma_lc", "least count", "setting a scale to a value"),
}
#: Rounding of every reading to the least count (``OperatorModel.quantise``).
ROUNDING = "operator.rounding"


@dataclass(frozen=True, slots=True)
class BudgetTerm:
    """One error of the budget.

    ``kind`` "instrument" or "operator"; ``per_trial``: the term varies trial by trial (a random
    draw); otherwise it is fixed for a whole run (backlash, rounding). ``variance_factor``: var /
    scale² of the distribution (1 normal, 1/3 uniform), None where no linear model exists.
    """

    name: str
    kind: str
    distribution: str
    scale: float
    unit: str
    source: str
    assumed: bool
    meaning: str
    per_trial: bool
    variance_factor: float | None


def budget_terms(model: ErrorModel, operator: OperatorModel) -> list[BudgetTerm]:
    """The instrument's error terms, then the operator's errors, in the order of the table."""
    out = []
    for t in model.terms:
        per_trial = t.distribution != "constant"
        factor = {"normal": 1.0, "uniform": 1.0 / 3.0}.get(t.distribution)
        out.append(
            BudgetTerm(
                t.name,
                "instrument",
                t.distribution,
                t.scale,
                t.unit,
                t.source_key,
                t.assumed,
                t.meaning,
                per_trial,
                factor,
            )
        )
    for name, (_, field, unit, meaning) in OPERATOR_TERMS.items():
        out.append(
            BudgetTerm(
                name,
                "operator",
                "normal",
                float(getattr(operator, field)),
                unit,
                f"OperatorModel.{field}",
                True,
                meaning,
                True,
                1.0,
            )
        )
    out.append(
        BudgetTerm(
            ROUNDING,
            "operator",
            "rounding",
            1.0 if operator.quantise else 0.0,
            "least count",
            "OperatorModel.quantise",
            True,
            "readings rounded to the least count",
            False,
            None,
        )
    )
    return out


class _BudgetNoise(Noise):
    """Operator judgments of stacked configurations: block k of n_base trials repeats base trials
    0 … n_base−1; ``factors[family]`` (T,) switches a family on (1) or off (0) per trial."""

    def __init__(
        self,
        seed: int,
        n_base: int,
        factors: dict[str, NDArray[np.float64]],
        cache: dict[str, NDArray[np.float64]],
    ):
        trials = len(next(iter(factors.values())))
        super().__init__(seed, trials)
        self.stacked_trials = trials
        self.n_base = n_base
        self.factors = factors
        self.cache = cache

    def normal(self, key: str, sigma: float) -> NDArray[np.float64]:
        f = _family_factor(self.factors, key)
        if sigma == 0.0 or not f.any():
            return np.zeros(self.stacked_trials)
        z = self.cache.get(key)
        if z is None:
            z = keyed_draws(self.seed, key, 0, self.n_base, _standard_normal)
            self.cache[key] = z
        out: NDArray[np.float64] = np.tile(z, self.stacked_trials // self.n_base) * f * sigma
        return out


class _LinearisationNoise(Noise):
    """Designed operator judgments: ``steps[key]`` (T,) in units of the act's σ; every other act
    exact. ``record`` collects the act keys in order of first use (the discovery run)."""

    def __init__(
        self, trials: int, steps: dict[str, NDArray[np.float64]], record: list[str] | None = None
    ):
        super().__init__(0, trials)
        self.design_trials = trials
        self.steps = steps
        self.record = record

    def normal(self, key: str, sigma: float) -> NDArray[np.float64]:
        _family_of(key)
        if self.record is not None and key not in self.record:
            self.record.append(key)
        step = self.steps.get(key)
        return np.zeros(self.design_trials) if step is None else step * sigma


_FAMILIES = {family: name for name, (family, *_rest) in OPERATOR_TERMS.items()}


def _family_of(key: str) -> str:
    family = key.split("/", 1)[0]
    if family not in _FAMILIES:
        raise StereoplotterError(
            f"error budget: an operator act {key!r} of no known kind ({', '.join(_FAMILIES)})"
        )
    return family


def _family_factor(factors: dict[str, NDArray[np.float64]], key: str) -> NDArray[np.float64]:
    return factors[_family_of(key)]


def _standard_normal(rng: np.random.Generator, n: int) -> NDArray[np.float64]:
    return rng.standard_normal(n)


@dataclass(frozen=True)
class _Config:
    """A configuration: the names of the terms switched on."""

    label: str
    on: frozenset[str]


def _configs(terms: Sequence[BudgetTerm]) -> list[_Config]:
    every = frozenset(t.name for t in terms)
    out = [_Config("all on", every), _Config("all off", frozenset())]
    for t in terms:
        out.append(_Config(f"only {t.name}", frozenset({t.name})))
        out.append(_Config(f"all but {t.name}", every - {t.name}))
    return out


def _run_key(config: _Config, terms: Sequence[BudgetTerm]) -> frozenset[str]:
    """What must be equal for configurations to share a run: the per-run terms switched on."""
    return frozenset(t.name for t in terms if not t.per_trial and t.name in config.on)


def _measures(
    result: Any, first: int, stop: int, n_base: int
) -> list[dict[str, NDArray[np.float64]]]:
    """Per configuration block of a stacked result: per-trial mean squares of each measure."""
    ev = result.evaluation
    q = np.asarray(result.q_grid_mm, float)[first:stop] * UM_PER_MM
    per_h = MM_PER_M / float(ev.flying_height_m)
    h = np.asarray(ev.grid.height_error_m, float)[first:stop] * per_h
    m = MM_PER_M / ev.map_scale_denominator if ev.map_scale_denominator else math.nan
    dx = np.asarray(ev.grid.x_error_m, float)[first:stop] * m
    dy = np.asarray(ev.grid.y_error_m, float)[first:stop] * m
    per_trial = {
        "residual_y_parallax_rms_um": np.mean(q**2, axis=1),
        "height_error_rms_permille": np.mean(h**2, axis=1),
        "plan_error_rms_map_mm": np.mean(dx**2 + dy**2, axis=1),
    }
    k = (stop - first) // n_base
    return [
        {key: v[i * n_base : (i + 1) * n_base] for key, v in per_trial.items()} for i in range(k)
    ]


#: Key of the per-trial decisions of a configuration (beside the measures' mean squares).
DECISIONS = "decisions"


def _decisions(result: Any, trials: int) -> NDArray[np.float64]:
    """The procedure's decisions per trial, (T, k): every loop's passes, every check's pass or
    fail and every remedy's application and rounds (what a linearisation holds fixed)."""
    cols = [s.iterations for _, s in sorted(result.stages.items())]
    for _, c in sorted(result.checks.items()):
        if c.passed is not None:
            cols.append(c.passed)
    for _, r in sorted(result.remedies.items()):
        cols += [r.applied, r.rounds]
    if not cols:
        return np.zeros((trials, 0))
    return np.stack([np.broadcast_to(np.asarray(c, float), (trials,)) for c in cols], axis=-1)


def _stacked_inputs(
    configs: Sequence[_Config],
    terms: Sequence[BudgetTerm],
    base: Mapping[str, NDArray[np.float64] | float],
    n_base: int,
) -> tuple[dict[str, Any], dict[str, NDArray[np.float64]]]:
    """Injected instrument errors and operator family switches of configurations stacked."""
    injected: dict[str, Any] = {}
    factors: dict[str, list[NDArray[np.float64]]] = {family: [] for family in _FAMILIES}
    for t in terms:
        if t.kind != "instrument":
            continue
        if t.per_trial:
            injected[t.name] = np.concatenate(
                [base[t.name] if t.name in c.on else np.zeros(n_base) for c in configs]
            )
        else:  # the same for every configuration of the run
            injected[t.name] = t.scale if t.name in configs[0].on else 0.0
    for c in configs:
        for family, name in _FAMILIES.items():
            factors[family].append(np.full(n_base, 1.0 if name in c.on else 0.0))
    return injected, {f: np.concatenate(v) for f, v in factors.items()}


def _run_group(
    prep: PreparedRun,
    configs: Sequence[_Config],
    terms: Sequence[BudgetTerm],
    base: Mapping[str, NDArray[np.float64] | float],
    n_base: int,
    chunk_trials: int,
    cache: dict[str, NDArray[np.float64]],
    progress: Callable[[int], None] | None,
) -> dict[str, dict[str, NDArray[np.float64]]]:
    """Run configurations sharing their per-run terms; label → per-trial mean squares."""
    rounding = ROUNDING in configs[0].on and prep.operator.quantise
    prep = replace(prep, operator=replace(prep.operator, quantise=rounding))
    per_chunk = max(1, chunk_trials // n_base)
    out = {}
    for i in range(0, len(configs), per_chunk):
        part = configs[i : i + per_chunk]
        injected, factors = _stacked_inputs(part, terms, base, n_base)
        noise = _BudgetNoise(prep.seed, n_base, factors, cache)
        trials = len(part) * n_base
        result = run_trials_chunk(
            prep, 0, trials, evaluate=True, transcript=False, injected=injected, noise=noise
        )
        decisions = _decisions(result, trials)
        for k, (c, ms) in enumerate(zip(part, _measures(result, 0, trials, n_base), strict=True)):
            ms[DECISIONS] = decisions[k * n_base : (k + 1) * n_base]
            out[c.label] = ms
        if progress is not None:
            progress(trials)
    return out


def _linear_predictions(
    prep: PreparedRun, terms: Sequence[BudgetTerm]
) -> tuple[dict[str, dict[str, float]], dict[str, dict[str, float]]]:
    """Δ_lin per term and measure from central differences about the error-free procedure,
    at :data:`LINEARISATION_STEP` and at :data:`CHECK_STEP` (the second for the step check)."""
    prep = replace(prep, operator=replace(prep.operator, quantise=False))
    zero = {t.name: 0.0 for t in terms if t.kind == "instrument"}
    acts: list[str] = []
    run_trials_chunk(
        prep,
        0,
        1,
        evaluate=False,
        transcript=False,
        injected=zero,
        noise=_LinearisationNoise(1, {}, acts),
    )
    linear = [t for t in terms if t.variance_factor is not None and t.scale > 0]
    instrument = [t for t in linear if t.kind == "instrument"]
    pairs = len(instrument) + len(acts)
    steps_sigma = (LINEARISATION_STEP, CHECK_STEP)
    trials = 1 + _POINTS * pairs * len(steps_sigma)
    injected: dict[str, Any] = {}
    for t in terms:
        if t.kind == "instrument":
            injected[t.name] = np.zeros(trials) if t.per_trial else 0.0
    steps: dict[str, NDArray[np.float64]] = {key: np.zeros(trials) for key in acts}
    for b, eps in enumerate(steps_sigma):
        first = 1 + _POINTS * pairs * b
        for j, t in enumerate(instrument):
            at = first + _POINTS * j
            injected[t.name][at : at + _POINTS] = np.multiply(_OFFSETS, eps * t.scale)
        for k, key in enumerate(acts):
            at = first + _POINTS * (len(instrument) + k)
            steps[key][at : at + _POINTS] = np.multiply(_OFFSETS, eps)
    result = run_trials_chunk(
        prep,
        0,
        trials,
        evaluate=True,
        transcript=False,
        injected=injected,
        noise=_LinearisationNoise(trials, steps),
    )
    fields = _difference_fields(result, trials)
    out = []
    for b, eps in enumerate(steps_sigma):
        first = 1 + _POINTS * pairs * b
        sq = _difference_squares(fields, first, pairs, eps)  # measure → (pairs,)
        by_term: dict[str, dict[str, float]] = {}
        for j, t in enumerate(instrument):
            by_term[t.name] = {m: float(t.variance_factor * v[j]) for m, v in sq.items()}
        for name, (family, field, *_rest) in OPERATOR_TERMS.items():
            if getattr(prep.operator, field) == 0.0:
                continue
            idx = [len(instrument) + k for k, key in enumerate(acts) if _family_of(key) == family]
            by_term[name] = {m: float(np.sum(v[idx])) for m, v in sq.items()}
        out.append(by_term)
    return out[0], out[1]


def _difference_fields(result: Any, trials: int) -> dict[str, list[NDArray[np.float64]]]:
    """The measures' fields of a linearisation run, (trials, points) each, in their units."""
    ev = result.evaluation
    m = MM_PER_M / ev.map_scale_denominator if ev.map_scale_denominator else math.nan
    fields = {
        "residual_y_parallax_rms_um": [np.asarray(result.q_grid_mm, float) * UM_PER_MM],
        "height_error_rms_permille": [
            np.asarray(ev.grid.height_error_m, float) * MM_PER_M / ev.flying_height_m
        ],
        "plan_error_rms_map_mm": [
            np.asarray(ev.grid.x_error_m, float) * m,
            np.asarray(ev.grid.y_error_m, float) * m,
        ],
    }
    return {k: [a.reshape(trials, -1) for a in v] for k, v in fields.items()}


#: Points of the difference scheme per term, in steps ε: none at 0 (the error-free value itself
#: can sit on a branch that any non-zero error leaves, e.g. a zero reading of exactly 0).
_OFFSETS = (1.0, -1.0, 2.0, -2.0)
_POINTS = len(_OFFSETS)


def _difference_squares(
    fields: dict[str, list[NDArray[np.float64]]], first: int, terms: int, eps: float
) -> dict[str, NDArray[np.float64]]:
    """mean_p (g² + y₀·h) per term from trial ``first`` on, in the measures' units² per σ²:
    g = (y₁ − y₋₁)/(2ε) and h = (y₂ + y₋₂ − y₁ − y₋₁)/(3ε²) the first and second derivatives
    (yₖ at k·ε, :data:`_OFFSETS`), y₀ the error-free result (trial 0). For a zero-mean error e of
    variance σ², E[(y₀ + g·e + ½h·e²)²] − y₀² = σ²(g² + y₀·h) + O(σ⁴): the σ² order of Δ of the
    mean square, which has the floor's curvature term y₀·h beside the linear g² (the floor y₀
    is not zero)."""
    out: dict[str, NDArray[np.float64]] = {}
    for key, arrays in fields.items():
        total: NDArray[np.float64] | float = 0.0
        for a in arrays:
            y0 = a[0]
            block = a[first : first + _POINTS * terms]
            p1, m1, p2, m2 = (block[i::_POINTS] for i in range(_POINTS))
            g = (p1 - m1) / (2.0 * eps)
            h = (p2 + m2 - p1 - m1) / (3.0 * eps**2)
            total = total + np.mean(g**2 + y0 * h, axis=1)
        out[key] = np.asarray(total)
    return out


def _rms(ms: NDArray[np.float64]) -> dict[str, float]:
    """RMS = √mean(ms) with its standard error (delta method)."""
    n = ms.size
    mean = float(np.mean(ms))
    se = float(np.std(ms, ddof=1) / math.sqrt(n)) if n > 1 else math.nan
    rms = math.sqrt(max(mean, 0.0))
    return {"rms": rms, "se": se / (2.0 * rms) if rms > 0 else 0.0, "ms": mean, "ms_se": se}


def _contribution(on: NDArray[np.float64], off: NDArray[np.float64]) -> dict[str, float]:
    """Δ = mean(on − off) (paired) with its SE, and the signed RMS sign(Δ)·√|Δ| with its SE."""
    d = on - off
    delta = float(np.mean(d))
    se = float(np.std(d, ddof=1) / math.sqrt(d.size)) if d.size > 1 else math.nan
    root = math.copysign(math.sqrt(abs(delta)), delta)
    lo = math.sqrt(max(abs(delta) - se, 0.0))
    hi = math.sqrt(abs(delta) + se)
    return {"rms": root, "se": (hi - lo) / 2.0, "delta_ms": delta, "delta_ms_se": se}


def _linear_entry(
    delta: float | None, check: float | None, sim: dict[str, float], changed: float, ms_on: float
) -> dict[str, Any]:
    """The predicted Δ validated against the simulated one-at-a-time Δ (``sim``) within
    :data:`Z_AGREE` SE, and against the step check; dropped (rms and delta_ms null) with the
    measured reason otherwise (``predicted_ms``: the σ² expansion whatever its status).
    ``changed``: the fraction of the trials with this term alone whose
    decisions differ from the error-free run's; ``ms_on``: the all-on mean square."""
    if delta is None:
        return {
            "rms": None,
            "delta_ms": None,
            "predicted_ms": None,
            "status": "none",
            "z": None,
            "reason": "",
        }
    d_sim, se = sim["delta_ms"], sim["delta_ms_se"]
    z = (d_sim - delta) / se if se > 0.0 and math.isfinite(se) else None
    tiny = NEGLIGIBLE * abs(ms_on)
    if max(abs(delta), abs(check or 0.0), abs(d_sim)) <= tiny:
        return {
            "rms": 0.0,
            "delta_ms": 0.0,
            "predicted_ms": delta,
            "status": "negligible",
            "z": None,
            "reason": "",
        }
    scale = max(abs(delta), abs(check or 0.0))
    stable = check is not None and abs(delta - check) <= STEP_AGREEMENT * scale
    agrees = abs(z) <= Z_AGREE if z is not None else abs(d_sim - delta) <= tiny
    if agrees and stable:
        return {
            "rms": math.sqrt(max(delta, 0.0)),
            "delta_ms": delta,
            "predicted_ms": delta,
            "status": "validated",
            "z": z,
            "reason": "",
        }
    if not stable:
        why = (
            f"not smooth about zero error: the σ² expansion at {LINEARISATION_STEP:g} σ "
            f"({delta:.4g}) and at {CHECK_STEP:g} σ ({check:.4g}) differ (a branch or kink "
            f"within the steps); simulated {d_sim:.4g} ± {se:.2g}"
        )
    else:
        why = (
            f"predicted Δ {delta:.4g} against the simulated {d_sim:.4g} ± {se:.2g} "
            f"({z:+.1f} SE); with this term alone the procedure decided otherwise than the "
            f"error-free run (loop passes, checks, remedies) in {changed:.1%} of the trials"
        )
    return {
        "rms": None,
        "delta_ms": None,
        "predicted_ms": delta,
        "status": "dropped",
        "z": z,
        "reason": why,
    }


def run_budget(
    scenario: Scenario,
    spec: InstrumentSpec,
    method: str = "setup",
    *,
    trials: int = DEFAULT_BUDGET_TRIALS,
    seed: int = 0,
    errors: ErrorModel | None = None,
    operator: OperatorModel | None = None,
    progress: Callable[[int], None] | None = None,
    memory_budget_mb: float = DEFAULT_MEMORY_BUDGET_MB,
) -> dict[str, Any]:
    """The error budget of ``method`` on ``spec`` for ``scenario`` (JSON-ready, module doc).

    ``progress(n)``: n more trial-configurations done (total :func:`budget_work`).
    """
    if trials < 2:
        raise StereoplotterError(f"trials: expected ≥ 2 (a standard error), found {trials}")
    if method not in ("setup", "conventional"):
        raise StereoplotterError(f"method: expected setup or conventional, found {method!r}")
    model = error_model_from_spec(spec) if errors is None else errors
    # σ_p, σ_q of the operator's eye on this instrument (procedure.eye), as the run uses them
    op = (OperatorModel() if operator is None else operator).for_instrument(spec)
    terms = budget_terms(model, op)
    prep = prepare_run(scenario, spec, method, model, seed, operator=op)
    base = model.draw_keyed(prep.seed, 0, trials)
    configs = _configs(terms)
    groups: dict[frozenset[str], list[_Config]] = {}
    for c in configs:
        groups.setdefault(_run_key(c, terms), []).append(c)
    chunk = chunk_trials_for(memory_budget_mb, method)
    if trials > chunk:
        raise StereoplotterError(
            f"trials: expected at most {chunk} for the {method} method (one configuration's "
            f"trials run in one chunk of {memory_budget_mb:g} MB), found {trials}"
        )
    cache: dict[str, NDArray[np.float64]] = {}
    ms: dict[str, dict[str, NDArray[np.float64]]] = {}
    for group in groups.values():
        ms.update(_run_group(prep, group, terms, base, trials, chunk, cache, progress))
    linear, linear_check = _linear_predictions(prep, terms)
    ref = ms["all off"][DECISIONS][:1]
    changed = {
        t.name: float(np.mean(np.any(ms[f"only {t.name}"][DECISIONS] != ref, axis=1)))
        for t in terms
    }
    rows = [_term_row(t, ms, linear, linear_check, changed[t.name]) for t in terms]
    valid = {r["name"]: {m: r["linear"][m]["delta_ms"] for m in MEASURES} for r in rows}
    totals = {m: _totals(m, terms, ms, valid) for m in MEASURES}
    return {
        "scenario": scenario.name,
        "instrument": spec.key,
        "method": method,
        "trials": int(trials),
        "seed": int(prep.seed),
        "configurations": len(configs),
        "linearisation_step_sigma": LINEARISATION_STEP,
        "check_step_sigma": CHECK_STEP,
        "agreement_z": Z_AGREE,
        "measures": {k: {"unit": u, "meaning": w} for k, (u, w) in MEASURES.items()},
        "operator": op.to_dict(),
        "terms": rows,
        "totals": totals,
    }


def _totals(
    m: str,
    terms: Sequence[BudgetTerm],
    ms: dict[str, dict[str, NDArray[np.float64]]],
    linear: dict[str, dict[str, float | None]],
) -> dict[str, Any]:
    """All on, all off (the error-free floor), and the additivity of the one-at-a-time Δᵢ.

    ``additivity``: Σᵢ Δᵢ(one at a time) against Δ(all on − all off), with the SE of their
    per-trial paired gap (equal in expectation when the terms act linearly and independently);
    ``adds_up``: |gap| ≤ :data:`Z_AGREE`·SE. ``interactions``: every term whose contribution in
    the presence of the others differs from its contribution alone, Iᵢ = Δᵢ(all but one) −
    Δᵢ(one at a time) (paired, same trials), by more than Z_AGREE·SE(Iᵢ).
    """
    off = ms["all off"][m]
    on = ms["all on"][m]
    gap_t = sum(ms[f"only {t.name}"][m] - off for t in terms) - (on - off)
    n = off.size
    floor = float(np.mean(off))
    gap, gap_se = float(np.mean(gap_t)), float(np.std(gap_t, ddof=1) / math.sqrt(n))
    interactions = []
    for t in terms:
        i_t = (on - ms[f"all but {t.name}"][m]) - (ms[f"only {t.name}"][m] - off)
        d, se = float(np.mean(i_t)), float(np.std(i_t, ddof=1) / math.sqrt(n))
        if abs(d) > Z_AGREE * se and d != 0.0:
            interactions.append({"term": t.name, "delta_ms": d, "delta_ms_se": se})
    lin = [x for v in linear.values() if (x := v.get(m)) is not None]
    return {
        "all_on": _rms(on),
        "all_off": _rms(off),
        "total_delta": _contribution(on, off),
        "additivity": {
            "sum_one_at_a_time_ms": float(
                sum(np.mean(ms[f"only {t.name}"][m] - off) for t in terms)
            ),
            "gap_ms": gap,
            "gap_ms_se": gap_se,
            "adds_up": bool(abs(gap) <= Z_AGREE * gap_se),
            "interactions": interactions,
        },
        "linear_all_on_rms": math.sqrt(max(floor + sum(lin), 0.0)),
    }


def budget_work(model: ErrorModel, trials: int) -> int:
    """Trial-configurations a budget runs: (2 per term + 2) × trials (for the progress bar)."""
    n_terms = len(model.terms) + len(OPERATOR_TERMS) + 1
    return (2 * n_terms + 2) * trials


def _term_row(
    t: BudgetTerm,
    ms: dict[str, dict[str, NDArray[np.float64]]],
    linear: dict[str, dict[str, float]],
    linear_check: dict[str, dict[str, float]],
    changed: float,
) -> dict[str, Any]:
    if t.variance_factor is None:
        how = "no linear model"
    elif t.scale == 0:
        how = "zero (σ = 0)"
    else:
        how = "numerical linearisation"
    one = {m: _contribution(ms[f"only {t.name}"][m], ms["all off"][m]) for m in MEASURES}
    lin: dict[str, float] | None = linear.get(t.name)
    linear_check_t: dict[str, float] | None
    if how.startswith("zero"):
        lin = linear_check_t = {m: 0.0 for m in MEASURES}
    else:
        linear_check_t = linear_check.get(t.name)
    return {
        "name": t.name,
        "kind": t.kind,
        "distribution": t.distribution,
        "scale": t.scale,
        "unit": t.unit,
        "source": t.source,
        "assumed": t.assumed,
        "meaning": t.meaning,
        "linear_model": how,
        "decisions_changed": changed,
        "one_at_a_time": one,
        "all_but_one": {
            m: _contribution(ms["all on"][m], ms[f"all but {t.name}"][m]) for m in MEASURES
        },
        "linear": {
            m: _linear_entry(
                None if lin is None else lin[m],
                None if linear_check_t is None else linear_check_t[m],
                one[m],
                changed,
                float(np.mean(ms["all on"][m])),
            )
            for m in MEASURES
        },
    }
