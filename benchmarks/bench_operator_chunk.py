"""CPU of one chunk of the simulated procedure, and what the operator's loops would save.

    PYTHONPATH=. python benchmarks/bench_operator_chunk.py conventional --trials 5000 --runs 5
    PYTHONPATH=. python benchmarks/bench_operator_chunk.py setup --draws

Runs trials 0 … N−1 of pair60 on the SC-1 (seed 1) in process, ``--runs`` times per variant in
turn, and prints the median process CPU of a chunk, its ratio to today's code and whether the
chunk's residual y-parallaxes (standard points and grid) are today's to the bit. Variants (each
a change of the operator's arithmetic, measured here and not in the package):

* ``kappa-one-at-a-time``: the cassette's κ look evaluated on x, x + h, x − h one after
  another instead of stacked (the knobs' looks stay stacked); the same bits;
* ``one-pass``: one look-and-correct pass of a drive instead of two (``Operator.passes``);
* ``one-pass+newton2``: and two Newton steps instead of four in C2's clearing of a point.

``--draws``: the share of the chunk's CPU in the keyed normal draws (``Noise.normal``), and
the number of keys drawn.

``--task N``: N consecutive chunks of ``--trials`` in one process (trials 0 …), as a worker
runs a task, with no variant: the process CPU of each chunk and of those after the first (the
first chunk of a process draws its keys' blocks without the states seeded together,
``random_streams._states_for_range``). Run it with each checkout on ``PYTHONPATH`` in turn.
"""

from __future__ import annotations

import argparse
import hashlib
import statistics
import time
from typing import Any

import numpy as np

import stereoplotter.procedure.conventional as conventional
import stereoplotter.procedure.operator as operator
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.paths import resolve_data_file
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.procedure.simulate import prepare_run, run_trials_chunk
from stereoplotter.procedure.trials import trial_columns

VARIANTS = {
    "today": {},
    "kappa-one-at-a-time": {"unstack": True},
    "one-pass": {"passes": 1},
    "one-pass+newton2": {"passes": 1, "newton": 2},
}
_NOW: dict[str, Any] = {}


def _patch() -> None:
    init, q_turning = operator.Operator.__init__, operator.Operator.q_turning
    solve = operator.solve_1d

    def patched_init(self: Any, *args: Any, **kwargs: Any) -> None:
        init(self, *args, **kwargs)
        self.passes = _NOW.get("passes", self.passes)

    def patched_solve(fun: Any, x0: Any, target: Any, iterations: int = 6, h: float = 1e-6) -> Any:
        return solve(fun, x0, target, _NOW.get("newton", iterations), h)

    def patched_q(self: Any, control: Any, images: Any) -> Any:
        look = q_turning(self, control, images)
        cassette = str(control).startswith("kappa_")
        return operator.Look(look.fn) if _NOW.get("unstack") and cassette else look

    operator.Operator.__init__ = patched_init  # type: ignore[method-assign]
    conventional.solve_1d = patched_solve  # C2's clearing of a point
    operator.Operator.q_turning = patched_q  # type: ignore[method-assign]


def _digest(result: Any) -> str:
    data = np.asarray(result.q_standard_mm).tobytes() + np.asarray(result.q_grid_mm).tobytes()
    return hashlib.sha1(data).hexdigest()


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("method", choices=("setup", "conventional"))
    p.add_argument("--trials", type=int, default=5000)
    p.add_argument("--runs", type=int, default=5)
    p.add_argument("--draws", action="store_true", help="the keyed draws' share only")
    p.add_argument("--task", type=int, default=0, help="N consecutive chunks in one process")
    args = p.parse_args()
    scenario = load_scenario(resolve_data_file("scenarios", "pair60"))
    prep = prepare_run(scenario, load_instrument("sc1"), args.method, seed=scenario.seed)
    if args.task:
        _task(prep, args)
        return
    run_trials_chunk(prep, 0, 16)  # warm: caches, first calls
    if args.draws:
        _draws(prep, args)
        return
    _patch()
    cpu: dict[str, list[float]] = {name: [] for name in VARIANTS}
    bits: dict[str, str] = {}
    for _ in range(args.runs):
        for name, variant in VARIANTS.items():
            _NOW.clear()
            _NOW.update(variant)
            t = time.process_time()
            result = run_trials_chunk(prep, 0, args.trials)
            cpu[name].append(time.process_time() - t)
            bits[name] = _digest(result)
    today = statistics.median(cpu["today"])
    for name, times in cpu.items():
        med = statistics.median(times)
        same = bits[name] == bits["today"]
        print(
            f"{args.method} {name}: CPU median {med:.3f} s, {med / today:.3f}× today, "
            f"bit-identical: {same}"
        )


def _task(prep: Any, args: argparse.Namespace) -> None:
    cpu = []
    for k in range(args.task):
        t = time.process_time()
        trial_columns(run_trials_chunk(prep, k * args.trials, args.trials, transcript=False))
        cpu.append(time.process_time() - t)
    chunks = " ".join(f"{c:.3f}" for c in cpu)
    rest = sum(cpu[1:])
    print(f"{args.method} chunks of {args.trials}: CPU {chunks} s; after the first {rest:.3f} s")


def _draws(prep: Any, args: argparse.Namespace) -> None:
    plain = operator.Noise.normal
    spent = {"cpu": 0.0, "depth": 0}
    keys: set[str] = set()

    def timed(self: Any, key: str, sigma: float) -> Any:
        if spent["depth"]:  # a compacted run's draw asks its parent's
            return plain(self, key, sigma)
        spent["depth"] += 1
        keys.add(key)
        t = time.process_time()
        try:
            return plain(self, key, sigma)
        finally:
            spent["cpu"] += time.process_time() - t
            spent["depth"] -= 1

    operator.Noise.normal = timed  # type: ignore[method-assign]
    for _ in range(args.runs):
        spent["cpu"] = 0.0
        t = time.process_time()
        run_trials_chunk(prep, 0, args.trials)
        total = time.process_time() - t
        print(
            f"{args.method}: chunk {total:.3f} s CPU, keyed draws {spent['cpu']:.3f} s "
            f"({spent['cpu'] / total:.0%}), {len(keys)} keys"
        )


if __name__ == "__main__":
    main()
