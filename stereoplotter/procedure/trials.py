"""Many trials of a procedure in chunks under a memory budget, summarised per measure.

A run of T trials is cut into chunks of :func:`chunk_trials_for` trials (from a memory budget);
:func:`iter_trial_chunks` runs them one after another on one :class:`PreparedRun`. Every random
draw is keyed by the trial index, so the results do not depend on the chunk size.

Each chunk is reduced at once to *columns*: one value per trial and measure
(:func:`trial_columns`: every check's residual, tolerance, pass flag and iterations, the
iterations per stage, the zero readings, the true residual y-parallax, and the evaluation's max
and RMS errors per point set in base units). Columns are what a long run keeps (the caller
spools them, ``stereoplotter.io.trial_store``); :func:`summarise_columns` turns them into the
summary that ``simulate --json`` prints: pass rates, means, RMS and quantiles with their Monte
Carlo standard errors (:mod:`stereoplotter.statistics`), never per-trial arrays.
"""

from __future__ import annotations

import collections
import itertools
import math
import multiprocessing
import os
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import Future, ProcessPoolExecutor, ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from stereoplotter.constants import MM_PER_M, UM_PER_MM
from stereoplotter.procedure.arrays import max_abs_last
from stereoplotter.procedure.run import PreparedRun
from stereoplotter.procedure.simulate import SimulationResult, run_trials_chunk
from stereoplotter.random_streams import BLOCK
from stereoplotter.statistics import scale_summary, summarise_flags, summarise_values

__all__ = [
    "BYTES_PER_TRIAL",
    "DEFAULT_MEMORY_BUDGET_MB",
    "PARALLEL_MIN_CHUNK",
    "RunInfo",
    "chunk_trials_for",
    "default_workers",
    "iter_chunk_columns",
    "iter_trial_chunks",
    "run_header",
    "run_info",
    "split_chunk",
    "summarise_columns",
    "summarise_result",
    "trial_columns",
    "worker_tasks",
]

#: Peak working memory per trial of one chunk (simulation and evaluation), rounded up for
#: safety. Setup: ≈ 20 kB on pair60 (``benchmarks/bench_simulate_scale.py``). Conventional:
#: 14.6 kB on pair60 and pair80, 12.8 kB on mountain60 (the rise of ``ru_maxrss`` over one chunk
#: of 4 096, 8 192 and 16 384 trials, SC-1; 7.8 kB of it without the evaluation), so a
#: chunk of 12 288 trials stays under 180 MB of the default 256 MB. [bytes]
BYTES_PER_TRIAL = {"setup": 32_000, "conventional": 20_000}

#: Default memory budget of one chunk (a convention: leaves room on a 1 GiB allowance for the
#: interpreter, the libraries and the columns of the current chunk). [MB]
DEFAULT_MEMORY_BUDGET_MB = 256

#: Smallest chunk (below it the per-chunk Python overhead dominates). [trials]
MIN_CHUNK = 256


def chunk_trials_for(memory_budget_mb: float, method: str) -> int:
    """Trials per chunk so that one chunk stays within the memory budget.

    A chunk of at least two keyed blocks (:data:`~stereoplotter.random_streams.BLOCK`) is cut
    down to whole blocks, so that every chunk starts at a block's start: a chunk starting inside
    a block draws that block's prefix for nothing, on every stream it reads.

    Examples
    --------
    >>> chunk_trials_for(256, "setup"), chunk_trials_for(256, "conventional")
    (8000, 12288)
    """
    if not memory_budget_mb > 0:
        raise ValueError(f"memory budget: expected > 0 MB, found {memory_budget_mb}")
    per_trial = BYTES_PER_TRIAL.get(method, max(BYTES_PER_TRIAL.values()))
    n = int(memory_budget_mb * 1e6 // per_trial)
    if n >= 2 * BLOCK:
        n -= n % BLOCK
    return max(MIN_CHUNK, n)


def iter_trial_chunks(
    prep: PreparedRun,
    trials: int,
    chunk_trials: int,
    *,
    evaluate: bool = True,
    progress: Callable[[int], None] | None = None,
) -> Iterator[SimulationResult]:
    """Run trials 0 … T−1 in chunks; yield each chunk's result (the first with its transcript).

    ``progress(n)`` is called after each chunk with the number of trials it ran.
    """
    if trials < 1:
        raise ValueError(f"trials: expected ≥ 1, found {trials}")
    if chunk_trials < 1:
        raise ValueError(f"chunk_trials: expected ≥ 1, found {chunk_trials}")
    for first in range(0, trials, chunk_trials):
        n = min(chunk_trials, trials - first)
        result = run_trials_chunk(prep, first, n, evaluate=evaluate, transcript=first == 0)
        yield result
        if progress is not None:
            progress(n)


def default_workers() -> int:
    """Processes for the chunks of a long run: the processors this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not on Linux
        return max(1, os.cpu_count() or 1)


#: Smallest chunk cut for the worker processes (a convention: below it a chunk's fixed cost,
#: ≈ 0.1 s of Python per pass of the procedure, is as large as its trials'). [trials]
PARALLEL_MIN_CHUNK = 1000


def split_chunk(trials: int, chunk_trials: int, workers: int) -> int:
    """Trials per chunk with ``workers`` processes: the memory budget's chunk, cut so that each
    process gets a chunk (a chunk has a fixed cost of its own: as few as the processes need),
    not below :data:`PARALLEL_MIN_CHUNK`; a run of at most that many trials is not cut.

    Examples
    --------
    >>> split_chunk(100_000, 8000, 2), split_chunk(10_000, 8000, 2), split_chunk(10_000, 8000, 1)
    (8000, 5000, 8000)
    >>> split_chunk(30, 8000, 2), split_chunk(1500, 8000, 2)
    (8000, 1000)
    """
    if workers <= 1 or trials <= PARALLEL_MIN_CHUNK:
        return chunk_trials
    return min(chunk_trials, max(-(-trials // workers), PARALLEL_MIN_CHUNK))


#: The prepared run of the forked chunk workers (set before the pool forks).
_PREPARED: list[tuple[PreparedRun, bool]] = []

#: Tasks a worker process has queued or done ahead of the one this process yields (a
#: convention: two keep a worker busy while this process hands a chunk's columns on; more only
#: hold more finished columns here). [tasks]
QUEUED_PER_WORKER = 2

#: Most trials of one worker's task of consecutive chunks, where the chunks do not start on a
#: keyed block (a convention: this process may hold the columns of the tasks queued ahead,
#: ≈ 20 MB a task at ≈ 100 columns). [trials]
TASK_TRIALS = 24_000


def _chunk_columns(chunks: list[tuple[int, int]]) -> list[dict[str, NDArray[Any]]]:
    prep, evaluate = _PREPARED[0]
    return [_columns_here(prep, first, n, evaluate) for first, n in chunks]


def worker_tasks(count: int, chunk_trials: int, processes: int) -> list[list[int]]:
    """The chunks after the first (1 … count − 1) as the workers' tasks, in order: one chunk a
    task where chunks start on a keyed block (:data:`~stereoplotter.random_streams.BLOCK`), else
    runs of consecutive chunks, up to :data:`TASK_TRIALS` trials and no more than an even share
    of the processes. A chunk that starts inside a block goes on with the generator the chunk
    before left (``random_streams.keyed_standard_normal``) only in the process that ran that
    chunk: in another it draws the block's prefix again, on every stream (≈ 10 % of a chunk of
    the setup method); within a task it never does.

    Examples
    --------
    >>> worker_tasks(13, 8000, 2)  # the setup method's chunks at 10⁵ trials
    [[1, 2, 3], [4, 5, 6], [7, 8, 9], [10, 11, 12]]
    >>> worker_tasks(9, 12288, 2)  # whole blocks: a chunk a task
    [[1], [2], [3], [4], [5], [6], [7], [8]]
    >>> worker_tasks(4, 8000, 2)
    [[1, 2], [3]]
    """
    chunks = list(range(1, count))
    if chunk_trials % BLOCK == 0 or not chunks:
        return [[k] for k in chunks]
    share = -(-len(chunks) // max(1, processes))
    size = max(1, min(share, TASK_TRIALS // chunk_trials))
    return [chunks[i : i + size] for i in range(0, len(chunks), size)]


def iter_chunk_columns(
    prep: PreparedRun,
    trials: int,
    chunk_trials: int,
    *,
    workers: int = 1,
    evaluate: bool = True,
    progress: Callable[[int], None] | None = None,
) -> Iterator[tuple[SimulationResult | None, dict[str, NDArray[Any]]]]:
    """Trials 0 … T−1 in chunks, as ``(result, columns)`` in trial order: the first chunk's
    :class:`SimulationResult` (with trial 0's transcript) and then None, and each chunk's
    :func:`trial_columns`.

    With ``workers`` > 1 the chunks after the first run in that many forked processes, each
    given the next task of :func:`worker_tasks` in trial order and at most
    :data:`QUEUED_PER_WORKER` ahead of the one yielded, while this process runs the first and
    then only collects: it holds the columns of a fixed number of tasks, never a share of the
    run, so its memory does not grow with the trials (the forked processes keep the cores
    busy). ``progress`` counts each chunk when it is yielded. Every draw is keyed by the trial,
    so the columns are the same whatever the workers and the chunks.
    """
    if trials < 1:
        raise ValueError(f"trials: expected ≥ 1, found {trials}")
    if chunk_trials < 1:
        raise ValueError(f"chunk_trials: expected ≥ 1, found {chunk_trials}")
    starts = list(range(0, trials, chunk_trials))
    sizes = [min(chunk_trials, trials - f) for f in starts]
    count = len(starts)
    pool = None
    tasks: list[list[int]] = []
    if workers > 1 and count > 1 and "fork" in multiprocessing.get_all_start_methods():
        _PREPARED[:] = [(prep, evaluate)]  # inherited by the forked workers
        context = multiprocessing.get_context("fork")
        processes = min(workers, count - 1)
        pool = ProcessPoolExecutor(max_workers=processes, mp_context=context)
        depth = QUEUED_PER_WORKER * processes
        tasks = worker_tasks(count, chunk_trials, processes)
    task_of = {k: j for j, task in enumerate(tasks) for k in task}
    given: dict[int, Future[Any]] = {}  # each task given to a process: its chunks' columns
    done: dict[int, dict[str, NDArray[Any]]] = {}  # columns of a finished task, not yet yielded
    given_next = 0  # the first task not yet given to a process

    def give_workers(yielding: int) -> None:
        nonlocal given_next
        while given_next < len(tasks) and given_next - yielding < depth:
            chunks = [(starts[k], sizes[k]) for k in tasks[given_next]]
            given[given_next] = cast(ProcessPoolExecutor, pool).submit(_chunk_columns, chunks)
            given_next += 1

    try:
        if pool is not None:
            give_workers(0)
        result = run_trials_chunk(prep, 0, sizes[0], evaluate=evaluate, transcript=True)
        yield result, trial_columns(result)
        del result  # the caller keeps what it needs of the first chunk
        if progress is not None:
            progress(sizes[0])
        for k in range(1, count):
            if pool is None:
                columns = _columns_here(prep, starts[k], sizes[k], evaluate)
            else:
                if k not in done:
                    j = task_of[k]
                    give_workers(j)
                    done.update(zip(tasks[j], given.pop(j).result(), strict=True))
                columns = done.pop(k)
            yield None, columns
            del columns
            if progress is not None:
                progress(sizes[k])
    finally:
        if pool is not None:
            pool.shutdown(cancel_futures=True)
            _PREPARED.clear()


def _columns_here(prep: PreparedRun, first: int, n: int, evaluate: bool) -> dict[str, NDArray[Any]]:
    return trial_columns(run_trials_chunk(prep, first, n, evaluate=evaluate, transcript=False))


def _full(value: Any, trials: int, dtype: type = float) -> NDArray[Any]:
    return np.broadcast_to(np.asarray(value, dtype), (trials,)).copy()


#: Evaluation keys kept per trial: base units only (‰ H and map mm are derived in the summary).
_BASE_UNITS = ("_mm", "_m")


def trial_columns(result: SimulationResult) -> dict[str, NDArray[Any]]:
    """One value per trial and measure of a vectorised result, shape (T,) each.

    Names: ``check/<check>/{residual,tolerance,passed,iterations}``, ``iterations/<stage>``,
    ``zero_reading/<scale>``, ``residual_y_parallax/{standard_points_max,grid_max,grid_rms}_um``
    and ``evaluation/<point set>/<measure>`` (max and RMS errors in mm or m).
    """
    t = result.trials
    if t is None:
        raise ValueError("trial_columns needs a vectorised result (trials = T)")
    cols: dict[str, NDArray[Any]] = {}
    for name, c in result.checks.items():
        cols[f"check/{name}/residual"] = _full(c.residual, t)
        if c.tolerance is not None:
            cols[f"check/{name}/tolerance"] = _full(c.tolerance, t)
            cols[f"check/{name}/passed"] = _full(c.passed, t, bool)
        if c.iterations is not None:
            cols[f"check/{name}/iterations"] = _full(c.iterations, t)
    for name, rem in result.remedies.items():
        cols[f"remedy/{name}/applied"] = _full(rem.applied, t, bool)
        cols[f"remedy/{name}/rounds"] = _full(rem.rounds, t)
        # the check's pass among the trials that needed the remedy (NaN elsewhere)
        cols[f"remedy/{name}/passed_after"] = np.where(
            _full(rem.applied, t, bool), _full(rem.passed, t), np.nan
        )
    for name, v in result.iterations.items():
        cols[f"iterations/{name}"] = _full(v, t)
    for name, v in result.zero_readings.items():
        cols[f"zero_reading/{name}"] = _full(v, t)
    q_std = np.asarray(result.q_standard_mm, float).reshape(t, -1)
    q_grid = np.asarray(result.q_grid_mm, float).reshape(t, -1)
    cols["residual_y_parallax/standard_points_max_um"] = max_abs_last(q_std) * UM_PER_MM
    cols["residual_y_parallax/grid_max_um"] = np.max(np.abs(q_grid), axis=1) * UM_PER_MM
    cols["residual_y_parallax/grid_rms_um"] = np.sqrt(np.mean(q_grid**2, axis=1)) * UM_PER_MM
    if result.evaluation is not None:
        for set_name, measures in result.evaluation.summary(permille=False).items():
            for key, v in measures.items():
                if key == "n_points" or not key.endswith(_BASE_UNITS):
                    continue
                cols[f"evaluation/{set_name}/{key}"] = _full(v, t)
    return cols


@dataclass(frozen=True)
class RunInfo:
    """What the summary needs besides the columns (from any chunk of the run)."""

    header: dict[str, Any]
    check_units: dict[str, str]
    flying_height_m: float | None
    map_scale_denominator: int | None
    points_per_set: dict[str, int]


def run_info(result: SimulationResult, trials: int) -> RunInfo:
    """The :class:`RunInfo` of a run of ``trials`` trials from one of its chunks."""
    header = run_header(result)
    header["trials"] = int(trials)
    ev = result.evaluation
    return RunInfo(
        header,
        {name: c.unit for name, c in result.checks.items()},
        None if ev is None else float(ev.flying_height_m),
        None if ev is None else ev.map_scale_denominator,
        {} if ev is None else {n: len(s.ids) for n, s in ev.sets().items()},
    )


def _derived(key: str, summary: dict[str, Any], info: RunInfo) -> dict[str, dict[str, Any]]:
    """The same measure in ‰ H (heights) or map mm (plan), from its metre summary."""
    out = {}
    if key.endswith("_m") and key.startswith("height_error") and info.flying_height_m:
        out[key[:-2] + "_permille"] = scale_summary(summary, MM_PER_M / info.flying_height_m)
    if key.endswith("_m") and key.startswith("plan_error") and info.map_scale_denominator:
        out[key[:-2] + "_map_mm"] = scale_summary(summary, MM_PER_M / info.map_scale_denominator)
    return out


def summarise_columns(
    info: RunInfo, columns: Iterable[tuple[str, NDArray[Any]]], extra: dict[str, Any] | None = None
) -> dict[str, Any]:
    """The JSON-ready summary of a run from its whole columns (a few at a time are enough).

    Per check: pass rate, residual, tolerance and iterations; per stage: iterations; the true
    residual y-parallax; per point set of the evaluation: each max/RMS error (and in ‰ H or map
    mm). Every figure with its Monte Carlo standard error or 95 % interval.

    Columns of at least :data:`THREADED_SUMMARY_TRIALS` trials are summarised on two threads
    (their sorts and reductions release the GIL; 0.7 s of one core at 10⁵ trials of the
    conventional method), a few columns ahead of the one being assembled.
    """
    out: dict[str, Any] = {**info.header, **(extra or {})}
    checks: dict[str, dict[str, Any]] = {}
    groups: dict[str, dict[str, Any]] = {
        "iterations": {},
        "zero_reading": {},
        "residual_y_parallax": {},
    }
    evaluation: dict[str, dict[str, Any]] = {}
    remedies: dict[str, dict[str, Any]] = {}
    for name, figure in _column_figures(columns):
        kind, _, rest = name.partition("/")
        if kind == "check":
            check, _, field = rest.rpartition("/")
            entry = checks.setdefault(check, {"unit": info.check_units.get(check)})
            entry["pass_rate" if field == "passed" else field] = figure
        elif kind == "remedy":
            rem, _, field = rest.rpartition("/")
            entry = remedies.setdefault(rem, {})
            key = {"applied": "applied_rate", "passed_after": "passed_after_rate"}.get(field, field)
            entry[key] = figure
        elif kind == "evaluation":
            set_name, _, key = rest.partition("/")
            s = evaluation.setdefault(set_name, {"n_points": info.points_per_set.get(set_name)})
            s[key] = figure
            s.update(_derived(key, s[key], info))
        else:
            groups[kind][rest] = figure
    out["checks"] = checks
    out["remedies"] = remedies
    out.update(groups)
    out["evaluation"] = evaluation or None
    return out


#: Trials from which :func:`summarise_columns` summarises columns on two threads (below, a
#: thread's start costs about what it saves). [trials]
THREADED_SUMMARY_TRIALS = 50_000


#: Column kinds summarised as values (those of :func:`trial_columns`).
_VALUE_KINDS = (
    "check", "remedy", "evaluation", "iterations", "zero_reading", "residual_y_parallax"
)  # fmt: skip


def _column_figure(name: str, values: NDArray[Any]) -> dict[str, Any] | None:
    """The summary of one column: a rate for a yes/no column, else the values' figures."""
    kind, _, rest = name.partition("/")
    field = rest.rpartition("/")[2]
    if kind == "check" and field == "passed":
        return summarise_flags(values)
    if kind == "remedy" and field == "applied":
        return summarise_flags(values)
    if kind == "remedy" and field == "passed_after":
        done = values[~np.isnan(values)]
        return summarise_flags(done.astype(bool)) if done.size else None
    if kind in _VALUE_KINDS:
        return summarise_values(values)
    raise ValueError(f"unknown column {name!r}")  # pragma: no cover - trial_columns makes these


def _column_figures(
    columns: Iterable[tuple[str, NDArray[Any]]], ahead: int = 4
) -> Iterator[tuple[str, dict[str, Any] | None]]:
    """(name, :func:`_column_figure`) in the columns' order; long columns on two threads, at
    most ``ahead`` columns read before the one yielded."""
    items = iter(columns)
    first = next(items, None)
    if first is None:
        return
    if len(first[1]) < THREADED_SUMMARY_TRIALS or default_workers() < 2:
        for name, values in itertools.chain([first], items):
            yield name, _column_figure(name, values)
        return
    with ThreadPoolExecutor(max_workers=2) as pool:
        pending: collections.deque[Any] = collections.deque()
        for name, values in itertools.chain([first], items):
            pending.append((name, pool.submit(_column_figure, name, values)))
            if len(pending) > ahead:
                done_name, future = pending.popleft()
                yield done_name, future.result()
        while pending:
            done_name, future = pending.popleft()
            yield done_name, future.result()


def summarise_result(result: SimulationResult) -> dict[str, Any]:
    """JSON-ready summary of a result in memory: one procedure's values, or the per-measure
    statistics over the trials of a vectorised result (one chunk)."""
    if result.trials is None:
        return _single_summary(result)
    return summarise_columns(run_info(result, result.trials), trial_columns(result).items())


def _value(v: Any) -> Any:
    a = np.asarray(v, float)
    x = float(a.reshape(-1)[0])
    return None if math.isnan(x) else x


def _single_summary(r: SimulationResult) -> dict[str, Any]:
    """The summary of one procedure (``trials`` None): its values and the evaluation per point."""
    checks = {}
    for name, c in r.checks.items():
        entry = {"residual": _value(c.residual), "unit": c.unit}
        if c.tolerance is not None:
            entry["tolerance"] = _value(c.tolerance)
            entry["passed"] = bool(np.asarray(c.passed).reshape(-1)[0])
        if c.iterations is not None:
            entry["iterations"] = _value(c.iterations)
        checks[name] = entry
    q_std = np.abs(np.asarray(r.q_standard_mm))
    q_grid = np.asarray(r.q_grid_mm)
    remedies = {
        name: {
            "applied": bool(np.asarray(m.applied).reshape(-1)[0]),
            "rounds": int(np.asarray(m.rounds).reshape(-1)[0]),
            "passed_after": bool(np.asarray(m.passed).reshape(-1)[0]),
        }
        for name, m in r.remedies.items()
    }
    return {
        **run_header(r),
        "iterations": {k: _value(v) for k, v in r.iterations.items()},
        "checks": checks,
        "remedies": remedies,
        "residual_y_parallax_um": {
            "standard_points_max": _value(np.max(q_std) * 1e3),
            "grid_max": _value(np.max(np.abs(q_grid)) * 1e3),
            "grid_rms": _value(np.sqrt(np.mean(q_grid**2)) * 1e3),
        },
        "evaluation": None if r.evaluation is None else r.evaluation.to_dict(),
    }


def run_header(r: SimulationResult) -> dict[str, Any]:
    """What a run was: method, back-end, seed, trials, scenario, instrument, operator."""
    return {
        "method": r.method,
        "backend": r.backend,
        "seed": r.seed,
        "trials": r.trials,
        "practice": r.practice,
        "scenario": r.sheet.scenario,
        "instrument": r.sheet.instrument,
        "instrument_options": list(r.instrument.options.names),
        "operator": r.operator_model.to_dict(),
        "fidelity": {k: getattr(r.fidelity, k) for k in r.fidelity.__dataclass_fields__},
    }
