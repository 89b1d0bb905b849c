"""Run a study's tasks serially or on dask.distributed, handing each finished cell to a sink.

The same code runs on a laptop and a cluster: :func:`run_study` takes a ``dask.distributed``
``Client`` (an embedded :func:`local_client`, or one connected to a scheduler's address) or
None for a serial run in this process. Tasks are (cell, chunk of trials), (cell, procedure MC)
and (cell, budget) (:meth:`StudyDesign.tasks`); they are submitted cell by cell, so cells finish
roughly in order and a killed study loses at most the cells in flight. A cell is handed to
``sink(cell, values)`` as soon as its last task returns; ``done`` cells (already in the store)
are skipped — that is how a study resumes.

Results do not depend on the partition of the work: each task's result depends only on the
study seed, its cell and its trial range (keyed random streams), and a cell's chunks are
combined in trial order (:func:`~stereoplotter.study.cells.combine_chunks`).
"""

from __future__ import annotations

import uuid
from collections.abc import Callable, Iterable
from typing import Any

from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.error_model import error_model_from_spec
from stereoplotter.procedure.operator import OperatorModel
from stereoplotter.procedure.simulate import prepare_run, run_trials_chunk
from stereoplotter.study.cells import cell_run, run_task
from stereoplotter.study.design import StudyDesign, Task
from stereoplotter.study.results import cell_values
from stereoplotter.verification.budget import budget_terms

__all__ = ["local_client", "run_study", "study_checks", "study_terms"]

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


def local_client(workers: int | None = None, dashboard: bool = True):
    """An embedded ``LocalCluster``: ``workers`` processes (default one per core), one thread
    each, and its client."""
    # Imported here: dask.distributed is the optional extra `study` and takes a second to load.
    from distributed import Client, LocalCluster

    cluster = LocalCluster(
        n_workers=workers,
        threads_per_worker=1,
        processes=True,
        dashboard_address=":0" if dashboard else None,
    )
    return Client(cluster)


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
) -> int:
    """Run every task of the cells not ``done``; call ``sink`` per finished cell. Returns the
    number of cells run. ``progress(n)``: n more tasks finished."""
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

    if client is None:
        for i, tasks in pending.items():
            for task in tasks:
                finish(*run_task(design, cells[i], task, checks))
        return len(pending)
    # Imported here: dask.distributed is the optional extra `study`.
    from distributed import as_completed

    shared = client.scatter(design, broadcast=True)
    token = uuid.uuid4().hex[:8]
    futures = [
        client.submit(run_task, shared, cells[i], t, checks, key=f"study-{token}-{t.key}")
        for i, tasks in pending.items()
        for t in tasks
    ]
    for future, (task, result) in as_completed(futures, with_results=True):
        finish(task, result)
        future.release()
    return len(pending)
