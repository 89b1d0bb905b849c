"""The forms' own table layout and the per-process font memory: a form's
bytes do not depend on what the process rendered before it; a table that runs over a page
continues under its header again, the header never left alone at a page's foot; a cell's text
is broken at spaces into lines within its column."""

from __future__ import annotations

import io
import re
from pathlib import Path

import pypdf
import pytest

from stereoplotter.commands.setup_job import compute_job
from stereoplotter.io.job_file import load_job
from stereoplotter.report import form_layout
from stereoplotter.report.form_layout import Form, table
from stereoplotter.report.forms import form_pdf
from stereoplotter.report.job import form_header

JOB = Path(__file__).resolve().parents[2] / "jobs" / "strip8" / "job.yaml"


@pytest.fixture(scope="module")
def result():
    return compute_job(load_job(JOB))


def _form(result, i: int) -> bytes:
    p = result.pairs[i]
    return form_pdf(p.sheet, form_header(result.job, p, result.spec, "ru"), "ru")


def test_a_forms_bytes_do_not_depend_on_the_forms_before_it(result):
    """Pair 2's form from a process that remembers nothing equals the one rendered after pairs
    0 and 1 (the parsed fonts, their subsets and the text widths are remembered in between)."""
    form_layout.forget_layout()
    fresh = _form(result, 2)
    _form(result, 0)
    _form(result, 1)
    assert _form(result, 2) == fresh
    assert _form(result, 2) != _form(result, 1)


def _pages(data: bytes) -> list[list[str]]:
    reader = pypdf.PdfReader(io.BytesIO(data))
    return [[w for w in re.split(r"\s+", page.extract_text()) if w] for page in reader.pages]


def test_a_long_table_repeats_its_header_on_the_next_page():
    pdf = Form("2026-01-01")
    pdf.add_page()
    rows = [(f"row{i:03d}", f"value {i}") for i in range(120)]
    table(pdf, ("HeadA", "HeadB"), rows, (1, 3), size=8)
    pages = _pages(bytes(pdf.output()))
    assert len(pages) >= 2
    for words in pages:
        assert words[:2] == ["HeadA", "HeadB"]
    rows_seen = [w for words in pages for w in words if w.startswith("row")]
    assert rows_seen == [r[0] for r in rows]  # every row once, in order


def test_the_header_is_never_left_alone_at_a_pages_foot():
    """A table started so low that only its header would fit begins on the next page."""
    pdf = Form("2026-01-01")
    pdf.add_page()
    pdf.set_y(pdf.page_break_trigger - 4.0)  # room for the header row (≈ 4 mm), not for a row
    table(pdf, ("HeadA", "HeadB"), [("first", "row")], (1, 1), size=8)
    pages = _pages(bytes(pdf.output()))
    assert len(pages) == 2
    assert "HeadA" not in pages[0]
    assert pages[1][:4] == ["HeadA", "HeadB", "first", "row"]


def test_a_cells_text_is_broken_into_lines_within_its_column():
    """Each line of a wrapped cell is no wider than the column less its padding (by the font's
    advance widths), and the words come back in their order."""
    pdf = Form("2026-01-01")
    pdf.add_page()
    pdf.set_font(form_layout.FONT, "", 7.5)
    text = "O_Y3,л = MO_Y + 139.49 mm; O_Y4,л = MO_Y − 148.22 mm; O_X2,л = MO_X + 148.31 mm"
    width = 40.0
    lines = form_layout.wrap_lines(pdf, text, width, "", 7.5)
    assert len(lines) > 1
    assert " ".join(lines) == text

    def drawn(line: str) -> float:  # a subscript (after "_") at 0.72 of the size
        total = 0.0
        for k, part in enumerate(re.split(r"_([^\s=;]+)", line)):
            pdf.set_font(form_layout.FONT, "", 7.5 * (0.72 if k % 2 else 1.0))
            total += pdf.get_string_width(part)
        return total

    for line in lines:
        assert drawn(line) <= width
    first, second = lines[0], lines[1].split(" ")[0]  # the next word would not have fitted
    assert drawn(f"{first} {second}") > width
