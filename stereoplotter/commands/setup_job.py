"""``stereoplotter setup JOB``: a production job (format ``stereoplotter-job/1``).

Load the job file (:mod:`stereoplotter.io.job_file`) → compute each pair's sheet from its
*measured* inputs with the one Table 24 computation (all pairs in one vectorised call,
:func:`stereoplotter.setup.sheet.compute_sheets_from_measurements`) → render every pair's files
(:func:`stereoplotter.report.job.job_files`) → write them, all rendered before any is written.
Part of the ``setup`` command (:mod:`stereoplotter.commands.setup`), not a command of its own;
imported by it only for a job file, so the library is imported here at the top.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from stereoplotter.errors import ConfigError, StereoplotterError
from stereoplotter.io.atomic_write import write_files
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.job_file import Job, MeasuredPair, load_job, measured_pair
from stereoplotter.report.job import JobResult, PairResult, job_files, pair_dict
from stereoplotter.report.plain_data import json_text
from stereoplotter.setup.records import SetupOptions, SetupRefusal
from stereoplotter.setup.sheet import compute_sheets_from_measurements
from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = ["compute_job", "run", "run_job", "write_job"]


def _instrument(job: Job) -> InstrumentSpec:
    """The job's instrument: a shipped name, or a YAML path relative to the job file (an unknown
    name is refused as the job's field ``instrument``; a bad YAML file names itself)."""
    beside = Path(job.source).parent / job.instrument
    if beside.suffix in (".yaml", ".yml") and beside.exists():
        return load_instrument(beside)
    try:
        return load_instrument(job.instrument)
    except StereoplotterError as exc:
        if str(exc).startswith(f"{job.instrument}: "):  # a YAML path that names itself
            raise
        raise ConfigError(
            job.source,
            "instrument",
            "a shipped instrument (sc1, spr3, sd3) or a YAML file beside the job",
            job.instrument,
            str(exc),
        ) from None


def compute_job(job: Job, spec: InstrumentSpec | None = None) -> JobResult:
    """Every pair's sheet from its measured inputs; a refused pair keeps its reason.

    The pairs' Table 24 is one vectorised call (per-pair f′ and marks,
    :func:`~stereoplotter.setup.sheet.compute_sheets_from_measurements`); each sheet is the one
    the pair alone would give, to the bit.
    """
    spec = spec or _instrument(job)
    options = SetupOptions(
        book_sign_n_right=job.book_sign,
        horizontal_scale_denominator=job.horizontal_scale,
        vertical_scale_denominator=job.vertical_scale,
        bz_scale_sense=job.bz_scale_sense,
    )
    measured: list[MeasuredPair | SetupRefusal] = []
    for pair in job.pairs:
        try:
            measured.append(measured_pair(job, pair))
        except SetupRefusal as exc:
            measured.append(exc)
    ready = [m for m in measured if isinstance(m, MeasuredPair)]
    sheets = iter(compute_sheets_from_measurements(
        [m.sheet_arguments() for m in ready], spec=spec, options=options, source=job.source,
        name=job.name,
    ))  # fmt: skip
    out = []
    for pair, m in zip(job.pairs, measured, strict=True):
        if isinstance(m, SetupRefusal):
            out.append(PairResult(pair, None, None, str(m)))
            continue
        sheet = next(sheets)
        if isinstance(sheet, SetupRefusal):
            out.append(PairResult(pair, m, None, str(sheet)))
        else:
            out.append(PairResult(pair, m, sheet, ""))
    return JobResult(job, spec, tuple(out))


def run_job(
    path: str | os.PathLike[str], output_dir: str | os.PathLike[str] | None = None
) -> JobResult:
    """Load a job file, compute every pair and optionally write the files (:func:`write_job`)."""
    result = compute_job(load_job(path))
    if output_dir is not None:
        write_job(result, output_dir)
    return result


def write_job(
    result: JobResult, output_dir: str | os.PathLike[str], lang: str = "en", rigorous: bool = False
) -> list[str]:
    """Write the files of a job (everything rendered before anything is written); the names."""
    files = job_files(result, lang, rigorous)
    write_files(output_dir, files)
    return list(files)


def run(args: argparse.Namespace) -> int:
    """``setup`` on a job file: every pair's sheet and printable form."""
    given = [
        o
        for o, v in (
            ("--seed", args.seed),
            ("--horizontal-scale", args.horizontal_scale),
            ("--vertical-scale", args.vertical_scale),
        )
        if v is not None
    ]
    if given:
        raise StereoplotterError(
            f"{args.scenario}: {given[0]}: expected nothing for a job file, found a value (a job "
            "draws no random numbers and sets its scales in its own 'scales' field)"
        )
    job = load_job(args.scenario)
    result = compute_job(job, load_instrument(args.instrument) if args.instrument else None)
    if args.json:
        pairs = [pair_dict(job, p) for p in result.pairs]
        sys.stdout.write(
            json_text({"job": job.name, "instrument": result.spec.key, "pairs": pairs})
        )
        if args.output is None:
            return 0
    out = Path(args.output or "stereoplotter-setup")
    names = write_job(result, out, getattr(args, "lang", "en"), getattr(args, "rigorous", False))
    if not args.json:
        sys.stdout.write(_summary(result, names, out))
    return 0


def _summary(result: JobResult, names: list[str], out: Path) -> str:
    accepted = sum(p.accepted for p in result.pairs)
    lines = [
        f"job {result.job.name} on {result.spec.title}: {accepted} of {len(result.pairs)} "
        "pairs set up"
    ]
    for p in result.pairs:
        s = p.sheet
        lines.append(
            f"  {p.pair.name}: M_г = 1:{s.horizontal_scale_denominator}, M_в = "
            f"1:{s.vertical_scale_denominator}, f_пр = {s.f_instrument_mm:.3f} mm, n_л = "
            f"{s.n_left:.5f}, n_п = {s.n_right:.5f}"
            if s is not None
            else f"  {p.pair.name}: REFUSED: {p.reason}"
        )
    pdfs = sum(n.endswith("/sheet.pdf") for n in names)
    lines.append(
        f"written: <pair>/sheet.yaml, sheet.md, sheet.pdf ({pdfs} forms), forms.pdf, "
        f"block.csv, refused.md in {out}"
    )
    return "\n".join(lines) + "\n"
