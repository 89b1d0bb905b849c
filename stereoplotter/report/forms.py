"""The printable setup form an operator sets the instrument from, as a PDF, in Russian or English.

One form per stereopair, A4 portrait (document and drawing primitives:
:mod:`stereoplotter.report.form_layout`; the text of the rows:
:mod:`stereoplotter.report.form_fields`; every label from :mod:`stereoplotter.glossary`). The
output is byte-identical for the same sheet, header and language.

Parts, in order, each table whole on a page with its heading (a table longer than a page
continues under its header), body 8 pt, tables 7.5 pt (the readings of stages 1–4: 7 pt), the
book's symbols with their subscripts typeset and the job's own texts printed as written: (1) the
header, Table 24 with the coordinatograph gear r, which values are given to set (the warning
and the note agree with the tables: a photo's marks and span by the book where all of them are
within their stage tolerance, else by the rigorous (3.17), the book's beside them,
:func:`~stereoplotter.report.form_fields.rigorous_sides`), and every reading to set at its
least count, one row per stage; (2) the working sheet: the zero readings MO to write in (the
decentration zeros per projector), every reading of stages 1–4 with its least count, tolerance
and a column to write in, the (6.9)–(6.11) corrections from the measured L′ (factor, formula,
field), stage 5 on corner 4, the plan control and the check points, the signatures; (3) the
method's limits (book against rigorous (3.17) on the counters), angles, settings, height
control, sheet corners, similarity (6.8), distortion, tolerances; (4) the sheet frame and the
control points in instrument coordinates, drawn black, labels placed so that none overlaps
another.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

from stereoplotter.glossary import check_language, instrument_name, parameter_name, term
from stereoplotter.report.form_fields import (
    LeastCounts,
    correction_rows,
    limit_rows,
    reading_rows,
    rigorous_sides,
    signature_rows,
    stage5_rows,
    summary_rows,
    value_to_set,
    zero_reading_names,
)
from stereoplotter.report.form_layout import (
    FONT,
    Form,
    LabelPlacer,
    fits,
    heading,
    literal,
    paragraph,
    table,
    table_height,
)
from stereoplotter.report.sheet import instrument_settings
from stereoplotter.setup.records import SetupSheet

__all__ = ["FormHeader", "LeastCounts", "form_pdf", "form_pdfs"]

#: Type sizes (pt): running text, notes and the tables of words (the header, Table 24, the
#: readings summary), the number tables, the headings. The body is at least 8 pt and the
#: number tables 7.5 pt (a form of the period: a typewritten or typeset
#: instruction, read at arm's length at the instrument); subscripts are 0.72 of their text.
_BODY, _TABLE, _HEAD = 8.0, 7.5, 10.5
#: The long number table of the working sheet (every reading of stages 1–4): 7 pt, so that it
#: is whole on one page for strip8 (40 rows).
_NUMBERS = 7.0
#: A non-breaking space: an id and its value, a corner and its reading are never split.
_NB = "\u00a0"


@dataclass(frozen=True, slots=True)
class FormHeader:
    """What the header of a form prints besides the sheet itself.

    ``date`` is YYYY-MM-DD from the job file (also the PDF's creation date); ``frame`` says in
    which photogrammetric system the pair was computed; ``least_counts`` come from the
    instrument spec.
    """

    job: str
    job_file: str
    pair: str
    left_photo: str
    right_photo: str
    map_sheet: str
    date: str
    program: str
    camera: str
    frame: str
    distortion: tuple[tuple[float, float], ...] = ()
    least_counts: LeastCounts = field(default_factory=LeastCounts)


def _f(value: float | None, digits: int = 3) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "—"
    if abs(value) < 0.5 * 10.0**-digits:
        value = 0.0
    return f"{value:.{digits}f}"


def _flag(sheet: SetupSheet, key: str) -> str:
    return " *" if sheet.assumed.get(key) else ""


def _gear_text(sheet: SetupSheet, lang: str) -> str:
    """M_г = r·M_map with the gear r = M_г/M_map of the coordinatograph (the YAML's ratio)."""
    m_map = sheet.map_scale_denominator
    if m_map is None:
        return term("no_gear", lang)
    r = sheet.horizontal_scale_denominator / m_map
    return f"{term('gear_ratio', lang)} r = {r:g} (M_г = r·M_map, 1:{m_map})"


def _instrument_text(sheet: SetupSheet, lang: str) -> str:
    name = instrument_name(sheet.instrument, sheet.instrument_title, lang)
    return name if lang == "ru" else f"{name} ({sheet.instrument})"


def _rigorous_marks(
    sheet: SetupSheet, side: int, keys: tuple[str, ...], sides: tuple[str, ...], lang: str
) -> str:
    """The rigorous (3.17) marks beside the book's in Table 24, for a photo whose marks the
    form gives to set from (3.17) (:func:`rigorous_sides`)."""
    photo = sheet.photos[side]
    if photo.name not in sides:
        return ""
    rig = photo.transformed_rigorous_mm
    values = ", ".join(_f(rig[k[1:]][0 if k[0] == "x" else 1]) for k in keys)
    return f"\n{term('to_set', lang)} (3.17): {values}"


def _rigorous_spans(sheet: SetupSheet, sides: tuple[str, ...], lang: str) -> str:
    """The rigorous (3.17) spans of the photos of ``sides`` beside the book's (6.5)."""
    spans = []
    for p, mark in zip(sheet.photos, ("л", "п"), strict=True):
        if p.name in sides:
            value = value_to_set(sheet, {"reading": f"L_{mark}", "value": 0.0}, sides)[0]
            spans.append(f"L_{mark}{_NB}={_NB}{_f(value)}")
    return f"\n{term('to_set', lang)} (3.17): {', '.join(spans)}" if spans else ""


def _table24_rows(
    sheet: SetupSheet, lang: str, rigorous: bool = False
) -> list[tuple[str, ...]]:
    left, right = sheet.photos
    sides = rigorous_sides(sheet, rigorous)
    t = lambda key: term(key, lang)  # noqa: E731 - a local shorthand for the many labels
    item = t("item1")
    rows: list[tuple[str, ...]] = [
        ("1", t("scale_horizontal"), "M_г", f"1:{sheet.horizontal_scale_denominator}"
         + _flag(sheet, "scale_horizontal") + "\n" + _gear_text(sheet, lang), "—", item,
         t("note_mg")),
        ("2", t("scale_vertical"), "M_в", f"1:{sheet.vertical_scale_denominator}"
         + _flag(sheet, "scale_vertical"), "—", item, t("note_mv")),
        ("3", t("transformation_coefficient"), "k", _f(sheet.transformation_coefficient, 5), "—",
         item, t("note_k")),
        ("4", t("focal_corrected"), "f′", _f(sheet.focal_length_corrected_mm, 4), "mm",
         "f·l′/l", t("note_f1")),
        ("5", t("f_instrument"), "f_пр", _f(sheet.f_instrument_mm)
         + _flag(sheet, "f_instrument_mm"), "mm", item, t("note_fpr")),
        ("6", t("base_components"), "b_x, b_y, b_z′",
         ", ".join(_f(v) for v in sheet.base_mm) + _flag(sheet, "base_mm"), "mm", item,
         t("note_b")),
        ("7", t("counter_coefficients"), "n_л, n_п", f"{sheet.n_left:.5f}, {sheet.n_right:.5f}"
         + _flag(sheet, "n_left"), "—", "(6.3), (6.4)", t("note_n")),
        ("8", t("marks_left"), "(x⁰₂)_л, (y⁰₃)_л, (y⁰₄)_л",
         ", ".join(_f(left.transformed_book_mm[k]) for k in ("x2", "y3", "y4"))
         + _rigorous_marks(sheet, 0, ("x2", "y3", "y4"), sides, lang), "mm",
         "(6.1)/(6.2)", t("note_marks")),
        ("9", t("marks_right"), "(x⁰₁)_п, (y⁰₃)_п, (y⁰₄)_п",
         ", ".join(_f(right.transformed_book_mm[k]) for k in ("x1", "y3", "y4"))
         + _rigorous_marks(sheet, 1, ("x1", "y3", "y4"), sides, lang), "mm",
         "(6.1)/(6.2)", t("note_marks")),
        ("10", t("mark_spans"), "L_л, L_п",
         f"{_f(left.mark_span_mm)}, {_f(right.mark_span_mm)}" + _flag(sheet, "L_mm")
         + _rigorous_spans(sheet, sides, lang), "mm", "(6.5)", t("note_L")),
        ("11", t("decentrations"), "d_x, d_y",
         "; ".join(f"{_f(p.decentration_mm[0])}, {_f(p.decentration_mm[1])}" for p in sheet.photos),
         "mm", "f′·tan α, f′·tan ω", t("note_d")),
    ]  # fmt: skip
    if sheet.control_heights:
        values = [f"{literal(h['id'])}:{_NB}{_f(h['model_height_mm'])}"
                  for h in sheet.control_heights]
        text = "\n".join("; ".join(values[i : i + 3]) for i in range(0, len(values), 3))
        rows.append(("12", t("model_heights"), "Z_i", text
                     + _flag(sheet, "control_heights_model_mm"), "mm", "(6.6)", t("note_Z")))
    if sheet.corners:
        values = [f"{c['corner']}:{_NB}{_f(c['x_mm'])},{_NB}{_f(c['y_mm'])}"
                  for c in sheet.corners]
        text = "\n".join("; ".join(values[i : i + 2]) for i in range(0, len(values), 2))
        rows.append(("13", t("sheet_corners"), "x′_i, y′_i", text
                     + _flag(sheet, "sheet_corners_mm"), "mm", "(6.7)", t("note_corner")))
    return rows


def _header_rows(sheet: SetupSheet, h: FormHeader, lang: str) -> list[tuple[str, str]]:
    t = lambda key: term(key, lang)  # noqa: E731 - a local shorthand for the many labels
    named = parameter_name if lang == "ru" else lambda key, _: literal(key)  # keys as written
    assumed = sorted({named(p, lang) for ps in sheet.assumed.values() for p in ps})
    theta = math.degrees(sheet.frame_rotation)
    return [
        (f"{t('job')}, {t('pair')}", f"{literal(h.job)} ({literal(h.job_file)}) · {t('pair')} "
         f"{literal(h.pair)}: {t('left_photo')} {literal(h.left_photo)}, {t('right_photo')} "
         f"{literal(h.right_photo)} · {t('date')} {h.date} ({t('from_job_file')}) · "
         f"{literal(h.program)}"),
        (f"{t('map_sheet')}, {t('instrument')}", f"{literal(h.map_sheet)} · "
         f"{_instrument_text(sheet, lang)}"),
        (t("camera"), h.camera),
        (t("frame"), f"{h.frame}; {t('base_direction')} = {theta:.4f}°"),
        (t("assumed"), t("assumed_note") + ": " + (", ".join(assumed) if assumed else t("none"))),
    ]  # fmt: skip


def _least_count_line(h: FormHeader, lang: str) -> str:
    lc = h.least_counts
    star = lambda k: " *" if k in lc.assumed else ""  # noqa: E731 - a local shorthand
    return (f"{term('least_count', lang)}: {term('counters', lang)} X,{_NB}Y {lc.counter_mm:g} mm"
            f"{star('counter_mm')}; {term('abs_height_counter', lang)} {lc.z_mm:g} mm"
            f"{star('z_mm')}; {term('height_scale', lang)} {lc.height_m:g} m{star('height_m')}; "
            f"{term('scales', lang)} f_пр, b, d {lc.scale_mm:g} mm{star('scale_mm')}")  # fmt: skip


def _page_summary(pdf: Form, sheet: SetupSheet, h: FormHeader, lang: str, rigorous: bool) -> None:
    """Page 1: header, Table 24, which values are to be set, the readings, one row per stage."""
    heading(pdf, f"{term('setup_data', lang)} ({term('table24', lang)}) — "
                 f"{term('stereopair', lang)} {literal(h.pair)}", _HEAD + 1.5)  # fmt: skip
    table(pdf, ("", ""), _header_rows(sheet, h, lang), (26, 149), size=_BODY, gap=1.0)
    table(
        pdf,
        (term("no", lang), term("quantity", lang), term("symbol", lang),
         term("value", lang), term("unit", lang), term("equation", lang), term("notes", lang)),
        _table24_rows(sheet, lang, rigorous), (7, 33, 21, 48, 8, 17, 41), size=_BODY, gap=1.0,
    )  # fmt: skip
    _choice(pdf, sheet, lang, rigorous)
    rows = summary_rows(sheet, h.least_counts, lang, rigorous)
    heading(pdf, term("readings_summary", lang), _HEAD,
            keep=table_height(pdf, ("", ""), rows, (26, 149), _BODY) + 10)  # fmt: skip
    paragraph(pdf, _least_count_line(h, lang), _BODY)
    table(pdf, (term("stage", lang), ""), rows, (26, 149), size=_BODY, gap=1.0)


def _choice(pdf: Form, sheet: SetupSheet, lang: str, rigorous: bool) -> None:
    """Which values the tables give to set: the warning (red) where a book value leaves its
    tolerance, and the line saying what the tables hold — both say what the tables do."""
    sides = rigorous_sides(sheet, rigorous)
    if sides and not rigorous:
        pdf.set_text_color(170, 0, 0)
        named = ", ".join(term("photo_" + s, lang) for s in sides)
        paragraph(pdf, term("limit_warning", lang).format(photos=named), _BODY + 0.5)
        pdf.set_text_color(0)
    key = "limit_choice_rigorous" if rigorous else ("limit_choice_mixed" if sides
                                                     else "limit_choice_book")  # fmt: skip
    paragraph(pdf, term(key, lang), _BODY)


def _page_readings(pdf: Form, sheet: SetupSheet, h: FormHeader, lang: str, rigorous: bool) -> None:
    """Zero readings, readings of stages 1–4, corrections, stage 5, signatures (each table
    whole on a page, its heading with it)."""
    t = lambda key: term(key, lang)  # noqa: E731 - a local shorthand for the many labels
    lc = h.least_counts
    names = zero_reading_names(sheet)
    cells = [f"{n}{_NB}={_NB}________" for n in names]
    zero_rows = [tuple(cells[i : i + 4] + [""] * (4 - len(cells[i : i + 4])))
                 for i in range(0, len(cells), 4)]  # fmt: skip
    heading(pdf, t("zero_readings"), _HEAD, keep=len(zero_rows) * 6.0)
    table(pdf, ("",) * 4, zero_rows, (1, 1, 1, 1), size=_BODY, gap=0.5)
    paragraph(pdf, t("zero_readings_right"), _BODY)
    pdf.ln(2)
    rows = reading_rows(sheet, lc, lang, rigorous)
    widths = (6, 56, 44, 16, 15, 23, 15)
    header = (t("stage_short"), t("step"), t("reading"), t("least_count"), t("equation"),
              t("tolerance"), t("set"))  # fmt: skip
    height = table_height(pdf, header, rows, widths, _NUMBERS)
    page = pdf.page_break_trigger - pdf.t_margin - 8.0
    heading(pdf, t("readings"), _HEAD, keep=height if height <= page else 60.0)
    table(pdf, header, rows, widths, size=_NUMBERS, gap=0.5)
    paragraph(pdf, t("readings_intro"), _BODY)
    pdf.ln(1.5)
    rows = correction_rows(sheet, lang)
    widths, header = (12, 45, 58, 22, 38), (t("symbol"), t("quantity"), t("formula"),
                                            t("factor"), t("result"))  # fmt: skip
    heading(pdf, t("corrections"), _HEAD, keep=table_height(pdf, header, rows, widths, _TABLE))
    table(pdf, header, rows, widths, size=_TABLE)
    rows = stage5_rows(sheet, lc, lang)
    widths = (14, 24, 35, 35, 17, 25, 25)
    header = (t("point"), t("role"), "x′", "y′", t("tolerance"), f"{t('read')} X",
              f"{t('read')} Y")  # fmt: skip
    heading(pdf, t("stage5"), _HEAD, keep=table_height(pdf, header, rows, widths, _TABLE))
    table(pdf, header, rows, widths, size=_TABLE)
    heading(pdf, t("signatures"), _HEAD, keep=25.0)
    pdf.ln(2)
    table(pdf, ("", t("name"), t("signature"), t("date")), signature_rows(lang),
          (25, 60, 50, 40), size=9, aligns=("LEFT",) * 4)  # fmt: skip


def _page_details(pdf: Form, sheet: SetupSheet, h: FormHeader, lang: str) -> None:
    _details_limits(pdf, sheet, lang)
    _details_orientation(pdf, sheet, lang)
    _details_control(pdf, sheet, h, lang)


def _section(
    pdf: Form,
    title: str,
    header: Sequence[str],
    rows: Sequence[Sequence[str]],
    widths: Sequence[float],
    size: float = _TABLE,
) -> None:
    """A heading and its table, kept together on one page (the table whole when it fits)."""
    heading(pdf, title, _HEAD, keep=table_height(pdf, header, rows, widths, size))
    table(pdf, header, rows, widths, size=size)


def _details_limits(pdf: Form, sheet: SetupSheet, lang: str) -> None:
    """Book against rigorous on the counters (× n), with the stage tolerance."""
    t = lambda key: term(key, lang)  # noqa: E731 - a local shorthand for the many labels
    rows = [
        (r["reading"], r["equation"], f"{r['book']:.3f}", f"{r['rigorous']:.3f}",
         f"{r['difference'] * 1000:+.1f} µm", f"± {r['tolerance'] * 1000:.1f} µm",
         t("limit_exceeds") if r["exceeds"] else t("limit_within"))
        for r in limit_rows(sheet)
    ]  # fmt: skip
    _section(pdf, t("limits"), (t("reading"), t("equation"), f"{t('limit_book')} mm",
                                f"{t('limit_rigorous')} (3.17) mm", t("limit_difference"),
                                t("tolerance"), ""),
             rows, (22, 22, 26, 30, 26, 24, 25))  # fmt: skip
    rows = []
    for p in sheet.photos:
        for key, value in p.transformed_book_mm.items():
            rig = p.transformed_rigorous_mm[key[1:]]
            axis = 0 if key[0] == "x" else 1
            measured = p.marks_measured_mm[key[1:]]
            rows.append((t(p.name), key, f"{measured[0]:.3f}, {measured[1]:.3f}", f"{value:.4f}",
                         f"{rig[0]:.4f}, {rig[1]:.4f}", f"{(value - rig[axis]) * 1000:+.2f}"))
    _section(pdf, t("details_marks"), (t("photo"), t("mark"), "x, y mm", "(6.1)/(6.2) mm",
                                       "(3.17) x⁰, y⁰ mm", "µm"),
             rows, (18, 14, 38, 30, 44, 36))  # fmt: skip


def _details_orientation(pdf: Form, sheet: SetupSheet, lang: str) -> None:
    """Angles, decentrations and correction planes; the instrument's settings."""
    rows = [
        (term(p.name, lang), f"{math.degrees(p.alpha):.5f}", f"{math.degrees(p.omega):.5f}",
         f"{math.degrees(p.kappa):.5f}", f"{_f(p.decentration_mm[0])}, {_f(p.decentration_mm[1])}",
         ", ".join(f"{math.degrees(v):.4f}" for v in p.correction_inclination))
        for p in sheet.photos
    ]  # fmt: skip
    _section(pdf, "α, ω, κ; d_x, d_y; θ_α, θ_ω", ("", "α °", "ω °", "κ °", "d_x, d_y mm",
                                                  "θ_α, θ_ω °"),
             rows, (18, 24, 24, 24, 45, 45))  # fmt: skip
    settings = instrument_settings(sheet.table24, 0) if sheet.table24 is not None else None
    if settings is not None:
        rows = [
            (st["symbol"], st["formula"],
             *(f"{st[side]:.4f}" if st["unit"] == "deg" else _f(st[side])
               for side in ("left", "right")), "°" if st["unit"] == "deg" else "mm")
            for st in settings["settings"]
        ]  # fmt: skip
        table(pdf, ("", "", term("side_left", lang), term("side_right", lang), ""), rows,
              (20, 60, 35, 35, 20), size=_TABLE)  # fmt: skip


def _details_control(pdf: Form, sheet: SetupSheet, h: FormHeader, lang: str) -> None:
    """Height control, sheet corners, the similarity, the distortion, the tolerances."""
    rows = [(literal(h_["id"]), f"{h_['Z_m']:.2f}", f"{h_['flying_height_m']:.2f}",
             f"{h_['model_height_mm']:.3f}") for h_ in sheet.control_heights]  # fmt: skip
    _section(pdf, "Z_i (6.6)", ("", "Z m", "H_Ф = Z_Sл − Z m", "Z_i mm"), rows,
             (30, 50, 50, 50))  # fmt: skip
    if sheet.corners:
        rows = [(c["corner"], c["position"], f"{c['gk_north_m']:.2f}", f"{c['gk_east_m']:.2f}",
                 _f(c["x_mm"]), _f(c["y_mm"])) for c in sheet.corners]  # fmt: skip
        _section(pdf, f"(6.7) {literal(h.map_sheet)}", ("", "", "x m", "ȳ m", "x′ mm", "y′ mm"),
                 rows, (18, 20, 38, 38, 33, 33))  # fmt: skip
    tail: list[tuple[str, Sequence[str], Sequence[tuple[str, ...]], Sequence[float]]] = []
    if h.distortion:
        tail.append(("", ("r mm", *(f"{r:g}" for r, _ in h.distortion)),
                     [("Δr µm", *(f"{d:g}" for _, d in h.distortion))],
                     (20, *([160 / len(h.distortion)] * len(h.distortion)))))  # fmt: skip
    tol = sheet.tolerances
    texts = []
    if sheet.similarity is not None:
        fit = sheet.similarity
        res = ", ".join(f"{literal(pid)}:{_NB}({r[0]:+.3f},{_NB}{r[1]:+.3f})"
                        for pid, r in zip(sheet.similarity_point_ids, fit.residuals_m, strict=True))
        texts.append(f"(6.8) Gauss–Krüger → X, Y ({len(fit.residuals_m)}): a = {fit.a:.6e}, "
                     f"b = {fit.b:.9f}, c_X = {fit.cx_m:.3f} m, c_Y = {fit.cy_m:.3f} m, RMS "
                     f"{fit.rms_m:.3f} m; {res} m.")  # fmt: skip
    texts.append(f"{term('tolerances', lang).capitalize()}: |L − L′| ≤ "
                 f"{tol['mark_span_mm']:.4f} mm; O_Y4 ≤ {tol['mark_fit_mm']:.4f} mm; "
                 f"q ≤ {tol['residual_y_parallax_mm']:.4f} mm; O_Zi ≤ "
                 f"{tol['control_height_m']:.3f} m; {term('corner', lang)} 4 ≤ "
                 f"{tol['corner_mm']:.2f} mm" + _flag(sheet, "tolerances") + ".")  # fmt: skip
    need = sum(table_height(pdf, hd, rw, wd, _TABLE) + 2 for _, hd, rw, wd in tail)
    need += sum(8.0 * (1 + len(tx) // 150) for tx in texts)
    if not fits(pdf, need):
        pdf.add_page()
    for _, header, rows_, widths in tail:
        table(pdf, header, rows_, widths, size=_TABLE)
    for text in texts:
        paragraph(pdf, text, _BODY)
        pdf.ln(1)


def _page_drawing(pdf: Form, sheet: SetupSheet, lang: str) -> None:
    """The sheet frame and the points, drawn black on white (every mark prints: the frame of
    the box dark grey, the symbols filled black), on a page of its own when it does not fit."""
    if not fits(pdf, 150.0 + 30.0):
        pdf.add_page()
    heading(pdf, term("drawing", lang), _HEAD)
    xs = [c["x_mm"] for c in sheet.corners] + [p["x_mm"] for p in sheet.points_model_mm]
    ys = [c["y_mm"] for c in sheet.corners] + [p["y_mm"] for p in sheet.points_model_mm]
    xs += [0.0, sheet.base_mm[0]]
    ys += [0.0, sheet.base_mm[1]]
    box_w, box_h = pdf.epw, 150.0
    x0, y0 = pdf.l_margin, pdf.get_y() + 4
    span = max(max(xs) - min(xs), max(ys) - min(ys), 1.0)
    scale = min(box_w / (max(xs) - min(xs) + 0.15 * span),
                box_h / (max(ys) - min(ys) + 0.15 * span))  # fmt: skip
    cx, cy = (max(xs) + min(xs)) / 2, (max(ys) + min(ys)) / 2

    def at(x: float, y: float) -> tuple[float, float]:  # model mm → page mm, y up
        return x0 + box_w / 2 + (x - cx) * scale, y0 + box_h / 2 - (y - cy) * scale

    pdf.set_draw_color(90)
    pdf.set_line_width(0.25)
    pdf.rect(x0, y0, box_w, box_h)
    pdf.set_draw_color(0)
    pdf.set_fill_color(0)
    pdf.set_font(FONT, "", _BODY)
    labels = LabelPlacer(pdf, (x0 + 0.5, y0 + 0.5, x0 + box_w - 0.5, y0 + box_h - 0.5))
    points = [(at(p["x_mm"], p["y_mm"]), p) for p in sheet.points_model_mm]
    for (px, py), _ in points:  # every symbol is kept free of labels before any label is placed
        labels.reserve((px - 1.5, py - 1.6, px + 1.5, py + 1.1))
    bx, by = x0 + 4, y0 + box_h - 4
    labels.text(bx, by - 1.5, f"{term('scale_bar', lang)} (1:{sheet.horizontal_scale_denominator})")
    for label, (x, y) in (("S_л", (0.0, 0.0)), ("S_п", (sheet.base_mm[0], sheet.base_mm[1]))):
        px, py = at(x, y)
        pdf.line(px - 2, py, px + 2, py)
        pdf.line(px, py - 2, px, py + 2)
        labels.reserve((px - 2, py - 2, px + 2, py + 2))
        labels.label(px, py, label)
    if sheet.corners:
        order = sorted(sheet.corners, key=lambda c: c["corner"])
        pts = [at(c["x_mm"], c["y_mm"]) for c in order]
        pdf.set_line_width(0.5)
        pdf.polygon(pts)
        for c, (px, py) in zip(order, pts, strict=True):
            labels.label(px, py, f"{c['corner']} ({c['position']})")
    pdf.set_line_width(0.25)
    for (px, py), p in points:
        if p["role"] == "check":
            pdf.circle(px, py, 1.2, style="D")
        elif p["kind"] == "height":
            pdf.circle(px, py, 1.2, style="DF")
        else:
            pdf.polygon([(px, py - 1.5), (px - 1.3, py + 0.9), (px + 1.3, py + 0.9)], style="DF")
        labels.label(px, py, literal(p["id"]))
    pdf.set_line_width(0.4)
    pdf.line(bx, by, bx + 50 * scale, by)
    pdf.set_y(y0 + box_h + 3)
    paragraph(pdf, term("legend", lang) + f" θ = {math.degrees(sheet.frame_rotation):.4f}°.", _BODY)


def _form_document(sheet: SetupSheet, header: FormHeader, lang: str, rigorous: bool) -> Form:
    """The form of one pair laid out (not yet output): the parts in order, each table whole
    on a page with its heading (a table longer than a page continues under its header), the
    drawing on a page of its own when it does not fit after the details."""
    pdf = Form(header.date, term("page", lang), lang)
    pdf.set_title(f"{term('setup_data', lang)} {header.job} {header.pair}")
    short = instrument_name(sheet.instrument, sheet.instrument, lang).split(" ")[-1]
    pdf.footer_text = (
        f"{literal(header.job)} · {term('pair', lang)} {literal(header.pair)} "
        f"({literal(header.left_photo)}, {literal(header.right_photo)}) · "
        f"{short if lang == 'ru' else sheet.instrument} · {header.date} · {literal(header.program)}"
    )
    pdf.add_page()
    _page_summary(pdf, sheet, header, lang, rigorous)
    if pdf.page_no() == 1:  # page 1 is the summary; the working sheet starts a page
        pdf.add_page()
    else:
        pdf.ln(3)
    _page_readings(pdf, sheet, header, lang, rigorous)
    pdf.ln(3)
    _page_details(pdf, sheet, header, lang)
    _page_drawing(pdf, sheet, lang)
    return pdf


def form_pdf(
    sheet: SetupSheet, header: FormHeader, lang: str = "en", rigorous: bool = False
) -> bytes:
    """The form of one pair as PDF bytes (the same inputs give the same bytes).

    ``lang``: ``"ru"`` or ``"en"``; ``rigorous``: print the rigorous (3.17) mark targets and
    spans as the values to set for both photos (by default only for a photo whose book values
    leave their tolerance, :func:`~stereoplotter.report.form_fields.rigorous_sides`), the
    book's beside them.
    """
    check_language(lang)
    return bytes(_form_document(sheet, header, lang, rigorous).output())


def form_pdfs(
    forms: Sequence[tuple[SetupSheet, FormHeader]],
    title: str,
    date: str,
    lang: str = "en",
    rigorous: bool = False,
) -> tuple[list[bytes], bytes]:
    """The form of each pair (:func:`form_pdf`) and all of them in one PDF (the combined
    print of a block), each form laid out once: the combined document takes each form's pages
    as drawn (:meth:`Form.append_pages`: the text re-encoded to its font subsets, the footers
    numbered in it)."""
    check_language(lang)
    combined = Form(date, term("page", lang))
    combined.set_title(title)
    singles = []
    for sheet, header in forms:
        pdf = _form_document(sheet, header, lang, rigorous)
        singles.append(bytes(pdf.output()))
        combined.append_pages(pdf)
    return singles, bytes(combined.output())
