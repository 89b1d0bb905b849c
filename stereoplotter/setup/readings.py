"""The readings each of the five stages asks for, as zero reading (MO) + signed value.

Eqs. (6.11)–(6.18) of the book (ch. 6, §26, OCR L3773–3821) read as in ``docs/setup-data.md``:
* readings are MO + **signed** value; the book's MO − (y⁰₄) and MO − (x⁰₁) treat the negative-side
  marks as magnitudes — the same number (``book_form`` is reported beside);
* the right photo's targets use its own zero reading MO_п = MO + (b_x, b_y) and n_п (decision D6);
* (6.16)–(6.18) reuse the names O_X1, O_Y3, O_Y4 for the sheet corners: they are kept apart here
  under the names ``corner 1`` … ``corner 4``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from stereoplotter.setup.equations import height_scale_reading
from stereoplotter.setup.records import SetupSheet

__all__ = ["signed_text", "stage_readings"]


def signed_text(value: float, digits: int = 3) -> str:
    """``+ 1.234`` or ``− 1.234`` [as given]; a value that rounds to zero is ``+ 0.000`` (never
    ``+ -0.000`` or ``− 0.000``)."""
    text = f"{abs(value):.{digits}f}"
    negative = value < 0 and text.strip("0.") != ""  # not a value that rounds to zero
    return f"{'−' if negative else '+'} {text}"


def _r(
    stage: int,
    step: str,
    name: str,
    zero: str,
    value: float,
    unit: str,
    equation: str,
    tolerance: float | None = None,
    note: str = "",
    **extra: Any,
) -> dict[str, Any]:
    value = 0.0 if abs(value) < 5e-7 else value  # no "−0.000"
    relation = extra.pop("relation", "=")
    if zero:
        formula = f"{name} = {zero} {signed_text(value)} {unit}"
    else:
        formula = (
            f"{name} {relation} {value:.4g} {unit}"
            if relation != "="
            else (f"{name} = {value:.3f} {unit}")
        )
    row = {
        "stage": stage,
        "step": step,
        "reading": name,
        "zero_reading": zero,
        "value": value,
        "unit": unit,
        "equation": equation,
        "formula": formula,
    }
    if tolerance is not None:
        row["tolerance"] = tolerance
    if note:
        row["note"] = note
    row.update(extra)
    return row


def _span_rows(sheet: SetupSheet) -> list[dict[str, Any]]:
    """Stage 1's span checks: L⁰ (units at zero, the stage-1 comparison, decision D5) and
    (6.5)'s L (the check repeated in stage 2 with the units set), left then right."""
    tol = sheet.tolerances
    sense = sheet.options.bz_scale_sense
    left, right = sheet.photos
    return [
        _r(
            1,
            f"check the span of marks 3–4, {photo.name} photo{when}",
            f"{name}_{side}",
            "",
            value,
            "mm",
            eq,
            tolerance=tol["mark_span_mm"],
            note=(
                "correct with ΔZ (6.9) and repeat until |L − L′| ≤ tolerance"
                if side == "л"
                else f"correct with Δb_z (6.10): O′_bz = O_bz {'+' if sense > 0 else '−'} "
                f"Δb_z (6.11, b_z scale sense {sense:+d})"
            )
            + extra,
        )
        for name, when, eq, extra, spans in (
            (
                "L⁰",
                " (correction units at zero: compare L′ with this)",
                "(6.5), decision D5",
                "; L⁰ = n·(y₃ − y₄) of the measured marks: with the units at zero the "
                "counters show the photo's own span, not (6.5)'s of the transformed y⁰",
                (left.mark_span_at_zero_mm, right.mark_span_at_zero_mm),
            ),
            (
                "L",
                " (with the correction units set: the check repeated in stage 2)",
                "(6.5)",
                "",
                (left.mark_span_mm, right.mark_span_mm),
            ),
        )
        for photo, side, value in ((left, "л", spans[0]), (right, "п", spans[1]))
    ]


def _stage1_rows(sheet: SetupSheet) -> list[dict[str, Any]]:
    """Stage 1: f_пр, the base, D_max, the mark spans and the zero readings."""
    sense = sheet.options.bz_scale_sense
    bx, by, bz = sheet.base_mm
    n_l = sheet.n_left
    rows = [
        _r(
            1,
            "set the instrument principal distance",
            "f_пр",
            "",
            sheet.f_instrument_mm,
            "mm",
            "item 1",
        ),
        _r(1, "base carriage", "O_bx", "MO_bx", bx, "mm", "item 1"),
        _r(
            1,
            "base carriage (MO_by from the two cassette centres)",
            "O_by",
            "MO_by",
            by,
            "mm",
            "item 1",
        ),
        _r(
            1,
            "lower the base carriage (foot wheel): absolute height counter",
            "O_Z",
            "",
            n_l * sheet.f_instrument_mm,
            "mm",
            "(6.3)",
            note="D = n_л·f_пр = D_max",
        ),
        *_span_rows(sheet),
        _r(
            1,
            "record the zero readings",
            "MO_bz",
            "O_bz",
            -sense * bz,
            "mm",
            "decision D7",
            note="MO_bz = (b_z reading) ∓ b_z′ (by the scale sense); MO_Z = height-scale "
            "reading [m]",
        ),
    ]
    return rows


def _mark_rows(sheet: SetupSheet) -> list[dict[str, Any]]:
    """Stage 2: k_ω on mark 3, the check on mark 4 and k_α on the x mark, left then right."""
    tol = sheet.tolerances
    bx, by, _ = sheet.base_mm
    left, right = sheet.photos
    n_l, n_r = sheet.n_left, sheet.n_right
    rows: list[dict[str, Any]] = []
    for photo, n, zero_x, zero_y, x_mark in (
        (left, n_l, "MO_X", "MO_Y", "2"),
        (right, n_r, "MO_X,п", "MO_Y,п", "1"),
    ):
        side = "л" if photo.name == "left" else "п"
        t = photo.transformed_book_mm
        extra = (
            {}
            if photo.name == "left"
            else {
                "zero_reading_definition": f"MO_X,п = MO_X + b_x = MO_X {signed_text(bx)}; "
                f"MO_Y,п = MO_Y + b_y = MO_Y {signed_text(by)}"
            }
        )
        rows += [
            _r(
                2,
                f"{photo.name} photo: k_ω on mark 3",
                f"O_Y3,{side}",
                zero_y,
                n * t["y3"],
                "mm",
                "(6.12)",
                **extra,
            ),
            _r(
                2,
                f"{photo.name} photo: check mark 4",
                f"O_Y4,{side}",
                zero_y,
                n * t["y4"],
                "mm",
                "(6.12)",
                tolerance=tol["mark_fit_mm"],
                book_form=f"{zero_y} − {abs(n * t['y4']):.3f}",
            ),
            _r(
                2,
                f"{photo.name} photo: k_α on mark {x_mark}",
                f"O_X{x_mark},{side}",
                zero_x,
                n * t[f"x{x_mark}"],
                "mm",
                "(6.13)",
                **({"book_form": f"{zero_x} − {abs(n * t['x1']):.3f}"} if x_mark == "1" else {}),
            ),
        ]
    return rows


def _stage2_rows(sheet: SetupSheet) -> list[dict[str, Any]]:
    """Stage 2 after the marks: the decentration scales, b_z and the residual y-parallax."""
    tol = sheet.tolerances
    sense = sheet.options.bz_scale_sense
    bz = sheet.base_mm[2]
    left, right = sheet.photos
    rows: list[dict[str, Any]] = []
    for photo in (left, right):
        side = "л" if photo.name == "left" else "п"
        rows += [
            _r(
                2,
                f"{photo.name} photo: decentration scale x",
                f"d_x,{side}",
                "MO_dx",
                photo.decentration_mm[0],
                "mm",
                "f′·tan α (kinematics §2.4)",
            ),
            _r(
                2,
                f"{photo.name} photo: decentration scale y",
                f"d_y,{side}",
                "MO_dy",
                photo.decentration_mm[1],
                "mm",
                "f′·tan ω (kinematics §2.4)",
            ),
        ]
    rows += [
        _r(
            2,
            "vertical base",
            "O_bz",
            "MO_bz",
            sense * bz,
            "mm",
            "(6.14)",
            note="b_z′ = k·b_z; under D7 a re-set of the stage-1 value",
        ),
        _r(
            2,
            "κ_л, κ_п by the initial directions; residual y-parallax",
            "residual q",
            "",
            tol["residual_y_parallax_mm"],
            "mm",
            "stage 2",
            tolerance=tol["residual_y_parallax_mm"],
            note="residual y-parallax ≤ ¼ of the mark diameter",
            relation="≤",
        ),
    ]
    return rows


def _height_rows(sheet: SetupSheet) -> list[dict[str, Any]]:
    """Stage 3: the height-scale readings of the height control points (6.15)."""
    tol = sheet.tolerances
    n_l = sheet.n_left
    heights = sheet.control_heights
    values = height_scale_reading(
        0.0,
        np.array([h["model_height_mm"] for h in heights], float),
        n_l,
        sheet.f_instrument_mm,
        sheet.vertical_scale_denominator,
    ).tolist()  # (6.15) of every height point in one array expression
    rows: list[dict[str, Any]] = []
    for h, value in zip(heights, values, strict=True):
        rows.append(
            _r(
                3,
                f"height control point {h['id']}: fuse the mark with b_x",
                f"O_Z{h['id']}",
                "MO_Z",
                value,
                "m",
                "(6.15)",
                tolerance=tol["control_height_m"],
                note=f"Z_{h['id']} = {h['model_height_mm']:.3f} mm (6.6)",
            )
        )
    return rows


def _corner_rows(sheet: SetupSheet) -> list[dict[str, Any]]:
    """Stages 4–5: the sheet corners (6.7), (6.16)–(6.18)."""
    tol = sheet.tolerances
    rows: list[dict[str, Any]] = []
    for corner in sheet.corners:
        stage = 5 if corner["corner"] == "4" else 4
        equation = {"1": "(6.16)", "3": "(6.17)", "4": "(6.18)"}.get(corner["corner"], "(6.7)")
        tolerance = tol["corner_mm"] if corner["corner"] == "4" else None
        c = corner["corner"]
        rows += [
            _r(
                stage,
                f"sheet corner {c} ({corner['position']})",
                f"corner {c}: O_X",
                "MO_X",
                corner["x_mm"],
                "mm",
                equation,
                tolerance=tolerance,
            ),
            _r(
                stage,
                f"sheet corner {c} ({corner['position']})",
                f"corner {c}: O_Y",
                "MO_Y",
                corner["y_mm"],
                "mm",
                equation,
                tolerance=tolerance,
            ),
        ]
    return rows


def stage_readings(sheet: SetupSheet) -> tuple[dict[str, Any], ...]:
    """All readings of stages 1–5 for a sheet, in the order the operator sets them.

    Returns
    -------
    tuple of dict
        ``stage``, ``step``, ``reading``, ``zero_reading`` (the MO it is added to, or "" for an
        absolute value), ``value`` (signed), ``unit``, ``equation``, ``formula`` (text),
        ``tolerance`` where the book gives one, ``note``.
    """
    rows = _stage1_rows(sheet) + _mark_rows(sheet) + _stage2_rows(sheet)
    return tuple(rows + _height_rows(sheet) + _corner_rows(sheet))
