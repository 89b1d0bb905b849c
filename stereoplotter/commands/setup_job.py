"""``stereoplotter setup JOB``: a production job (format ``stereoplotter-job/1``).

Load the job file (:mod:`stereoplotter.io.job_file`) → compute each pair's sheet from its
*measured* inputs with the one Table 24 computation (all pairs in one vectorised call,
:func:`stereoplotter.setup.sheet.compute_sheets_from_measurements`) → render every pair's files
(:func:`stereoplotter.report.job.job_files`) → write them, all rendered before any is written,
into a new or empty folder (``--force``: replacing the previous outputs as a whole, with a
manifest; :mod:`stereoplotter.io.output_folder`). A pair that cannot be set up is refused alone
(``refused.md``); the exit is 1 only when no pair is set up, or with ``--strict`` when any is
refused. Part of the ``setup`` command (:mod:`stereoplotter.commands.setup`), not a command of
its own; imported by it only for a job file, so the library is imported here at the top.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import threading
from pathlib import Path

from stereoplotter.errors import ConfigError, StereoplotterError, raise_keyboard_interrupt
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.job_file import Job, load_job
from stereoplotter.io.job_measured import MeasuredPair, measured_pairs
from stereoplotter.io.output_folder import OutputReport, write_outputs
from stereoplotter.report.job import JobResult, PairResult, job_files, manifest_about, pair_dict
from stereoplotter.report.plain_data import json_text
from stereoplotter.setup.records import SetupOptions, SetupRefusal
from stereoplotter.setup.sheet import deferred_sheets
from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = ["compute_job", "run", "write_job"]


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

    The measured inputs of all pairs in one pass (:func:`~stereoplotter.io.job_measured.
    measured_pairs`), the pairs' sheets as one block of columns with Table 24 in one vectorised
    call (per-pair f′ and marks, :func:`~stereoplotter.setup.sheet.deferred_sheets`); each
    pair's record is built from the columns when first read (``PairResult.sheet``), the one the
    pair alone would give, to the bit.
    """
    spec = spec or _instrument(job)
    options = SetupOptions(
        book_sign_n_right=job.book_sign,
        horizontal_scale_denominator=job.horizontal_scale,
        vertical_scale_denominator=job.vertical_scale,
        bz_scale_sense=job.bz_scale_sense,
    )
    measured = measured_pairs(job)
    ready = [m for m in measured if isinstance(m, MeasuredPair)]
    sheets = iter(deferred_sheets(
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


def write_job(
    result: JobResult,
    output_dir: str | os.PathLike[str],
    *,
    force: bool = False,
    lang: str = "en",
    rigorous: bool = False,
) -> OutputReport:
    """Write the files of a job and their manifest (everything rendered before anything is
    written): into a new or empty folder, or with ``force`` replacing the previous outputs as a
    whole (:func:`stereoplotter.io.output_folder.write_outputs`). ``lang`` and ``rigorous``: the
    forms' language and which mark targets they give to set (:func:`report.job.job_files`)."""
    files = job_files(result, lang, rigorous)
    return write_outputs(output_dir, files, manifest_about(result), force=force)


def run(args: argparse.Namespace) -> int:
    """``setup`` on a job file: every pair's sheet and printable form. An interrupt (Ctrl-C,
    SIGTERM) ends in one line; the output folder holds the previous run or this one whole
    (:func:`stereoplotter.io.output_folder.write_outputs`)."""
    previous = signal.getsignal(signal.SIGTERM)
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, raise_keyboard_interrupt)
    try:
        return _run(args)
    except KeyboardInterrupt:  # one line, the exit code of an interrupt (128 + SIGINT)
        out = getattr(args, "output", None) or "stereoplotter-setup"
        sys.stderr.write(f"error: {out}: interrupted: the folder holds the previous run or this "
                         "one, each whole (never a mix of the two)\n")  # fmt: skip
        return 130
    finally:
        if threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGTERM, previous)


def _run(args: argparse.Namespace) -> int:
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
    out = None if args.json and args.output is None else Path(args.output or "stereoplotter-setup")
    force = getattr(args, "force", False)
    report = (
        write_job(
            result,
            out,
            force=force,
            lang=getattr(args, "lang", "en"),
            rigorous=getattr(args, "rigorous", False),
        )
        if out is not None
        else None
    )
    if args.json:
        pairs = [pair_dict(job, p) for p in result.pairs]
        sys.stdout.write(
            json_text({"job": job.name, "instrument": result.spec.key, "pairs": pairs})
        )
    elif report is not None and out is not None and not getattr(args, "quiet", False):
        sys.stdout.write(_summary(result, report, out))
    elif getattr(args, "quiet", False):  # warnings and errors only: the refused pairs
        for p in result.pairs:
            if not p.accepted:
                sys.stderr.write(f"warning: {p.pair.name}: refused: {p.reason}\n")
    _refusals(result, out, strict=getattr(args, "strict", False))
    return 0


def _refusals(result: JobResult, out: Path | None, *, strict: bool) -> None:
    """A job with refused pairs still gives the forms of the others (exit 0): exit 1 (this
    error, after the files are written) only when no pair is set up, or with ``strict`` when
    any is refused."""
    refused = [p for p in result.pairs if not p.accepted]
    if not refused or (len(refused) < len(result.pairs) and not strict):
        return
    where = f"reasons in {out / 'refused.md'}" if out is not None else "reasons in the JSON"
    first = f"{refused[0].pair.name}: {refused[0].reason}"
    if len(refused) == len(result.pairs):
        raise StereoplotterError(
            f"{result.job.source}: pairs: expected at least one pair set up, found all "
            f"{len(refused)} refused ({where}; {first})"
        )
    raise StereoplotterError(
        f"{result.job.source}: pairs: expected every pair set up (--strict), found "
        f"{len(refused)} of {len(result.pairs)} refused ({where}; {first})"
    )


def _summary(result: JobResult, report: OutputReport, out: Path) -> str:
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
    pdfs = sum(n.endswith("/sheet.pdf") for n in report.written)
    lines.append(
        f"written: <pair>/sheet.yaml, sheet.md, sheet.pdf ({pdfs} forms), forms.pdf, "
        f"block.csv, refused.md, manifest.json in {out}"
    )
    if report.removed:
        lines.append(f"removed {len(report.removed)} stale files of the previous run: "
                     + ", ".join(report.removed[:6]) + (" …" if len(report.removed) > 6 else ""))
    if report.kept_foreign:
        lines.append(f"left in place: {report.kept_foreign} file(s) no job run wrote")
    return "\n".join(lines) + "\n"
