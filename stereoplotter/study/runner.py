"""Run a study's tasks serially or on dask.distributed, handing each finished cell to a sink.

The same code runs on a laptop and a cluster: :func:`run_study` takes a ``dask.distributed``
``Client`` (an embedded :func:`local_client`, or one connected to a scheduler's address) or
None for a serial run in this process. Tasks are (cell, chunk of trials), (cell, procedure MC)
and (cell, budget) (:meth:`StudyDesign.tasks`); they are submitted cell by cell, so cells finish
roughly in order and a killed study loses at most the cells in flight. A cell's consecutive
chunks run as one batch (:func:`chunk_batches`: one pass of the procedure over their trials,
up to the memory budget's chunk, its fixed cost paid once), each chunk still reduced to its own
moments; a process keeps the prepared run of the cell it last ran (:func:`run_chunks`), not one
per task. :func:`start_local_client` starts an embedded cluster on a thread, so that it comes
up while the study is being prepared; its workers are forked from this process with the library
loaded (on Linux; elsewhere spawned). A cell is handed to
``sink(cell, values)`` as soon as its last task returns; ``done`` cells (already in the store)
are skipped — that is how a study resumes.

Results do not depend on the partition of the work: each task's result depends only on the
study seed, its cell and its trial range (keyed random streams), and a cell's chunks are
combined in trial order (:func:`~stereoplotter.study.cells.combine_chunks`).
"""

from __future__ import annotations

import os
import sys
import threading
import uuid
from collections.abc import Callable, Iterable
from concurrent.futures import Future
from typing import Any, ClassVar

from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.error_model import error_model_from_spec
from stereoplotter.procedure.operator import OperatorModel
from stereoplotter.procedure.run import PreparedRun
from stereoplotter.procedure.simulate import prepare_run, run_trials_chunk
from stereoplotter.procedure.trials import (
    DEFAULT_MEMORY_BUDGET_MB,
    chunk_trials_for,
    trial_columns,
)
from stereoplotter.study.cells import (
    CellRun,
    Moments,
    cell_run,
    chunk_measures,
    prepared_run,
    run_task,
)
from stereoplotter.study.design import StudyDesign, Task
from stereoplotter.study.results import cell_values
from stereoplotter.verification.budget import budget_terms

__all__ = [
    "chunk_batches",
    "local_client",
    "run_chunks",
    "run_study",
    "start_local_client",
    "started_client",
    "study_checks",
    "study_terms",
    "worker_start_method",
]

Sink = Callable[[int, dict[str, Any]], None]


def study_checks(design: StudyDesign, cells: list[dict[str, Any]]) -> tuple[str, ...]:
    """The checks of every (instrument, method, practice) of the study, in order of first
    appearance: one trial of the first cell of each combination that is not refused."""
    names: dict[str, None] = {}
    seen: set[tuple[str, str, str]] = set()
    for i, cell in enumerate(cells):
        run = cell_run(design, i, cell)
        combo = (run.spec.key, run.method, run.practice)
        if combo in seen:
            continue
        try:
            prep = prepare_run(
                run.scenario,
                run.spec,
                run.method,
                "zero",
                design.seed,
                operator=run.operator,
                practice=run.practice,
            )
            result = run_trials_chunk(prep, 0, 1, evaluate=False, transcript=False)
        except StereoplotterError:  # refused here: its checks come from another cell
            continue
        seen.add(combo)
        names.update({name: None for name, c in result.checks.items() if c.tolerance is not None})
    return tuple(names)


def study_terms(design: StudyDesign) -> tuple[str, ...]:
    """The budget's error terms of every instrument of the study (instrument terms, operator)."""
    names: dict[str, None] = {}
    for spec in design.instruments.values():
        for term in budget_terms(error_model_from_spec(spec), OperatorModel().for_instrument(spec)):
            names[term.name] = None
    return tuple(names)


def worker_start_method() -> str:
    """How the embedded cluster starts its worker processes: forked from this process on Linux
    (each worker has the library loaded at once: a spawned worker imports numpy, Dask and the
    library again, ≈ 2 s of CPU each), spawned elsewhere (macOS's system libraries are not safe
    to fork; Windows cannot)."""
    return "fork" if sys.platform.startswith("linux") else "spawn"


#: Dask's periodic housekeeping, slowed for the embedded cluster. Its scheduler and the workers'
#: nannies live in the study's process and its workers take every core, so each wake-up of
#: theirs is taken from a task: work stealing (off: the batches are few and queued at the
#: scheduler), the event loop's responsiveness tick (20 ms by default), the system monitor behind
#: the dashboard's CPU and memory plots (500 ms), the nanny's poll of its worker's memory against
#: the limit (100 ms). Measured on a 2-worker study: the study process's CPU while the tasks run
#: about halved (benchmarks/README.md, ``bench_study.py``).
QUIET_CLUSTER = {
    "distributed.scheduler.work-stealing": False,
    "distributed.admin.tick.interval": "500ms",
    "distributed.admin.system-monitor.interval": "5s",
    "distributed.worker.memory.monitor-interval": "1s",
}


def local_client(workers: int | None = None, dashboard: bool = True):
    """An embedded ``LocalCluster``: ``workers`` processes (default one per core), one thread
    each, started by :func:`worker_start_method`, and its client. The workers' statistical
    profiler is off (it samples the task's thread every 10 ms and competes with it for the
    interpreter), and the cluster's housekeeping is slowed (:data:`QUIET_CLUSTER`)."""
    # Imported here: dask.distributed is the optional extra `study` and takes a second to load.
    import dask
    from distributed import Client, LocalCluster

    settings = {
        "distributed.worker.profile.enabled": False,
        "distributed.worker.multiprocessing-method": worker_start_method(),
        **QUIET_CLUSTER,
    }
    with dask.config.set(settings):
        cluster = LocalCluster(
            n_workers=_worker_count(workers),
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0" if dashboard else None,
        )
    return Client(cluster)


def _worker_count(workers: int | None) -> int:
    """The embedded cluster's workers: ``workers``, or one per core (as ``LocalCluster`` counts
    them: the cores this process may use)."""
    # Imported here: dask is the optional extra `study`.
    from dask.system import CPU_COUNT

    return workers if workers is not None else max(1, CPU_COUNT)


def _load_library() -> None:
    # imported here: run on each worker as it starts, so that its first task does not pay it
    import stereoplotter.study.runner  # noqa: F401


class ForkCounter:
    """Counts the forks this process makes from threads other than the one that created it
    (``os.register_at_fork``); ``done`` is set at ``expected`` of them, or by :meth:`stop`."""

    _counting: ClassVar[list[ForkCounter]] = []
    _registered = False

    def __init__(self, expected: int):
        self.expected = expected
        self.waiter = threading.get_ident()
        self.seen = 0
        self.done = threading.Event()
        self._lock = threading.Lock()
        if not ForkCounter._registered and hasattr(os, "register_at_fork"):
            os.register_at_fork(after_in_parent=ForkCounter._after_fork)
            ForkCounter._registered = True
        ForkCounter._counting.append(self)
        if expected <= 0:
            self.stop()

    @staticmethod
    def _after_fork() -> None:
        for forks in list(ForkCounter._counting):
            if threading.get_ident() != forks.waiter:
                with forks._lock:
                    forks.seen += 1
                    if forks.seen >= forks.expected:
                        forks.stop()

    def stop(self) -> None:
        if self in ForkCounter._counting:
            ForkCounter._counting.remove(self)
        self.done.set()


def start_local_client(workers: int | None = None, dashboard: bool = True) -> Future:
    """:func:`local_client` as a Future of the client, to be taken once the study is prepared.

    The cluster is started on a thread and comes up while the study is prepared (its scheduler
    starting, its workers connecting). Forked workers (:func:`worker_start_method`) inherit the
    library, loaded here first; this returns once every worker process has been forked, so
    that no fork happens while this thread prepares the study (a lock it held at the fork, an
    import half done, would stay so in the worker). Spawned workers each load the library as
    they start."""
    started: Future = Future()
    fork = worker_start_method() == "fork"
    if fork:
        try:
            _load_library()  # the workers inherit it
        except BaseException as exc:  # handed to whoever takes the client
            started.set_exception(exc)
            return started
        forks = ForkCounter(_worker_count(workers))

    def start() -> None:
        try:
            client = local_client(workers, dashboard)
            if not fork:
                client.run(_load_library)
        except BaseException as exc:  # handed to whoever takes the client
            started.set_exception(exc)
        else:
            started.set_result(client)
        finally:
            if fork:  # whatever happened, no fork of the start is left to wait for
                forks.stop()

    threading.Thread(target=start, name="cluster-start", daemon=True).start()
    if fork:
        forks.done.wait()
    return started


def started_client(client: Any) -> Any:
    """The client itself, or the one of a Future (:func:`start_local_client`; None if it did not
    start): what is to be closed after a run."""
    if isinstance(client, Future):
        return None if client.exception() is not None else client.result()
    return client


def chunk_batches(tasks: list[Task], batch_trials: int) -> list[list[Task]]:
    """A cell's tasks in batches: consecutive chunks while their trials stay within
    ``batch_trials`` (at least one chunk a batch); every other task alone.

    Examples
    --------
    >>> chunks = [Task("chunk", 0, f, 1000) for f in range(0, 4000, 1000)]
    >>> [len(b) for b in chunk_batches(chunks + [Task("procedure", 0, 0, 50)], 2500)]
    [2, 2, 1]
    """
    out: list[list[Task]] = []
    batch: list[Task] = []
    for task in tasks:
        if batch and (
            task.kind != "chunk" or sum(t.trials for t in batch) + task.trials > batch_trials
        ):
            out.append(batch)
            batch = []
        if task.kind != "chunk":
            out.append([task])
        else:
            batch.append(task)
    if batch:
        out.append(batch)
    return out


def _batch_trials(design: StudyDesign, cells: int, processes: int) -> int:
    """Trials of a batch: the memory budget's chunk of the study's method (the largest of its
    methods' chunks is not taken: a batch stays within any method's budget), but small enough
    that each process gets two batches, and not below the study's chunk."""
    budget = min(chunk_trials_for(DEFAULT_MEMORY_BUDGET_MB, m) for m in ("setup", "conventional"))
    share = cells * design.trials // (2 * max(1, processes))
    return max(design.chunk_trials, min(budget, share))


#: The prepared run of the cell this process ran last: (run key, cell) → (CellRun, PreparedRun).
_PREPARED: dict[tuple[str, int], tuple[CellRun, PreparedRun]] = {}


def _prepared(design: StudyDesign, config: dict[str, Any], cell: int, key: str):
    if (key, cell) not in _PREPARED:
        run = cell_run(design, cell, config)
        prep = prepared_run(design, run)
        _PREPARED.clear()  # one cell at a time: cells are submitted in order
        _PREPARED[(key, cell)] = (run, prep)
    return _PREPARED[(key, cell)]


def run_chunks(
    design: StudyDesign,
    config: dict[str, Any],
    batch: list[Task],
    checks: tuple[str, ...],
    key: str = "",
) -> list[tuple[Task, Any]]:
    """Run a batch of one cell's consecutive chunk tasks in one pass of the procedure; each
    chunk's moments (the same as :func:`~stereoplotter.study.cells.run_task` gives it: every
    draw is keyed by the trial), or each ``("refused", message)``. The cell's prepared run is
    kept for the next batch of the run ``key``; other tasks go to ``run_task``."""
    if batch[0].kind != "chunk":
        return [run_task(design, config, task, checks) for task in batch]
    cell, first = batch[0].cell, batch[0].first
    try:
        run, prep = _prepared(design, config, cell, key)
        total = sum(t.trials for t in batch)
        result = run_trials_chunk(prep, first, total, evaluate=True, transcript=False)
        assert result.evaluation is not None
        height_m = float(result.evaluation.flying_height_m)
        rows = chunk_measures(run, checks, trial_columns(result), height_m)
    except StereoplotterError as exc:
        return [(task, ("refused", str(exc).splitlines()[0])) for task in batch]
    out = []
    for task in batch:
        start = task.first - first
        out.append((task, Moments.of(rows[:, start : start + task.trials])))
    return out


def _batch_key(token: str, batch: list[Task]) -> str:
    return f"study-{token}-{batch[0].key}-{len(batch)}"


def _client_processes(client: Any) -> int:
    try:
        return max(1, sum(client.nthreads().values()))
    except Exception:  # a client that cannot say: as on one process
        return 1


def run_study(
    design: StudyDesign,
    cells: list[dict[str, Any]],
    sink: Sink,
    *,
    checks: tuple[str, ...],
    terms: tuple[str, ...],
    done: Iterable[int] = (),
    client: Any = None,
    progress: Callable[[int], None] | None = None,
    submitted: Callable[[], None] | None = None,
) -> int:
    """Run every task of the cells not ``done``; call ``sink`` per finished cell. Returns the
    number of cells run. ``progress(n)``: n more tasks finished. ``client``: a Dask client, a
    Future of one (:func:`start_local_client`), or None (serial, in this process).
    ``submitted()``: called before the first result is taken — on Dask once every task is
    submitted, so that what it does (creating the store) overlaps the first tasks."""
    skip = set(done)
    pending = {i: design.tasks(i) for i in range(len(cells)) if i not in skip}
    parts: dict[int, list[tuple[Task, Any]]] = {}

    def finish(task: Task, result: Any) -> None:
        got = parts.setdefault(task.cell, [])
        got.append((task, result))
        if len(got) == len(pending[task.cell]):
            sink(task.cell, cell_values(design, parts.pop(task.cell), checks, terms))
        if progress is not None:
            progress(1)

    token = uuid.uuid4().hex[:8]
    client = client.result() if isinstance(client, Future) else client
    if client is None:
        size = _batch_trials(design, len(pending), 1)
        if submitted is not None:
            submitted()
        try:
            for i, tasks in pending.items():
                for batch in chunk_batches(tasks, size):
                    for task, result in run_chunks(design, cells[i], batch, checks, token):
                        finish(task, result)
        finally:
            _PREPARED.clear()
        return len(pending)
    # Imported here: dask.distributed is the optional extra `study`.
    from distributed import as_completed

    size = _batch_trials(design, len(pending), _client_processes(client))
    shared = client.scatter(design, broadcast=True)
    batches = [(i, b) for i, tasks in pending.items() for b in chunk_batches(tasks, size)]
    futures = [
        client.submit(run_chunks, shared, cells[i], b, checks, token, key=_batch_key(token, b))
        for i, b in batches
    ]
    if submitted is not None:
        try:
            submitted()
        except BaseException:
            client.cancel(futures)
            raise
    for future, results in as_completed(futures, with_results=True):
        for task, result in results:
            finish(task, result)
        future.release()
    return len(pending)
