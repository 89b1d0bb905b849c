"""Linear control variate of a procedure Monte Carlo (``verification.procedure_mc``).

The statistic of the procedure MC is the mean square of an error field v (T trials × P points)
caused by random inputs u: the operator's judgments (one standard normal z per act key, σ·z) and
the injected instrument errors (one draw per term and trial, scale·u). The procedure is run as
built; nothing here changes a trial. For a small error the field is nearly linear in u:

    v ≈ b + Σₖ Gₖ uₖ   (b: the field with every random input at 0, constants such as the
                        backlash on; Gₖ = ∂v/∂uₖ by central differences of ±ε, ε = 0.1)

so L = mean_p (b + Σₖ Gₖ uₖ)² is known per trial from the trial's own draws, and its expectation
is exact: E[L] = mean_p b² + Σₖ var(uₖ) mean_p Gₖ² (var 1 for a normal draw, 1/3 for a uniform
one on [−1, 1]). The estimator of E[mean_p v²] is the mean over trials of

    mean_p v² − L + E[L]

— unbiased whatever the procedure's non-linearity (E[L] is exact, the draws are the trial's), with
a variance of only the non-linear remainder; its standard error comes from the per-trial scatter
as usual. Acts that a noisy trial makes but the error-free run does not (a loop that iterates
longer) are not in L; they stay in the remainder (still unbiased).

Pure numpy; the runs themselves are made by the caller (``procedure.simulate.run_trials_chunk``
with the noise objects of this module).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from stereoplotter.instrument.error_model import ErrorModel, ErrorTerm
from stereoplotter.procedure.operator import Noise

__all__ = [
    "BLOCK_TRIALS",
    "STEP",
    "Design",
    "DesignNoise",
    "LinearControl",
    "RecordingNoise",
    "SourceNoise",
    "StackedNoise",
    "control_from",
    "design",
    "design_inputs",
    "linear_control",
    "per_trial_controlled",
    "row_blocks",
]

#: Step of the central differences, in units of the draw (σ of a normal, half-width of a
#: uniform). [—]
STEP = 0.1

#: Trials whose per-trial reductions are computed at once: a block's arrays (≈ 0.5–2 MB) stay
#: in the processor's cache, where a chunk's (tens of MB) would stream through memory several
#: times. Each trial's row is computed alone, so the block changes no value.
BLOCK_TRIALS = 512

#: Variance of the standardised draw of a distribution.
_VARIANCE = {"normal": 1.0, "uniform": 1.0 / 3.0}


class RecordingNoise(Noise):
    """:class:`Noise` that keeps each act's standard normal draws, key → z (T,)."""

    def __init__(self, seed: int, trials: int, first_trial: int = 0):
        super().__init__(seed, trials, None, first_trial)
        self.z: dict[str, NDArray[np.float64]] = {}

    def normal(self, key: str, sigma: float) -> NDArray[np.float64]:
        v = super().normal(key, sigma)
        if sigma != 0.0:
            self.z[key] = np.asarray(v, float) / sigma
        return v


class SourceNoise(RecordingNoise):
    """:class:`RecordingNoise` whose acts of some sources are exact on some trials: ``off`` maps
    a key prefix (``"q/"``, ``"stereo/"``) to a (T,) mask of the trials where the acts whose key
    starts with it draw 0. A trial so masked is the trial of a run with that source's σ = 0 (the
    other draws keyed as ever), so one run holds the blocks of several source configurations
    (``procedure_mc.conventional_sources_mc``); the recorded z are the masked ones."""

    def __init__(self, seed: int, trials: int, first_trial: int, off: dict[str, NDArray[np.bool_]]):
        super().__init__(seed, trials, first_trial)
        self.off = off

    def normal(self, key: str, sigma: float) -> NDArray[np.float64]:
        v = Noise.normal(self, key, sigma)
        mask = next((m for prefix, m in self.off.items() if key.startswith(prefix)), None)
        if mask is not None and sigma != 0.0:
            v = np.where(mask, 0.0, v)
        if sigma != 0.0:
            self.z[key] = np.asarray(v, float) / sigma
        return v


class DesignNoise(Noise):
    """Designed judgments: ``steps[key]`` (T,) in units of the act's σ, every other act exact;
    ``record`` collects the keys of the acts with σ > 0 in order of first use."""

    def __init__(
        self, trials: int, steps: dict[str, NDArray[np.float64]], record: list[str] | None = None
    ):
        super().__init__(0, trials)
        self.design_trials = trials
        self.steps = steps
        self.record = record

    def normal(self, key: str, sigma: float) -> NDArray[np.float64]:
        if self.record is not None and sigma != 0.0 and key not in self.record:
            self.record.append(key)
        step = self.steps.get(key)
        return np.zeros(self.design_trials) if step is None else step * sigma


@dataclass(frozen=True)
class LinearControl:
    """The linearised field per name: b (P,), G (K, P) over the inputs, and E[L]."""

    inputs: tuple[str, ...]  # "noise:<key>" or "instrument:<term>"
    center: dict[str, NDArray[np.float64]]
    gradient: dict[str, NDArray[np.float64]]
    expectation: dict[str, float]
    #: var(uₖ) (1 normal, 1/3 uniform) and mean_p Gₖ² per name: E[L] of a trial whose inputs
    #: are partly off (:class:`SourceNoise`) is mean_p b² + Σₖ var(uₖ)·onₖ·mean_p Gₖ².
    variance: NDArray[np.float64] | None = None
    gradient_ms: dict[str, NDArray[np.float64]] | None = None


def _random_terms(model: ErrorModel | None) -> list[ErrorTerm]:
    if model is None:
        return []
    return [t for t in model.terms if t.distribution in _VARIANCE and t.scale]


def _scale(model: ErrorModel | None, name: str) -> float:
    """The σ (scale) of the instrument error term ``name`` of ``model``."""
    if model is None:
        raise ValueError(f"{name}: an instrument input without an instrument error model")
    return model.term(name).scale


def design_inputs(model: ErrorModel | None, trials: int) -> dict[str, object]:
    """Injected errors of a designed run of ``trials`` trials: constants at their value, every
    random term 0 (arrays the caller steps). None: no instrument errors (an empty mapping)."""
    if model is None:
        return {}
    out: dict[str, object] = {}
    for t in model.terms:
        if t.distribution == "constant":
            out[t.name] = np.full(trials, t.scale)
        else:
            out[t.name] = np.zeros(trials)
    return out


@dataclass(frozen=True)
class Design:
    """The designed run of a linearisation (:func:`design`): its ``inputs`` ("noise:<key>" or
    "instrument:<term>"), ``trials`` (1 + 2K: the centre, then each input stepped by +STEP and
    −STEP), the injected errors and the judgment steps of every trial, and var(uₖ)."""

    inputs: tuple[str, ...]
    trials: int
    injected: dict[str, object]
    steps: dict[str, NDArray[np.float64]]
    variance: NDArray[np.float64]

    def noise(self) -> DesignNoise:
        """The judgments of the designed run."""
        return DesignNoise(self.trials, self.steps)


#: A run of the fields to linearise: (injected, noise, trials) → {name: (T, P)}.
FieldRun = Callable[[dict[str, object], Noise, int], dict[str, NDArray[np.float64]]]


def design(run: FieldRun, model: ErrorModel | None) -> Design:
    """The designed run of :func:`linear_control`: a discovery run of ``run`` (1 trial) lists
    the acts with σ > 0 in order of first use; each of them and each random instrument error
    term of ``model`` (None: none) is an input."""
    keys: list[str] = []
    run(design_inputs(model, 1), DesignNoise(1, {}, keys), 1)
    terms = _random_terms(model)
    names = [f"noise:{k}" for k in keys] + [f"instrument:{t.name}" for t in terms]
    trials = 1 + 2 * len(names)
    injected = design_inputs(model, trials)
    steps: dict[str, NDArray[np.float64]] = {}
    for j, name in enumerate(names):
        kind, _, key = name.partition(":")
        s = np.zeros(trials)
        s[1 + 2 * j], s[2 + 2 * j] = STEP, -STEP
        if kind == "noise":
            steps[key] = s
        else:
            injected[key] = s * _scale(model, key)
    variance = np.array([1.0] * len(keys) + [_VARIANCE[t.distribution] for t in terms], float)
    return Design(tuple(names), trials, injected, steps, variance)


def control_from(d: Design, fields: dict[str, NDArray[np.float64]]) -> LinearControl:
    """The linear control from the ``fields`` of the designed run ``d`` (its trials' rows)."""
    center, gradient, expectation, gms = {}, {}, {}, {}
    for name, v in fields.items():
        v = np.asarray(v, float).reshape(d.trials, -1)
        b = v[0]
        g = (v[1::2] - v[2::2]) / (2.0 * STEP)
        center[name], gradient[name], gms[name] = b, g, np.mean(g**2, axis=1)
        expectation[name] = float(np.mean(b**2) + d.variance @ gms[name])
    return LinearControl(d.inputs, center, gradient, expectation, d.variance, gms)


def linear_control(run: FieldRun, model: ErrorModel | None) -> LinearControl:
    """Linearise the fields of ``run(injected, noise, trials) -> {name: (T, P)}`` about the run
    with every random input 0: a discovery run (1 trial) lists the acts, then one designed run
    of 1 + 2K trials steps each input by ±:data:`STEP` (:func:`design`, :func:`control_from`).
    ``model``: the instrument's error model (None: no instrument errors)."""
    d = design(run, model)
    return control_from(d, run(d.injected, d.noise(), d.trials))


class StackedNoise(Noise):
    """The trials of a designed run (:class:`DesignNoise`) followed by those of a chunk
    (:class:`RecordingNoise`), for one run of both: each act draws the design's values, then
    the chunk's (recorded by it as ever). The procedure treats every trial alone, so each
    trial's result is the one it has in a run of its own part."""

    def __init__(self, designed: DesignNoise, recorded: RecordingNoise):
        trials = designed.design_trials + (recorded.trials or 1)
        super().__init__(recorded.seed, trials, None, recorded.first_trial)
        self.designed, self.recorded = designed, recorded

    def normal(self, key: str, sigma: float) -> NDArray[np.float64]:
        return np.concatenate([self.designed.normal(key, sigma), self.recorded.normal(key, sigma)])


def per_trial_controlled(
    fields: dict[str, NDArray[np.float64]],
    lin: LinearControl,
    noise: RecordingNoise,
    injected: dict[str, object],
    model: ErrorModel | None,
    on: NDArray[np.float64] | None = None,
) -> dict[str, NDArray[np.float64]]:
    """Per trial and field: mean_p v² − L + E[L] (module docstring), shape (T,) each.

    ``on`` (K, T): 1 where input k is drawn on trial t, 0 where it is held exact
    (:class:`SourceNoise`); E[L] is then per trial. None: every input on."""
    trials = next(iter(fields.values())).shape[0]
    u = np.zeros((len(lin.inputs), trials))
    for j, name in enumerate(lin.inputs):
        kind, _, key = name.partition(":")
        if kind == "noise":
            z = noise.z.get(key)
            if z is not None:
                u[j] = z
        else:
            u[j] = np.asarray(injected[key], float) / _scale(model, key)
    out = {}
    for name, v in fields.items():
        v = np.asarray(v, float).reshape(trials, -1)
        expect: float | NDArray[np.float64]
        if on is None:
            expect = lin.expectation[name]
        else:
            if lin.variance is None or lin.gradient_ms is None:
                raise ValueError("on: the linearisation holds no input variances")
            b2 = float(np.mean(lin.center[name] ** 2))
            expect = b2 + (lin.variance * lin.gradient_ms[name]) @ on
        res = np.empty(trials)
        for s, e in row_blocks(trials):  # each trial's values depend on its own row only
            lin_v = u[:, s:e].T @ lin.gradient[name]
            lin_v += lin.center[name][None, :]
            lin_ms = np.einsum("tp,tp->t", lin_v, lin_v) / lin_v.shape[1]
            vb = v[s:e]
            res[s:e] = np.einsum("tp,tp->t", vb, vb) / vb.shape[1] - lin_ms
        out[name] = res + expect
    return out


def row_blocks(trials: int, block: int | None = None) -> list[tuple[int, int]]:
    """(start, end) of consecutive blocks of ``block`` trials (default :data:`BLOCK_TRIALS`)
    covering 0 … trials − 1."""
    b = BLOCK_TRIALS if block is None else block
    return [(s, min(s + b, trials)) for s in range(0, trials, b)]
