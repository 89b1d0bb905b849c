"""Benchmark: a production job, the per-pair sheets and the vectorised Table 24 part.

Run ``python benchmarks/bench_job.py`` (``--copies 1250``: 10 000 pairs in the vectorised part).

The job ``jobs/strip8`` is repeated (its 8 pairs each time) and timed, numeric part only (no file
read or written, no PDF):

* **measured inputs** — ``io.job_measured.measured_pair`` per pair (SK-42 → the pair's local frame,
  f′, the pair's points, the working area);
* **sheets, one at a time** — ``setup.sheet.compute_sheet_from_measurements`` per pair (Table 24
  as a block of one, corners (6.7)/(6.8), readings);
* **sheets, one call** — ``setup.sheet.compute_sheets_from_measurements``, what ``stereoplotter
  setup JOB`` does (``commands.setup_job.compute_job``): Table 24 of all pairs in one
  ``compute_table24`` call, then each pair's corners and readings;
* **vectorised Table 24** — ((6.1)–(6.6) and the scale choice) of N = 8 × ``--copies`` pairs in
  one ``setup.table24.compute_table24`` call on the stacked measured inputs, each pair with its
  own f′ and measured marks (the per-pair f′ of the job's films).

Goal: ≥ 10⁴ pairs/s for the numeric part of a block. Speed is measured here, never
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
from stereoplotter.io.job_file import load_job
from stereoplotter.io.job_measured import measured_pair
from stereoplotter.setup.records import SetupOptions
from stereoplotter.setup.scale_choice import candidate_scales
from stereoplotter.setup.sheet import (
    compute_sheet_from_measurements,
    compute_sheets_from_measurements,
)
from stereoplotter.setup.table24 import compute_table24

JOB = Path(__file__).resolve().parents[1] / "jobs" / "strip8" / "job.yaml"


def _rate(n: int, seconds: float) -> str:
    return f"{n} pairs in {seconds * 1000:.0f} ms = {n / seconds:,.0f} pairs/s"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--copies", type=int, default=1250, help="repeats of the 8 pairs")
    parser.add_argument("--loop-copies", type=int, default=25, help="repeats in the sheet runs")
    args = parser.parse_args()
    job = load_job(JOB)
    spec = load_instrument(job.instrument)
    options = SetupOptions()

    start = time.perf_counter()
    measured = [measured_pair(job, p) for _ in range(args.loop_copies) for p in job.pairs]
    t_measured = time.perf_counter() - start
    arguments = [m.sheet_arguments() for m in measured]
    start = time.perf_counter()
    for a in arguments:
        compute_sheet_from_measurements(spec=spec, options=options, source=job.source, **a)
    t_loop = time.perf_counter() - start
    start = time.perf_counter()
    sheets = compute_sheets_from_measurements(
        arguments, spec=spec, options=options, source=job.source
    )
    t_batch = time.perf_counter() - start
    assert len(sheets) == len(arguments)

    one = measured[: len(job.pairs)]
    reps = args.copies
    centres = np.concatenate([np.array([m.centres_m for m in one])] * reps)
    rotations = np.concatenate([np.array([m.rotations for m in one])] * reps)
    marks = np.concatenate([np.array([m.marks_mm for m in one])] * reps)
    f_pairs = np.array([m.focal_length_corrected_mm for m in one] * reps)
    depth = np.array(
        [[m.centres_m[0, 2] - m.working_area_m[:, 2].max(),
          m.centres_m[0, 2] - m.working_area_m[:, 2].min()] for m in one] * reps
    )  # fmt: skip
    heights = np.full((len(centres), 1), 150.0)
    grid = candidate_scales(spec, 10000, None, None)
    names = tuple(str(i) for i in range(len(centres)))
    best = np.inf
    for _ in range(5):
        start = time.perf_counter()
        result = compute_table24(
            f_pairs, marks, centres, rotations, depth, grid, spec, heights_m=heights,
            map_scale_denominator=10000, model_names=names,
            height_point_ids=(("h",),) * len(centres),
        )  # fmt: skip
        best = min(best, time.perf_counter() - start)
    n = len(centres)
    machine = f"{platform.machine()}, os.cpu_count() = {os.cpu_count()}, numpy {np.__version__}"
    print(f"machine: {machine}")
    print(f"measured inputs (measured_pair): {_rate(len(measured), t_measured)}")
    print(f"sheets one at a time (compute_sheet_from_measurements): {_rate(len(measured), t_loop)}")
    print(f"sheets in one call (compute_sheets_from_measurements): {_rate(len(measured), t_batch)}")
    print(f"vectorised Table 24, per-pair f' and marks: {_rate(n, best)} (best of 5, "
          f"{int(np.sum(result.accepted))} accepted)")  # fmt: skip


if __name__ == "__main__":
    main()
