"""Benchmark: `stereoplotter simulate --trials T` end to end — seconds, peak memory, output size.

python benchmarks/bench_simulate_scale.py                      # T = 10³ … 10⁶, setup method
python benchmarks/bench_simulate_scale.py --trials 1000 10000 --method conventional

Each run is a fresh Python process that calls the command line exactly as a user would
(``simulate pair60 --instrument sc1 --trials T --json -o DIR``: simulation, evaluation, summary,
trial-0 files and ``trials.npz``) and reports its own peak resident memory (``ru_maxrss``).
Goals (issue 16): peak ≤ 1 GiB at 10⁶ trials, time linear in T, ≥ 5 000 procedures/s end to
end at 10⁴, ``--json`` output under 100 kB.
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
rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
print(json.dumps({"code": code, "json_bytes": len(buf.getvalue().encode()), "peak_rss": rss}))
"""


def run(trials: int, method: str, memory_mb: float | None) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        args = ["simulate", "pair60", "--instrument", "sc1", "--method", method]
        args += ["--trials", str(trials), "--json", "-q", "-o", str(Path(tmp) / "out")]
        if memory_mb:
            args += ["--memory-mb", str(memory_mb)]
        t = time.perf_counter()
        done = subprocess.run(
            [sys.executable, "-c", CHILD, *args], capture_output=True, text=True, check=True
        )
        seconds = time.perf_counter() - t
        out = json.loads(done.stdout.strip().splitlines()[-1])
        out["npz_bytes"] = (Path(tmp) / "out" / "trials.npz").stat().st_size
    out.update(trials=trials, seconds=seconds, per_second=trials / seconds)
    return out


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("--trials", type=int, nargs="+", default=[1_000, 10_000, 100_000, 1_000_000])
    p.add_argument("--method", choices=("setup", "conventional"), default="setup")
    p.add_argument("--memory-mb", type=float, help="chunk memory budget (default: the CLI's)")
    a = p.parse_args()
    import numpy

    print(f"cpus {os.cpu_count()}, numpy {numpy.__version__}, method {a.method}")
    print(f"{'trials':>9} {'seconds':>9} {'per s':>8} {'peak MiB':>9} {'json kB':>8} {'npz MB':>8}")
    for t in a.trials:
        r = run(t, a.method, a.memory_mb)
        print(
            f"{t:>9} {r['seconds']:>9.2f} {r['per_second']:>8.0f} "
            f"{r['peak_rss'] / 2**20:>9.0f} {r['json_bytes'] / 1e3:>8.1f} "
            f"{r['npz_bytes'] / 1e6:>8.1f}",
            flush=True,
        )


if __name__ == "__main__":
    main()
