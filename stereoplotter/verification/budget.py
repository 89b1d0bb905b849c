"""Per-part error budget of a simulated procedure (issue 10, deliverable 5).

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

Linear prediction (first-order propagation by a numerical linearisation of the error-free
procedure, central differences with a step of ε = 0.1 σ): for an instrument term with gradient
gₚ at grid point p, Δ_lin = var · mean_p gₚ² (var = σ² for a normal term, a²/3 for a uniform one
of half-width a); for an operator error, the sum over every judgment act of the procedure (each
act an independent draw). The backlash (a dead band, not differentiable at 0) and the rounding to
the least count (a step function) have no linear model. No accuracy formula of ch. 6 gives the
separate contribution of these terms on this grid, so every prediction here is the numerical
one (``method`` says so per term).

Pure: no file, no plot (``report.budget`` and ``plotting.budget`` render the result).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
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

#: Step of the numerical linearisation, in σ of the term (central differences). [—]
LINEARISATION_STEP = 0.1

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

    def __init__(self, seed: int, n_base: int, factors: dict[str, NDArray], cache: dict):
        trials = len(next(iter(factors.values())))
        super().__init__(seed, trials)
        self.n_base = n_base
        self.factors = factors
        self.cache = cache

    def normal(self, key: str, sigma: float) -> NDArray[np.float64]:
        f = _family_factor(self.factors, key)
        if sigma == 0.0 or not f.any():
            return np.zeros(self.trials)
        z = self.cache.get(key)
        if z is None:
            z = keyed_draws(self.seed, key, 0, self.n_base, _standard_normal)
            self.cache[key] = z
        return np.tile(z, self.trials // self.n_base) * f * sigma


class _LinearisationNoise(Noise):
    """Designed operator judgments: ``steps[key]`` (T,) in units of the act's σ; every other act
    exact. ``record`` collects the act keys in order of first use (the discovery run)."""

    def __init__(self, trials: int, steps: dict[str, NDArray], record: list[str] | None = None):
        super().__init__(0, trials)
        self.steps = steps
        self.record = record

    def normal(self, key: str, sigma: float) -> NDArray[np.float64]:
        _family_of(key)
        if self.record is not None and key not in self.record:
            self.record.append(key)
        step = self.steps.get(key)
        return np.zeros(self.trials) if step is None else step * sigma


_FAMILIES = {family: name for name, (family, *_rest) in OPERATOR_TERMS.items()}


def _family_of(key: str) -> str:
    family = key.split("/", 1)[0]
    if family not in _FAMILIES:
        raise StereoplotterError(
            f"error budget: an operator act {key!r} of no known kind ({', '.join(_FAMILIES)})"
        )
    return family


def _family_factor(factors: dict[str, NDArray], key: str) -> NDArray:
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


def _measures(result: Any, first: int, stop: int, n_base: int) -> list[dict[str, NDArray]]:
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


def _stacked_inputs(
    configs: Sequence[_Config],
    terms: Sequence[BudgetTerm],
    base: dict[str, NDArray],
    n_base: int,
) -> tuple[dict[str, Any], dict[str, NDArray]]:
    """Injected instrument errors and operator family switches of configurations stacked."""
    injected: dict[str, Any] = {}
    factors = {family: [] for family in _FAMILIES}
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
    base: dict[str, NDArray],
    n_base: int,
    chunk_trials: int,
    cache: dict,
    progress: Callable[[int], None] | None,
) -> dict[str, dict[str, NDArray]]:
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
        for c, ms in zip(part, _measures(result, 0, trials, n_base), strict=True):
            out[c.label] = ms
        if progress is not None:
            progress(trials)
    return out


def _linear_predictions(
    prep: PreparedRun, terms: Sequence[BudgetTerm]
) -> dict[str, dict[str, float]]:
    """Δ_lin per term and measure from central differences about the error-free procedure."""
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
    trials = 1 + 2 * pairs
    injected: dict[str, Any] = {}
    for t in terms:
        if t.kind == "instrument":
            injected[t.name] = np.zeros(trials) if t.per_trial else 0.0
    for j, t in enumerate(instrument):
        injected[t.name][1 + 2 * j] = LINEARISATION_STEP * t.scale
        injected[t.name][2 + 2 * j] = -LINEARISATION_STEP * t.scale
    steps = {}
    for k, key in enumerate(acts):
        s = np.zeros(trials)
        s[1 + 2 * (len(instrument) + k)] = LINEARISATION_STEP
        s[2 + 2 * (len(instrument) + k)] = -LINEARISATION_STEP
        steps[key] = s
    result = run_trials_chunk(
        prep,
        0,
        trials,
        evaluate=True,
        transcript=False,
        injected=injected,
        noise=_LinearisationNoise(trials, steps),
    )
    sq = _difference_squares(result, trials)  # measure → (pairs,)
    out: dict[str, dict[str, float]] = {}
    for j, t in enumerate(instrument):
        out[t.name] = {m: float(t.variance_factor * v[j]) for m, v in sq.items()}
    for name, (family, field, *_rest) in OPERATOR_TERMS.items():
        if getattr(prep.operator, field) == 0.0:
            continue
        idx = [len(instrument) + k for k, key in enumerate(acts) if _family_of(key) == family]
        out[name] = {m: float(np.sum(v[idx])) for m, v in sq.items()}
    return out


def _difference_squares(result: Any, trials: int) -> dict[str, NDArray]:
    """mean_p ((y₊ − y₋)/(2ε))² per ± pair of a linearisation run, in the measures' units²."""
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
    out = {}
    for key, arrays in fields.items():
        total = 0.0
        for a in arrays:
            a = a.reshape(trials, -1)
            g = (a[1::2] - a[2::2]) / (2.0 * LINEARISATION_STEP)
            total = total + np.mean(g**2, axis=1)
        out[key] = total
    return out


def _rms(ms: NDArray) -> dict[str, float]:
    """RMS = √mean(ms) with its standard error (delta method)."""
    n = ms.size
    mean = float(np.mean(ms))
    se = float(np.std(ms, ddof=1) / math.sqrt(n)) if n > 1 else math.nan
    rms = math.sqrt(max(mean, 0.0))
    return {"rms": rms, "se": se / (2.0 * rms) if rms > 0 else 0.0, "ms": mean, "ms_se": se}


def _contribution(on: NDArray, off: NDArray) -> dict[str, float]:
    """Δ = mean(on − off) (paired) with its SE, and the signed RMS sign(Δ)·√|Δ| with its SE."""
    d = on - off
    delta = float(np.mean(d))
    se = float(np.std(d, ddof=1) / math.sqrt(d.size)) if d.size > 1 else math.nan
    root = math.copysign(math.sqrt(abs(delta)), delta)
    lo = math.sqrt(max(abs(delta) - se, 0.0))
    hi = math.sqrt(abs(delta) + se)
    return {"rms": root, "se": (hi - lo) / 2.0, "delta_ms": delta, "delta_ms_se": se}


def _linear_entry(delta: float | None) -> dict[str, Any]:
    if delta is None:
        return {"rms": None, "delta_ms": None}
    return {"rms": math.sqrt(max(delta, 0.0)), "delta_ms": delta}


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
    op = OperatorModel() if operator is None else operator
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
    cache: dict[str, NDArray] = {}
    ms: dict[str, dict[str, NDArray]] = {}
    for group in groups.values():
        ms.update(_run_group(prep, group, terms, base, trials, chunk, cache, progress))
    linear = _linear_predictions(prep, terms)
    rows = [_term_row(t, ms, linear) for t in terms]
    totals = {m: _totals(m, terms, ms, linear) for m in MEASURES}
    return {
        "scenario": scenario.name,
        "instrument": spec.key,
        "method": method,
        "trials": int(trials),
        "seed": int(prep.seed),
        "configurations": len(configs),
        "linearisation_step_sigma": LINEARISATION_STEP,
        "measures": {k: {"unit": u, "meaning": w} for k, (u, w) in MEASURES.items()},
        "operator": op.to_dict(),
        "terms": rows,
        "totals": totals,
    }


def _totals(
    m: str,
    terms: Sequence[BudgetTerm],
    ms: dict[str, dict[str, NDArray]],
    linear: dict[str, dict[str, float]],
) -> dict[str, Any]:
    """All on, all off (the error-free floor), and the additivity of the one-at-a-time Δᵢ.

    ``additivity``: Σᵢ Δᵢ(one at a time) against Δ(all on − all off), with the SE of their
    per-trial paired gap (equal in expectation when the terms act linearly and independently).
    """
    off = ms["all off"][m]
    gap_t = sum(ms[f"only {t.name}"][m] - off for t in terms) - (ms["all on"][m] - off)
    n = off.size
    floor = float(np.mean(off))
    return {
        "all_on": _rms(ms["all on"][m]),
        "all_off": _rms(off),
        "total_delta": _contribution(ms["all on"][m], off),
        "additivity": {
            "sum_one_at_a_time_ms": float(
                sum(np.mean(ms[f"only {t.name}"][m] - off) for t in terms)
            ),
            "gap_ms": float(np.mean(gap_t)),
            "gap_ms_se": float(np.std(gap_t, ddof=1) / math.sqrt(n)),
        },
        "linear_all_on_rms": math.sqrt(max(floor + sum(v[m] for v in linear.values()), 0.0)),
    }


def budget_work(model: ErrorModel, trials: int) -> int:
    """Trial-configurations a budget runs: (2 per term + 2) × trials (for the progress bar)."""
    n_terms = len(model.terms) + len(OPERATOR_TERMS) + 1
    return (2 * n_terms + 2) * trials


def _term_row(
    t: BudgetTerm, ms: dict[str, dict[str, NDArray]], linear: dict[str, dict[str, float]]
) -> dict[str, Any]:
    if t.variance_factor is None:
        how = "no linear model"
    elif t.scale == 0:
        how = "zero (σ = 0)"
    else:
        how = "numerical linearisation"
    lin = linear.get(t.name)
    zero_lin = {m: 0.0 for m in MEASURES} if how.startswith("zero") else None
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
        "one_at_a_time": {
            m: _contribution(ms[f"only {t.name}"][m], ms["all off"][m]) for m in MEASURES
        },
        "all_but_one": {
            m: _contribution(ms["all on"][m], ms[f"all but {t.name}"][m]) for m in MEASURES
        },
        "linear": {
            m: _linear_entry((lin or zero_lin or {}).get(m) if (lin or zero_lin) else None)
            for m in MEASURES
        },
    }
