"""``stereoplotter study run|report|eye-range``: studies over the design space (docs/studies.md).

``study run STUDY.yaml -o RESULTS.zarr [--scheduler ADDRESS] [--workers N]`` runs a study on
dask.distributed — an embedded ``LocalCluster`` (processes, one per core) by default, the
scheduler at ``ADDRESS`` when given, in this process with ``--workers 0`` — and writes each
cell to the Zarr store as it finishes; run again, it skips the finished cells.
``study report RESULTS.zarr -o DIR`` draws the figures and writes the Markdown summary.
``study eye-range [SCENARIO …]`` prints the pass rates of the book's checks across the published
range of the operator's σ_q, σ_p (``procedure.eye_range``).
"""

from __future__ import annotations

import argparse
import copy
import functools
import os
import sys
from contextlib import nullcontext
from typing import Any

from stereoplotter.commands.arguments import bounded_int

_non_negative = bounded_int(0)
_positive = bounded_int(1)

__all__ = ["add_arguments", "run", "run_eye_range", "run_report", "run_study_command"]


def add_arguments(sub: Any) -> None:
    """Add the ``study`` subparser (``run``, ``report``) to the CLI's subparsers."""
    p = sub.add_parser(
        "study",
        help="studies over the design space on Dask (needs the extra stereoplotter[study])",
    )
    actions = p.add_subparsers(dest="study_command", required=True, metavar="ACTION")
    r = actions.add_parser("run", help="run a study into a Zarr store (resumes a killed run)")
    r.add_argument("study", help="a study file, or a shipped study's name (formula-validity)")
    r.add_argument("-o", "--output", required=True, help="the results store (RESULTS.zarr)")
    r.add_argument("--scheduler", help="a Dask scheduler's address (default: an embedded cluster)")
    r.add_argument(
        "--workers",
        type=_non_negative,
        help="worker processes of the embedded cluster (default: one per core; 0: serial, "
        "in this process)",
    )
    r.add_argument("--trials", type=_positive, help="override the study's trials per cell")
    r.add_argument(
        "--procedure-trials", type=_non_negative, help="override the procedure MC's trials"
    )
    r.add_argument("--budget-trials", type=_non_negative, help="override the budget's trials")
    r.add_argument(
        "--steps", type=_positive, help="override the steps of every ranged axis (a reduced grid)"
    )
    r.add_argument(
        "--axis",
        action="append",
        default=[],
        metavar="NAME=V1,V2,…",
        help="replace an axis by a list of values (repeatable; a reduced study)",
    )
    r.set_defaults(func=run_study_command)
    rep = actions.add_parser("report", help="figures and a Markdown summary of a results store")
    rep.add_argument("results", help="the results store (RESULTS.zarr)")
    rep.add_argument("-o", "--output", required=True, help="folder for the report")
    rep.set_defaults(func=run_report)
    eye = actions.add_parser(
        "eye-range",
        help="pass rates of the book's checks across the published range of the operator's "
        "σ_q, σ_p (the table of docs/procedure.md)",
    )
    eye.add_argument("scenarios", nargs="*", default=["pair60", "pair80"])
    eye.add_argument("--instrument", default="sc1")
    eye.add_argument("--trials", type=_positive, default=500, help="trials per table cell")
    eye.set_defaults(func=run_eye_range)


def run(args: argparse.Namespace) -> int:
    """Run the chosen action (``study run``, ``study report`` or ``study eye-range``)."""
    if args.study_command == "eye-range":
        return run_eye_range(args)
    return run_report(args) if args.study_command == "report" else run_study_command(args)


def run_eye_range(args: argparse.Namespace) -> int:
    """``study eye-range``: the pass-rate table over the operator's published σ range."""
    # imported here: the CLI loads no library module until a command runs (it starts fast)
    from stereoplotter.io.instrument_file import load_instrument
    from stereoplotter.io.scenario_file import load_scenario
    from stereoplotter.procedure.eye_range import pass_rate_table, table_markdown

    spec = load_instrument(args.instrument)
    scenarios = [load_scenario(s) for s in args.scenarios]
    rows = pass_rate_table(scenarios, spec, args.trials)
    sys.stdout.write(
        f"{args.trials} trials per cell, {spec.key}, default instrument errors, the scenarios' "
        "seeds; every check passed ± SE (the check passed least, its rate)\n\n"
    )
    sys.stdout.write(table_markdown(rows, scenarios))
    return 0


def reduced(data: dict[str, Any], args: argparse.Namespace) -> dict[str, Any]:
    """The study document with the command line's overrides (a reduced run)."""
    out = copy.deepcopy(data)
    for key in ("trials", "procedure_trials", "budget_trials"):
        value = getattr(args, key, None)
        if value is not None:
            out[key] = value
    if getattr(args, "steps", None):
        for axis in (out.get("axes") or {}).values():
            if isinstance(axis, dict) and "steps" in axis:
                axis["steps"] = args.steps
    for item in getattr(args, "axis", None) or []:
        name, _, values = item.partition("=")
        out.setdefault("axes", {})[name.strip()] = [_value(v) for v in values.split(",") if v]
    return out


def _value(text: str) -> Any:
    try:
        return float(text)
    except ValueError:
        return text.strip()


def run_into_store(
    data: dict[str, Any],
    source: str,
    output: str,
    client: Any = None,
    bar: Any = None,
    progress: Any = None,
) -> tuple[int, int]:
    """Run the study document ``data`` into the store ``output`` (created or resumed), serially
    (``client`` None) or on a Dask client (or a Future of one, taken once the study is
    prepared; a new store is then created while the first tasks run). ``bar(total)``: a
    context manager giving the progress callback (``stereoplotter.progress.progress_bar``);
    ``progress(n)``: another callback (tests). Returns (cells of the study, cells run now)."""
    # Imported here: xarray and zarr (the extra `study`) load in seconds; `--help` must not.
    from stereoplotter.io.study_file import study_fingerprint, study_from_mapping
    from stereoplotter.io.study_store import StudyStore, open_store
    from stereoplotter.study.results import empty_dataset
    from stereoplotter.study.runner import run_study, study_checks, study_terms

    design = study_from_mapping(data, source)
    cells = design.cells()
    checks = study_checks(design, cells) if "checks" in design.measures else ()
    terms = study_terms(design) if "budget" in design.measures else ()
    empty = empty_dataset(design, cells, checks, terms)
    stores: list[StudyStore] = []

    def create() -> None:
        if not stores:
            stores.append(open_store(output, empty, study_fingerprint(data), data))

    def write(cell: int, values: dict[str, Any]) -> None:
        stores[0].write_cell(cell, values)

    # A new store on Dask is written while the first tasks run (run_study's ``submitted``), in
    # a folder that can take it; any other store first (its errors before any task).
    parent = os.path.dirname(os.path.abspath(output))
    fresh = (
        client is not None
        and not os.path.lexists(output)
        and os.path.isdir(parent)
        and os.access(parent, os.W_OK | os.X_OK)
    )
    if not fresh:
        create()
    done = stores[0].done() if stores else set()
    tasks = sum(len(design.tasks(i)) for i in range(len(cells)) if i not in done)
    print(
        f"study {design.name}: {len(cells)} cells ({len(done)} done), {tasks} tasks to run, "
        f"{design.trials} trials per cell",
        file=sys.stderr,
    )
    with bar(tasks) if bar else nullcontext(lambda n: None) as advance:

        def both(n: int) -> None:
            advance(n)
            if progress is not None:
                progress(n)

        ran = run_study(
            design,
            cells,
            write,
            checks=checks,
            terms=terms,
            done=done,
            client=client,
            progress=both,
            submitted=create,
        )
    return len(cells), ran


def run_study_command(args: argparse.Namespace) -> int:
    """``study run``: the cells not yet in the store, serially or on Dask."""
    # Imported here: dask.distributed (the extra `study`) loads in seconds; `--help` must not.
    from stereoplotter.io.study_file import load_study
    from stereoplotter.progress import progress_bar
    from stereoplotter.study.runner import start_local_client, started_client

    _, data = load_study(args.study)
    data = reduced(data, args)
    client: Any = None
    try:
        if args.scheduler:
            from distributed import Client  # the extra `study`, loaded only to run on Dask

            client = Client(args.scheduler)
            _print_dashboard(client)
        elif args.workers != 0:
            # the embedded cluster comes up on a thread while the study is prepared
            client = start_local_client(args.workers)
            client.add_done_callback(lambda f: f.exception() or _print_dashboard(f.result()))
        bar = functools.partial(progress_bar, description="study", unit="task")
        cells, ran = run_into_store(data, args.study, args.output, client, bar)
    finally:
        client = started_client(client)
        if client is not None:
            cluster = None if args.scheduler else client.cluster
            client.close()
            if cluster is not None:
                cluster.close()
    print(f"study: {ran} of {cells} cells run now; results in {args.output}", file=sys.stderr)
    return 0


def _print_dashboard(client: Any) -> None:
    if client.dashboard_link:
        print(f"Dask dashboard: {client.dashboard_link}", file=sys.stderr)


def run_report(args: argparse.Namespace) -> int:
    """``study report``: figures and ``README.md`` in the output folder."""
    # Imported here: xarray, zarr and matplotlib load in seconds; `--help` must not.
    from stereoplotter.io.atomic_write import write_files
    from stereoplotter.io.study_store import open_results
    from stereoplotter.plotting.study_figures import study_figures
    from stereoplotter.report.study import study_report_files

    ds = open_results(args.results)
    figures, note = study_figures(ds)
    written = write_files(args.output, study_report_files(ds, figures, note))
    for path in written.values():
        print(path)
    return 0
