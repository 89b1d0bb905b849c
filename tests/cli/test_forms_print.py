"""The strip8 job's forms as printed: one language per form, and page 1 as an office prints it.

The text of every page is read back from the PDF with pdfium (``pypdfium2``), character by
character with its font size, so that a subscript (a smaller run: the пр of f_пр) is a word of
its own. A Russian form holds no Latin word of two letters or more outside :data:`SYMBOLS`
(the book's formula letters and subscripts) and the job's own texts (its name, file, camera:
user text printed as written). Page 1 of every form, Russian and English: no character below
8 pt but the subscripts (0.72 of their text, lowered), no two text boxes overlapping, none
outside the page's margins, no id left at a line's end without its value; every page of two
forms the same with 7 pt for the long number table; no table split across pages; the
drawing's marks print dark on the rendered page.
"""

from __future__ import annotations

import ctypes
import re
from pathlib import Path

import numpy as np
import pypdfium2 as pdfium
import pypdfium2.raw as raw
import pytest
import yaml

from stereoplotter.cli import main
from stereoplotter.commands.setup_job import compute_job
from stereoplotter.io.job_file import load_job
from stereoplotter.report import form_layout
from stereoplotter.report.job import form_header

ROOT = Path(__file__).resolve().parents[2]
JOB = ROOT / "jobs" / "strip8" / "job.yaml"
#: Latin words a Russian form may hold: tg (the tangent), formula subscripts (O_bx, d_x …,
#: D_max, O_Zi), and the program's name.
SYMBOLS = {"tg", "max", "bx", "by", "bz", "dx", "dy", "Zi", "stereoplotter"}
#: The job's own texts, printed as written: the words of its name, its file's name and its camera.
_JOB = yaml.safe_load(JOB.read_text("utf-8"))
JOB_TEXTS = set(re.findall("[A-Za-z]+", f"{_JOB['name']} {JOB.name} {_JOB['camera']['camera']}"))
MM = 25.4 / 72.0


@pytest.fixture(scope="module")
def forms(tmp_path_factory) -> dict[str, Path]:
    out = {}
    for lang in ("ru", "en"):
        folder = tmp_path_factory.mktemp(lang)
        assert main(["setup", str(JOB), "-o", str(folder), "--lang", lang, "-q"]) == 0
        out[lang] = folder
    return out


def _chars(page) -> list[tuple[str, float, tuple[float, float, float, float]]]:
    """(character, font size pt, box l, b, r, t in pt) of a page's drawn characters."""
    text = page.get_textpage()
    out = []
    left, bottom, right, top = (pdfium_double() for _ in range(4))
    for i in range(text.count_chars()):
        if raw.FPDFText_IsGenerated(text.raw, i):
            continue
        char = chr(raw.FPDFText_GetUnicode(text.raw, i))
        raw.FPDFText_GetCharBox(text.raw, i, left, right, bottom, top)
        out.append((char, raw.FPDFText_GetFontSize(text.raw, i),
                    (left.value, bottom.value, right.value, top.value)))  # fmt: skip
    return out


def pdfium_double():
    return ctypes.c_double()


def _words(chars) -> list[str]:
    """The words of a page: runs of adjacent letters of one font size (a subscript is a word;
    two cells' texts side by side are two words)."""
    words, current, last = [], "", None
    for char, size, box in chars:
        joined = (last is not None and abs(size - last[0]) < 0.05
                  and abs(box[0] - last[1][2]) < 0.25 * size)  # fmt: skip
        if char.isalpha() and current and joined:
            current += char
        else:
            if current:
                words.append(current)
            current = char if char.isalpha() else ""
        last = (size, box)
    if current:
        words.append(current)
    return words


def _latin(word: str) -> bool:
    return len(word) >= 2 and re.fullmatch("[A-Za-z]+", word) is not None


def test_a_russian_form_holds_no_latin_word_but_the_books_symbols(forms):
    pdf = pdfium.PdfDocument(forms["ru"] / "forms.pdf")
    found: dict[str, int] = {}
    for i in range(len(pdf)):
        for word in _words(_chars(pdf[i])):
            if _latin(word) and word not in SYMBOLS | JOB_TEXTS:
                found[word] = found.get(word, 0) + 1
    assert len(pdf) >= 8 * 4
    assert found == {}
    md = (forms["ru"] / "101-102" / "sheet.md").read_text("utf-8")
    for unit in (" mm", " µm", " m ", " m,", "SW", "NE"):
        assert unit not in md, unit
    # sheet.md: no Latin word of three letters outside `code` (the instrument file's keys), a
    # control's identifier (k_alpha_left …), the job's texts, det (the determinant), YAML
    md = re.sub(r"`[^`]*`", "", md)
    md = re.sub(r"\b\w+_(left|right)\b", "", md)
    words = set(re.findall(r"(?<![A-Za-z_])[A-Za-z]{3,}(?![A-Za-z_])", md))
    assert words <= SYMBOLS | JOB_TEXTS | {"det", "YAML"}, words


def _clashes(boxes, slack: float = 0.3) -> list[tuple[int, int]]:
    """The pairs of boxes (l, b, r, t in pt) overlapping by more than ``slack`` both ways."""
    a = np.array(boxes, float).reshape(-1, 4)
    wide = np.minimum(a[:, None, 2], a[None, :, 2]) - np.maximum(a[:, None, 0], a[None, :, 0])
    tall = np.minimum(a[:, None, 3], a[None, :, 3]) - np.maximum(a[:, None, 1], a[None, :, 1])
    i, j = np.nonzero(np.triu((wide > slack) & (tall > slack), k=1))
    return list(zip(i.tolist(), j.tolist(), strict=True))


def _boxes(chars) -> list[tuple[float, float, float, float]]:
    """Each run of characters on one baseline and size (a word or a subscript) as one box."""
    boxes: list[list[float]] = []
    last = None
    for char, size, (x0, y0, x1, y1) in chars:
        if char.isspace() or x1 <= x0:
            last = None
            continue
        if last is not None and abs(last[1] - size) < 0.05 and abs(last[0] - y0) < 0.5 and (
                0 <= x0 - boxes[-1][2] < 1.0):  # fmt: skip
            box = boxes[-1]
            box[1], box[2], box[3] = min(box[1], y0), x1, max(box[3], y1)
        else:
            boxes.append([x0, y0, x1, y1])
        last = (y0, size)
    return [tuple(b) for b in boxes]


@pytest.mark.parametrize("lang", ["ru", "en"])
def test_page_one_of_every_form_is_legible_and_nothing_overlaps_or_is_clipped(forms, lang):
    for pair in sorted(p.name for p in forms[lang].iterdir() if p.is_dir()):
        pdf = pdfium.PdfDocument(forms[lang] / pair / "sheet.pdf")
        page = pdf[0]
        width, height = page.get_size()
        chars = _chars(page)
        sizes = [c[1] for c in chars if not c[0].isspace()]
        assert min(sizes) >= 0.72 * 8.0 - 0.05, pair
        for k, (char, size, box) in enumerate(chars):
            if size < 7.95 and not char.isspace():  # a subscript: smaller than its symbol
                base = next(c for c in reversed(chars[:k]) if c[1] >= 7.95)
                assert abs(size - 0.72 * base[1]) < 0.1 and box[1] < base[2][1] + 0.5 * size, (
                    pair, char, size)
        boxes = _boxes(chars)
        for box in boxes:  # inside the paper with its margins (12 mm top, 15–20 mm sides)
            assert box[0] >= 10 / MM and box[2] <= width - 10 / MM, (pair, box)
            assert box[1] >= 5 / MM and box[3] <= height - 10 / MM, (pair, box)
        assert _clashes(boxes) == [], pair
        text = page.get_textpage().get_text_range()
        assert not re.search(r"(^|\s)[\w-]+:\s*$", text, re.M), pair  # an id without its value
        assert len(pdf) <= 6 and len(_chars(pdf[len(pdf) - 1])) > 100  # no orphan last page


@pytest.mark.parametrize("lang", ["ru", "en"])
def test_every_page_keeps_its_margins_and_no_text_overlaps(forms, lang):
    """Every page of the forms of 101-102 (the largest tilts) and 104-105 (the most height
    control): text boxes inside the margins (20 mm left, 15 mm right, 10 mm top), none
    overlapping another, no character under 7 pt but a subscript (the readings of stages 1–4
    are 7 pt, everything else 7.5 pt or more)."""
    for pair in ("101-102", "104-105"):
        _every_page(pdfium.PdfDocument(forms[lang] / pair / "sheet.pdf"))


def _every_page(pdf) -> None:
    for i in range(len(pdf)):
        page = pdf[i]
        width, height = page.get_size()
        chars = _chars(page)
        boxes = _boxes(chars)
        outside = [b for b in boxes if b[0] < 20 / MM - 1 or b[2] > width - 15 / MM + 1
                   or b[3] > height - 10 / MM]  # fmt: skip
        assert outside == [] and _clashes(boxes) == [], (i + 1, outside[:2])
        sizes = {round(c[1], 2) for c in chars if not c[0].isspace()}
        assert min(s for s in sizes if s > 6.0) >= 7.0 and min(sizes) >= 0.72 * 7.0 - 0.01, (
            i + 1, sorted(sizes))


def test_the_drawing_prints_dark(forms):
    """On the drawing page rendered without smoothing (each pixel its mark's own grey), no
    drawn pixel is paler than grey 110 of 255 (a pale grey fill, such as 225, is nearly
    invisible on a copier)."""
    heading = {"ru": "Рамка трапеции", "en": "Sheet frame and control"}
    for lang in ("ru", "en"):
        pdf = pdfium.PdfDocument(forms[lang] / "101-102" / "sheet.pdf")
        page = pdf[len(pdf) - 1]
        text = page.get_textpage()
        start = text.get_text_range().find(heading[lang])
        assert start >= 0
        top = text.get_charbox(start)[3]  # pt from the page's foot: the drawing is below it
        image = page.render(scale=2, no_smoothtext=True, no_smoothpath=True).to_pil()
        below = image.convert("L").crop((0, int(2 * (page.get_height() - top)), image.width,
                                         image.height))  # fmt: skip
        counts = below.histogram()  # pixels by grey level 0–255
        assert sum(counts[110:250]) / sum(counts[:250]) < 0.01


def test_no_table_is_split_unless_longer_than_a_page(monkeypatch):
    """Every table of every strip8 form, ru and en, starts and ends on one page (a table taller
    than a page would continue on the next; none is, for strip8: the readings of stages 1–4
    are set at 7 pt), and no word is wider than its cell (none broken between letters)."""
    from stereoplotter.report import forms  # here: the name is also this module's fixture

    drawn = []
    real = form_layout.table

    def recording(pdf, *args, **kwargs):
        first = pdf.page
        height = real(pdf, *args, **kwargs)
        top = pdf.get_y() - kwargs.get("gap", 2.0) - height  # where it began, if on this page
        whole = pdf.page == first or top >= pdf.t_margin - 1e-6
        drawn.append((whole, height, pdf.page_break_trigger - pdf.t_margin))
        return height

    monkeypatch.setattr(forms, "table", recording)
    wide = set()
    wrap, width = form_layout.wrap_lines, form_layout.text_width

    def checking(pdf, text, room, style, size):
        wide.update((word, size) for line in text.split("\n") for word in line.split(" ")
                    if word and width(pdf, word, style, size) > room)  # fmt: skip
        return wrap(pdf, text, room, style, size)

    monkeypatch.setattr(form_layout, "wrap_lines", checking)
    form_layout.forget_layout()  # every cell's lines found again
    result = compute_job(load_job(JOB))
    for lang in ("ru", "en"):
        for p in result.pairs:
            forms.form_pdf(p.sheet, form_header(result.job, p, result.spec, lang), lang)
    assert len(drawn) >= 2 * 8 * 12  # a dozen tables a form
    assert [d for d in drawn if not d[0] and d[1] <= d[2]] == []  # split, though it fits a page
    assert wide == set()
