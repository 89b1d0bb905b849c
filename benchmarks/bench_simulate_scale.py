"""Benchmark: `stereoplotter simulate --trials T` end to end — seconds, peak memory, output size.

python benchmarks/bench_simulate_scale.py                      # T = 10⁵, 10⁶, setup method
python benchmarks/bench_simulate_scale.py --trials 100000 1000000 10000000   # and 10⁷
python benchmarks/bench_simulate_scale.py --trials 1000 10000 --method conventional
python benchmarks/bench_simulate_scale.py --no-output --workers 1   # without -o, one worker

Each run is a fresh Python process that calls the command line exactly as a user would
(``simulate pair60 --instrument sc1 --seed 1 --trials T --json -o DIR``: simulation,
evaluation, summary, trial-0 files and ``trials.npz``) and reports its own peak resident memory
(``ru_maxrss`` of the process that runs the command, not of its forked chunk workers) and the
CPU seconds of it and of its workers (which, unlike the wall seconds, a loaded machine does not
stretch much). Goals: peak ≤ 350 MB at 10⁶ trials and within 10 % of the 10⁵ figure, time
linear in T, ``--json`` output under 100 kB.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CHILD = """
import contextlib, io, json, resource, sys
from stereoplotter.cli import main
buf = io.StringIO()
with contextlib.redirect_stdout(buf):
    code = main(sys.argv[1:])
me = resource.getrusage(resource.RUSAGE_SELF)
kids = resource.getrusage(resource.RUSAGE_CHILDREN)
cpu = me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime
out = {"code": code, "json_bytes": len(buf.getvalue().encode()), "peak_rss": me.ru_maxrss * 1024}
print(json.dumps({**out, "cpu_seconds": cpu}))
"""


def run(
    trials: int, method: str, memory_mb: float | None, output: bool, workers: int | None
) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        args = ["simulate", "pair60", "--instrument", "sc1", "--method", method, "--seed", "1"]
        args += ["--trials", str(trials), "--json", "-q"]
        if output:
            args += ["-o", str(Path(tmp) / "out")]
        if memory_mb:
            args += ["--memory-mb", str(memory_mb)]
        if workers:
            args += ["--workers", str(workers)]
        t = time.perf_counter()
        done = subprocess.run(
            [sys.executable, "-c", CHILD, *args], capture_output=True, text=True, check=True
        )
        seconds = time.perf_counter() - t
        out = json.loads(done.stdout.strip().splitlines()[-1])
        npz = Path(tmp) / "out" / "trials.npz"
        out["npz_bytes"] = npz.stat().st_size if output else 0
    out.update(trials=trials, seconds=seconds, per_second=trials / seconds)
    return out


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("--trials", type=int, nargs="+", default=[100_000, 1_000_000])
    p.add_argument("--method", choices=("setup", "conventional"), default="setup")
    p.add_argument("--memory-mb", type=float, help="chunk memory budget (default: the CLI's)")
    p.add_argument("--no-output", action="store_true", help="run without -o (no files)")
    p.add_argument("--workers", type=int, help="--workers of simulate (default: the CLI's)")
    a = p.parse_args()
    import numpy

    print(
        f"cpus {os.cpu_count()}, numpy {numpy.__version__}, method {a.method}, "
        f"{'no -o' if a.no_output else '-o'}, workers {a.workers or 'default'}, "
        f"load {os.getloadavg()[0]:.1f}"
    )
    print(
        f"{'trials':>9} {'seconds':>9} {'per s':>8} {'CPU s':>8} {'peak MB':>8} "
        f"{'json kB':>8} {'npz MB':>8}"
    )
    for t in a.trials:
        r = run(t, a.method, a.memory_mb, not a.no_output, a.workers)
        print(
            f"{t:>9} {r['seconds']:>9.2f} {r['per_second']:>8.0f} {r['cpu_seconds']:>8.1f} "
            f"{r['peak_rss'] / 1e6:>8.0f} {r['json_bytes'] / 1e3:>8.1f} "
            f"{r['npz_bytes'] / 1e6:>8.1f}",
            flush=True,
        )


if __name__ == "__main__":
    main()
