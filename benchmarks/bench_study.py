"""Scale of `stereoplotter study run`: procedures/s serial, on 1 and 2 local Dask workers, memory
per worker, and a paper estimate of a 10⁸-procedure study on a cluster.

python benchmarks/bench_study.py                      # 8 cells × 4000 trials, chunks of 1000
python benchmarks/bench_study.py --trials 2000 --chunk 1000 --cells 4
python benchmarks/bench_study.py --warm               # the cluster started before the clock
python benchmarks/bench_study.py --timeline           # where the runs on Dask spend their wall

The study: the shipped formula-validity file on f = 70, 140 mm × overlap 60, 80 % (× α 0, 1°
for 8 cells), SC-1, setup data, the chunked measures only (checks, y-parallax, heights, plan):
cells·T/C chunk tasks of C trials each. Each configuration (serial; 1 worker; 2 workers) writes
a fresh Zarr store. By default the clock includes the embedded cluster's start, as ``study
run --workers N`` pays it (started by ``study.runner.start_local_client`` while the study is
prepared); the one-time imports of this process (dask.distributed, xarray, zarr, what a
procedure loads at its first run) are done before any clock, so that no run pays one the others
do not (``study run`` pays them once); with ``--warm`` the cluster is started and the library
loaded on every worker before the clock starts. CPU seconds: this process's during the run and
the workers' whole lives (their start included unless ``--warm``), which a loaded machine
stretches far less than the wall seconds. The Datasets of the three runs are compared bit for bit.

Peak memory per worker: the worker's maximum resident set size after the run (ru_maxrss), to be
read against the chunk's budget (C × BYTES_PER_TRIAL of procedure.trials, plus the interpreter
and the libraries).

The paper estimate scales the measured per-core rate (serial, at this chunk size) by the
cluster's cores and the measured parallel efficiency of 2 workers; the scheduler's load is the
task rate against Dask's documented per-task overhead (about 1 ms of scheduler time per task,
"Dask Best Practices"); the result size is the store's measured bytes per cell.
"""

import argparse
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

ROOT = Path(__file__).parents[1]
sys.path.insert(0, str(ROOT))

from stereoplotter.commands.study import run_into_store  # noqa: E402
from stereoplotter.io.study_store import open_results  # noqa: E402
from stereoplotter.procedure.trials import BYTES_PER_TRIAL  # noqa: E402

#: Scheduler time per task (Dask documentation: "each task has an overhead of about 1 ms"). [s]
SCHEDULER_SECONDS_PER_TASK = 1e-3


def study(trials: int, chunk: int, cells: int) -> dict:
    data = yaml.safe_load((ROOT / "studies" / "formula-validity.yaml").read_text("utf-8"))
    data["axes"] = {"f_mm": [70, 140], "overlap": [0.6, 0.8], "instrument": ["sc1"],
                    "method": ["setup"]}  # fmt: skip
    if cells == 8:
        data["axes"]["alpha_deg"] = [0, 1]
    elif cells != 4:
        raise SystemExit("--cells: 4 or 8")
    data.update(trials=trials, chunk_trials=chunk,
                measures=["checks", "y_parallax", "heights", "plan"])  # fmt: skip
    return data


def _peak_rss_mb() -> float:
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _cpu_seconds() -> float:
    import resource

    me = resource.getrusage(resource.RUSAGE_SELF)
    return me.ru_utime + me.ru_stime


def _warm() -> None:
    import stereoplotter.study.cells  # noqa: F401 - the library loaded before the clock starts


def _load_before_clocks(out: Path) -> None:
    """The one-time loads of this process before any clock, so that the three runs are timed
    alike: dask.distributed (else only the first run on Dask, the 1-worker one, pays its import)
    and what a study's first procedure loads (else only the serial run, the first, pays it).
    A 4-cell study of 10 trials, serial."""
    import distributed  # noqa: F401

    run_into_store(study(10, 10, 4), "warm", str(out), None)


def _start(workers: int):
    try:
        from stereoplotter.study.runner import start_local_client
    except ImportError:  # an older tree (before/after figures): started as `study run` did
        from stereoplotter.study.runner import local_client

        return local_client(workers, dashboard=False)
    return start_local_client(workers, dashboard=False)


def _timeline(label: str, t0: float, stamps: dict, end: float, stream: list) -> None:
    """Where a run's wall time goes: ``start_local_client`` returned (its workers forked), the
    cluster up, the study's checks and store (start–end), the first task submitted, each
    worker's first task, its busy time (the sum of its tasks), its last task's end, the run's
    end (the last cell written)."""

    def at(name: str) -> str:
        return "–".join(f"{t - t0:.2f}" for t in stamps.get(name, [])) or "-"

    print(f"  {label} timeline (s from the clock's start): start returned {at('returned')}, "
          f"cluster up {at('up')}, checks {at('checks')}, store {at('store')}, first submit "
          f"{at('submit')}, study returned {end - t0:.2f}")  # fmt: skip
    by_worker: dict[str, list[tuple[float, float]]] = {}
    for task in stream:
        for s in task["startstops"]:
            if s["action"] == "compute":
                by_worker.setdefault(task["worker"], []).append((s["start"], s["stop"]))
    for i, spans in enumerate(sorted(by_worker.values())):
        busy = sum(b - a for a, b in spans)
        first, last = min(a for a, _ in spans), max(b for _, b in spans)
        gaps = last - first - busy
        print(f"    worker {i}: {len(spans)} tasks, first start {first - t0:.2f}, last end "
              f"{last - t0:.2f}, busy {busy:.2f}, idle between {gaps:.2f}")  # fmt: skip


def _stamped(module, name: str, stamps: dict, key: str):
    """Wrap ``module.name`` to stamp its start and end in ``stamps[key]``; returns the undo."""
    original = getattr(module, name)

    def wrapped(*args, **kwargs):
        stamps.setdefault(key, []).append(time.time())
        try:
            return original(*args, **kwargs)
        finally:
            stamps[key].append(time.time())

    setattr(module, name, wrapped)
    return lambda: setattr(module, name, original)


def _when_up(client, stamps: dict) -> None:
    """Note when the cluster is up, have its scheduler record the task stream from then on and
    stamp the first task submitted (``client`` a client or a Future of one: the study is
    prepared meanwhile, not after)."""

    def up(taken) -> None:
        stamps["up"] = [time.time()]
        taken.get_task_stream(count=0)  # the scheduler's task-stream plugin, added now
        submit = taken.submit

        def stamped(*args, **kwargs):
            stamps.setdefault("submit", [time.time()])
            return submit(*args, **kwargs)

        taken.submit = stamped

    if hasattr(client, "add_done_callback"):
        client.add_done_callback(lambda f: f.exception() or up(f.result()))
    else:
        up(client)


def timed(data: dict, out: Path, workers: int | None, warm: bool, timeline: bool = False):
    from stereoplotter.study.runner import local_client

    client = None
    if workers and warm:
        client = local_client(workers, dashboard=False)
        client.run(_warm)
    try:
        t0 = time.perf_counter()
        c0 = time.process_time()
        t0_epoch = time.time()
        if workers and not warm:
            client = _start(workers)
        stamps: dict[str, list[float]] = {"returned": [time.time()]}
        undo = []
        if timeline and workers:
            import stereoplotter.io.study_store as study_store
            import stereoplotter.study.runner as runner

            _when_up(client, stamps)
            undo = [_stamped(runner, "study_checks", stamps, "checks"),
                    _stamped(study_store, "open_store", stamps, "store")]  # fmt: skip
        try:
            run_into_store(data, "bench", str(out), client)
        finally:
            for restore in undo:
                restore()
        end = time.time()
        wall = time.perf_counter() - t0
        cpu = time.process_time() - c0
        if hasattr(client, "result"):  # a Future of the client
            client = client.result()
        if timeline and workers:
            stream = client.get_task_stream(start=t0_epoch)
            _timeline(f"{workers} worker(s)", t0_epoch, stamps, end, stream)
        rss = list(client.run(_peak_rss_mb).values()) if client else [_peak_rss_mb()]
        if client:  # the workers' CPU seconds (with their start when not --warm)
            cpu += sum(client.run(_cpu_seconds).values())
    finally:
        if client is not None:
            cluster = client.cluster
            client.close()
            cluster.close()
    return wall, cpu, rss


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--trials", type=int, default=4000, help="trials per cell")
    ap.add_argument("--cells", type=int, default=8, help="cells: 4 or 8")
    ap.add_argument("--warm", action="store_true", help="start the cluster before the clock")
    ap.add_argument("--timeline", action="store_true",
                    help="where the runs on Dask spend their wall time (Dask's task stream)")
    ap.add_argument("--chunk", type=int, default=1000, help="trials per task")
    ap.add_argument("--nodes", type=int, default=32)
    ap.add_argument("--cores-per-node", type=int, default=32)
    ap.add_argument("--procedures", type=float, default=1e8)
    a = ap.parse_args()
    print(f"cpu_count={os.cpu_count()} numpy={np.__version__} load={os.getloadavg()[0]:.1f}")
    data = study(a.trials, a.chunk, a.cells)
    cells = a.cells
    procedures = cells * a.trials
    tasks = cells * -(-a.trials // a.chunk)
    tmp = Path(tempfile.mkdtemp(prefix="bench_study_"))
    results, rates = {}, {}
    try:
        _load_before_clocks(tmp / "warm.zarr")
        for label, workers in (("serial", None), ("1 worker", 1), ("2 workers", 2)):
            out = tmp / f"{label.replace(' ', '_')}.zarr"
            wall, cpu, rss = timed(data, out, workers, a.warm, a.timeline)
            rates[label] = procedures / wall
            results[label] = open_results(out)
            print(f"{label:10s}: {wall:6.1f} s (CPU {cpu:5.1f} s), "
                  f"{rates[label]:7.0f} procedures/s, "
                  f"{tasks} tasks of {a.chunk} trials, peak RSS per process "
                  + ", ".join(f"{r:.0f} MB" for r in rss))  # fmt: skip
        same = all(results["serial"].identical(r) for r in results.values())
        print(f"Datasets identical to the serial run: {same}")
        speedup = rates["2 workers"] / rates["1 worker"]
        print(f"speed-up 2 workers / 1 worker: {speedup:.2f}, 2 workers / serial: "
              f"{rates['2 workers'] / rates['serial']:.2f}; chunk budget "
              f"{a.chunk * BYTES_PER_TRIAL['setup'] / 1e6:.0f} MB per task")  # fmt: skip
        per_cell = results["serial"].nbytes / cells  # uncompressed, coordinates included
        per_task_s = 1.0 / rates["serial"] * a.chunk
        cores = a.nodes * a.cores_per_node
        efficiency = min(1.0, speedup / 2.0)
        wall = a.procedures / (rates["serial"] * cores * efficiency)
        n_tasks = a.procedures / a.chunk
        sched = n_tasks * SCHEDULER_SECONDS_PER_TASK / wall
        print("paper estimate:")
        print(f"  {a.procedures:.0e} procedures on {a.nodes} nodes × {a.cores_per_node} cores, "
              f"parallel efficiency {efficiency:.2f} (measured on 2 workers), "
              f"{per_task_s:.2f} s per task of {a.chunk} trials")  # fmt: skip
        print(f"  wall time ≈ {wall / 3600:.2f} h; {n_tasks:.0f} tasks, {n_tasks / wall:.1f} "
              f"tasks/s: scheduler busy ≈ {sched:.1%} at 1 ms per task")  # fmt: skip
        print(f"  result ≈ {per_cell / 1e3:.2f} kB per cell uncompressed (this study's variables);"
              f" 10⁴ cells ≈ {per_cell * 1e4 / 1e6:.0f} MB")  # fmt: skip
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
