"""Benchmark: speed where the user waits — whole commands and where their time goes.

python benchmarks/bench_wait.py times                       # the rows of ROWS, this checkout
python benchmarks/bench_wait.py times --before /path/main   # … and another checkout, in turn
python benchmarks/bench_wait.py profile simulate --label after   # cProfile → benchmarks/profiles/

``times`` runs each row as a whole process (``python -m stereoplotter …``) ``--runs`` times,
alternating with the ``--before`` checkout when given (PYTHONPATH set to each), and prints the
median wall time, the procedures per second where the row has trials, and the peak resident
memory of the largest process of the run (``resource.getrusage(RUSAGE_CHILDREN).ru_maxrss``
read after each run; its worker processes are its children). The ratio column is before/after
pair by pair (median), which holds when the shared machine's speed drifts.

``profile NAME`` prints (and writes to ``benchmarks/profiles/NAME-LABEL.txt``) the cProfile
summary of one part, in this process: ``simulate`` / ``conventional`` (one chunk of the
procedure on pair60/SC-1, ``--trials``, default 8000, the memory budget's chunk), ``info`` (the
command in-process), ``cli`` (``import stereoplotter.cli`` and its parser). Run it with the
checkout to profile first on ``sys.path`` (``PYTHONPATH=/path/main``) for the "before".
"""

from __future__ import annotations

import argparse
import cProfile
import io
import json
import os
import pstats
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent

#: The timed rows: label, arguments of ``python -m stereoplotter``, trials (None: no rate).
ROWS = (
    ("--version", ["--version"], None),
    ("info", ["info"], None),
    ("simulate 10⁴ (default)", ["simulate", "pair60", "--instrument", "sc1", "--trials", "10000",
                                 "--json", "-q"], 10_000),
    ("simulate 10⁵ (default)", ["simulate", "pair60", "--instrument", "sc1", "--trials", "100000",
                                 "--json", "-q"], 100_000),
    ("conventional 10⁴", ["simulate", "pair60", "--instrument", "sc1", "--method",
                          "conventional", "--trials", "10000", "--json", "-q"], 10_000),
    ("conventional 10⁵", ["simulate", "pair60", "--instrument", "sc1", "--method",
                          "conventional", "--trials", "100000", "--json", "-q"], 100_000),
    ("verify (defaults)", ["verify", "-q"], None),
)  # fmt: skip


def _run(checkout: str, argv: list[str]) -> tuple[float, float]:
    """Wall seconds and the peak RSS (MiB) of the largest process so far of one run."""
    env = {**os.environ, "PYTHONPATH": checkout}
    t = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "stereoplotter", *argv],
        env=env,
        cwd=checkout,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        check=False,
    )
    wall = time.perf_counter() - t
    return wall, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0


def times(args: argparse.Namespace) -> None:
    after = str(Path(args.after).resolve())
    before = str(Path(args.before).resolve()) if args.before else None
    print(f"cpu_count={os.cpu_count()} runs={args.runs} after={after} before={before}")
    print("| what | before | after | ratio before/after | peak RSS before / after |")
    print("|---|---|---|---|---|")
    for label, argv, trials in ROWS:
        if args.only and not any(word in label for word in args.only):
            continue
        walls: dict[str, list[float]] = {"before": [], "after": []}
        rss: dict[str, float] = {}
        for _ in range(args.runs):
            for name, checkout in (("before", before), ("after", after)):
                if checkout is None:
                    continue
                # ru_maxrss of the children is a running maximum: one process per reading
                wall, peak = _run_fresh(checkout, argv)
                walls[name].append(wall)
                rss[name] = max(rss.get(name, 0.0), peak)
        cells = {}
        for name, values in walls.items():
            if not values:
                cells[name] = "—"
                continue
            med = statistics.median(values)
            rate = f" ≈ {trials / med:,.0f}/s" if trials else ""
            cells[name] = f"{med:.2f} s{rate}"
        ratio = "—"
        if walls["before"]:
            pairs = zip(walls["before"], walls["after"], strict=True)
            ratio = f"{statistics.median(b / a for b, a in pairs):.2f}×"
        mem = " / ".join(f"{rss[n]:.0f} MiB" if n in rss else "—" for n in ("before", "after"))
        print(f"| {label} | {cells['before']} | {cells['after']} | {ratio} | {mem} |", flush=True)


def _run_fresh(checkout: str, argv: list[str]) -> tuple[float, float]:
    """:func:`_run` in a child of its own, so that the peak memory is this run's alone."""
    code = (
        f"import sys, json; sys.path.insert(0, {str(HERE)!r}); import bench_wait as b; "
        f"print(json.dumps(b._run({checkout!r}, {argv!r})))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    wall, peak = json.loads(done.stdout.strip().splitlines()[-1])
    return float(wall), float(peak)


def _procedure(method: str, trials: int):
    from stereoplotter.io.instrument_file import load_instrument
    from stereoplotter.io.paths import resolve_data_file
    from stereoplotter.io.scenario_file import load_scenario
    from stereoplotter.procedure.simulate import prepare_run, run_trials_chunk

    scenario = load_scenario(resolve_data_file("scenarios", "pair60"))
    prep = prepare_run(scenario, load_instrument("sc1"), method, seed=scenario.seed)
    run_trials_chunk(prep, 0, 16)  # warm: caches, first calls

    def part() -> None:
        run_trials_chunk(prep, 0, trials)

    return part


def profile(args: argparse.Namespace) -> None:
    if args.name in ("simulate", "conventional"):
        part = _procedure("setup" if args.name == "simulate" else "conventional", args.trials)
    elif args.name == "info":
        from stereoplotter.cli import main

        def part() -> None:
            with open(os.devnull, "w") as sink:
                saved, sys.stdout = sys.stdout, sink
                try:
                    main(["info"])
                finally:
                    sys.stdout = saved
    else:

        def part() -> None:
            import stereoplotter.cli as cli

            cli.full_parser()

    prof = cProfile.Profile()
    t = time.perf_counter()
    prof.enable()
    part()
    prof.disable()
    wall = time.perf_counter() - t
    out = io.StringIO()
    import stereoplotter

    out.write(
        f"# {args.name} ({args.label}): {wall:.2f} s under cProfile; stereoplotter from "
        f"{Path(stereoplotter.__file__).parent}; trials {args.trials}; cpu_count {os.cpu_count()}\n"
    )
    stats = pstats.Stats(prof, stream=out)
    stats.sort_stats("cumulative").print_stats(args.top)
    stats.sort_stats("tottime").print_stats(args.top)
    text = out.getvalue().replace(str(Path(stereoplotter.__file__).parent.parent) + "/", "")
    text = text.replace(str(HERE.parent) + "/", "").replace(sys.prefix + "/", "<python>/")
    print(text)
    target = HERE / "profiles" / f"{args.name}-{args.label}.txt"
    target.parent.mkdir(exist_ok=True)
    target.write_text(text, encoding="utf-8")
    print(f"written: {target}")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="what", required=True)
    t = sub.add_parser("times", help="whole commands, before and after")
    t.add_argument(
        "--after", default=str(HERE.parent), help="the checkout measured (default: this)"
    )
    t.add_argument("--before", help="a second checkout, run in turn with the first")
    t.add_argument("--runs", type=int, default=3)
    t.add_argument("--only", nargs="*", help="rows whose label contains one of these words")
    t.set_defaults(func=times)
    f = sub.add_parser("profile", help="cProfile of one part, written to benchmarks/profiles/")
    f.add_argument("name", choices=("simulate", "conventional", "info", "cli"))
    f.add_argument("--label", default="after")
    f.add_argument("--trials", type=int, default=8000)
    f.add_argument("--top", type=int, default=30)
    f.set_defaults(func=profile)
    args = p.parse_args()
    args.func(args)


if __name__ == "__main__":
    main()
