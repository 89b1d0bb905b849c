"""A production job's files: every pair's sheet, its printable form, the block summary.

:func:`job_files` renders a computed job (:class:`JobResult`, made by
:func:`stereoplotter.commands.setup_job.compute_job`) as per pair ``PAIR/sheet.yaml``,
``PAIR/sheet.md`` and ``PAIR/sheet.pdf`` (the form, :mod:`stereoplotter.report.forms`), and for
the job ``forms.pdf`` (all forms), ``block.csv`` and ``refused.md`` (the pairs the instrument
cannot take, with the reason: a pair refused alone, the others still produced), and
:func:`manifest_about`, the header of the folder's manifest
(:mod:`stereoplotter.io.output_folder`). No clock and no random number is read: the same job
gives the same files, byte for byte.
"""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from stereoplotter import __version__
from stereoplotter.glossary import TERMS, check_language, term
from stereoplotter.io.job_file import Job, JobPair
from stereoplotter.io.job_measured import MeasuredPair
from stereoplotter.io.yaml_output import yaml_text
from stereoplotter.report.form_fields import rigorous_sides
from stereoplotter.report.form_layout import literal, localized_text, plain
from stereoplotter.report.forms import FormHeader, LeastCounts, form_pdfs
from stereoplotter.report.sheet import sheet_markdown, sheet_to_dict
from stereoplotter.setup.records import SetupSheet
from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = [
    "JobResult",
    "PairResult",
    "block_csv",
    "form_header",
    "job_files",
    "least_counts",
    "manifest_about",
    "pair_dict",
    "refused_markdown",
]


@dataclass(frozen=True, slots=True)
class PairResult:
    """One pair of a job: its measured inputs, and the sheet or the refusal.

    The sheet may be given as a function that builds it (:func:`stereoplotter.setup.sheet.
    deferred_sheets`): it is then built when first read, once."""

    pair: JobPair
    measured: MeasuredPair | None
    sheet_or_builder: SetupSheet | Callable[[], SetupSheet] | None
    reason: str

    @property
    def sheet(self) -> SetupSheet | None:
        """The pair's sheet (None for a refused pair)."""
        found = self.sheet_or_builder
        if found is None or isinstance(found, SetupSheet):
            return found
        built = found()
        object.__setattr__(self, "sheet_or_builder", built)  # built once, kept
        return built

    @property
    def accepted(self) -> bool:
        return self.sheet_or_builder is not None


@dataclass(frozen=True, slots=True)
class JobResult:
    job: Job
    spec: InstrumentSpec
    pairs: tuple[PairResult, ...]


def _frame_text(m: MeasuredPair | None, lang: str = "en") -> str:
    if m is None or m.origin_sk42_m is None:
        return term("frame_local", lang)
    n, e, h = m.origin_sk42_m
    return f"{term('frame_sk42', lang)} x = {n:.3f} m, ȳ = {e:.3f} m, H = {h:.3f} m"


#: The least count of the f_пр, base and decentration scales: an optional leaf of the instrument
#: file (the shipped ones give it, ``assumed``); a file without it falls back to the X, Y counters'.
SCALE_LEAST_COUNT_KEY = "counters.scale_least_count_mm"


def least_counts(spec: InstrumentSpec) -> LeastCounts:
    """The least counts of the form from the instrument spec, with those the file assumes."""
    keys = {
        "counter_mm": "xy_least_count_mm",
        "z_mm": "z_least_count_mm",
        "height_m": "height_scale_least_count_m",
    }
    scale = spec.parameters.get(SCALE_LEAST_COUNT_KEY)
    assumed = {k for k, attr in keys.items() if spec.is_assumed(attr)}
    if scale is None or scale.is_assumed:
        assumed.add("scale_mm")
    return LeastCounts(
        counter_mm=spec.xy_least_count_mm,
        z_mm=spec.z_least_count_mm,
        height_m=spec.height_scale_least_count_m,
        scale_mm=float(scale.value) if scale is not None else spec.xy_least_count_mm,
        assumed=frozenset(assumed),
    )


def form_header(
    job: Job, p: PairResult, spec: InstrumentSpec | None = None, lang: str = "en"
) -> FormHeader:
    """The header of a pair's form, all from the job file (no clock) and the instrument's least
    counts (``spec``; the defaults of :class:`LeastCounts` without one), in ``lang``."""
    cam = job.camera
    sheet = p.pair.map_sheet
    sheet_text = term("no_map_sheet", lang) if sheet is None else (
        f"{sheet.nomenclature or 'given by corners'}, 1:{sheet.scale_denominator}"
    )  # fmt: skip
    given = f"fiducials_{cam.fiducials_given_as}"
    given = term(given, lang) if given in TERMS else literal(cam.fiducials_given_as)
    camera = (f"{literal(job.camera_name) + ': ' if job.camera_name else ''}f = "
              f"{cam.focal_length_mm:.3f} mm, x₀, y₀ = {cam.principal_point_mm[0]:.3f}, "
              f"{cam.principal_point_mm[1]:.3f} mm, {term('fiducials_given_as', lang)} "
              f"{given}")  # fmt: skip
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
        frame=_frame_text(p.measured, lang),
        distortion=job.distortion,
        least_counts=least_counts(spec) if spec is not None else LeastCounts(),
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


def _markdown(job: Job, p: PairResult, lang: str = "en", rigorous: bool = False) -> str:
    h = form_header(job, p, lang=lang)
    t = lambda key: term(key, lang)  # noqa: E731 - a local shorthand for the many labels
    head = (
        f"{t('job').capitalize()} **{h.job}** ({h.job_file}), {t('pair')} **{h.pair}**: "
        f"{t('left_photo')} {h.left_photo}, {t('right_photo')} {h.right_photo}; "
        f"{t('map_sheet')} {h.map_sheet}; {h.camera}; {t('frame')}: {h.frame}; "
        f"{t('date')} {h.date}; {h.program}.\n\n"
    )
    assert p.sheet is not None
    text = sheet_markdown(p.sheet, lang, rigorous_sides(p.sheet, rigorous))
    title, rest = text.split("\n", 1)
    return plain(localized_text(f"{title}\n\n{head}{rest.lstrip()}", lang))


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


def job_files(result: JobResult, lang: str = "en", rigorous: bool = False) -> dict[str, bytes]:
    """Every file of a job, rendered in memory: per pair ``PAIR/sheet.yaml`` (and, set up,
    ``sheet.md`` and the form ``sheet.pdf``), ``forms.pdf``, ``block.csv`` and ``refused.md``.

    ``lang`` (``"ru"``/``"en"``) is the language of the forms and ``sheet.md``; ``rigorous``
    prints the rigorous (3.17) mark targets and spans on the forms as the values to set.
    """
    check_language(lang)
    files: dict[str, bytes] = {}
    forms, names = [], []
    for p in result.pairs:
        data = pair_dict(result.job, p)
        text = yaml_text(data, width=100, c_emitter=True)  # libyaml: same text (strip8, block3x6)
        files[f"{p.pair.name}/sheet.yaml"] = text.encode("utf-8")
        if p.sheet is None:
            continue
        header = form_header(result.job, p, result.spec, lang)
        files[f"{p.pair.name}/sheet.md"] = _markdown(result.job, p, lang, rigorous).encode("utf-8")
        files[f"{p.pair.name}/sheet.pdf"] = b""  # in the order of the files before
        forms.append((p.sheet, header))
        names.append(p.pair.name)
    if forms:  # each form laid out once, for its sheet.pdf and for forms.pdf
        title = f"{term('setup_data', lang)}: {result.job.name}"
        singles, files["forms.pdf"] = form_pdfs(forms, title, result.job.date, lang, rigorous)
        for name, data in zip(names, singles, strict=True):
            files[f"{name}/sheet.pdf"] = data
    files["block.csv"] = block_csv(result).encode("utf-8")
    files["refused.md"] = refused_markdown(result).encode("utf-8")
    return files


def manifest_about(result: JobResult) -> dict[str, Any]:
    """Who wrote a job's output folder: the job, its file's name, the instrument and program."""
    return {
        "job": result.job.name,
        "job_file": Path(result.job.source).name,
        "instrument": result.spec.key,
        "program": f"stereoplotter {__version__}",
    }
