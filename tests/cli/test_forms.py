"""The setup form an operator sets the instrument from: every reading
at its least count, the gear r, the zero-reading and L′ fields with the (6.9)–(6.11) rows, stage 5,
the signatures, page 1 holding the readings, labels that do not overlap, Russian and English,
fonts embedded, the book's limits flagged."""

from __future__ import annotations

import io
import re
from dataclasses import replace
from pathlib import Path

import pypdf
import pytest

from stereoplotter.cli import main
from stereoplotter.commands.setup_job import compute_job
from stereoplotter.glossary import TERMS
from stereoplotter.io.job_file import load_job
from stereoplotter.report.form_fields import rigorous_sides, value_to_set, zero_of
from stereoplotter.report.form_layout import FONT, MARGIN_BOTTOM, Form
from stereoplotter.report.forms import form_pdf
from stereoplotter.report.job import form_header, least_counts

ROOT = Path(__file__).resolve().parents[2]
JOB = ROOT / "jobs" / "strip8" / "job.yaml"
PT = 25.4 / 72  # mm per PDF point
A4_HEIGHT_MM = 297.0


@pytest.fixture(scope="module")
def job():
    result = compute_job(load_job(JOB))
    return result, result.pairs[0]


@pytest.fixture(scope="module")
def forms(job):
    """The form of pair 101-102 in both languages, read back: (bytes, reader, flat text)."""
    result, p = job
    out = {}
    for lang in ("ru", "en"):
        data = form_pdf(p.sheet, form_header(result.job, p, result.spec, lang), lang)
        reader = pypdf.PdfReader(io.BytesIO(data))
        pages = [page.extract_text() for page in reader.pages]
        out[lang] = (data, reader, [re.sub(r"\s+", " ", t) for t in pages])
    return out


def _flat(forms, lang: str) -> str:
    return " ".join(forms[lang][2])


_RU = {"µm": "мкм", "mm": "мм", "m": "м", "MO": "МО", "NW": "СЗ", "tan": "tg"}


def _printed(text: str, lang: str) -> str:
    """A text as the form prints it: a symbol's subscript typeset (read back without its "_"),
    and in Russian the units, corners, МО and tg."""
    if lang == "ru":
        text = re.sub(r"(?<![A-Za-zА-яЁё])(µm|mm|m|MO|NW|tan)(?![A-Za-zА-яЁё])",
                      lambda m: _RU[m[1]], text)  # fmt: skip
    return re.sub(r"(?<=[^\s_])_(?=[^\s_])", "", text)


def _at(value: float, decimals: int) -> str:
    """A signed reading at the least count, by plain formatting (sign as the book prints it)."""
    text = f"{abs(value):.{decimals}f}"
    return f"{'−' if value < 0 and float(text) != 0 else '+'} {text}"


def _readings_to_set(sheet, lang: str):
    """(row, text) of every reading of stages 1–5 at the shipped least counts: 0.01 mm on the
    counters and scales, 0.1 m on the height scale."""
    decimals = {"mm": 2, "m": 1}
    sides = rigorous_sides(sheet)
    for r in sheet.readings:
        if r["reading"] == "residual q":
            continue
        name = r["reading"].replace("corner", TERMS["corner"][lang])
        value = _at(value_to_set(sheet, r, sides)[0], decimals[r["unit"]])
        yield r, _printed(f"{name} = {zero_of(r)} {value} {r['unit']}" if r["zero_reading"]
                          else f"{name} = {value[2:]} {r['unit']}", lang)  # fmt: skip


@pytest.mark.parametrize("lang", ["ru", "en"])
def test_every_reading_is_printed_at_its_least_count(forms, job, lang):
    """The counters and scales of the SC-1 read 0.01 mm, the metre height scale 0.1 m (all
    assumed in sc1.yaml); every reading of stages 1–5 appears rounded to them, and the least
    counts themselves are printed (with the * of an assumed value)."""
    result, p = job
    spec = result.spec
    flat = _flat(forms, lang)
    assert spec.xy_least_count_mm == 0.01 and spec.height_scale_least_count_m == 0.1
    for r, expected in _readings_to_set(p.sheet, lang):
        assert expected in flat, expected
        assert r["formula"] not in forms[lang][2][1], r  # no 0.001 mm to set
    assert _printed("0.01 mm *", lang) in flat and _printed("0.1 m *", lang) in flat
    assert f"{TERMS['least_count'][lang]}:" in flat


@pytest.mark.parametrize("lang", ["ru", "en"])
def test_gear_zero_readings_corrections_stage5_and_signatures(forms, job, lang):
    result, p = job
    s = p.sheet
    flat = _flat(forms, lang)
    r = s.horizontal_scale_denominator / s.map_scale_denominator  # 12500 / 10000
    gear = f"r = {r:g} (M_г = r·M_map, 1:{s.map_scale_denominator})"
    assert _printed(gear, lang).replace("map", "карты" if lang == "ru" else "map") in flat
    assert r == 1.25 and r in result.spec.coordinatograph_ratios
    for mo in ("MO_X", "MO_Y", "MO_Z", "MO_bx", "MO_by", "MO_bz", "MO_dx,л", "MO_dy,л",
               "MO_dx,п", "MO_dy,п"):  # each projector its own decentration zeros
        assert _printed(f"{mo} = ________", lang) in flat, mo
    assert _printed("MO_dx = ", lang) not in flat
    # (6.9)-(6.11): D = n_л·f_пр = D_max (6.3); the factors the operator multiplies ΔL by, with
    # the L stage 1 compares with (units at zero: L⁰ of the measured marks)
    d = result.spec.projection_distance_max_mm
    left, right = s.photos
    for expected in (
        "L′_л", "L′_п", "ΔZ = D·(L_л − L′_л)·M_в/(1000·L_л)", "Δb_z = D·(L_п − L′_п)/L_п",
        f"{d * s.vertical_scale_denominator / (1000 * left.mark_span_at_zero_mm):.4f} m/mm",
        f"{d / left.mark_span_at_zero_mm:.5f}", f"{d / right.mark_span_at_zero_mm:.5f}",
        "O′_bz = O_bz + Δb_z",
    ):  # fmt: skip
        assert _printed(expected, lang) in flat, expected
    # stage 5: every plan control and check point with its x′, y′ readings
    points = [q for q in s.points_model_mm if q["role"] == "check" or q["kind"] != "height"]
    assert {q["role"] for q in points} == {"control", "check"}
    for q in points:
        role = TERMS["check_point" if q["role"] == "check" else "plan_control"][lang]
        assert _printed(
            f"{q['id']} {role} O_X = MO_X {_at(q['x_mm'], 2)} O_Y = MO_Y {_at(q['y_mm'], 2)}",
            lang) in flat, q
    for key in ("signatures", "operator", "checker", "name", "signature", "date"):
        assert TERMS[key][lang] in flat, key


def test_russian_form_uses_the_books_terms_and_embeds_cyrillic(forms):
    _data, reader, pages = forms["ru"]
    for expected in ("Установочные данные (Таблица 24) — стереопара 101-102", "nл, nп", "fпр",
                     "горизонтальный масштаб модели", "Места нуля МО", "исполнитель",
                     "Пределы метода"):  # fmt: skip
        assert expected in " ".join(pages), expected
    assert "Setup data" not in " ".join(pages)
    assert "Setup data (Table 24) — stereopair 101-102" in forms["en"][2][0]
    assert not re.search("[А-Яа-яЁё]{4,}", re.sub(r"N-35-14-А-а-4|СЦ-1|[a-zA-Z_]+[лп]\b", "",
                                                  " ".join(forms["en"][2])))  # fmt: skip
    fonts = set()
    for page in reader.pages:
        for font in page["/Resources"]["/Font"].values():
            font = font.get_object()
            descriptor = font["/DescendantFonts"][0].get_object()["/FontDescriptor"]
            assert "/FontFile2" in descriptor, font["/BaseFont"]  # embedded TrueType subset
            fonts.add(str(font["/BaseFont"]).split("+")[-1])
    assert fonts == {"DejaVuSansBook", "DejaVuSansBold"}


def _texts(page) -> list[tuple[str, float, float, float]]:
    """(text, x mm, y mm from the top, font size pt) of every text run on a page."""
    runs = []

    def visit(text, cm, tm, font, size):
        if text.strip():
            runs.append((text.strip(), tm[4] * PT, A4_HEIGHT_MM - tm[5] * PT, size))

    page.extract_text(visitor_text=visit)
    return runs


def test_the_readings_summary_is_whole_on_one_page_and_the_page_count(forms, job):
    """The readings summary (one row per stage) is on one page, whole, after Table 24 (on
    page 1 or at the top of page 2); strip8 gives 6 pages in either language; a pair with
    three times the height control still prints every stage-3 reading."""
    result, p = job
    for lang, count in (("ru", 6), ("en", 6)):
        reader = forms[lang][1]
        assert len(reader.pages) == count
        holding = [i for i, text in enumerate(forms[lang][2])
                   if TERMS["readings_summary"][lang] in text]  # fmt: skip
        assert holding in ([0], [1])
        page = forms[lang][2][holding[0]]
        for stage in range(1, 6):
            assert TERMS[f"stage_{stage}"][lang] in page, stage
    heights = tuple(_renamed(h, "id", k) for k in range(3) for h in p.sheet.control_heights)
    stage3 = [r for r in p.sheet.readings if r["stage"] == 3]
    readings = (*(r for r in p.sheet.readings if r["stage"] < 3),
                *(_renamed(r, "reading", k) for k in range(3) for r in stage3),
                *(r for r in p.sheet.readings if r["stage"] > 3))  # fmt: skip
    sheet = replace(p.sheet, control_heights=heights, readings=readings)
    data = form_pdf(sheet, form_header(result.job, p, result.spec, "ru"), "ru")
    flat = re.sub(r"\s+", " ", " ".join(q.extract_text() for q in pypdf.PdfReader(
        io.BytesIO(data)).pages))  # fmt: skip
    assert "5 · угол 4" in flat and "OZ25c" in flat


def _renamed(row: dict, key: str, k: int) -> dict:
    """A copy of a control height or a reading row under another point id (a, b, c)."""
    return {**row, key: f"{row[key]}{'abc'[k]}"}


def _label_boxes(page) -> list[tuple[str, float, float, float, float]]:
    """The drawing's labels (8 pt, inside the drawing's 150 mm frame under its 10.5 pt heading;
    a subscript a run of its own) with their boxes in mm: advance width from the font's
    metrics, ascent 0.8 and descent 0.25 of the size."""
    widths = Form("2026-01-01")
    boxes = []
    runs = _texts(page)
    top = max((y for _, _, y, size in runs if size == 10.5), default=A4_HEIGHT_MM)
    for text, x, y, size in runs:
        if size != 8 or not top < y < top + 155 or y > A4_HEIGHT_MM - MARGIN_BOTTOM:
            continue
        widths.set_font(FONT, "", size)
        h = size * PT
        boxes.append((text, x, y - 0.8 * h, x + widths.get_string_width(text), y + 0.25 * h))
    widths.close_fonts()
    return boxes


def _overlapping(boxes) -> list[tuple]:
    out = []
    for i, a in enumerate(boxes):
        for b in boxes[i + 1 :]:
            overlap = min(a[3], b[3]) - max(a[1], b[1]), min(a[4], b[4]) - max(a[2], b[2])
            if overlap[0] > 1e-6 and overlap[1] > 1e-6:
                out.append((a, b))
    return out


def test_drawing_labels_do_not_overlap(forms):
    """The text boxes of the drawing's labels pairwise do not overlap (pair 101-102, where the
    labels of 16 and K1 ran together before)."""
    boxes = _label_boxes(forms["en"][1].pages[-1])
    assert {"11", "16", "K1", "S", "4 (NW)"} <= {b[0] for b in boxes}
    assert _overlapping(boxes) == []


def test_book_limits_warned_and_rigorous_values_on_request(forms, job):
    """Pair 101-102 (left tilts 0.87°, −0.85°): L_л by (6.5) with the book's (6.1)/(6.2) is
    33 µm shorter than with (3.17), beyond ±0.03/n_л = 17.7 µm; the form says so, and with
    rigorous=True prints n·(y⁰₃ − y⁰₄) of (3.17) as the value to set, the book's beside it."""
    result, p = job
    s = p.sheet
    left = s.photos[0]
    rig = s.n_left * (left.transformed_rigorous_mm["3"][1] - left.transformed_rigorous_mm["4"][1])
    diff = left.mark_span_mm - rig
    assert abs(diff) > s.tolerances["mark_span_mm"] == pytest.approx(0.03 / s.n_left)
    assert "ВНИМАНИЕ" in forms["ru"][2][0] and "WARNING" in forms["en"][2][0]
    assert f"Lл (6.5) {left.mark_span_mm:.3f} {rig:.3f} {diff * 1000:+.1f} µm" in _flat(
        forms, "en"
    )
    data = form_pdf(s, form_header(result.job, p, result.spec, "en"), "en", rigorous=True)
    pages = [re.sub(r"\s+", " ", q.extract_text()) for q in pypdf.PdfReader(io.BytesIO(data)).pages]
    flat = " ".join(pages)
    assert f"Lл = {rig:.2f} mm (book: {left.mark_span_mm:.2f}) 0.01 mm * (3.17)" in flat
    y3 = s.n_left * left.transformed_rigorous_mm["3"][1]
    assert f"OY3,л = MOY {_at(y3, 2)} mm (book:" in flat
    right = s.photos[1]  # within its tolerance, yet rigorous as asked
    y3 = s.n_right * right.transformed_rigorous_mm["3"][1]
    assert f"OY3,п = MOY,п {_at(y3, 2)} mm (book:" in flat
    # by default only the photo whose book values leave their tolerance: the left
    flat = _flat(forms, "en")
    assert f"Lл = {rig:.2f} mm (book: {left.mark_span_mm:.2f}) 0.01 mm * (3.17)" in flat
    assert f"Lп = {right.mark_span_mm:.2f} mm 0.01 mm * (6.5)" in flat
    assert "WARNING: for the left photo the book's" in flat
    page1 = forms["en"][2][0]  # Table 24: the span to set under the book's, the left photo's only
    assert f"to set (3.17): Lл = {rig:.3f}" in page1 and "Lп = " not in page1


def test_setup_command_writes_the_same_bytes_in_ru(forms, tmp_path, job):
    """`setup jobs/strip8/job.yaml --lang ru -o DIR` writes the form rendered above, byte for
    byte, and sheet.md in Russian."""
    assert main(["setup", str(JOB), "--lang", "ru", "-o", str(tmp_path)]) == 0
    assert (tmp_path / "101-102" / "sheet.pdf").read_bytes() == forms["ru"][0]
    for p in job[0].pairs:  # every pair's form: its readings at the least count, in Russian
        reader = pypdf.PdfReader(tmp_path / p.pair.name / "sheet.pdf")
        flat = re.sub(r"\s+", " ", " ".join(page.extract_text() for page in reader.pages))
        assert f"Установочные данные (Таблица 24) — стереопара {p.pair.name}" in flat
        for _, expected in _readings_to_set(p.sheet, "ru"):
            assert expected in flat, (p.pair.name, expected)
        assert len(reader.pages) in (5, 6)
        drawing = _label_boxes(reader.pages[-1])  # the drawing, the form's last page
        assert len(drawing) > 10 and _overlapping(drawing) == [], p.pair.name
    md = (tmp_path / "101-102" / "sheet.md").read_text("utf-8")
    assert "Установочные данные" in md and "левый снимок 101" in md
    assert least_counts(job[0].spec).scale_mm == 0.01


def test_rigorous_is_refused_outside_a_job(capsys):
    """--rigorous sets the values of a job's forms; a scenario has none: one line, exit 1."""
    assert main(["setup", "pair60", "--instrument", "sc1", "--rigorous"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--rigorous: expected a job file" in err[0]
