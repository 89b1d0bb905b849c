"""forms.pdf of a job takes each pair's pages as drawn for its sheet.pdf (each form laid out
once): the text of every page of forms.pdf, as pypdf extracts it, is the
text of the pairs' own forms page by page, only the page number in the footer counted through
the whole document; each page names its own pair in the footer; the fonts each page uses are
in its resources (text extraction decodes through them)."""

from __future__ import annotations

import io
import re
from pathlib import Path

import pypdf
import pytest

from stereoplotter.commands.setup_job import compute_job
from stereoplotter.io.job_file import load_job
from stereoplotter.report.job import job_files

JOB = Path(__file__).resolve().parents[2] / "jobs" / "strip8" / "job.yaml"


@pytest.fixture(scope="module")
def files():
    result = compute_job(load_job(JOB))
    pairs = [p.pair.name for p in result.pairs if p.accepted][:3]
    keep = type(result)(result.job, result.spec,
                        tuple(p for p in result.pairs if p.pair.name in pairs))  # fmt: skip
    return pairs, job_files(keep, "ru")


def _texts(data: bytes) -> list[str]:
    pages = pypdf.PdfReader(io.BytesIO(data)).pages
    return [re.sub(r"\s+", " ", page.extract_text()).strip() for page in pages]


def test_forms_pdf_is_the_pairs_pages_renumbered(files):
    pairs, out = files
    combined = _texts(out["forms.pdf"])
    expected = []
    for name in pairs:
        own = _texts(out[f"{name}/sheet.pdf"])
        for number, text in enumerate(own, 1):
            assert text.endswith(f"стр. {number}")  # the pair's own form counts from 1
            assert f"пара {name} " in text.rsplit("strip8 ·", 1)[1]  # its footer names the pair
            expected.append(text.removesuffix(f"стр. {number}"))
    assert len(combined) == len(expected) > 3 * 4
    for number, (text, own) in enumerate(zip(combined, expected, strict=True), 1):
        assert text == f"{own}стр. {number}"
