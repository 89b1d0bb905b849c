"""Rows of the outcomes of §27 problem 1: (6.39)–(6.44) the parallax of unadjusted setup data
from the pointing error m_xy, (6.45)/(6.46) the conventional method it is compared with."""

from __future__ import annotations

import math

from stereoplotter.accuracy import setup_accuracy as sa
from stereoplotter.verification.entry import RULE, DeclaredRows, Entry, ProcedureMeasure, Setting

__all__ = ["ROWS"]

#: The rows of (6.39)–(6.46), in the table's order.
ROWS = DeclaredRows()


def _from_pointing(s: Setting, overlap: str, mode: str = "book") -> float:
    _, p = s.slot(overlap)
    return float(sa.setup_parallax_rms_from_pointing(s.f, p, s.c, s.l, s.n, 1.0, mode=mode))


def _outcome(
    s: Setting,
    eq: str,
    overlap: str,
    quantity: str,
    printed: float,
    verdict: str,
    note: str,
    *,
    from_printed_inputs: float | None = None,
    digits: int | None = None,
    book_only: bool = False,
) -> Entry:
    """A row of m_p⁰/m_xy of unadjusted setup data at ``overlap``: book σ's of (6.31)–(6.38)
    (m_bz = f m_y/l) and rigorous σ's (m_bz = f m_y/(n l) at photo scale, ``docs/errata.md``);
    the linear MC propagates the rigorous σ's."""
    a, p = s.slot(overlap)
    rigorous_sigmas = sa.setup_element_sigmas(s.f, s.l, s.n, 1.0, mode="rigorous")
    return Entry(
        eq=eq,
        quantity=quantity,
        printed=printed,
        book=_from_pointing(s, overlap),
        rigorous=_from_pointing(s, overlap, "rigorous"),
        model=s.unadjusted(a, p, rigorous_sigmas),
        verdict=verdict,
        note=note
        + "; rigorous: m_bz of (6.37) at photo scale, f m_y/(n l) (15p²/l² for 15p²n²/l²)",
        upstream="(6.37)",
        from_printed_inputs=from_printed_inputs,
        digits=digits,
        book_only=book_only,
        procedure=ProcedureMeasure(overlap, "setup", "parallax"),
    )


@ROWS.row
def eq_6_39(s: Setting) -> Entry:
    return _outcome(
        s,
        "(6.39)",
        "60",
        f"m_p⁰/m_xy, 60 %, l = {s.l:g}, n = {s.n:g}",
        sa.setup_parallax_rms_printed_60(s.p60, s.l, s.n, 1.0),
        RULE,
        "with the least-squares m_ω (not the printed (6.35)) and f_пр = f in (6.37)",
    )


@ROWS.row
def eq_6_40(s: Setting) -> Entry:
    return _outcome(
        s,
        "(6.40)",
        "80",
        f"m_p⁰/m_xy, 80 %, l = {s.l:g}, n = {s.n:g}",
        sa.setup_parallax_rms_printed_80(s.p80, s.l, s.n, 1.0),
        RULE,
        "as (6.39)",
    )


@ROWS.row
def eq_6_41(s: Setting) -> Entry:
    return _outcome(
        s,
        "(6.41)",
        "60",
        f"m_p⁰/m_xy, 60 %, n = {s.n:g}, rounded coefficients",
        sa.setup_parallax_rms_rounded_60(s.n, 1.0),
        RULE,
        "coefficients of (6.39) at l = 85: 124 ← 123.63, 10 ← 10.17, 6.7 ← 3√5 = 6.708",
        book_only=True,
    )


@ROWS.row
def eq_6_42(s: Setting) -> Entry:
    return _outcome(
        s,
        "(6.42)",
        "80",
        f"m_p⁰/m_xy, 80 %, n = {s.n:g}, rounded coefficients",
        sa.setup_parallax_rms_rounded_80(s.n, 1.0),
        RULE,
        "coefficients of (6.40) at l = 85: 113 ← 113.28, 2.5 ← 2.54",
        book_only=True,
    )


@ROWS.row
def eq_6_43(s: Setting) -> Entry:
    return _outcome(
        s,
        "(6.43)",
        "60",
        "m_p⁰/m_xy, 60 %, SC-1",
        1.26,
        RULE,
        "from printed inputs: the printed (6.41) at n = 1.42",
        from_printed_inputs=sa.setup_parallax_rms_rounded_60(s.n, 1.0),
        digits=2,
    )


@ROWS.row
def eq_6_44(s: Setting) -> Entry:
    return _outcome(
        s,
        "(6.44)",
        "80",
        "m_p⁰/m_xy, 80 %, SC-1",
        1.11,
        RULE,
        "from printed inputs: the printed (6.42) at n = 1.42; 1.11 not reached by any reading "
        "of (6.40)",
        from_printed_inputs=sa.setup_parallax_rms_rounded_80(s.n, 1.0),
        digits=2,
    )


@ROWS.row
def eq_6_45(s: Setting) -> Entry:
    pr, bk, rg = s.conventional_values(s.a60, s.p60)
    return s.convention_off_book(
        Entry(
            eq="(6.45)",
            quantity=f"m_p⁰/m_p conventional, 60 %, p = {s.p60:g}, m_q = m_p",
            printed=0.98,
            book=bk,
            rigorous=rg,
            model=s.conventional(s.a60, s.p60),
            verdict=RULE,
            note="from printed inputs: the intermediates printed before (6.45), the printed (5.54) "
            f"and (5.55) of chapter 5, unrounded: {pr:.4f}; the 0.24 and 0.95 the book prints "
            "after it ((6.51), (6.54)) give "
            f"√(0.24² + (0.95 p/f)²) = {math.hypot(0.24, 0.95 * s.p60 / s.f):.4f}; the "
            "integral of (5.53) gives the book value",
            from_printed_inputs=pr,
            digits=2,
            upstream="(5.55)",
            procedure=ProcedureMeasure("60", "conventional"),
        )
    )


@ROWS.row
def eq_6_46(s: Setting) -> Entry:
    pr, bk, rg = s.conventional_values(s.a80, s.p80)
    return s.convention_off_book(
        Entry(
            eq="(6.46)",
            quantity=f"m_p⁰/m_p conventional, 80 %, p = {s.p80:g}, m_q = m_p",
            printed=0.67,
            book=bk,
            rigorous=rg,
            model=s.conventional(s.a80, s.p80),
            verdict="not reproducible",
            note="tried: from the intermediates printed before (6.46), the printed (5.54)/(5.55) "
            f"unrounded, {pr:.4f}; with the 0.33 and 0.63 printed after it ((6.52), (6.55)) "
            f"√(0.33² + (0.63 p/f)²) = {math.hypot(0.33, 0.63 * s.p80 / s.f):.4f}; "
            "√(0.63² + 0.23²) = 0.671 (p/f dropped and the 60 % m_p,в used) is the only reading "
            "found that gives 0.67",
            from_printed_inputs=pr,
            digits=2,
            procedure=ProcedureMeasure("80", "conventional"),
        )
    )
