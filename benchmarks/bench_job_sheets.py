"""Benchmark: whole sheets of a job's pairs, and their PDF forms.

Run ``python benchmarks/bench_job_sheets.py`` (``--pairs 10000 --forms 100``).

The 8 pairs of ``jobs/strip8`` are repeated up to ``--pairs`` pairs and timed end to end, as
``stereoplotter setup JOB`` computes them (``commands.setup_job.compute_job``), split into:

* **measured inputs** — ``io.job_measured.measured_pairs`` (what ``compute_job`` runs: SK-42 → each
  pair's local frame for all pairs in one geodesy call, f′, the pair's points, the working area);
* **sheet block** — ``setup.sheet_block.compute_sheet_block``: the columns of all pairs' sheets
  (frame, ground in it, (6.8) over pairs of unequal point counts, sheet corners, Table 24 with
  the scale choice), no per-pair record;
* **sheets** — ``setup.sheet.compute_sheets_from_measurements``: the block, then each pair's
  record (``SetupSheet`` with its stage readings, ``setup.sheet.sheet_of_block``) as a job
  builds them before printing;
* **scale-candidate tables** — ``setup.table24.candidates_of`` per pair (the candidate table
  that ``sheet.yaml`` prints), timed alone on the same Table 24;

**whole job** — ``compute_job`` (measured inputs, the block, the refusals; each pair's record
is built when first read), then every pair's record read (``PairResult.sheet``) as the printing
does; and the files of ``--forms`` pairs (``report.job.job_files``: every ``sheet.yaml``,
``sheet.md``, the PDF form of each pair and ``forms.pdf``), rendered in memory and then written
through ``commands.setup_job.write_job`` into a new folder.

Goals: ≥ 10⁴ pairs/s for the sheet block without PDFs, ≥ 5 000 pairs/s for the whole
``compute_job``, ≥ 20 pairs/s with the PDF forms.
Each figure is printed by the wall clock and by the process's CPU time (the machine is shared by
other jobs: compare the CPU rates between runs). Speed is measured here, never asserted in the
tests.
"""

from __future__ import annotations

import argparse
import os
import platform
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from stereoplotter.commands.setup_job import compute_job, write_job
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.job_file import load_job
from stereoplotter.io.job_measured import measured_pairs
from stereoplotter.report.job import job_files
from stereoplotter.setup.records import SetupOptions
from stereoplotter.setup.sheet import compute_sheets_from_measurements
from stereoplotter.setup.sheet_block import compute_sheet_block
from stereoplotter.setup.table24 import candidates_of

JOB = Path(__file__).resolve().parents[1] / "jobs" / "strip8" / "job.yaml"


def _rate(n: int, seconds: tuple[float, float], what: str = "pairs") -> str:
    """The rate by the wall clock and by the process's CPU time (the machine is shared: the CPU
    rate is the one to compare between runs)."""
    wall, cpu = seconds
    return (f"{n} {what} in {wall:.2f} s wall = {n / wall:,.1f} {what}/s; "
            f"CPU {cpu:.2f} s = {n / cpu:,.1f} {what}/s")  # fmt: skip


def _repeated(job, n: int):
    """The job with its pairs repeated to ``n`` pairs, each copy on photos of its own numbers
    (``101_k``): every pair has its own folder and form."""
    photos, pairs = {}, []
    for k in range(-(-n // len(job.pairs))):
        for number, photo in job.photos.items():
            photos[f"{number}_{k}"] = replace(photo, number=f"{number}_{k}")
        pairs += [replace(p, left=f"{p.left}_{k}", right=f"{p.right}_{k}")
                  for p in job.pairs]  # fmt: skip
    return replace(job, photos=photos, pairs=tuple(pairs[:n]))


def _timed(function, *args, **kwargs):
    start, cpu = time.perf_counter(), time.process_time()
    value = function(*args, **kwargs)
    return value, (time.perf_counter() - start, time.process_time() - cpu)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=10_000, help="pairs of the sheet runs")
    parser.add_argument("--forms", type=int, default=100, help="pairs of the PDF run")
    args = parser.parse_args()
    job = load_job(JOB)
    spec = load_instrument(job.instrument)
    options = SetupOptions()
    big = _repeated(job, args.pairs)
    print(f"python {platform.python_version()}, numpy {np.__version__}, "
          f"{platform.machine()}, os.cpu_count() = {os.cpu_count()}")  # fmt: skip

    measured, t_measured = _timed(measured_pairs, big)
    arguments = [m.sheet_arguments() for m in measured]
    block, t_block = _timed(
        compute_sheet_block, arguments, spec=spec, options=options, source=job.source
    )
    sheets, t_sheets = _timed(
        compute_sheets_from_measurements, arguments, spec=spec, options=options,
        source=job.source,
    )  # fmt: skip
    tables = [s.table24 for s in sheets]
    _, t_candidates = _timed(lambda: [candidates_of(t, 0) for t in tables])
    result, t_job = _timed(compute_job, big, spec)
    assert all(p.accepted for p in result.pairs)
    _, t_records = _timed(lambda: [p.sheet for p in result.pairs])
    t_both = (t_job[0] + t_records[0], t_job[1] + t_records[1])
    print(f"measured inputs:  {_rate(len(measured), t_measured)}")
    print(f"sheet block:      {_rate(len(block), t_block)}")
    print(f"sheets (block + records): {_rate(len(sheets), t_sheets)}")
    print(f"scale-candidate tables (candidates_of): {_rate(len(tables), t_candidates)}")
    print(f"whole job (compute_job: inputs, block, refusals): {_rate(len(result.pairs), t_job)}")
    print(f"every pair's record read after it: {_rate(len(result.pairs), t_records)}")
    print(f"whole job and every record: {_rate(len(result.pairs), t_both)}")

    small = _repeated(job, args.forms)
    result = compute_job(small, spec)
    files, t_render = _timed(job_files, result)
    pdfs = sum(name.endswith("/sheet.pdf") for name in files)
    print(f"PDF forms (render all files in memory): {_rate(pdfs, t_render, 'forms')}")
    with tempfile.TemporaryDirectory() as folder:
        _, t_write = _timed(write_job, result, Path(folder) / "out")
    print(f"PDF forms (render + write, manifest): {_rate(pdfs, t_write, 'forms')}")


if __name__ == "__main__":
    main()
