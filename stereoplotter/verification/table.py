"""The verification table of §27 and the chapter-5 results it uses (``accuracy.md``).

:func:`run_verification` builds one row per numbered result, each with the printed value, the
book-mode and rigorous values, the linear Monte Carlo RMS with its CI half-width, the exact
covariance propagation on the same grid, a verdict and a note. The rows are data: each is an
:class:`~stereoplotter.verification.entry.Entry` (its formulas, verdict rule and procedure
measure) returned by one declared function of a topic module (``rows_chapter5``: Tables 19, 20
and chapter 5; ``rows_setup_elements``: (6.28)–(6.38); ``rows_outcomes``: (6.39)–(6.46);
``rows_levelled``: (6.47)–(6.61)); :func:`row_entries` concatenates the modules' declared rows
(:data:`ROW_MODULES`) in order. :func:`closing_comparison` is the book's closing claim (setup
data vs the conventional method at 60 % and 80 %). Rendered by
:mod:`stereoplotter.report.verification`, written by :mod:`stereoplotter.commands.verification`.

Book geometry (§27): f = 70 mm, l = 85 mm, n = 1.42 (SC-1), c = 70 mm; 60 %: p = 70, a = 0;
80 %: p = 35, a = 35. Values are coefficients: m_x = m_y = m_xy = 1 for (6.31)-(6.50),
m_q = m_p = 1 (and m_xy = √2 m_p) for (6.45)-(6.61).
"""

from __future__ import annotations

import math
import multiprocessing
import warnings
from collections.abc import Callable, Mapping
from concurrent.futures import Future, ProcessPoolExecutor, as_completed
from dataclasses import dataclass, replace
from functools import cache
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
from threadpoolctl import threadpool_limits

from stereoplotter.procedure.fidelity import MECHANISMS, Fidelity
from stereoplotter.random_streams import key_code
from stereoplotter.verification import decomposition as dc
from stereoplotter.verification import linear_mc as mc
from stereoplotter.verification import (
    rows_chapter5,
    rows_levelled,
    rows_outcomes,
    rows_setup_elements,
)
from stereoplotter.verification.as_formula import (
    ProcedureResults,
    RunResult,
    as_formula_block,
    procedure_value,
    switch_chain,
    switch_decomposition,
)
from stereoplotter.verification.entry import (
    BOOK,
    RULE,
    DeclaredRows,
    Entry,
    ProcedureMeasure,
    Setting,
)
from stereoplotter.verification.procedure_mc import (
    conventional_sources_mc,
    idealised_geometry,
    procedure_mc,
)
from stereoplotter.verification.verdicts import VERDICTS, decide

if TYPE_CHECKING:
    from stereoplotter.scenario.model import Scenario
    from stereoplotter.spec.instrument_spec import InstrumentSpec

#: ``progress(done, total, label)`` after each step.
Progress = Callable[[int, int, str], None]
#: A row of the table: the values of :data:`ROW_KEYS`.
Row = dict[str, Any]


class FieldErrors(Protocol):
    """Where :func:`check_geometry` reports a bad field: ``error(field, expected, found)``
    returns the exception to raise."""

    def error(self, field: str, expected: str, found: str) -> Exception: ...


__all__ = [
    "BOOK",
    "ROW_KEYS",
    "ROW_MODULES",
    "VERDICTS",
    "attach_procedure_mc",
    "check_geometry",
    "closing_comparison",
    "procedure_rows",
    "row_entries",
    "run_procedure_job",
    "run_procedure_mc",
    "run_verification",
    "start_procedure_mc",
]

ROW_KEYS = (
    "eq",
    "quantity",
    "printed",
    "from_printed_inputs",
    "book",
    "rigorous",
    "covariance",
    "mc_linear",
    "mc_linear_ci",
    "mc_procedure",
    "mc_procedure_ci",
    "mc_procedure_formula",
    "mc_procedure_instrument",
    "mc_procedure_instrument_ci",
    "verdict",
    "note",
    "as_formula",
    "decomposition",
)
#: The columns of the CSV (the nested ``as_formula``, ``decomposition`` blocks: JSON only).
CSV_KEYS = tuple(k for k in ROW_KEYS if k not in ("as_formula", "decomposition"))
PROCEDURE_NOTE = "no procedure MC (the simulated procedure does not measure this quantity)"


@dataclass(frozen=True)
class ProcedureConfig:
    """A configuration of the procedure MC: its ``method`` and the options of its runs (the
    fields of :class:`~stereoplotter.verification.procedure_mc.ProcedureOptions` it sets:
    ``grid``, ``passes``, ``sources``, ``fidelity``, ``control_variate``, ``decompose``,
    ``measure``);
    ``idealised``: run on the scenario with vertical photos over flat terrain
    (:func:`idealised_geometry`). A run the table reads only for its value skips the
    decomposition, one read only for its plain per-trial mean squares (a switch step) also the
    control variate: the values read are the same."""

    method: str
    grid: tuple[int, int] = (16, 32)
    passes: int | None = None
    sources: str = "both"
    fidelity: Fidelity | None = None
    idealised: bool = False
    control_variate: bool = True
    decompose: bool = True
    measure: tuple[str, ...] | None = None

    def options(self) -> dict[str, Any]:
        """The :func:`procedure_mc` keyword arguments of a run of this configuration."""
        return {
            "method": self.method,
            "grid": self.grid,
            "passes": self.passes,
            "sources": self.sources,
            "fidelity": self.fidelity,
            "control_variate": self.control_variate,
            "decompose": self.decompose,
            "measure": self.measure,
        }


#: Procedure-MC configurations: name → :class:`ProcedureConfig`. "setup" is one
#: run of the setup-data method with three readings (§27 task 1, and task 2: levelled on
#: control exactly and with observed control parallaxes); the conventional method with both
#: judgment errors, the y-parallax σ_q only and the stereo σ_p only. Conventional runs make a
#: fixed number of passes of every loop (``passes``: no stop-when-satisfied selection, which
#: (5.54)/(5.55) do not model; it makes the run smooth enough for the control variate). The
#: setup run's statistic is the mean over a midpoint grid of 8 × 16 (not 16 × 32): half the
#: time, values within 0.3 % of the finer grid on the same 4 000 trials (pair60 levelled
#: 0.1298 / 0.1302, observed 0.6696 / 0.6707; parallax within 0.02 %). A conventional run
#: measures only its statistic's reading (``measure=()``: the table reads no other datum).
PROCEDURE_CONFIGS = {
    "setup": ProcedureConfig("setup", grid=(8, 16)),
    "conventional": ProcedureConfig("conventional", passes=3, measure=()),
    "y_parallax": ProcedureConfig("conventional", passes=3, sources="y_parallax", measure=()),
    "stereo": ProcedureConfig("conventional", passes=3, sources="stereo", measure=()),
}
#: The seed stream of each configuration's runs, declared (not its place in
#: :data:`PROCEDURE_CONFIGS`): a run of configuration c at overlap slot s takes the seed
#: ``seed + 7·(2·CONFIG_STREAM[c] + (s == "80")) + 1``. A new configuration takes a new number.
CONFIG_STREAM = {"setup": 0, "conventional": 1, "y_parallax": 2, "stereo": 3}
#: Default trials per configuration: the fewest that keep every row's 99.9 % CI ≤ 1 % of its
#: value at the book's scenarios (``benchmarks/bench_procedure_verify.py``; measured CIs in
#: ``docs/accuracy.md``). The setup method's loops stop when a check passes, which makes its
#: δp not linear in the draws and the control variate weak there: 45 000 trials.
PROCEDURE_TRIALS = {"setup": 45000, "conventional": 1500, "y_parallax": 3000, "stereo": 300}
#: The setup method with every mechanism switch at the formula's assumption
#: (:meth:`~stereoplotter.procedure.fidelity.Fidelity.as_formula`; the ``as_formula`` block of
#: the setup rows), and the steps of the ``decomposition`` from it to the run as configured,
#: one switch each: run on the first trials of the "setup" run's seed (paired trials, so each
#: step's CI is that of a paired difference). Every element is then set once from linear
#: pointings: the control variate holds the as-formula value to < 0.1 % with 2 000 trials, which
#: also pair with the first step.
FORMULA_TRIALS = 2000
STEP_TRIALS = 2000
#: Trials of the runs with every instrument error term at its σ (``mc_procedure_instrument``;
#: a comparison with the ideal instrument, not held to 1 %).
INSTRUMENT_TRIALS = {"setup": 4000, "conventional": 600, "y_parallax": 600, "stereo": 300}


#: The rows each topic module declares (:class:`~stereoplotter.verification.entry.DeclaredRows`),
#: in the table's order. A new row is declared in its topic module only; a new topic module is
#: added here.
ROW_MODULES: tuple[DeclaredRows, ...] = (
    rows_chapter5.ROWS,
    rows_setup_elements.ROWS,
    rows_outcomes.ROWS,
    rows_levelled.ROWS,
)


def row_entries(g: Mapping[str, float]) -> list[Entry]:
    """Every row of the table as an :class:`~stereoplotter.verification.entry.Entry`, in the
    table's order (a row's random stream is keyed by its identity, not by its place)."""
    s = Setting.from_mapping(g)
    return [entry for rows in ROW_MODULES for entry in rows.entries(s)]


@cache
def procedure_rows() -> dict[str, ProcedureMeasure]:
    """Rows with a procedure MC: eq → the :class:`~.entry.ProcedureMeasure` its row declares
    (every outcome row of §27, (6.39)–(6.61)). The measures do not depend on the geometry: they
    are read from the rows at the book's."""
    out: dict[str, ProcedureMeasure] = {}
    for entry in row_entries(BOOK):
        if entry.procedure is None:
            continue
        if out.setdefault(entry.eq, entry.procedure) != entry.procedure:
            raise ValueError(f"two procedure rows of the table share the equation {entry.eq!r}")
    return out


#: Accepted values of a flat ``--geometry`` mapping (keys of :data:`BOOK`), in mm or [—]: wide
#: round bounds around the book's setting that keep every formula finite.
def check_geometry(fields: FieldErrors, geometry: Mapping[str, float]) -> None:
    """Refuse a geometry outside the domain of the table's formulas, naming the field.

    The standard and control points sit at x_п = −c, a and −(p + a): they must be distinct
    (a > −c, a > −p/2), and the root of (5.54) must be real (it is for a = c − p, the default).
    Last, every formula is evaluated with floating-point errors raised, so nothing undefined
    reaches the Monte Carlo.
    """
    g = _normalise_geometry(geometry)
    for ov in ("60", "80"):
        a, c, p = g[f"a{ov}"], g["c"], g[f"p{ov}"]
        name = next((k for k in (f"a{ov}", f"p{ov}", "c") if k in geometry), f"a{ov}")
        found = f"a{ov} = {a:g}, c = {c:g}, p{ov} = {p:g} mm"
        if not (a + c > 0 and p + 2 * a > 0):
            raise fields.error(
                name,
                f"a{ov} > −c and a{ov} > −p{ov}/2 (distinct points x_п = −c, a, −(p + a))",
                found,
            )
        if not 1 / 48 + (6 * c**2 + 10 * a * c - 5 * p * (2 * a + c)) / (30 * (a + c) ** 2) > 0:
            raise fields.error(
                name,
                f"a geometry where the root of (5.54) is real, as it is for a{ov} = c − p{ov} "
                f"with p{ov} < 2c",
                found,
            )
    try:
        with np.errstate(all="raise"), warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            specs = row_entries(g)
    except (ArithmeticError, ValueError, np.linalg.LinAlgError, RuntimeWarning) as exc:
        raise fields.error(
            "(geometry)",
            "values of " + ", ".join(BOOK) + " for which every formula of the table is defined",
            f"{type(exc).__name__}: {exc}",
        ) from None
    for entry in specs:
        values = [v for v in (entry.printed, entry.book, entry.rigorous) if v is not None]
        if not all(math.isfinite(v) for v in values):
            raise fields.error(
                "(geometry)",
                "values of " + ", ".join(BOOK) + " for which every formula of the table is finite",
                f"{entry.eq} {entry.quantity}: {values}",
            )


def _normalise_geometry(geometry: Mapping[str, float] | None) -> dict[str, float]:
    g = dict(BOOK)
    if geometry:
        unknown = set(geometry) - set(BOOK)
        if unknown:
            raise ValueError(f"geometry keys {sorted(unknown)} are not among {sorted(BOOK)}")
        g.update({k: float(v) for k, v in geometry.items()})
        # the standard/control points sit at x_п ∈ {−c, a}: c − p = a unless a is given
        for ov in ("60", "80"):
            if f"p{ov}" in geometry and f"a{ov}" not in geometry:
                g[f"a{ov}"] = g["c"] - g[f"p{ov}"]
    return g


#: The jobs of the current :func:`run_procedure_mc`, read by forked workers by index (the loaded
#: scenarios and instrument hold mappings that do not pickle).
_JOBS: list[ProcedureJob] = []

#: The configurations that run the same procedure (the conventional method, its judgment
#: sources on or off): one job, one run with a block of trials per configuration
#: (:func:`~stereoplotter.verification.procedure_mc.conventional_sources_mc`), which shares the
#: error-free run, the linearisation and the procedure's per-act work.
SHARED_RUNS = {"conventional": ("conventional", "y_parallax", "stereo")}
#: Cost of a trial relative to a setup trial, for the order of the jobs (longest first: both
#: workers finish together); measured by ``benchmarks/bench_procedure_verify.py``.
TRIAL_COST = {"setup": 1.0, "conventional": 4.0}


def _job_at(i: int) -> dict[str, RunResult]:
    # one BLAS thread a worker: the workers are the parallelism (two processes × two OpenBLAS
    # threads on two cores made `verify` 1.2 × the CPU and 1.5 × the wall, benchmarks/README.md)
    with threadpool_limits(limits=1, user_api="blas"):
        return run_procedure_job(_JOBS[i])


@dataclass(frozen=True)
class ProcedureJob:
    """The runs one worker makes: the configurations ``configs`` (one, or the configurations of
    a :data:`SHARED_RUNS` run) on ``scenario`` with ``spec``, each with its ``trials`` and its
    :func:`procedure_configs` keyword arguments (``options``), at ``seed``; with every
    instrument error term at its σ (``instrument_errors``) or on the ideal instrument; the
    ``linkage`` (None: the run's fidelity's or the instrument's)."""

    scenario: Scenario
    spec: InstrumentSpec
    configs: tuple[str, ...]
    trials: dict[str, int]
    seed: int
    instrument_errors: bool
    linkage: str | None
    options: dict[str, ProcedureConfig]

    def cost(self) -> float:
        """Estimated cost of the job in setup trials (:data:`TRIAL_COST`)."""
        method = self.options[self.configs[0]].method
        return TRIAL_COST.get(method, 1.0) * sum(self.trials.values())


def run_procedure_job(job: ProcedureJob) -> dict[str, RunResult]:
    """A job's results, configuration → :func:`procedure_mc` result."""
    if len(job.configs) == 1:
        (config,) = job.configs
        run = job.options[config]
        scenario = job.scenario
        if run.idealised:  # vertical photos over flat terrain
            scenario = idealised_geometry(scenario)
        options = run.options()
        if job.instrument_errors:  # read for its value only (``mc_procedure_instrument``)
            options["decompose"] = False
        res = procedure_mc(
            scenario,
            spec=job.spec,
            trials=job.trials[config],
            seed=job.seed,
            instrument=job.instrument_errors,
            linkage=job.linkage,
            **options,
        )
        return {config: res}
    (passes,) = {job.options[c].passes for c in job.configs}  # the shared run: one number
    (measure,) = {job.options[c].measure for c in job.configs}
    by_source = {job.options[c].sources: c for c in job.configs}
    out = conventional_sources_mc(
        job.scenario,
        spec=job.spec,
        trials={k: job.trials[c] for k, c in by_source.items()},
        seed=job.seed,
        instrument=job.instrument_errors,
        linkage=job.linkage,
        passes=passes,
        measure=measure,
    )
    return {by_source[k]: r for k, r in out.items()}


def _trials_of(trials: int | None, config: str, instrument: bool) -> int:
    if config.startswith(("setup_formula", "setup_step")):
        cap = FORMULA_TRIALS if config.startswith("setup_formula") else STEP_TRIALS
        main = _trials_of(trials, "setup", instrument)
        return min(cap, main)
    if isinstance(trials, int):
        return trials
    return (INSTRUMENT_TRIALS if instrument else PROCEDURE_TRIALS)[config]


def procedure_configs(fidelity: Fidelity | None = None) -> dict[str, ProcedureConfig]:
    """The configurations of a ``verify`` run: :data:`PROCEDURE_CONFIGS` with the setup method
    at ``fidelity``, "setup_formula" (every switch at the formula's assumption) and
    "setup_step_i" (the formula's setting with the first i switches of :func:`switch_chain`
    at ``fidelity``'s, i = 1 … k − 1; the k-th is "setup" itself)."""
    f = fidelity or Fidelity()
    base = PROCEDURE_CONFIGS["setup"]
    out = {**PROCEDURE_CONFIGS, "setup": replace(base, fidelity=f)}
    formula = Fidelity.as_formula()
    # the as-formula runs are read for their values (control variate), the steps for their
    # plain per-trial mean squares (:func:`switch_decomposition`): neither for a decomposition
    read = replace(base, decompose=False)
    out["setup_formula"] = replace(read, fidelity=formula)
    out["setup_formula_flat"] = replace(read, fidelity=formula, idealised=True)
    chain = switch_chain(f)
    step = formula
    for i, name in enumerate(chain[:-1], 1):
        value = getattr(f, name)
        change: dict[str, Any] = {name: value}
        step = replace(step, **change)
        if name == "linkage" and value is None:
            step = replace(step, linkage=None)
        out[f"setup_step_{i}"] = replace(read, fidelity=step, control_variate=False)
    return out


def _stream(config: str) -> str:
    """The configuration whose seed a configuration's run takes (the as-formula and step
    runs take the setup run's: their trials are its first trials)."""
    return "setup" if config.startswith("setup") else config


def run_procedure_mc(
    trials: int | None = None,
    seed: int = 20240601,
    scenarios: Mapping[str, Scenario | None] | None = None,
    progress: Progress | None = None,
    *,
    instrument: InstrumentSpec | None = None,
    with_instrument: bool = True,
    workers: int = 2,
    linkage: str | None = None,
    fidelity: Fidelity | None = None,
) -> dict[tuple[str, ...], RunResult]:
    """:func:`start_procedure_mc` and wait for its result (arguments as there)."""
    return start_procedure_mc(
        trials,
        seed,
        scenarios,
        instrument=instrument,
        with_instrument=with_instrument,
        workers=workers,
        linkage=linkage,
        fidelity=fidelity,
    ).result(progress)


def start_procedure_mc(
    trials: int | None = None,
    seed: int = 20240601,
    scenarios: Mapping[str, Scenario | None] | None = None,
    *,
    instrument: InstrumentSpec | None = None,
    with_instrument: bool = True,
    workers: int = 2,
    linkage: str | None = None,
    fidelity: Fidelity | None = None,
) -> PendingProcedureMC:
    """The procedure MC of :mod:`stereoplotter.verification.procedure_mc` for every
    configuration of :data:`PROCEDURE_CONFIGS` at each overlap slot, on the ideal instrument and
    (``with_instrument``) with every instrument error term at its configured σ.

    ``trials``: None (the defaults :data:`PROCEDURE_TRIALS`, :data:`INSTRUMENT_TRIALS`), an int
    (every run), or 0 (none). ``scenarios`` maps "60"/"80" to a loaded
    :class:`~stereoplotter.scenario.model.Scenario` (None for a slot skips it; None or empty: no
    procedure MC); the book's are the shipped ``pair60`` and ``pair80``
    (:func:`stereoplotter.io.book_setting.book_scenarios`). ``instrument`` is the loaded
    :class:`~stereoplotter.spec.instrument_spec.InstrumentSpec` (the book's SC-1), required when a
    slot is run. ``workers``: processes (the runs are independent; 1 runs them here). The
    configurations of :data:`SHARED_RUNS` at a slot are one run (one job) with a block of trials
    each: the conventional one on trials 0 … T − 1 of its seed as before, σ_q only and σ_p only
    on the trials after it (one error-free run, one linearisation and the procedure's per-act
    work for the three).
    ``linkage``: the knob–decentration linkage of the runs, "drag" or "independent" (None: the
    instrument's ``correction.decentration_linkage``;
    :data:`~stereoplotter.verification.procedure_mc.LINKAGE_VARIANTS`). ``fidelity``: the
    setup method's mechanism switches (:class:`~stereoplotter.procedure.fidelity.Fidelity`,
    None: the defaults); the as-formula run and the steps to it (:func:`procedure_configs`)
    run on the ideal instrument beside it.

    Returns
    -------
    PendingProcedureMC
        Its :meth:`~PendingProcedureMC.result`: (slot, configuration) →
        :func:`~stereoplotter.verification.procedure_mc.procedure_mc` result, and
        (slot, configuration, "instrument") → the run with instrument errors.
    """
    if trials == 0 or not scenarios:
        return PendingProcedureMC([], [], 1)
    if linkage is not None:
        fidelity = replace(fidelity or Fidelity(), linkage=linkage)
    configs = procedure_configs(fidelity)
    todo = [
        (s, c, inst)
        for inst in ((False, True) if with_instrument else (False,))
        for s in ("60", "80")
        if scenarios.get(s)
        for c in configs
        if not (inst and c not in PROCEDURE_CONFIGS)  # the switch runs: ideal instrument only
    ]
    if not todo:
        return PendingProcedureMC([], [], workers)
    if instrument is None:
        raise ValueError("instrument: expected the InstrumentSpec of the procedure MC, found None")
    shared = {c: lead for lead, cs in SHARED_RUNS.items() for c in cs}
    groups: dict[tuple[str, str, bool], list[str]] = {}
    for s, c, inst in todo:  # the configurations of one procedure go into one job
        groups.setdefault((s, shared.get(c, c), inst), []).append(c)
    jobs = [
        ProcedureJob(
            scenario=_loaded(scenarios[s]),
            spec=instrument,
            configs=tuple(cs),
            trials={c: _trials_of(trials, c, inst) for c in cs},
            seed=seed + 7 * (2 * CONFIG_STREAM[_stream(lead)] + (s == "80")) + 1,
            instrument_errors=inst,
            linkage=None if configs[lead].fidelity is not None else linkage,  # else its fidelity's
            options={c: configs[c] for c in cs},
        )
        for (s, lead, inst), cs in groups.items()
    ]
    keys: list[list[tuple[str, ...]]] = [
        [(s, c, "instrument") if inst else (s, c) for c in cs]
        for (s, _, inst), cs in groups.items()
    ]
    return PendingProcedureMC(jobs, keys, workers)


def _loaded(scenario: Scenario | None) -> Scenario:
    """A slot's scenario (a slot without one is never run)."""
    if scenario is None:
        raise ValueError("scenario: expected a loaded Scenario for a slot that runs, found None")
    return scenario


class PendingProcedureMC:
    """Procedure-MC jobs started in ``workers`` forked processes (longest first, so the workers
    finish together); :meth:`result` waits for them. With one worker, or where processes cannot
    be forked, the jobs are run by :meth:`result` itself. Meanwhile the caller may compute
    (the linear rows): ``verify`` overlaps the two. ``keys[i]``: the result keys of job i, one
    per configuration it runs."""

    def __init__(
        self, jobs: list[ProcedureJob], keys: list[list[tuple[str, ...]]], workers: int = 2
    ):
        self.jobs, self.keys = jobs, keys
        self.order = sorted(range(len(jobs)), key=lambda i: -jobs[i].cost())
        self.pool: ProcessPoolExecutor | None = None
        self.futures: dict[Future[dict[str, RunResult]], int] = {}
        if workers > 1 and len(jobs) > 1 and "fork" in multiprocessing.get_all_start_methods():
            _JOBS[:] = jobs  # inherited by the forked workers
            context = multiprocessing.get_context("fork")
            self.pool = ProcessPoolExecutor(max_workers=workers, mp_context=context)
            self.futures = {self.pool.submit(_job_at, i): i for i in self.order}
            # and one here while they run (the caller's linear rows): no process oversubscribes
            self.limits = threadpool_limits(limits=1, user_api="blas")

    def result(self, progress: Progress | None = None) -> dict[tuple[str, ...], RunResult]:
        """(slot, configuration[, "instrument"]) → result; ``progress(done, total, label)``."""
        out: dict[tuple[str, ...], RunResult] = {}
        n = len(self.jobs)
        if self.pool is None:
            for done, i in enumerate(self.order, 1):
                out.update(self._keyed(i, run_procedure_job(self.jobs[i])))
                if progress is not None:
                    progress(done, n, "proc " + " ".join(self.keys[i][0]))
            return {k: out[k] for ks in self.keys for k in ks}
        try:
            for done, fut in enumerate(as_completed(self.futures), 1):
                i = self.futures[fut]
                out.update(self._keyed(i, fut.result()))
                if progress is not None:
                    progress(done, n, "proc " + " ".join(self.keys[i][0]))
        finally:
            self.pool.shutdown(cancel_futures=True)
            self.limits.restore_original_limits()
            _JOBS.clear()
        return {k: out[k] for ks in self.keys for k in ks}

    def _keyed(self, i: int, results: Mapping[str, RunResult]) -> dict[tuple[str, ...], RunResult]:
        """Job i's results (configuration → result) under their keys."""
        return {key: results[key[1]] for key in self.keys[i]}


#: What a setup run's reading measures: field → text (a conventional row has no field, None).
_FIELD_TEXT: dict[str | None, str] = {
    "parallax": "δp of the built model on the (6.27) domain per m_xy = n_л·σ (task 1)",
    "levelled": "δp on the chapter-5 domain after levelling on Fig. 39's four control points "
    "(least-squares plane, exact control heights) per m_xy = n_л·σ (task 2)",
    "observed": "δp on the chapter-5 domain after levelling on Fig. 39's four control points, "
    "each control parallax observed with m_p = m_xy/√2, per m_p (task 2)",
}


def _switches_text(fidelity: Fidelity | None) -> str:
    """``name=value`` of each mechanism switch of a run's :class:`Fidelity`."""
    if fidelity is None:
        return "the defaults"
    return ", ".join(f"{m.name}={getattr(fidelity, m.name)}" for m in MECHANISMS)


def _procedure_note(eq: str, res: RunResult, field: str | None, scaled: bool) -> str:
    """The note of a procedure-MC row: the run, the formula at the simulated geometry, their
    ratio and the mismatches of assumptions."""
    f, p, c, a, n, ll = res["f"], res["p"], res["c"], res["a"], res["n"], res["l"]
    v, h, ref = procedure_value(res, field, scaled)
    head = (
        f"procedure MC ({res['scenario']}, T = {res['trials']}, σ = {res['sigma_mm'] * 1000:g} µm"
        f" photo, linear control variate): {v:.4f} ± {h:.4f} against the rigorous formula at the "
        f"simulated geometry (f = {f:.2f}, p = {p:.2f}, c = {c:.2f}, a = {a:.2f}, l = {ll:g}, "
        f"n_л = {n:.3f} of our SC-1 sheet) {ref:.4f}: ratio {v / ref - 1.0:+.1%}"
    )
    if res["method"] != "conventional":
        return (
            f"{head}. Measured: {_FIELD_TEXT[field]}; bias of the error-free run "
            f"{res['bias_mm'] * 1000:.1f} µm removed. Only the monocular pointing σ of the "
            "operator; the mechanisms by which the procedure departs from the formula's "
            f"assumptions, switched as {_switches_text(res.get('fidelity'))} "
            "(procedure.fidelity; the as_formula block: all at the formula's; the decomposition: "
            "one switch a step); tilted photos and relief of the scenario"
        )
    part = {
        "both": "σ_q = σ_p = σ",
        "y_parallax": "σ_q only (the (5.54) part)",
        "stereo": "σ_p only (the (5.55) part" + (", × f/p: k" if scaled else "") + ")",
    }
    return (
        f"{head}. Measured: {part[res['sources']]}, per σ; the heights as read on the slipped "
        "height scale, standard points at a = c − p, the height datum the mean of the four "
        "levelling heights (the formula's plane), every loop 3 passes. The formula is taken with "
        "the plane at the procedure's levelling points (the scenario's control points nearest "
        "standard points 3–6); at Fig. 39's x_п ∈ {−c, a}, y = ±c it gives "
        f"{res['formula']['rigorous']:.4f}. Mismatches: scaling "
        "by b_x on plan control, relative orientation by (5.11); bias of the error-free run "
        f"{res['bias_mm'] * 1000:.1f} µm removed"
    )


def run_verification(
    trials: int = 60000,
    seed: int = 20240601,
    geometry: Mapping[str, float] | None = None,
    progress: Progress | None = None,
    procedure_trials: int | None = None,
    procedure_scenarios: Mapping[str, Scenario | None] | None = None,
    instrument: InstrumentSpec | None = None,
    linkage: str | None = None,
) -> list[Row]:
    """Compute the verification table.

    Parameters
    ----------
    trials : int
        Monte Carlo trials per row (60 000 gives half-widths ≤ 1.4 % at 99.9 %, ≤ 0.8 % at
        95 %; most rows, with several sources, are tighter).
    seed : int
        Seed of the linear Monte Carlo (one stream per row, keyed by the row's identity:
        :func:`row_stream`).
    geometry : mapping, optional
        Overrides of :data:`BOOK` (keys f, l, n, c, p60, a60, p80, a80).
    progress : callable, optional
        ``progress(done, total, eq)`` after each row.
    procedure_trials : int or None
        Trials of the procedure MC per run (None: :data:`PROCEDURE_TRIALS` and
        :data:`INSTRUMENT_TRIALS`); 0 disables it.
    procedure_scenarios : mapping, optional
        "60"/"80" → loaded scenario of the procedure MC (None for a slot skips it; None: no
        procedure MC). The book's are the shipped ``pair60``, ``pair80``, loaded by the caller
        (:func:`stereoplotter.io.book_setting.book_scenarios`): this layer reads no files.
    instrument : InstrumentSpec, optional
        The instrument of the procedure MC (the book's SC-1); required with a scenario.
    linkage : {"drag", "independent"}, optional
        The knob–decentration linkage of the procedure MC (None: the instrument's).

    Returns
    -------
    list of dict
        Rows with the keys :data:`ROW_KEYS` (plus ``units`` free text in ``quantity``).

    Examples
    --------
    >>> rows = run_verification(trials=200, seed=1, procedure_trials=0)
    >>> rows[0]["eq"], sorted(rows[0]) == sorted(ROW_KEYS)
    ('Table 19', True)
    """
    g = _normalise_geometry(geometry)
    pending = start_procedure_mc(
        procedure_trials, seed, procedure_scenarios, instrument=instrument, linkage=linkage
    )  # in worker processes while the linear rows are computed here
    specs = row_entries(g)
    rows = _rows(specs, trials, seed, progress, Setting.from_mapping(g).is_book)
    attach_procedure_mc(rows, pending.result())
    return rows


def attach_procedure_mc(rows: list[Row], proc: ProcedureResults) -> list[Row]:
    """Fill ``mc_procedure``, ``mc_procedure_ci``, ``mc_procedure_formula`` (the rigorous
    formula at the simulated geometry), ``mc_procedure_instrument`` (and its CI) and the note
    from :func:`run_procedure_mc`."""
    for r in rows:
        spec = procedure_rows().get(r["eq"])
        if spec is None:
            continue
        slot, config, field, scaled = spec
        pr = proc.get((slot, config))
        if pr is not None:
            v, h, ref = procedure_value(pr, field, scaled)
            r["mc_procedure"], r["mc_procedure_ci"], r["mc_procedure_formula"] = v, h, ref
            first = row_decomposition(r["rigorous"], pr, field, scaled)
            r["as_formula"] = as_formula_block(r["eq"], proc, slot, config, field, scaled)
            r["decomposition"] = switch_decomposition(proc, slot, field, scaled, r["as_formula"])
            r["decomposition"]["first_order"] = first
            r["decomposition"]["linkage"] = first["linkage"]
            r["note"] = r["note"].replace(
                PROCEDURE_NOTE, _procedure_note(r["eq"], pr, field, scaled)
            )
        pi = proc.get((slot, config, "instrument"))
        if pi is not None:
            v, h, _ = procedure_value(pi, field, scaled)
            r["mc_procedure_instrument"], r["mc_procedure_instrument_ci"] = v, h
            r["note"] += (
                f"; with every instrument error term of {pi.get('instrument_key', 'the')} "
                f"instrument at its σ (real mechanics, T = {pi['trials']}): {v:.4f} ± {h:.4f}"
            )
    return rows


#: Mechanisms of decomposition steps, each shown by a switch run that removes it (``verify -o
#: DIR``'s verification.md, "Decomposition of the procedure rows"), on the book's scenarios with
#: the SC-1 and the dragging linkage only: step → text. Attached only to runs of that setting.
FIRST_ORDER_MECHANISMS = {
    "element_errors": "the knob–decentration linkage: switched to independent "
    "(verify --linkage independent) the step changes sign (levelled rows −35 % → +8 %)",
    "principal_distance": "the L-check's correction at the carriage's bottom stop, which "
    "reaches n = D/f_пр by f_пр: with --bottom-stop free f_пр stays at the sheet's value and "
    "the step is 0; the decomposition's bottom_stop step is its size in the RMS",
    "levelling_points": "the procedure's levelling points: re-levelled at Fig. 39's points "
    "(procedure_mc levelling='book') the run is the formula there within its CI",
    "procedure": "σ_q part: the scenario's tilted photos and relief (on vertical photos over "
    "flat terrain the rest is 0 within its CI; 3, 6 or 10 passes do not change it)",
}
MECHANISM_SETTING = ({"pair60", "pair80"}, "sc1", "drag")


def _mechanism(res: RunResult, step: str, field: str | None) -> str | None:
    names, key, linkage = MECHANISM_SETTING
    shown = res.get("scenario") in names and res.get("instrument_key") == key
    if not shown or res.get("linkage") != linkage or res.get("instrument"):
        return None
    if step == "procedure" and res.get("sources") != "y_parallax":
        return None
    return FIRST_ORDER_MECHANISMS.get(step)


def row_decomposition(
    book: float, res: RunResult, field: str | None, scaled: bool
) -> dict[str, Any]:
    """The ``decomposition`` block of a procedure row (:mod:`.decomposition`): the formula at
    the book geometry (``book``, the row's rigorous column) → at the simulated geometry → the
    first order of each trial's own errors → the procedure, each step with its CI; ``sum``
    (the plain procedure value of the same trials), ``procedure`` (the row's value, control
    variate) and ``closes`` (they agree within their CIs).

    Setup rows carry every step. Conventional rows: geometry (Fig. 39's points at the simulated
    geometry) → the levelling plane at the procedure's own levelling points (the rigorous
    formula there, :func:`~.procedure_mc.levelling_formula`) → the procedure (the rest, with
    the run's CI): their element errors are not decomposed.
    """
    k = res["f"] / res["p"] if scaled else 1.0
    value, ci, _ = procedure_value(res, field, scaled)
    if field is not None:
        out = dc.at_book(res["fields"][field]["decomposition"], book, k)
        plain = out["values"]["procedure"]
    else:
        formula = res["formula"]
        plain = {"value": value, "ci": 0.0}  # the rest is taken at the row's own value
        levels = {
            "book_geometry": (book, 0.0),
            "simulated_geometry": (formula["rigorous"] * k, 0.0),
            "levelling_points": (formula["procedure"] * k, 0.0),
            "procedure": (value, ci),
        }
        names = list(levels)
        texts = (
            dc.STEPS[0][1],
            "→ the plane at the procedure's levelling points (the formula there)",
            "→ the procedure (the rest: element errors not decomposed)",
        )
        steps = []
        for a, b, text in zip(names[:-1], names[1:], texts, strict=True):
            c = levels[b][0] - levels[a][0]
            ref = book if a == "book_geometry" else levels["simulated_geometry"][0]
            name = "geometry" if a == "book_geometry" else b
            steps.append(
                {
                    "step": name,
                    "text": text,
                    "contribution": c,
                    "ci": levels[b][1],
                    "relative": c / ref,
                }
            )
        out = {
            "values": {n: {"value": v, "ci": h} for n, (v, h) in levels.items()},
            "steps": steps,
            "sum": book + sum(s["contribution"] for s in steps),
        }
    for step in out["steps"]:
        step["mechanism"] = _mechanism(res, step["step"], field)
    out["procedure"] = {"value": value, "ci": ci}
    out["closes"] = bool(abs(out["sum"] - value) <= ci + plain["ci"])
    out["linkage"] = res.get("linkage")
    return out


#: Rows that print a quantity already printed by an earlier row (M_p/m_p of the conventional
#: method with m_q = m_p at 60 % and 80 %: (6.45) = (6.53) = (6.60), (6.46) = (6.61)): one
#: verdict and one value from printed inputs per quantity, decided at its first print.
SAME_QUANTITY = {"(6.60)": "(6.45)", "(6.61)": "(6.46)"}


def _one_verdict_per_quantity(rows: list[Row]) -> list[Row]:
    """The later print of a quantity (:data:`SAME_QUANTITY`) takes the first print's verdict
    and value from printed inputs; its note keeps what its own print gave."""
    by = {r["eq"]: r for r in rows}
    for later, first in SAME_QUANTITY.items():
        a, b = by.get(first), by.get(later)
        if a is None or b is None:
            continue
        own = f"{b['verdict']}: {b['note']}"
        if b["from_printed_inputs"] is not None:
            own = f"from its own printed inputs {b['from_printed_inputs']:.4f}, {own}"
        b["note"] = (
            f"same quantity as {first} (one verdict, decided there); this row's own print "
            f"{_fmt_printed(b['printed'])}, {own}"
        )
        b["verdict"], b["from_printed_inputs"] = a["verdict"], a["from_printed_inputs"]
    return rows


def _fmt_printed(v: float | None) -> str:
    return "—" if v is None else f"{v:g}"


def row_stream(seed: int, entry: Entry) -> np.random.Generator:
    """The generator of ``entry``'s linear Monte Carlo: seeded with ``[seed, crc32(identity)]``
    (:attr:`~stereoplotter.verification.entry.Entry.identity`; the keys of
    :mod:`stereoplotter.random_streams`), whatever rows come before it."""
    return np.random.default_rng([seed, key_code(entry.identity)])


def _rows(
    specs: list[Entry],
    trials: int,
    seed: int,
    progress: Progress | None,
    at_book: bool = True,
) -> list[Row]:
    seen: dict[str, int] = {}
    for i, e in enumerate(specs):
        if seen.setdefault(e.identity, i) != i:
            raise ValueError(f"two rows of the table share the identity {e.identity!r}")
    rows = []
    for i, e in enumerate(specs):
        rows.append(_row(e, trials, row_stream(seed, e), at_book))
        if progress is not None:
            progress(i + 1, len(specs), e.eq)
    return _one_verdict_per_quantity(rows)


def _verdict(e: Entry, at_book: bool) -> tuple[float | None, float | None, str, str]:
    """printed, from_printed_inputs, verdict and note of ``e``. The book's printed *numbers*
    (``e.digits`` set) and the arithmetic on them apply only at the book's geometry; elsewhere
    the verdict compares the book's formula with the rigorous one and the note says so."""
    number = e.digits is not None or e.book_only
    printed = e.printed if at_book or not number else None
    fpi = e.from_printed_inputs if at_book else None
    hand = None if e.verdict == RULE else e.verdict
    verdict, check = decide(
        printed, fpi, e.book, e.rigorous, digits=e.digits, upstream=e.upstream, hand=hand
    )
    if at_book:
        return printed, fpi, verdict, f"{check}. {e.note}"
    head = "geometry differs from the book's"
    if number:
        head += ": the book's printed number and its arithmetic do not apply"
    keep = not number or hand == "convention"
    return printed, fpi, verdict, f"{head}; {check}" + (f". {e.note}" if keep else "")


def _row(e: Entry, trials: int, rng: np.random.Generator, at_book: bool = True) -> Row:
    """The row of ``e``: its linear MC (``trials``, ``rng``) and covariance RMS."""
    # a squared statistic doubles the relative CI: four times the trials keep it ≤ 1 %
    r, h, _ = mc.mc_rms(e.model, 4 * trials if e.squared else trials, rng)
    cov = mc.covariance_rms(e.model)
    if e.squared:
        r, h, cov = r**2, 2 * r * h, cov**2
    printed, fpi, verdict, note = _verdict(e, at_book)
    return {
        "eq": e.eq,
        "quantity": e.quantity,
        "printed": printed,
        "from_printed_inputs": fpi,
        "book": e.book,
        "rigorous": e.rigorous,
        "covariance": cov * e.scale,
        "mc_linear": r * e.scale,
        "mc_linear_ci": h * e.scale,
        "mc_procedure": None,
        "mc_procedure_ci": None,
        "mc_procedure_formula": None,
        "mc_procedure_instrument": None,
        "mc_procedure_instrument_ci": None,
        "verdict": verdict,
        "note": note + "; " + PROCEDURE_NOTE,
        "as_formula": None,
        "decomposition": None,
    }


def closing_comparison(rows: list[Row]) -> list[dict[str, Any]]:
    """The book's closing claim (OCR L4022-4026) against the recomputed chain.

    Examples
    --------
    >>> rows = run_verification(trials=100, procedure_trials=0)
    >>> [r["overlap"] for r in closing_comparison(rows)]
    ['60 %', '80 %']
    """
    by = {r["eq"]: r for r in rows}
    out = []
    for ov, s, cv, claim in (
        ("60 %", "(6.58)", "(6.60)", "equal accuracy"),
        ("80 %", "(6.59)", "(6.61)", "setup data 20 % better"),
    ):
        row: dict[str, Any] = {"overlap": ov, "book_claim": claim}
        for key in ("printed", "book", "rigorous", "mc_linear", "mc_procedure"):
            a, b = by[s][key], by[cv][key]
            row[f"setup_{key}"], row[f"conventional_{key}"] = a, b
            row[f"gain_{key}"] = None if a is None or b is None else 1.0 - a / b
        out.append(row)
    return out
