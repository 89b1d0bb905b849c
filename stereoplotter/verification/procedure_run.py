"""One configuration's run of the procedure Monte Carlo, in typed parts: the operator, domain
and unit of a method (:class:`MethodOperator`), the run (:class:`ProcedureRun`: every option a
field), what it measures (:class:`FieldMaker`) and the per-trial mean squares of its fields,
plain and with the linear control variate (:func:`mean_squares`, :class:`MeanSquares`).
:mod:`~stereoplotter.verification.procedure_mc` turns them into results.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from stereoplotter.accuracy.chapter5 import levelling_design
from stereoplotter.procedure.fidelity import Fidelity
from stereoplotter.procedure.operator import Noise, OperatorModel
from stereoplotter.procedure.simulate import SimulationResult, prepare_run, run_trials_chunk
from stereoplotter.procedure.trials import DEFAULT_MEMORY_BUDGET_MB, chunk_trials_for
from stereoplotter.verification import control_variate as cvar
from stereoplotter.verification import decomposition as dc
from stereoplotter.verification.linear_mc import FloatArray
from stereoplotter.verification.procedure_geometry import (
    control_frame_points,
    domain_points,
    dp_at,
    dp_function,
    height_errors_parallax,
    levelling_frame_points,
    standard_points_at_a,
)

if TYPE_CHECKING:
    from stereoplotter.procedure.run import PreparedRun
    from stereoplotter.scenario.model import Scenario
    from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = [
    "METHODS",
    "Decompose",
    "FieldKey",
    "FieldMaker",
    "Fields",
    "MeanSquares",
    "MethodOperator",
    "ProcedureRun",
    "mean_squares",
    "method_operator",
]


#: The procedure methods: §27 task 1 with unadjusted setup data ("setup"), task 2 with setup data
#: refined on control ("setup_control"), and the conventional method.
METHODS = ("setup", "setup_control", "conventional")


@dataclass(frozen=True)
class MethodOperator:
    """The operator and the statistic's domain of a method's runs (the module docstring).

    Attributes
    ----------
    error_free : OperatorModel
        Every operator error zero: the run whose δp is the deterministic residue (``bias``).
    noisy : OperatorModel
        The formula's operator errors on (monocular σ; or σ_q, σ_p of the conventional method).
    x_left_range_mm : tuple of float
        The statistic's domain in x_л [mm]: (6.27)'s [0, c], or chapter 5's x_п ∈ [−c, 0].
    unit_mm : float
        The statistic's unit [photo mm]: m_xy = n_л·σ (setup) or σ (conventional).
    relative : {"elements", "equations"}
        The relative orientation of the run (``prepare_run``): by the elements (setup data) or
        by the six measured q and (5.11) (conventional, least squares as (5.54) assumes).
    stereo_sigma_mm : float
        σ_p of the noisy operator's stereo judgments (conventional; 0 for the setup methods),
        also the σ of each observed levelling height.
    """

    error_free: OperatorModel
    noisy: OperatorModel
    x_left_range_mm: tuple[float, float]
    unit_mm: float
    relative: str
    stereo_sigma_mm: float = 0.0


def method_operator(
    method: str, sigma_mm: float, c: float, p: float, n: float, sources: str = "both"
) -> MethodOperator:
    """The operator, domain and unit of ``method`` (module docstring).

    ``sources`` (conventional only): "both" (σ_q = σ_p = σ, the formula's m_q = m_p), or only
    the y-parallax σ_q ("y_parallax", the relative-orientation part (5.54)) or only the stereo σ_p
    ("stereo", the levelling part (5.55))."""

    zero = OperatorModel().zero()
    if method in ("setup", "setup_control"):
        op = replace(zero, monocular_sigma_mm=sigma_mm)
        return MethodOperator(zero, op, (0.0, c), n * sigma_mm, "elements")  # domain of (6.27)
    if method == "conventional":
        sq = 0.0 if sources == "stereo" else sigma_mm
        sp = 0.0 if sources == "y_parallax" else sigma_mm
        op = replace(zero, stereo_sigma_mm=sp, y_parallax_sigma_mm=sq)
        return MethodOperator(zero, op, (p - c, p), sigma_mm, "equations", sp)  # x_п ∈ [−c, 0]
    raise ValueError(f"method: expected one of {METHODS}, found {method!r}")


#: The key of a per-trial mean square: a field's name, or (reading, level) of a decomposition
#: (:mod:`.decomposition`) and ("element", element) of the setup elements' errors.
FieldKey = str | tuple[str, str]
#: A run's fields: (result, noise) → field name → per-trial values over the domain, (T, n).
Fields = Callable[[SimulationResult, Noise], dict[str, FloatArray]]
#: The decomposition's mean squares: (result, the run's fields, the rows of the result's trials
#: they are) → (reading, level) → (T,).
Decompose = Callable[[SimulationResult, dict[str, FloatArray], slice], dict[FieldKey, FloatArray]]


@dataclass(frozen=True)
class FieldMaker:
    """What a method's procedure MC measures on a run: its ``fields`` and, for the setup-data
    method, the per-trial mean squares of their first-order ``decompose`` (None: none)."""

    fields: Fields
    decompose: Decompose | None = None


@dataclass(frozen=True)
class ProcedureRun:
    """One configuration's run of the procedure MC: what :func:`mean_squares` runs.

    Attributes
    ----------
    scenario : Scenario
        The simulated pair (loaded by the caller).
    spec : InstrumentSpec
        The instrument, its standard points at the geometry's c (``standard_points_c_mm``).
    method : {"setup", "setup_control", "conventional"}
        :data:`METHODS`.
    seed : int
        The seed of every keyed draw of the run.
    trials : int
        Trials 0 … trials − 1.
    operator : MethodOperator
        The error-free and the noisy operator, the domain and the unit (:func:`method_operator`).
    geometry : dict
        :func:`~.procedure_geometry.scenario_geometry` of the scenario.
    grid : tuple of int
        Midpoint grid of the statistic (nx, ny).
    variant : str
        The instrument's decentration variant (:data:`LINKAGE_VARIANTS` of the linkage).
    fidelity : Fidelity
        The mechanism switches, resolved (:meth:`ProcedureOptions.switches`).
    instrument_errors : bool
        Every injected instrument error term at its configured σ, with the real mechanics.
    control_variate : bool
        Also the estimate with the linear control variate
        (:mod:`~stereoplotter.verification.control_variate`).
    standard_points_at_a : bool
        The standard points moved to Fig. 39 at a = c − p (the conventional method's "book"
        layout; :func:`~.procedure_geometry.standard_points_at_a`).
    sigma_control_mm : float
        Setup methods: σ of each observed control parallax (the "observed" reading).
    sources_off : mapping or None
        Key prefix → (trials,) mask of the trials whose acts of that prefix draw 0
        (:func:`conventional_sources_mc`); None: every act drawn on every trial.
    decompose : bool
        Setup methods: also the first-order fields of the decomposition (:mod:`.decomposition`)
        of each reading; False: only the readings and the elements' errors.
    measure : tuple of str or None
        Conventional method: the readings measured (of "parallax", "slip", "plane", "book");
        None: every one.
    """

    scenario: Scenario
    spec: InstrumentSpec
    method: str
    seed: int
    trials: int
    operator: MethodOperator
    geometry: dict[str, float]
    grid: tuple[int, int]
    variant: str
    fidelity: Fidelity
    instrument_errors: bool = False
    control_variate: bool = True
    standard_points_at_a: bool = False
    sigma_control_mm: float = 0.0
    sources_off: Mapping[str, NDArray[np.bool_]] | None = None
    decompose: bool = True
    measure: tuple[str, ...] | None = None

    @property
    def procedure(self) -> str:
        """The procedure that runs: the conventional method or the setup-data method."""
        return "conventional" if self.method == "conventional" else "setup"

    def prepared(self, operator: OperatorModel, errors: str | None) -> PreparedRun:
        """The prepared run with ``operator``; ``errors`` "zero" (none injected, ideal
        mechanics) or None (the instrument's error model, real mechanics if
        :attr:`instrument_errors`). The formulas of §27 describe the book's procedure, task 1:
        each element set once, no remedies (``practice="book"``) — for both methods (the
        operator's remedies would lower the setup-data value)."""
        real_mechanics = self.instrument_errors and errors != "zero"
        prep = prepare_run(
            self.scenario,
            self.spec,
            self.procedure,
            errors,
            self.seed,
            operator=operator,
            ideal_mechanics=not real_mechanics,
            variant=self.variant,
            relative=self.operator.relative,
            practice="book",
            fidelity=self.fidelity,
        )
        if self.standard_points_at_a:
            tol = prep.sheet.tolerances  # keep the operator's tolerances (stopping rule as built)
            prep = standard_points_at_a(prep, self.geometry)
            prep = replace(prep, sheet=replace(prep.sheet, tolerances=tol))
        return prep


@dataclass(frozen=True)
class MeanSquares:
    """Per-trial mean squares of each field of a run, (trials,) each: ``plain`` (and the
    decomposition's, :data:`FieldKey`), ``controlled`` (with the linear control variate; empty
    without it), and ``error_free_dp`` (δp of the error-free run on the statistic's domain)."""

    plain: dict[FieldKey, FloatArray]
    controlled: dict[FieldKey, FloatArray]
    error_free_dp: FloatArray


def _setup_fields(run: ProcedureRun, zero_run: SimulationResult) -> tuple[FieldMaker, FloatArray]:
    """Field makers of the setup-data method: δp on the (6.27) domain ("parallax", task 1), and
    on the chapter-5 domain after levelling on Fig. 39's four control points (task 2,
    :data:`METHODS` "setup_control"): "levelled" with exact control heights, "observed" with
    each control height's parallax observed with σ_c = ``run.sigma_control_mm`` (keyed draws
    ``mc/control/i``). With the error-free run's δp on the (6.27) domain."""

    sc, g, grid = run.scenario, run.geometry, run.grid
    f, p, c, h = g["f"], g["p"], g["c"], g["flying_height_m"]
    sheet = zero_run.sheet
    pts = domain_points(sc, sheet, run.operator.x_left_range_mm, c, p, f, h, grid)
    lev = domain_points(sc, sheet, (p - c, p), c, p, f, h, grid)
    book, _, _ = control_frame_points(sc, sheet, g)
    n, nl = len(pts), len(lev)
    # below 70 % overlap c = p: the two domains are one (60 %: x_л ∈ [0, p]), δp computed once
    same = pts.shape == lev.shape and np.array_equal(pts, lev)
    allp = np.vstack([pts, book] if same else [pts, lev, book])
    first_lev, first_ctl = (0, n) if same else (n, n + nl)
    zero = dp_at(sc, sheet, zero_run.instrument, allp)
    refit = levelling_design(lev[:, 0], lev[:, 1]) @ np.linalg.pinv(
        levelling_design(book[:, 0], book[:, 1])
    )
    sigma_control = run.sigma_control_mm

    def readings(d: FloatArray) -> dict[str, FloatArray]:
        dom, ctl = d[:, first_lev : first_lev + nl], d[:, first_ctl:]
        return {"parallax": d[:, :n], "levelled": dom - ctl @ refit.T}

    def fields(result: SimulationResult, noise: Noise) -> dict[str, FloatArray]:
        d = dp_at(sc, result.sheet, result.instrument, allp) - zero
        out = readings(d)
        obs = np.stack(
            [noise.normal(f"mc/control/{i}", sigma_control) for i in range(len(book))], -1
        )
        return {**out, "observed": out["levelled"] - obs @ refit.T}

    units0 = zero_run.instrument.state()["units"]
    state0 = (zero_run.instrument.setting, {s: units0[s] for s in ("left", "right")})
    jac = dc.state_jacobian(*state0, dp_function(sc, sheet, allp)) if run.decompose else None

    def decompose(
        result: SimulationResult, main: dict[str, FloatArray], rows: slice
    ) -> dict[FieldKey, FloatArray]:
        """Per-trial mean squares of the first-order fields of the decomposition
        (:mod:`.decomposition`) of each reading, (reading, level) → (T,) [photo mm²], and
        each (6.22) element's squared error ("element", name); the elements' only without
        ``run.decompose``."""
        units = result.instrument.state()["units"]
        trials = len(next(iter(main.values())))
        deltas = dc.state_deltas(
            result.instrument.setting,
            {s: units[s] for s in ("left", "right")},
            *state0,
            trials,
            rows,
        )
        # each (6.22) element's error (instrument units: mm, tangent, rad), squared per trial
        out: dict[FieldKey, FloatArray] = {
            ("element", f"{o}.{f}"): deltas[i] ** 2 for i, (o, f) in enumerate(dc.ELEMENTS)
        }
        if jac is None:
            return out
        noise = main["observed"] - main["levelled"]  # the observed control parallaxes' part
        blocks = cvar.row_blocks(trials)
        for step, d in dc.linear_fields(jac, deltas):
            ms: dict[FieldKey, FloatArray] = {
                (key, step): np.empty(trials) for key in ("parallax", "levelled", "observed")
            }
            for s, e in blocks:  # a trial's readings are its own row's
                r = readings(d[s:e])
                r["observed"] = r["levelled"] + noise[s:e]
                for key, v in r.items():
                    ms[key, step][s:e] = np.mean(v**2, axis=-1)
            out.update(ms)
        return out

    return FieldMaker(fields, decompose), zero[:n]


def _conventional_fields(
    run: ProcedureRun, zero_prep: PreparedRun, zero_run: SimulationResult
) -> tuple[FieldMaker, FloatArray]:
    """Field makers of the conventional method (``procedure_mc`` options): δp at the ideal model
    position ("parallax") and the heights read on the slipped height scale in parallax units
    (dp/dH = B·f/(Z_S − Z)², frame origin S_л) with three datums: the procedure's slip ("slip"),
    the levelling plane's offset from the four levelling heights each observed with σ_p ("plane",
    the formula's), and the built model re-levelled by the least-squares plane through its
    height errors at x_п ∈ {−c, a}, y = ±c, each observed with σ_p ("book"). With the
    error-free run's δp on the statistic's domain."""

    sc, g, grid = run.scenario, run.geometry, run.grid
    sigma_p = run.operator.stereo_sigma_mm
    f, p, c, h = g["f"], g["p"], g["c"], g["flying_height_m"]
    sheet = zero_run.sheet
    pts = domain_points(sc, sheet, run.operator.x_left_range_mm, c, p, f, h, grid)
    d_zero = dp_at(sc, sheet, zero_run.instrument, pts)
    _, lev = levelling_frame_points(zero_prep)
    book, _, _ = control_frame_points(sc, sheet, g)
    allp = np.vstack([pts, lev, book])
    k = (p * h / f) * f / allp[:, 2] ** 2  # photo mm of x-parallax per m of height
    h_zero = height_errors_parallax(sc, sheet, zero_run.instrument, allp)
    n, nl = len(pts), len(lev)
    refit = levelling_design(pts[:, 0], pts[:, 1]) @ np.linalg.pinv(
        levelling_design(book[:, 0], book[:, 1])
    )

    measure = run.measure or ("parallax", "slip", "plane", "book")  # None: every reading

    def fields(result: SimulationResult, noise: Noise) -> dict[str, FloatArray]:
        e = (height_errors_parallax(sc, result.sheet, result.instrument, allp) - h_zero) * k
        # every observation drawn, measured or not: the same acts in the linear control
        datum = np.stack([noise.normal(f"mc/datum/{i}", sigma_p) for i in range(nl)], -1)
        control = np.stack([noise.normal(f"mc/book/{i}", sigma_p) for i in range(len(book))], -1)
        out: dict[str, FloatArray] = {}
        if "parallax" in measure:
            out["parallax"] = dp_at(sc, result.sheet, result.instrument, pts) - d_zero
        if "slip" in measure:
            out["slip"] = e[:, :n]
        if "plane" in measure:
            obs = e[:, n : n + nl] + datum
            out["plane"] = e[:, :n] - np.mean(obs, axis=-1, keepdims=True)
        if "book" in measure:
            ctl = e[:, n + nl :] + control
            out["book"] = e[:, :n] - ctl @ refit.T
        return out

    return FieldMaker(fields), d_zero


def mean_squares(run: ProcedureRun) -> MeanSquares:
    """Per-trial mean squares of each field of ``run`` (:func:`_setup_fields`,
    :func:`_conventional_fields`), plain and with the linear control variate
    (:mod:`~stereoplotter.verification.control_variate`), and the error-free run's δp.

    The error-free run once; the linearisation once, its designed run in one run with the first
    chunk on the ideal instrument (the procedure's per-act work paid once for both); the noisy
    trials in chunks under the memory budget (the random draws are keyed by trial, so the chunk
    size changes no result).
    """

    zero_prep = run.prepared(run.operator.error_free, "zero")
    zero_run = run_trials_chunk(zero_prep, 0, None, evaluate=False, transcript=False)
    if run.procedure == "setup":
        maker, d_zero = _setup_fields(run, zero_run)
    else:
        maker, d_zero = _conventional_fields(run, zero_prep, zero_run)
    prep = run.prepared(run.operator.noisy, None if run.instrument_errors else "zero")
    design = _design(prep, maker) if run.control_variate else None
    lin: cvar.LinearControl | None = None
    chunk = chunk_trials_for(DEFAULT_MEMORY_BUDGET_MB, run.procedure)
    plain: dict[FieldKey, FloatArray] = {}
    controlled: dict[FieldKey, FloatArray] = {}
    for first in range(0, run.trials, chunk):
        m = min(chunk, run.trials - first)
        # with the real mechanics (instrument errors) a trial's last bits depend on the trials
        # run beside it (1e-14 relative, measured): the designed run goes alone there
        with_design = design if first == 0 and not run.instrument_errors else None
        if design is not None and lin is None and with_design is None:
            lin = _linearised(prep, maker, design)
        part_plain, part_controlled, lin = _chunk_mean_squares(
            run, prep, maker, lin, first, m, with_design
        )
        for name, v in part_plain.items():
            plain.setdefault(name, np.empty(run.trials))[first : first + m] = v
            if name in part_controlled:
                controlled.setdefault(name, np.empty(run.trials))[first : first + m] = (
                    part_controlled[name]
                )
    return MeanSquares(plain, controlled, d_zero)


def _design(prep: PreparedRun, maker: FieldMaker) -> cvar.Design:
    """The designed run of the linear control variate of ``maker``'s fields about the run with
    every random input 0 (:func:`~stereoplotter.verification.control_variate.design`: its
    discovery run made here)."""

    def fields_of(injected: dict[str, Any], noise: Noise, trials: int) -> dict[str, FloatArray]:
        result = run_trials_chunk(
            prep, 0, trials, evaluate=False, transcript=False, injected=injected, noise=noise
        )
        return maker.fields(result, noise)

    return cvar.design(fields_of, prep.model)


def _linearised(prep: PreparedRun, maker: FieldMaker, design: cvar.Design) -> cvar.LinearControl:
    """The linear control from ``design``'s run made alone."""
    noise = design.noise()
    result = run_trials_chunk(
        prep, 0, design.trials, evaluate=False, transcript=False, injected=design.injected,
        noise=noise,
    )  # fmt: skip
    return cvar.control_from(design, maker.fields(result, noise))


def _chunk_mean_squares(
    run: ProcedureRun,
    prep: PreparedRun,
    maker: FieldMaker,
    lin: cvar.LinearControl | None,
    first: int,
    trials: int,
    design: cvar.Design | None = None,
) -> tuple[dict[FieldKey, FloatArray], dict[str, FloatArray], cvar.LinearControl | None]:
    """Per-trial mean squares of trials ``first … first + trials − 1``: plain (with the
    decomposition's) and controlled (empty without a linear control); and the linear control.
    With ``design`` its designed run goes before the trials in the same run, and the linear
    control is built from it (else ``lin``, None: none)."""
    model = prep.model
    injected = model.draw_keyed(prep.seed, first, first + trials)
    off = run.sources_off
    noise: cvar.RecordingNoise
    part: dict[str, NDArray[np.bool_]] = {}
    if off:
        part = {k: v[first : first + trials] for k, v in off.items()}
        noise = cvar.SourceNoise(prep.seed, trials, first, part)
    else:
        noise = cvar.RecordingNoise(prep.seed, trials, first)
    if design is None:
        result = run_trials_chunk(
            prep, first, trials, evaluate=False, transcript=False, injected=injected, noise=noise
        )
        fs = maker.fields(result, noise)
        rows = slice(0, trials)
    else:  # the designed trials, then the chunk's, in one run
        d = design.trials
        stacked = cvar.StackedNoise(design.noise(), noise)
        both = {
            k: np.concatenate([np.broadcast_to(np.asarray(design.injected[k], float), (d,)), v])
            for k, v in injected.items()
        }
        result = run_trials_chunk(
            prep, first, d + trials, evaluate=False, transcript=False, injected=both, noise=stacked
        )
        every = maker.fields(result, stacked)
        lin = cvar.control_from(design, {k: v[:d] for k, v in every.items()})
        fs = {k: v[d:] for k, v in every.items()}
        rows = slice(d, d + trials)
    controlled: dict[str, FloatArray] = {}
    if lin:
        on = _inputs_on(lin, part, trials) if off else None
        controlled = cvar.per_trial_controlled(fs, lin, noise, dict(injected), model, on)
    plain: dict[FieldKey, FloatArray] = {}
    for name, v in fs.items():
        ms = plain[name] = np.empty(trials)
        for s, e in cvar.row_blocks(trials):  # each trial's own row
            ms[s:e] = np.mean(np.asarray(v[s:e]) ** 2, axis=-1)
    if maker.decompose is not None:  # already mean squares
        plain.update(maker.decompose(result, fs, rows))
    return plain, controlled, lin


def _inputs_on(
    lin: cvar.LinearControl, off: Mapping[str, NDArray[np.bool_]], trials: int
) -> FloatArray:
    """(K, T): 1 where input k of ``lin`` is drawn on a trial, 0 where its source is off."""
    on = np.ones((len(lin.inputs), trials))
    for j, name in enumerate(lin.inputs):
        kind, _, key = name.partition(":")
        mask = next((m for p, m in off.items() if key.startswith(p)), None)
        if kind == "noise" and mask is not None:
            on[j] = ~mask
    return on
