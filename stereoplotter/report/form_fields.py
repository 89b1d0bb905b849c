"""What the setup form says, in rows of text: the values to set at the least count, the zero
readings and the (6.9)–(6.11) corrections to write in, the stage-5 readings, the signatures and
the method's limits (the book's (6.1)/(6.2), (6.5) against the rigorous (3.17)).

Text only, no layout: :mod:`stereoplotter.report.forms` draws these rows. Every label comes from
:mod:`stereoplotter.glossary` in the form's language.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Any

from stereoplotter.glossary import term, translate
from stereoplotter.setup.records import SetupSheet

__all__ = [
    "LeastCounts",
    "correction_rows",
    "limit_rows",
    "reading_rows",
    "rigorous_sides",
    "set_value",
    "signature_rows",
    "stage5_rows",
    "summary_rows",
    "value_to_set",
    "zero_of",
    "zero_reading_names",
]


@dataclass(frozen=True, slots=True)
class LeastCounts:
    """Least counts of the instrument's counters and scales (from the instrument spec).

    ``counter_mm``: the X, Y counters (marks, spans, corners, points); ``z_mm``: the absolute
    height counter; ``height_m``: the metre height scale (stage 3); ``scale_mm``: the f_пр, base
    and decentration scales. ``assumed`` names those the instrument file marks ``assumed``.
    """

    counter_mm: float = 0.01
    z_mm: float = 0.01
    height_m: float = 0.1
    scale_mm: float = 0.01
    assumed: frozenset[str] = field(default_factory=frozenset)

    def of(self, reading: str) -> tuple[str, float] | None:
        """(kind, least count) of the counter or scale a reading is set on; None for none."""
        if reading == "residual q":
            return None
        if reading == "f_пр" or reading.startswith(("O_b", "MO_b", "d_")):
            return "scale_mm", self.scale_mm
        if reading == "O_Z":
            return "z_mm", self.z_mm
        if reading.startswith("O_Z"):
            return "height_m", self.height_m
        return "counter_mm", self.counter_mm


def _decimals(step: float) -> int:
    return max(0, -math.floor(math.log10(step) + 1e-9))


def set_value(value: float, step: float) -> str:
    """``value`` rounded to the least count ``step``, printed to the step's decimals (no −0)."""
    digits = _decimals(step)
    rounded = round(value / step) * step
    text = f"{abs(rounded):.{digits}f}"
    return ("-" if rounded < 0 and float(text) != 0.0 else "") + text


_NB = "\u00a0"  # a non-breaking space: a sign, its value and its unit stay on one line


def _signed(value: float, step: float) -> str:
    text = set_value(value, step)
    return f"−{_NB}{text[1:]}" if text.startswith("-") else f"+{_NB}{text}"


# --- rigorous values --------------------------------------------------------------------------

_MARK = re.compile(r"^O_(?P<axis>[XY])(?P<mark>[1-4]),(?P<side>[лп])$")


def _rigorous_value(sheet: SetupSheet, reading: str) -> float | None:
    """The rigorous (3.17) counterpart n·x⁰, n·y⁰ of a mark target, n·(y⁰₃ − y⁰₄) of a span."""
    left, right = sheet.photos
    if reading in ("L_л", "L_п"):
        photo, n = (left, sheet.n_left) if reading == "L_л" else (right, sheet.n_right)
        rig = photo.transformed_rigorous_mm
        return n * (rig["3"][1] - rig["4"][1])
    m = _MARK.match(reading)
    if m is None:
        return None
    photo, n = (left, sheet.n_left) if m["side"] == "л" else (right, sheet.n_right)
    return n * photo.transformed_rigorous_mm[m["mark"]][0 if m["axis"] == "X" else 1]


def limit_rows(sheet: SetupSheet) -> list[dict[str, Any]]:
    """Each mark target and span by the book and rigorously, on the counters (× n), with the
    stage tolerance it is checked against (mark-4 fit for the targets, |L − L′| for spans)."""
    tol = sheet.tolerances
    out = []
    for r in sheet.readings:
        rig = _rigorous_value(sheet, r["reading"])
        if rig is None:
            continue
        span = r["reading"].startswith("L_")
        tolerance = tol["mark_span_mm"] if span else tol["mark_fit_mm"]
        diff = r["value"] - rig
        out.append({
            "reading": r["reading"], "book": r["value"], "rigorous": rig, "difference": diff,
            "tolerance": tolerance, "exceeds": abs(diff) > tolerance,
            "equation": "(6.5)" if span else r["equation"],
        })  # fmt: skip
    return out


def rigorous_sides(sheet: SetupSheet, rigorous: bool = False) -> tuple[str, ...]:
    """The photos ("left", "right") whose mark targets and span the form gives to set from the
    rigorous (3.17): both with ``rigorous``; else each photo one of whose book values
    ((6.1)/(6.2) targets, (6.5) span) leaves its stage tolerance (:func:`limit_rows`).

    A photo is taken whole: its k_ω target (mark 3), its check (mark 4), its k_α target and its
    span L are one fit of one photo carrier, so they come from one computation — setting mark 3
    by the book and checking mark 4 against the rigorous value would check one model against
    another.
    """
    if rigorous:
        return ("left", "right")
    bad = {row["reading"][-1] for row in limit_rows(sheet) if row["exceeds"]}
    return tuple(side for side, mark in (("left", "л"), ("right", "п")) if mark in bad)


def _side(reading: str) -> str | None:
    """The photo ("left"/"right") of a mark target or span reading, else None."""
    if _rigorous_name(reading):
        return "left" if reading.endswith("л") else "right"
    return None


def _rigorous_name(reading: str) -> bool:
    return reading in ("L_л", "L_п") or _MARK.match(reading) is not None


def value_to_set(
    sheet: SetupSheet, row: dict[str, Any], sides: tuple[str, ...]
) -> tuple[float, float | None]:
    """(the value a reading row gives to set, the book's value beside it or None): the
    rigorous (3.17) value of a mark target or span of a photo in ``sides``
    (:func:`rigorous_sides`), else the row's own value."""
    side = _side(row["reading"])
    if side is None or side not in sides:
        return row["value"], None
    rig = _rigorous_value(sheet, row["reading"])
    return (row["value"], None) if rig is None else (rig, row["value"])


# --- readings -------------------------------------------------------------------------------------

_STEPS_RU = (
    (r"^f_пр$", "установить фокусное расстояние прибора f_пр"),
    (r"^O_bx$", "базисная каретка b_x"),
    (r"^O_by$", "базисная каретка b_y (MO_by по центрам кассет)"),
    (r"^O_Z$", "опустить базисную каретку (ножной штурвал) до D_max: абсолютный счётчик высот"),
    (r"^L⁰_л$", "контроль расстояния между метками 3–4, левый снимок (коррекционные механизмы "
     "на нулях)"),
    (r"^L⁰_п$", "контроль расстояния между метками 3–4, правый снимок (коррекционные механизмы "
     "на нулях)"),
    (r"^L_л$", "контроль расстояния между метками 3–4, левый снимок"),
    (r"^L_п$", "контроль расстояния между метками 3–4, правый снимок"),
    (r"^MO_bz$", "записать место нуля b_z"),
    (r"^O_Y3,л$", "левый снимок: k_ω по метке 3"),
    (r"^O_Y4,л$", "левый снимок: контроль по метке 4"),
    (r"^O_X2,л$", "левый снимок: k_α по метке 2"),
    (r"^O_Y3,п$", "правый снимок: k_ω по метке 3"),
    (r"^O_Y4,п$", "правый снимок: контроль по метке 4"),
    (r"^O_X1,п$", "правый снимок: k_α по метке 1"),
    (r"^d_x,л$", "левый снимок: шкала децентрации x"),
    (r"^d_y,л$", "левый снимок: шкала децентрации y"),
    (r"^d_x,п$", "правый снимок: шкала децентрации x"),
    (r"^d_y,п$", "правый снимок: шкала децентрации y"),
    (r"^O_bz$", "вертикальная составляющая базиса"),
    (r"^residual q$", "κ_л, κ_п по начальным направлениям; остаточный поперечный параллакс"),
    (r"^O_Z(?P<id>.+)$", "высотная опорная точка {id}: совместить марку с точкой вращением b_x"),
    (r"^corner (?P<id>\d)", "угол трапеции {id}{position}"),
)


def step_text(row: dict[str, Any], lang: str) -> str:
    """What the operator does for a reading row, in ``lang``."""
    if lang == "en":
        return str(row["step"])
    where = re.search(r" \((SW|SE|NE|NW)\)$", str(row["step"]))  # a corner's position
    for pattern, text in _STEPS_RU:
        m = re.match(pattern, row["reading"])
        if m:
            return text.format(**m.groupdict(), position=f" ({where[1]})" if where else "")
    return str(row["step"])  # pragma: no cover - every reading of stages 1–5 is listed above


def zero_of(row: dict[str, Any]) -> str:
    """The zero reading of a row; a decentration's is its own projector's (MO_dx,л, MO_dx,п):
    each projector has its own decentration scales, so each has its own place of zero."""
    zero, reading = str(row["zero_reading"]), str(row["reading"])
    if zero in ("MO_dx", "MO_dy") and reading[-2:] in (",л", ",п"):
        return zero + reading[-2:]
    return zero


def _residual_text(row: dict[str, Any], lang: str) -> str:
    text = str(row["formula"])
    return text.replace("residual q", term("residual_q", lang))


def _reading_text(row: dict[str, Any], value: float, lc: LeastCounts, lang: str) -> str:
    kind = lc.of(row["reading"])
    name, zero, unit = row["reading"], zero_of(row), row["unit"]
    name = name.replace("corner", term("corner", lang)).replace(" ", "\u00a0")
    if kind is None:
        return _residual_text(row, lang)
    step = kind[1]
    if zero:
        return f"{name} = {zero} {_signed(value, step)}{_NB}{unit}"
    return f"{name} = {set_value(value, step)}{_NB}{unit}"


def _least_count_text(row: dict[str, Any], lc: LeastCounts) -> str:
    kind = lc.of(row["reading"])
    if kind is None:
        return "—"
    name, step = kind
    star = " *" if name in lc.assumed else ""
    return f"{step:g} {'m' if name == 'height_m' else 'mm'}{star}"


def _tolerance_text(row: dict[str, Any]) -> str:
    return f"±{_NB}{row['tolerance']:.4g}{_NB}{row['unit']}" if "tolerance" in row else ""


def _equation_text(row: dict[str, Any], lang: str) -> str:
    """A reading's equation in ``lang``, without the pointer into the program's own notes (the
    form names the book's equations only)."""
    return translate(str(row["equation"]).replace(" (kinematics §2.4)", ""), lang)


def _book_text(row: dict[str, Any], book: float | None, lc: LeastCounts, lang: str) -> str:
    """" (book: …)" beside a rigorous value to set, at the same least count."""
    if book is None:
        return ""
    kind = lc.of(row["reading"])
    step = kind[1] if kind else 0.001
    return f" ({term('limit_book', lang)}: {set_value(book, step).replace('-', '−')})"


def reading_rows(
    sheet: SetupSheet, lc: LeastCounts, lang: str, rigorous: bool = False
) -> list[tuple[str, ...]]:
    """Every reading of stages 1–4 (stage 5 is :func:`stage5_rows`): stage, step, the value to
    set at its least count (:func:`value_to_set`: the rigorous one, the book's beside it, for
    the marks and span of a photo of :func:`rigorous_sides`), the least count, the equation,
    the tolerance and an empty column to write in."""
    sides = rigorous_sides(sheet, rigorous)
    rows = []
    for r in sheet.readings:
        if r["stage"] == 5:
            continue
        value, book = value_to_set(sheet, r, sides)
        equation = "(3.17)" if book is not None else _equation_text(r, lang)
        rows.append((str(r["stage"]), step_text(r, lang),
                     _reading_text(r, value, lc, lang) + _book_text(r, book, lc, lang),
                     _least_count_text(r, lc), equation, _tolerance_text(r), ""))  # fmt: skip
    return rows


def summary_rows(
    sheet: SetupSheet, lc: LeastCounts, lang: str, rigorous: bool = False
) -> list[tuple[str, str]]:
    """The compact readings of page 1: one row per stage, every value at its least count (the
    same values as :func:`reading_rows`, the book's beside a rigorous one)."""
    sides = rigorous_sides(sheet, rigorous)
    out = []
    for stage in range(1, 6):
        texts, tolerances = [], {}
        for r in sheet.readings:
            if r["stage"] != stage:
                continue
            value, book = value_to_set(sheet, r, sides)
            texts.append(_reading_text(r, value, lc, lang) + _book_text(r, book, lc, lang))
            if "tolerance" in r and r["reading"] != "residual q":
                name = re.sub(r"\d+$", "i", r["reading"]) if stage == 3 else r["reading"]
                name = name.replace("corner", term("corner", lang))
                tolerances.setdefault(f"±{r['tolerance']:.3g}{_NB}{r['unit']}", []).append(name)
        if stage == 5:
            texts.append(f"{term('points_stage5', lang)}: "
                         + ", ".join(str(p["id"]) for p in _stage5_points(sheet)))  # fmt: skip
        tol = "; ".join(f"{', '.join(dict.fromkeys(n))} {t}" for t, n in tolerances.items())
        if texts:
            tail = f". {term('tolerance', lang).capitalize()}: {tol}" if tol else ""
            out.append((term(f"stage_{stage}", lang), "; ".join(texts) + tail))
    return out


# --- write-in fields ----------------------------------------------------------------------------


def zero_reading_names(sheet: SetupSheet) -> list[str]:
    """The zero readings every reading depends on, in the order the readings use them."""
    names = dict.fromkeys(["MO_X", "MO_Y", "MO_Z"])
    for r in sheet.readings:
        zero = zero_of(r)
        if zero.startswith(("MO_dx,", "MO_dy,")):
            names.setdefault(zero)
            continue
        if zero.startswith("MO") and "," not in zero:
            names.setdefault(zero)
    names.setdefault("MO_bz")
    return list(names)


def correction_rows(sheet: SetupSheet, lang: str) -> list[tuple[str, ...]]:
    """Rows of the (6.9)–(6.11) corrections: symbol, quantity, formula, factor, field.

    D = n_л·f_пр is the absolute height reading of stage 1 (6.3); the factors are those of
    :func:`stereoplotter.setup.equations.height_correction` and ``base_z_correction`` evaluated
    for this sheet, so the operator multiplies the span error ΔL = L − L′ by them.
    """
    left, right = sheet.photos
    d = sheet.n_left * sheet.f_instrument_mm
    # stage 1 compares with L⁰ (units at zero, decision D5), the sheet's printed value; it has
    # no transformed y⁰, so the rigorous form is the same number
    ll, lr = left.mark_span_at_zero_mm, right.mark_span_at_zero_mm
    mv = sheet.vertical_scale_denominator
    sign = "+" if sheet.options.bz_scale_sense > 0 else "−"
    blank = "__________"
    return [
        ("L′_л", term("corr_L_left", lang), f"L⁰_л (D5) = {ll:.3f} mm", "", f"{blank} mm"),
        ("ΔZ", term("corr_dz", lang), "ΔZ = D·(L_л − L′_л)·M_в/(1000·L_л)",
         f"{d * mv / (1000.0 * ll):.4f} m/mm", f"{blank} m"),
        ("O′_Z", term("corr_dz_counter", lang), "O′_Z = O_Z + D·(L_л − L′_л)/L_л",
         f"{d / ll:.5f}", f"{blank} mm"),
        ("L′_п", term("corr_L_right", lang), f"L⁰_п (D5) = {lr:.3f} mm", "", f"{blank} mm"),
        ("Δb_z", term("corr_dbz", lang), "Δb_z = D·(L_п − L′_п)/L_п", f"{d / lr:.5f}",
         f"{blank} mm"),
        ("O′_bz", term("corr_bz", lang), f"O′_bz = O_bz {sign} Δb_z", "", f"{blank} mm"),
    ]  # fmt: skip


def _stage5_points(sheet: SetupSheet) -> list[dict[str, Any]]:
    return [p for p in sheet.points_model_mm if p["role"] == "check" or p["kind"] != "height"]


def stage5_rows(sheet: SetupSheet, lc: LeastCounts, lang: str) -> list[tuple[str, ...]]:
    """Stage 5: corner 4 and the x′, y′ readings of the plan control and check points, at the
    counters' least count, with the coordinatograph tolerance of corner 4 and fields to write."""
    step = lc.counter_mm
    tol = f"±\u00a0{sheet.tolerances['corner_mm']:.2g}\u00a0mm"
    rows = []
    for c in sheet.corners:
        if c["corner"] == "4":
            rows.append((f"{term('corner', lang)}\u00a04", c["position"],
                         f"O_X = MO_X {_signed(c['x_mm'], step)}",
                         f"O_Y = MO_Y {_signed(c['y_mm'], step)}", tol, "", ""))  # fmt: skip
    for p in _stage5_points(sheet):
        role = term("check_point" if p["role"] == "check" else "plan_control", lang)
        rows.append((str(p["id"]), role, f"O_X = MO_X {_signed(p['x_mm'], step)}",
                     f"O_Y = MO_Y {_signed(p['y_mm'], step)}", tol, "", ""))  # fmt: skip
    return rows


def signature_rows(lang: str) -> list[tuple[str, ...]]:
    """Operator and checker: name, signature and date fields."""
    return [(term(who, lang), "_" * 30, "_" * 24, "_" * 16) for who in ("operator", "checker")]
