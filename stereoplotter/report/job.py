"""A production job at the edge: every pair's sheet, its printable form, the block summary.

:func:`run_job` loads a job file (:mod:`stereoplotter.io.job_file`), computes each pair's sheet
from its *measured* inputs with the one Table 24 computation (all pairs in one vectorised call:
:func:`stereoplotter.setup.sheet.compute_sheets_from_measurements`), and :func:`write_job` writes
per pair ``PAIR/sheet.yaml``, ``PAIR/sheet.md`` and ``PAIR/sheet.pdf`` (the form,
:mod:`stereoplotter.report.forms`), and for the job ``forms.pdf`` (all forms), ``block.csv`` and
``refused.md`` (the pairs the instrument cannot take, with the reason). No clock and no random
number is read: the same job gives the same files, byte for byte.
"""

from __future__ import annotations

import csv
import io
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from stereoplotter import __version__
from stereoplotter.errors import ConfigError, StereoplotterError
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.job_file import Job, JobPair, MeasuredPair, load_job, measured_pair
from stereoplotter.io.yaml_files import atomic_write_bytes
from stereoplotter.report.forms import FormHeader, form_pdf, forms_pdf
from stereoplotter.report.sheet import sheet_markdown, sheet_to_dict
from stereoplotter.setup.records import SetupOptions, SetupRefusal, SetupSheet
from stereoplotter.setup.sheet import compute_sheets_from_measurements
from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = [
    "JobResult",
    "PairResult",
    "block_csv",
    "compute_job",
    "form_header",
    "pair_dict",
    "refused_markdown",
    "run_job",
    "write_job",
]


@dataclass(frozen=True, slots=True)
class PairResult:
    """One pair of a job: its measured inputs, and the sheet or the refusal."""

    pair: JobPair
    measured: MeasuredPair | None
    sheet: SetupSheet | None
    reason: str

    @property
    def accepted(self) -> bool:
        return self.sheet is not None


@dataclass(frozen=True, slots=True)
class JobResult:
    job: Job
    spec: InstrumentSpec
    pairs: tuple[PairResult, ...]


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
        raise ConfigError(job.source, "instrument", "a shipped instrument (sc1, spr3, sd3) or "
                          "a YAML file beside the job", job.instrument, str(exc)) from None


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


def _frame_text(m: MeasuredPair | None) -> str:
    if m is None or m.origin_sk42_m is None:
        return "the job's local photogrammetric system (no SK-42 tie)"
    n, e, h = m.origin_sk42_m
    return f"§10 local system at SK-42 x = {n:.3f} m, ȳ = {e:.3f} m, H = {h:.3f} m"


def form_header(job: Job, p: PairResult) -> FormHeader:
    """The header of a pair's form, all from the job file (no clock)."""
    cam = job.camera
    sheet = p.pair.map_sheet
    sheet_text = "none (scales forced)" if sheet is None else (
        f"{sheet.nomenclature or 'given by corners'}, 1:{sheet.scale_denominator}"
    )  # fmt: skip
    camera = (f"{job.camera_name + ': ' if job.camera_name else ''}f = {cam.focal_length_mm:.3f} "
              f"mm, x₀, y₀ = {cam.principal_point_mm[0]:.3f}, {cam.principal_point_mm[1]:.3f} mm, "
              f"fiducials given as {cam.fiducials_given_as}")  # fmt: skip
    return FormHeader(
        job=job.name,
        job_file=Path(job.source).name,
        pair=p.pair.name,
        left_photo=str(p.pair.left),
        right_photo=str(p.pair.right),
        map_sheet=sheet_text,
        date=job.date,
        program=f"stereoplotter {__version__}",
        camera=camera,
        frame=_frame_text(p.measured),
        distortion=job.distortion,
    )


def pair_dict(job: Job, p: PairResult) -> dict[str, Any]:
    """A pair's sheet as plain data: the keys of ``sheet.yaml`` of a scenario plus ``job``."""
    data: dict[str, Any] = sheet_to_dict(p.sheet) if p.sheet is not None else {
        "status": "refused", "reason": p.reason,
    }  # fmt: skip
    m = p.measured
    data["job"] = {
        "name": job.name,
        "file": Path(job.source).name,
        "date": job.date,
        "pair": p.pair.name,
        "photos": {"left": p.pair.left, "right": p.pair.right},
        "map_sheet": p.pair.map_sheet.nomenclature if p.pair.map_sheet else None,
        "frame_origin_sk42_m": list(m.origin_sk42_m) if m and m.origin_sk42_m else None,
        "fiducial_distances_mm": {
            str(n): list(job.photos[n].fiducial_distances_mm) for n in (p.pair.left, p.pair.right)
        },
        "program": f"stereoplotter {__version__}",
    }
    return json.loads(json.dumps(data, default=_plain))


def _plain(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(type(value).__name__)


def _markdown(job: Job, p: PairResult) -> str:
    h = form_header(job, p)
    head = (
        f"Job **{h.job}** ({h.job_file}), pair **{h.pair}**: left photo {h.left_photo}, right "
        f"photo {h.right_photo}; map sheet {h.map_sheet}; {h.camera}; frame: {h.frame}; "
        f"date {h.date}; {h.program}.\n\n"
    )
    assert p.sheet is not None
    text = sheet_markdown(p.sheet)
    title, rest = text.split("\n", 1)
    return f"{title}\n\n{head}{rest.lstrip()}"


_CSV = (
    "pair", "left_photo", "right_photo", "map_sheet", "status", "scale_horizontal",
    "scale_vertical", "f_instrument_mm", "transformation_coefficient", "n_left", "n_right",
    "bx_mm", "by_mm", "bz_mm", "L_left_mm", "L_right_mm", "reason",
)  # fmt: skip


def _csv_mm(value: float) -> str:
    return f"{value + 0.0:.4f}" if abs(value) >= 5e-5 else "0.0000"  # no "-0.0000"


def block_csv(result: JobResult) -> str:
    """One row per pair: the main Table 24 values, or the refusal."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(_CSV)
    for p in result.pairs:
        sheet_name = p.pair.map_sheet.nomenclature if p.pair.map_sheet else ""
        head = [p.pair.name, p.pair.left, p.pair.right, sheet_name]
        s = p.sheet
        if s is None:
            writer.writerow([*head, "refused", *[""] * (len(_CSV) - 6), p.reason])
            continue
        writer.writerow([
            *head, "ok", s.horizontal_scale_denominator, s.vertical_scale_denominator,
            f"{s.f_instrument_mm:.4f}", f"{s.transformation_coefficient:.6f}",
            f"{s.n_left:.6f}", f"{s.n_right:.6f}", *(_csv_mm(v) for v in s.base_mm),
            _csv_mm(s.photos[0].mark_span_mm), _csv_mm(s.photos[1].mark_span_mm), "",
        ])  # fmt: skip
    return buffer.getvalue()


def refused_markdown(result: JobResult) -> str:
    """The refused pairs with their reasons (a line saying none when all are accepted)."""
    refused = [p for p in result.pairs if not p.accepted]
    lines = [f"# Refused pairs of job {result.job.name} on {result.spec.title}", ""]
    if not refused:
        lines.append(f"None: all {len(result.pairs)} pairs are set up.")
    for p in refused:
        lines.append(f"* **{p.pair.name}** (photos {p.pair.left}, {p.pair.right}): {p.reason}")
    return "\n".join(lines) + "\n"


def write_job(result: JobResult, output_dir: str | os.PathLike[str]) -> list[str]:
    """Write the files of a job (everything rendered before anything is written); the names."""
    out = Path(output_dir)
    files: dict[str, bytes] = {}
    forms = []
    for p in result.pairs:
        data = pair_dict(result.job, p)
        text = yaml.safe_dump(data, sort_keys=False, allow_unicode=True, width=100)
        files[f"{p.pair.name}/sheet.yaml"] = text.encode("utf-8")
        if p.sheet is None:
            continue
        header = form_header(result.job, p)
        files[f"{p.pair.name}/sheet.md"] = _markdown(result.job, p).encode("utf-8")
        files[f"{p.pair.name}/sheet.pdf"] = form_pdf(p.sheet, header)
        forms.append((p.sheet, header))
    if forms:
        files["forms.pdf"] = forms_pdf(forms, f"Setup sheets of job {result.job.name}",
                                       result.job.date)  # fmt: skip
    files["block.csv"] = block_csv(result).encode("utf-8")
    files["refused.md"] = refused_markdown(result).encode("utf-8")
    for name, content in files.items():
        atomic_write_bytes(out / name, content)
    return list(files)

