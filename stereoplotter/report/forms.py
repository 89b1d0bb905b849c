"""The printable setup form: Table 24 with notes, every stage reading and a drawing, as a PDF.

One form per stereopair, A4 portrait, written with fpdf2 (a document library: real text that can
be searched and extracted, tables that break across pages, vector drawing, embedded TrueType
fonts). The Cyrillic and Greek symbols of the book need a Unicode font: DejaVu Sans, the font that
ships inside matplotlib (``mpl-data/fonts/ttf``), so no system font is read. The output is
byte-identical for the same sheet and header: the creation date is the job's date, never the
clock, and no producer version is written.

Pages: (1) the header and Table 24 in the book's layout with a notes column (what each value is
for and at which stage it is set) and, below it, every stage reading (6.9)–(6.18) in one row per
stage; (2) the transformed marks, decentrations, Z_i of the height
control, the sheet corners, the similarity (6.8) and the certificate's distortion; (3) the
readings of stages 1–5, Eqs. (6.9)–(6.18); (4) the sheet frame and the control points in
instrument coordinates.
"""

from __future__ import annotations

import datetime as _dt
import importlib.util
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fpdf import FPDF
from fpdf.enums import XPos, YPos
from fpdf.fonts import FontFace

from stereoplotter.report.sheet import instrument_settings
from stereoplotter.setup.records import SetupSheet

__all__ = ["FormHeader", "form_pdf", "forms_pdf"]

_FONT = "DejaVu"
_MARGIN_LEFT, _MARGIN_RIGHT, _MARGIN_TOP, _MARGIN_BOTTOM = 20.0, 15.0, 15.0, 18.0


@dataclass(frozen=True, slots=True)
class FormHeader:
    """What the header of a form prints besides the sheet itself.

    ``date`` is YYYY-MM-DD from the job file (also the PDF's creation date); ``frame`` says in
    which photogrammetric system the pair was computed; ``assumed`` is filled from the sheet.
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


def _font_path(style: str = "") -> str:
    """The DejaVu font file matplotlib ships, found without importing matplotlib (its package
    folder from the import system's spec: only ``plotting`` imports matplotlib)."""
    name = {"": "DejaVuSans.ttf", "B": "DejaVuSans-Bold.ttf"}[style]
    spec = importlib.util.find_spec("matplotlib")
    if spec is None or not spec.submodule_search_locations:  # pragma: no cover - a dependency
        raise RuntimeError("matplotlib (a dependency) is not installed: no DejaVu font")
    folder = Path(next(iter(spec.submodule_search_locations)))
    return str(folder / "mpl-data" / "fonts" / "ttf" / name)


class _Form(FPDF):
    """A4 portrait with the margins, fonts and the running footer of the forms."""

    def __init__(self, date: str) -> None:
        super().__init__(orientation="P", unit="mm", format="A4")
        self.add_font(_FONT, "", _font_path(""))
        self.add_font(_FONT, "B", _font_path("B"))
        self.set_margins(_MARGIN_LEFT, _MARGIN_TOP, _MARGIN_RIGHT)
        self.set_auto_page_break(True, _MARGIN_BOTTOM)
        day = _dt.datetime.strptime(date, "%Y-%m-%d").replace(tzinfo=_dt.UTC)
        self.set_creation_date(day)
        self.set_producer("stereoplotter")
        self.set_creator("stereoplotter")
        self.footer_text = ""

    def footer(self) -> None:
        self.set_y(-_MARGIN_BOTTOM + 5)
        self.set_font(_FONT, "", 7)
        self.set_text_color(90)
        self.cell(0, 4, self.footer_text, align="L")
        self.set_x(self.l_margin)
        self.cell(0, 4, f"page {self.page_no()}", align="R")
        self.set_text_color(0)


# --- what the rows say -------------------------------------------------------------------------

#: Notes of the Table 24 rows: what the value is for and at which stage it is set.
NOTES = {
    "M_г": "horizontal model scale r·M_map: set the coordinatograph gear r before stage 1",
    "M_в": "vertical model scale: set the height-counter gears before stage 1; stage 3 reads at it",
    "k": "f_пр/f′ = M_г/M_в, the height exaggeration; tilts the correction planes (stage 2)",
    "f′": "f corrected for film deformation from the measured fiducial distances; "
    "enters (6.1)/(6.2)",
    "f_пр": "principal distance set on both projectors, stage 1",
    "b": "base carriage: b_x, b_y set in stage 1; b_z′ recorded in stage 1 (MO_bz), set in "
    "stage 2 (6.14)",
    "n": "n_л = D_max/f_пр: carriage lowered to D_max in stage 1; n_п scales the right "
    "photo's spans and targets",
    "marks_left": "targets of k_ω (mark 3, check on 4) and k_α (mark 2), stage 2, (6.12)/(6.13)",
    "marks_right": "targets of k_ω (mark 3, check on 4) and k_α (mark 1), stage 2, (6.12)/(6.13)",
    "L": "span of marks 3–4 checked in stage 1; corrected with ΔZ (6.9) and Δb_z (6.10), (6.11)",
    "d": "set on the decentration scales in stage 2",
    "Z": "model height over the height control point: stage 3 readings O_Zi (6.15)",
    "corner": "stage 4 (corners 1–3, (6.16)/(6.17)); corner 4 checks in stage 5 (6.18)",
}


def _f(value: float | None, digits: int = 3) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "—"
    if abs(value) < 0.5 * 10.0**-digits:
        value = 0.0
    return f"{value:.{digits}f}"


def _flag(sheet: SetupSheet, key: str) -> str:
    return " *" if sheet.assumed.get(key) else ""


def _table24_rows(sheet: SetupSheet) -> list[tuple[str, ...]]:
    left, right = sheet.photos
    rows: list[tuple[str, ...]] = [
        ("1", "horizontal model scale", "M_г", f"1:{sheet.horizontal_scale_denominator}"
         + _flag(sheet, "scale_horizontal"), "—", "item 1", NOTES["M_г"]),
        ("2", "vertical model scale", "M_в", f"1:{sheet.vertical_scale_denominator}"
         + _flag(sheet, "scale_vertical"), "—", "item 1", NOTES["M_в"]),
        ("3", "transformation coefficient", "k", _f(sheet.transformation_coefficient, 5), "—",
         "item 1", NOTES["k"]),
        ("4", "corrected focal length", "f′", _f(sheet.focal_length_corrected_mm, 4), "mm",
         "f·l′/l", NOTES["f′"]),
        ("5", "instrument principal distance", "f_пр", _f(sheet.f_instrument_mm)
         + _flag(sheet, "f_instrument_mm"), "mm", "item 1", NOTES["f_пр"]),
        ("6", "base components", "b_x, b_y, b_z′",
         ", ".join(_f(v) for v in sheet.base_mm) + _flag(sheet, "base_mm"), "mm", "item 1",
         NOTES["b"]),
        ("7", "counter coefficients", "n_л, n_п", f"{sheet.n_left:.5f}, {sheet.n_right:.5f}"
         + _flag(sheet, "n_left"), "—", "(6.3), (6.4)", NOTES["n"]),
        ("8", "marks, left photo", "(x⁰₂)_л, (y⁰₃)_л, (y⁰₄)_л",
         ", ".join(_f(left.transformed_book_mm[k]) for k in ("x2", "y3", "y4")), "mm",
         "(6.1)/(6.2)", NOTES["marks_left"]),
        ("9", "marks, right photo", "(x⁰₁)_п, (y⁰₃)_п, (y⁰₄)_п",
         ", ".join(_f(right.transformed_book_mm[k]) for k in ("x1", "y3", "y4")), "mm",
         "(6.1)/(6.2)", NOTES["marks_right"]),
        ("10", "mark spans 3–4", "L_л, L_п",
         f"{_f(left.mark_span_mm)}, {_f(right.mark_span_mm)}" + _flag(sheet, "L_mm"), "mm",
         "(6.5)", NOTES["L"]),
    ]  # fmt: skip
    rows.append(
        ("11", "decentrations, left; right photo", "d_x, d_y (л; п)",
         "\n".join(f"{_f(p.decentration_mm[0])}, {_f(p.decentration_mm[1])}" for p in sheet.photos),
         "mm", "f′·tan α, f′·tan ω", NOTES["d"])
    )  # fmt: skip
    if sheet.control_heights:
        values = [f"{h['id']}: {_f(h['model_height_mm'])}" for h in sheet.control_heights]
        text = "\n".join("; ".join(values[i : i + 2]) for i in range(0, len(values), 2))
        rows.append(
            ("12", "model heights over the height control points", "Z_i",
             text + _flag(sheet, "control_heights_model_mm"), "mm", "(6.6)", NOTES["Z"])
        )  # fmt: skip
    if sheet.corners:
        rows.append(
            ("13", "sheet corners 1 SW, 2 SE, 3 NE, 4 NW", "x′_i, y′_i",
             "\n".join(f"{c['corner']}: {_f(c['x_mm'])}, {_f(c['y_mm'])}" for c in sheet.corners)
             + _flag(sheet, "sheet_corners_mm"), "mm", "(6.7)", NOTES["corner"])
        )  # fmt: skip
    return rows


# --- drawing the pages ----------------------------------------------------------------------------


def _heading(pdf: _Form, text: str, size: float = 11.0) -> None:
    pdf.set_font(_FONT, "B", size)
    pdf.cell(0, 7, text, new_x=XPos.LMARGIN, new_y=YPos.NEXT)
    pdf.set_font(_FONT, "", 8)


def _table(
    pdf: _Form,
    header: Sequence[str],
    rows: Sequence[Sequence[str]],
    widths: Sequence[float],
    size: float = 7.5,
    aligns: Sequence[str] | None = None,
) -> None:
    pdf.set_font(_FONT, "", size)
    headings = any(header)
    with pdf.table(
        first_row_as_headings=headings,
        col_widths=tuple(widths),
        width=pdf.epw,
        line_height=1.25 * size * 0.3528 + 0.6,
        text_align=tuple(aligns) if aligns else "LEFT",
        headings_style=_headings_style(),
        borders_layout="SINGLE_TOP_LINE",
        padding=0.6,
    ) as table:
        if headings:
            row = table.row()
            for h in header:
                row.cell(h)
        for r in rows:
            row = table.row()
            for c in r:
                row.cell(str(c))
    pdf.ln(2)


def _headings_style() -> Any:
    return FontFace(family=_FONT, emphasis="BOLD", fill_color=(225, 225, 225))


def _header_block(pdf: _Form, sheet: SetupSheet, h: FormHeader) -> None:
    _heading(pdf, f"Setup sheet (Table 24) — stereopair {h.pair}", 13)
    pdf.set_font(_FONT, "", 8)
    assumed = sorted({p for ps in sheet.assumed.values() for p in ps})
    items = [
        ("job, pair", f"{h.job} ({h.job_file}) · pair {h.pair}: left photo {h.left_photo}, "
         f"right photo {h.right_photo} · date {h.date} (from the job file) · {h.program}"),
        ("map, instrument", f"map sheet {h.map_sheet} · {sheet.instrument_title} "
         f"({sheet.instrument})"),
        ("camera", h.camera),
        ("frame", h.frame + f"; base azimuth θ = {math.degrees(sheet.frame_rotation):.4f}°"),
        ("assumed", "values marked * rest on instrument parameters no source documents: "
         + (", ".join(assumed) if assumed else "none")),
    ]  # fmt: skip
    _table(pdf, ("", ""), items, (24, 151), size=7.5)


#: The stages of the setup-data method, as the compact readings of page 1 name them.
STAGES = {
    1: "1 · scales, base, spans",
    2: "2 · tilts, decentrations",
    3: "3 · height control",
    4: "4 · sheet corners 1–3",
    5: "5 · corner 4, check",
}


def _readings_rows(sheet: SetupSheet) -> list[tuple[str, str]]:
    """Every stage reading (6.9)–(6.18) as 'reading = MO + value (± tolerance)', one row per
    stage: the compact list of page 1 (page 3 has them one by one with a column to write in)."""
    rows = []
    for stage, title in STAGES.items():
        texts, tolerances = [], {}
        for r in sheet.readings:
            if r["stage"] != stage:
                continue
            texts.append(r["formula"])
            if "tolerance" in r and r["reading"] != "residual q":
                name = re.sub(r"\d+", "i", r["reading"]) if stage == 3 else r["reading"]
                tolerances.setdefault(f"±{r['tolerance']:.3g} {r['unit']}", []).append(name)
        tol = "; ".join(f"{', '.join(dict.fromkeys(names))} {t}" for t, names in tolerances.items())
        if texts:
            rows.append((title, "; ".join(texts) + (f". Tolerance: {tol}" if tol else "")))
    return rows


def _page_table24(pdf: _Form, sheet: SetupSheet, h: FormHeader) -> None:
    _header_block(pdf, sheet, h)
    _heading(pdf, "Table 24 — setup data")
    _table(
        pdf,
        ("No.", "quantity", "symbol", "value", "unit", "equation", "notes: what for, which stage"),
        _table24_rows(sheet),
        (6, 27, 23, 33, 7, 15, 64),
        size=6.5,
    )
    _heading(pdf, "Readings to set, stage by stage (6.9)–(6.18): zero reading MO + value", 9)
    _table(pdf, ("stage", "readings and tolerances; one by one with a column to write in: page 3"),
           _readings_rows(sheet), (26, 149), size=6.5)  # fmt: skip


def _page_details(pdf: _Form, sheet: SetupSheet, h: FormHeader) -> None:
    _details_orientation(pdf, sheet)
    _details_control(pdf, sheet, h)


def _details_orientation(pdf: _Form, sheet: SetupSheet) -> None:
    """Transformed marks, angles and decentrations, the instrument's settings."""
    _heading(pdf, "Transformed marks: the book's (6.1)/(6.2) beside the rigorous (3.17), κ = 0")
    rows = []
    for p in sheet.photos:
        for key, value in p.transformed_book_mm.items():
            rig = p.transformed_rigorous_mm[key[1:]]
            axis = 0 if key[0] == "x" else 1
            measured = p.marks_measured_mm[key[1:]]
            rows.append(
                (
                    p.name,
                    key,
                    f"{measured[0]:.3f}, {measured[1]:.3f}",
                    f"{value:.4f}",
                    f"{rig[0]:.4f}, {rig[1]:.4f}",
                    f"{(value - rig[axis]) * 1000:+.2f}",
                )
            )
    _table(pdf, ("photo", "mark", "measured x, y mm", "(6.1)/(6.2) mm", "(3.17) x⁰, y⁰ mm",
                 "difference µm"), rows, (18, 14, 38, 30, 44, 36))  # fmt: skip
    _heading(pdf, "Angles, decentrations and correction planes (instrument frame)")
    rows = [
        (p.name, f"{math.degrees(p.alpha):.5f}", f"{math.degrees(p.omega):.5f}",
         f"{math.degrees(p.kappa):.5f}", f"{_f(p.decentration_mm[0])}, {_f(p.decentration_mm[1])}",
         ", ".join(f"{math.degrees(v):.4f}" for v in p.correction_inclination))
        for p in sheet.photos
    ]  # fmt: skip
    _table(pdf, ("photo", "α °", "ω °", "κ °", "d_x, d_y mm", "planes α, ω °"), rows,
           (18, 24, 24, 24, 45, 45))  # fmt: skip
    settings = instrument_settings(sheet.table24, 0) if sheet.table24 is not None else None
    if settings is not None:
        _heading(pdf, f"Settings of the instrument: {settings['phi_omega_dependent']} depend on "
                      f"φ, ω ({settings['count_status']})")  # fmt: skip
        rows = [
            (st["symbol"], st["name"], st["formula"],
             *(f"{st[side]:.4f}" if st["unit"] == "deg" else _f(st[side])
               for side in ("left", "right")), "°" if st["unit"] == "deg" else "mm")
            for st in settings["settings"]
        ]  # fmt: skip
        _table(pdf, ("symbol", "setting", "formula", "left", "right", "unit"), rows,
               (16, 62, 46, 22, 22, 12))  # fmt: skip


def _details_control(pdf: _Form, sheet: SetupSheet, h: FormHeader) -> None:
    """Height control, sheet corners, the similarity, the distortion, the tolerances."""
    _heading(pdf, "Height control: model heights Z_i (6.6)")
    rows = [
        (h_["id"], f"{h_['Z_m']:.2f}", f"{h_['flying_height_m']:.2f}",
         f"{h_['model_height_mm']:.3f}")
        for h_ in sheet.control_heights
    ]  # fmt: skip
    _table(pdf, ("point", "Z m (pair frame)", "H_Ф = Z_Sл − Z m", "Z_i mm"), rows, (30, 50, 50, 50))
    if sheet.corners:
        _heading(pdf, f"Sheet corners (6.7) of {h.map_sheet}, from the left plumb")
        rows = [
            (c["corner"], c["position"], f"{c['gk_north_m']:.2f}", f"{c['gk_east_m']:.2f}",
             _f(c["x_mm"]), _f(c["y_mm"]))
            for c in sheet.corners
        ]  # fmt: skip
        _table(pdf, ("corner", "position", "x (north) m", "ȳ (east) m", "x′ mm", "y′ mm"), rows,
               (18, 20, 38, 38, 33, 33))  # fmt: skip
    if sheet.similarity is not None:
        fit = sheet.similarity
        res = ", ".join(
            f"{pid}: ({r[0]:+.3f}, {r[1]:+.3f})"
            for pid, r in zip(sheet.similarity_point_ids, fit.residuals_m, strict=True)
        )
        pdf.set_font(_FONT, "", 7.5)
        pdf.multi_cell(
            0, 3.8,
            f"Similarity (6.8) Gauss–Krüger → instrument frame over {len(fit.residuals_m)} plan "
            f"control points: a = {fit.a:.6e}, b = {fit.b:.9f}, c_X = {fit.cx_m:.3f} m, "
            f"c_Y = {fit.cy_m:.3f} m, RMS {fit.rms_m:.3f} m; residuals m: {res}.",
            new_x=XPos.LMARGIN, new_y=YPos.NEXT,
        )  # fmt: skip
        pdf.ln(2)
    if h.distortion:
        _heading(pdf, "Radial distortion of the certificate (not applied on the instrument)")
        _table(pdf, ("r mm", *(f"{r:g}" for r, _ in h.distortion)),
               [("Δr µm", *(f"{d:g}" for _, d in h.distortion))],
               (20, *([160 / len(h.distortion)] * len(h.distortion))))  # fmt: skip
    tol = sheet.tolerances
    pdf.set_font(_FONT, "", 7.5)
    pdf.multi_cell(
        0, 3.8,
        f"Tolerances: |L − L′| ≤ {tol['mark_span_mm']:.4f} mm; mark-4 misfit ≤ "
        f"{tol['mark_fit_mm']:.4f} mm; residual y-parallax ≤ {tol['residual_y_parallax_mm']:.4f} "
        f"mm; control heights ≤ {tol['control_height_m']:.3f} m; corner 4 ≤ "
        f"{tol['corner_mm']:.2f} mm" + _flag(sheet, "tolerances") + ".",
        new_x=XPos.LMARGIN, new_y=YPos.NEXT,
    )  # fmt: skip


def _page_readings(pdf: _Form, sheet: SetupSheet) -> None:
    _heading(pdf, "Readings, stage by stage (6.9)–(6.18): zero reading MO + signed value")
    pdf.set_font(_FONT, "", 7.5)
    pdf.multi_cell(
        0, 3.8,
        "MO is found on the instrument. The right photo's zero readings are MO_X,п = MO_X + b_x, "
        "MO_Y,п = MO_Y + b_y. Write the reading actually set in the last column.",
        new_x=XPos.LMARGIN, new_y=YPos.NEXT,
    )  # fmt: skip
    pdf.ln(1)
    rows = []
    for r in sheet.readings:
        tol = f"± {r['tolerance']:.4g} {r['unit']}" if "tolerance" in r else ""
        formula = r["formula"] + (f" (book: {r['book_form']})" if "book_form" in r else "")
        rows.append((str(r["stage"]), r["step"], formula, r["equation"], tol, ""))
    _table(pdf, ("stage", "step", "reading", "equation", "tolerance", "set"), rows,
           (9, 44, 56, 30, 22, 14), size=7)  # fmt: skip


def _page_drawing(pdf: _Form, sheet: SetupSheet, h: FormHeader) -> None:
    _heading(pdf, "Sheet frame and control in instrument coordinates (from the left plumb)")
    xs = [c["x_mm"] for c in sheet.corners] + [p["x_mm"] for p in sheet.points_model_mm]
    ys = [c["y_mm"] for c in sheet.corners] + [p["y_mm"] for p in sheet.points_model_mm]
    xs += [0.0, sheet.base_mm[0]]
    ys += [0.0, sheet.base_mm[1]]
    box_w, box_h = pdf.epw, 150.0
    x0, y0 = pdf.l_margin, pdf.get_y() + 4
    span = max(max(xs) - min(xs), max(ys) - min(ys), 1.0)
    scale = min(
        box_w / (max(xs) - min(xs) + 0.15 * span), box_h / (max(ys) - min(ys) + 0.15 * span)
    )
    cx, cy = (max(xs) + min(xs)) / 2, (max(ys) + min(ys)) / 2

    def at(x: float, y: float) -> tuple[float, float]:  # model mm → page mm, y up
        return x0 + box_w / 2 + (x - cx) * scale, y0 + box_h / 2 - (y - cy) * scale

    pdf.set_draw_color(160)
    pdf.set_line_width(0.2)
    pdf.rect(x0, y0, box_w, box_h)
    pdf.set_draw_color(0)
    pdf.set_font(_FONT, "", 7)
    if sheet.corners:
        order = sorted(sheet.corners, key=lambda c: c["corner"])
        pts = [at(c["x_mm"], c["y_mm"]) for c in order]
        pdf.set_line_width(0.5)
        pdf.polygon(pts)
        for c, (px, py) in zip(order, pts, strict=True):
            pdf.text(px + 1.2, py - 1.2, f"{c['corner']} ({c['position']})")
    pdf.set_line_width(0.25)
    for p in sheet.points_model_mm:
        px, py = at(p["x_mm"], p["y_mm"])
        if p["role"] == "check":
            pdf.circle(px, py, 1.1, style="D")
        elif p["kind"] == "height":
            pdf.circle(px, py, 1.1, style="F")
        else:
            pdf.polygon([(px, py - 1.5), (px - 1.3, py + 0.9), (px + 1.3, py + 0.9)], style="DF")
        pdf.text(px + 1.6, py + 2.6, str(p["id"]))
    for label, (x, y) in (("S_л", (0.0, 0.0)), ("S_п", (sheet.base_mm[0], sheet.base_mm[1]))):
        px, py = at(x, y)
        pdf.line(px - 2, py, px + 2, py)
        pdf.line(px, py - 2, px, py + 2)
        pdf.text(px + 1.5, py - 1.5, label)
    # a 50 mm scale bar of the model
    bx, by = x0 + 4, y0 + box_h - 4
    pdf.set_line_width(0.4)
    pdf.line(bx, by, bx + 50 * scale, by)
    pdf.text(bx, by - 1.5, f"50 mm of the model (1:{sheet.horizontal_scale_denominator})")
    pdf.set_y(y0 + box_h + 3)
    pdf.set_font(_FONT, "", 7.5)
    pdf.multi_cell(
        0, 3.8,
        "Triangles: plan/full control; filled circles: height control; open circles: check "
        "points; crosses: the plumbs of the left and right projection centres. X along the base "
        f"(θ = {math.degrees(sheet.frame_rotation):.4f}° from the frame's X), Y to the left of it."
        + ("" if sheet.corners else " No sheet corners: the job has no SK-42 tie or map sheet."),
        new_x=XPos.LMARGIN, new_y=YPos.NEXT,
    )  # fmt: skip


def _add_form(pdf: _Form, sheet: SetupSheet, header: FormHeader) -> None:
    pdf.footer_text = (
        f"{header.job} · pair {header.pair} (photos {header.left_photo}, {header.right_photo}) · "
        f"{sheet.instrument} · {header.date} · {header.program}"
    )
    pdf.add_page()
    _page_table24(pdf, sheet, header)
    pdf.add_page()
    _page_details(pdf, sheet, header)
    pdf.add_page()
    _page_readings(pdf, sheet)
    pdf.add_page()
    _page_drawing(pdf, sheet, header)


def form_pdf(sheet: SetupSheet, header: FormHeader) -> bytes:
    """The form of one pair as PDF bytes (the same inputs give the same bytes)."""
    pdf = _Form(header.date)
    pdf.set_title(f"Setup sheet {header.job} {header.pair}")
    _add_form(pdf, sheet, header)
    return bytes(pdf.output())


def forms_pdf(forms: Sequence[tuple[SetupSheet, FormHeader]], title: str, date: str) -> bytes:
    """The forms of many pairs in one PDF (the combined print of a block)."""
    pdf = _Form(date)
    pdf.set_title(title)
    for sheet, header in forms:
        _add_form(pdf, sheet, header)
    return bytes(pdf.output())
