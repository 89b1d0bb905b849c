"""Benchmark: a production job (issue 12), the per-pair sheets and the vectorised Table 24 part.

Run ``python benchmarks/bench_job.py`` (optionally ``--copies 1250`` for 10 000 pairs).

The job ``jobs/strip8`` is repeated ``--copies`` times (its 8 pairs each time) and timed in two
ways, numeric part only (no file read or written, no PDF):

* **per pair** — what ``stereoplotter setup JOB`` does: the measured inputs of each pair
  (``io.job_file.measured_pair``: SK-42 → the pair's local frame, f′, the pair's points, the
  working area) and its full sheet (``setup.sheet.compute_sheet_from_measurements``: Table 24 as a
  block of one, corners (6.7)/(6.8), readings);
* **vectorised** — Table 24 ((6.1)–(6.6) and the scale choice) of all N pairs in one
  ``setup.table24.compute_table24`` call on the stacked measured inputs. compute_table24 takes one
  f′ for the block; the job's pairs have their own f′ (film), so this uses the job's mean f′: the
  speed of the numeric part, not the sheets the job prints.

Goal (issue 12): ≥ 10⁴ pairs/s for the numeric part of a block. Speed is measured here, never
asserted in the tests.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from pathlib import Path

import numpy as np

from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.job_file import load_job, measured_pair
from stereoplotter.setup.records import SetupOptions
from stereoplotter.setup.scale_choice import candidate_scales
from stereoplotter.setup.sheet import compute_sheet_from_measurements
from stereoplotter.setup.table24 import compute_table24

JOB = Path(__file__).resolve().parents[1] / "jobs" / "strip8" / "job.yaml"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--copies", type=int, default=1250, help="repeats of the 8 pairs")
    parser.add_argument("--loop-copies", type=int, default=25, help="repeats in the per-pair run")
    args = parser.parse_args()
    job = load_job(JOB)
    spec = load_instrument(job.instrument)
    options = SetupOptions()

    start = time.perf_counter()
    measured = []
    for _ in range(args.loop_copies):
        for pair in job.pairs:
            m = measured_pair(job, pair)
            compute_sheet_from_measurements(spec=spec, options=options, source=job.source,
                                            **m.sheet_arguments())  # fmt: skip
            measured.append(m)
    loop = time.perf_counter() - start
    n_loop = args.loop_copies * len(job.pairs)

    one = measured[: len(job.pairs)]
    reps = args.copies
    centres = np.concatenate([np.array([m.centres_m for m in one])] * reps)
    rotations = np.concatenate([np.array([m.rotations for m in one])] * reps)
    marks = np.concatenate([np.array([m.marks_mm for m in one])] * reps)
    depth = np.array(
        [[m.centres_m[0, 2] - m.working_area_m[:, 2].max(),
          m.centres_m[0, 2] - m.working_area_m[:, 2].min()] for m in one] * reps
    )  # fmt: skip
    heights = np.full((len(centres), 1), 150.0)
    f_mean = float(np.mean([m.focal_length_corrected_mm for m in one]))
    grid = candidate_scales(spec, 10000, None, None)
    names = tuple(str(i) for i in range(len(centres)))
    best = np.inf
    for _ in range(5):
        start = time.perf_counter()
        result = compute_table24(
            f_mean, marks, centres, rotations, depth, grid, spec, heights_m=heights,
            map_scale_denominator=10000, model_names=names,
            height_point_ids=(("h",),) * len(centres),
        )  # fmt: skip
        best = min(best, time.perf_counter() - start)
    n = len(centres)
    machine = f"{platform.machine()}, os.cpu_count() = {os.cpu_count()}, numpy {np.__version__}"
    print(f"machine: {machine}")
    print(f"per pair (measured inputs + full sheet): {n_loop} pairs in {loop:.2f} s = "
          f"{n_loop / loop:,.0f} pairs/s")  # fmt: skip
    print(f"vectorised Table 24: {n} pairs in {best * 1000:.0f} ms = {n / best:,.0f} pairs/s "
          f"({int(np.sum(result.accepted))} accepted)")  # fmt: skip


if __name__ == "__main__":
    main()
