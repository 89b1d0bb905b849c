"""Rows of §27 problem 2, setup data with levelling against the conventional method:
(6.47)–(6.50) the relative residual of setup data, (6.51)–(6.57) the conventional terms, and the
closing pair (6.58)–(6.61) (m_q = m_p = 1, m_xy = √2 m_p)."""

from __future__ import annotations

import math

from stereoplotter.accuracy import chapter5 as c5
from stereoplotter.accuracy import setup_accuracy as sa
from stereoplotter.verification.entry import RULE, DeclaredRows, Entry, ProcedureMeasure, Setting

__all__ = ["ROWS"]

#: The rows of (6.47)–(6.61), in the table's order.
ROWS = DeclaredRows()


def _residual(s: Setting, overlap: str, mode: str, m_xy: float = 1.0) -> float:
    a, _ = s.slot(overlap)
    return float(sa.setup_relative_residual_rms(a, s.c, s.f, s.l, s.n, m_xy, mode))


def _residual_printed(s: Setting, overlap: str) -> float:
    a, _ = s.slot(overlap)
    return float(sa.setup_relative_residual_rms_printed(a, s.c, s.l, s.n, 1.0))


def _residual_entry(
    s: Setting,
    eq: str,
    overlap: str,
    quantity: str,
    printed: float | None,
    verdict: str,
    note: str,
    *,
    from_printed_inputs: float | None = None,
    digits: int | None = None,
    upstream: str | None = None,
) -> Entry:
    """m_p,во/m_xy of setup data after levelling on exact control ((6.47)–(6.50))."""
    a, p = s.slot(overlap)
    return Entry(
        eq=eq,
        quantity=quantity,
        printed=printed,
        book=_residual(s, overlap, "book"),
        rigorous=_residual(s, overlap, "rigorous"),
        model=s.levelled(a, p, s.setup_sigmas()),
        verdict=verdict,
        note=note,
        from_printed_inputs=from_printed_inputs,
        digits=digits,
        upstream=upstream,
        procedure=ProcedureMeasure(overlap, "setup", "levelled"),
    )


@ROWS.row
def eq_6_47(s: Setting) -> Entry:
    return _residual_entry(
        s,
        "(6.47)",
        "60",
        "m_p,во/m_xy setup data after levelling, 60 %",
        None,
        RULE,
        "(6.47) carries one m_α, m_ω; both photos' errors enter (residual ∝ α_л − α_п, "
        "ω_л − ω_п): variance ×2",
    )


@ROWS.row
def eq_6_48(s: Setting) -> Entry:
    return _residual_entry(
        s,
        "(6.48)",
        "80",
        "m_p,во/m_xy, formula at 80 %",
        _residual_printed(s, "80"),
        RULE,
        "the integral of (6.47) with the printed (6.32), (6.35) gives (…)/(15c²), not /21 "
        "(sympy, tests/reference); rigorous: the least-squares (6.35) (1/24 for 1/48), the "
        "second photo and the exact ω residual",
    )


@ROWS.row
def eq_6_49(s: Setting) -> Entry:
    return _residual_entry(
        s,
        "(6.49)",
        "60",
        "m_p,во/m_xy, 60 %",
        0.12,
        RULE,
        "from printed inputs: the printed (6.48) at 60 %; its coefficients are wrong, see (6.48)",
        from_printed_inputs=_residual_printed(s, "60"),
        digits=2,
        upstream="(6.48)",
    )


@ROWS.row
def eq_6_50(s: Setting) -> Entry:
    return _residual_entry(
        s,
        "(6.50)",
        "80",
        "m_p,во/m_xy, 80 %",
        0.12,
        "not reproducible",
        "tried: the printed (6.48) at 80 % (its /21 is not derived from (6.47), whose "
        "integral gives /(15c²)) "
        f"{_residual_printed(s, '80'):.4f}; the integral of (6.47) with the printed (6.32), "
        f"(6.35) {_residual(s, '80', 'book'):.4f}; 0.12 equals the 60 % value (6.49)",
        from_printed_inputs=_residual_printed(s, "80"),
        digits=2,
        upstream="(6.48)",
    )


def _relative(s: Setting, overlap: str, mode: str) -> float:
    a, p = s.slot(overlap)
    return float(c5.relative_orientation_parallax_rms(a, s.c, p, 1.0, mode))


def _relative_entry(
    s: Setting, eq: str, overlap: str, printed: float, verdict: str, note: str
) -> Entry:
    """m_p,во/m_q of the conventional method ((5.54)), relative orientation only; the printed
    number has 2 decimals; at 80 % the rigorous value inherits the (5.19) residual."""
    a, p = s.slot(overlap)
    return Entry(
        eq=eq,
        quantity=f"m_p,во/m_q conventional, {overlap} %",
        printed=printed,
        book=_relative(s, overlap, "book"),
        rigorous=_relative(s, overlap, "rigorous" if overlap == "80" else "book"),
        model=s.conventional(a, p, sc=0.0),
        verdict=verdict,
        note=note,
        digits=2,
        upstream="(5.19)",
        procedure=ProcedureMeasure(overlap, "y_parallax"),
    )


@ROWS.row
def eq_6_51(s: Setting) -> Entry:
    ro6 = _relative(s, "60", "book")
    return _relative_entry(
        s,
        "(6.51)",
        "60",
        0.24,
        RULE,
        f"(5.54) gives {ro6:.4f}; the book's own (6.56) prints 0.23",
    )


@ROWS.row
def eq_6_52(s: Setting) -> Entry:
    ro8b, ro8r = _relative(s, "80", "book"), _relative(s, "80", "rigorous")
    return _relative_entry(
        s,
        "(6.52)",
        "80",
        0.33,
        RULE,
        f"(5.54) {ro8b:.4f}; rigorous (exact plane residual) {ro8r:.4f}",
    )


@ROWS.row
def eq_6_53(s: Setting) -> Entry:
    _, bk, rg = s.conventional_values(s.a80, s.p80)
    return Entry(
        eq="(6.53)",
        quantity="M_p/m_p = √(m²_во + m²_го), conventional 80 %",
        printed=None,
        book=bk,
        rigorous=rg,
        model=s.conventional(s.a80, s.p80),
        verdict="convention",
        note="independent sources: MC of the summed fields has no cross term; book and rigorous "
        "differ by the readings of (6.55) (control heights (p/f)·m_p versus k·m_p) and the "
        "exact (5.19) residual",
        procedure=ProcedureMeasure("80", "conventional"),
    )


@ROWS.row
def eq_6_54(s: Setting) -> Entry:
    g6 = [s.geodetic(s.a60, s.p60, m) for m in ("printed", "book", "rigorous")]
    return s.convention_off_book(
        Entry(
            eq="(6.54)",
            quantity=f"coefficient k of (k·p/f)·m_p, 60 %, p = {s.p60:g}",
            printed=0.95,
            book=g6[1],
            rigorous=g6[2],
            model=s.conventional(s.a60, s.p60, sq=0.0),
            verdict=RULE,
            note="from printed inputs: the printed (5.55) at 60 %; (5.55) is not its integral, "
            "see (5.55) 60 %; 0.12 m_xy as (6.49)",
            from_printed_inputs=g6[0],
            digits=2,
            upstream="(5.55)",
            procedure=ProcedureMeasure("60", "stereo"),
        )
    )


@ROWS.row
def eq_6_55(s: Setting) -> Entry:
    f, p8 = s.f, s.p80
    g8 = [s.geodetic(s.a80, p8, m) * f / p8 for m in ("printed", "book", "rigorous")]
    return Entry(
        eq="(6.55)",
        quantity="coefficient k of (k·p/f)·m_p, 80 %",
        printed=0.63,
        book=g8[1],
        rigorous=g8[2],
        model=s.conventional(s.a80, p8, sq=0.0),
        verdict="convention",
        note="√(43/108) = 0.6310. Two readings of the 80 % control heights' error: the book's "
        "(k·p/f)·m_p and the rigorous k·m_p (a control height measured in the model has error "
        "(H/p)m_p, (5.42); docs/errata.md (5.17)/(5.20)), i.e. k·f/p in this row's unit",
        scale=f / p8,
        digits=2,
        procedure=ProcedureMeasure("80", "stereo", scaled=True),  # the row's unit: k·f/p
    )


@ROWS.row
def eq_6_56(s: Setting) -> Entry:
    ro6 = _relative(s, "60", "book")
    return _relative_entry(s, "(6.56)", "60", 0.23, RULE, f"(5.54) {ro6:.4f}; 0.95 term as (6.54)")


@ROWS.row
def eq_6_57(s: Setting) -> Entry:
    return _relative_entry(s, "(6.57)", "80", 0.33, RULE, "as (6.52); 0.63 term as (6.55)")


def _label(s: Setting, p: float) -> str:
    """The overlap named in (6.58)–(6.61): "60" whenever p is the 60 % slot's p."""
    return "60" if p == s.p60 else "80"


def _setup_levelled(
    s: Setting, eq: str, overlap: str, printed: float, chain: float, upstream: str
) -> Entry:
    """(6.58)/(6.59): setup data + levelling, M_p/m_p with m_p = m_q = m_xy/√2."""
    a, p = s.slot(overlap)
    r2 = s.r2
    bk = math.hypot(_residual(s, overlap, "book", r2), s.geodetic(a, p, "book"))
    rg = math.hypot(_residual(s, overlap, "rigorous", r2), s.geodetic(a, p, "rigorous"))
    return s.convention_off_book(
        Entry(
            eq=eq,
            quantity=f"M_p/m_p setup data + levelling, {_label(s, p)} %, f = {s.f:g}, "
            "m_p = m_q = m_xy/√2",
            printed=printed,
            book=bk,
            rigorous=rg,
            model=s.levelled(a, p, s.setup_sigmas(r2), control=1.0),
            verdict=RULE,
            note="from printed inputs: √((0.12·√2)² + (k·p/f)²) with the printed 0.12 of "
            + (
                "(6.49) and k = 0.95 of (6.54)"
                if eq == "(6.58)"
                else "(6.50) and k = 0.63 of (6.55)"
            )
            + ", m_xy = √2 m_p"
            + (
                ""
                if eq == "(6.58)"
                else "; the rigorous value also takes the k·m_p reading of (6.55)"
            ),
            from_printed_inputs=chain,
            digits=2,
            upstream=upstream,
            procedure=ProcedureMeasure(overlap, "setup", "observed"),
        )
    )


@ROWS.row
def eq_6_58(s: Setting) -> Entry:
    chain = math.hypot(0.12 * s.r2, 0.95 * s.p60 / s.f)
    return _setup_levelled(s, "(6.58)", "60", 0.96, chain, "(6.49), (6.54)")


@ROWS.row
def eq_6_59(s: Setting) -> Entry:
    chain = math.hypot(0.12 * s.r2, 0.63 * s.p80 / s.f)
    return _setup_levelled(s, "(6.59)", "80", 0.35, chain, "(6.50)")


def _conventional_total(
    s: Setting, eq: str, overlap: str, printed: float, verdict: str, note: str, chain: float
) -> Entry:
    a, p = s.slot(overlap)
    _, bk, rg = s.conventional_values(a, p)
    return Entry(
        eq=eq,
        quantity=f"M_p/m_p conventional, {_label(s, p)} %, f = {s.f:g}",
        printed=printed,
        book=bk,
        rigorous=rg,
        model=s.conventional(a, p),
        verdict=verdict,
        note=note,
        from_printed_inputs=chain,
        digits=2,
        procedure=ProcedureMeasure(overlap, "conventional"),
    )


@ROWS.row
def eq_6_60(s: Setting) -> Entry:
    chain = math.hypot(0.23, 0.95 * s.p60 / s.f)
    return s.convention_off_book(
        _conventional_total(
            s,
            "(6.60)",
            "60",
            0.96,
            "not reproducible",
            "tried: from printed inputs √(0.23² + 0.95²) with (6.56), m_q = m_p; m_q = m_p/√2 "
            "gives 0.964 but then (6.61) would be 0.39; book-mode value from the correct (5.55)",
            chain,
        )
    )


@ROWS.row
def eq_6_61(s: Setting) -> Entry:
    chain = math.hypot(0.33, 0.63 * s.p80 / s.f)
    return _conventional_total(
        s,
        "(6.61)",
        "80",
        0.45,
        "convention",
        "from printed inputs: √(0.33² + (0.63 p/f)²) with (6.57); book and rigorous differ by "
        "the readings of (6.55): control heights (k·p/f)·m_p (book) versus k·m_p (rigorous), "
        "and the exact (5.19) residual",
        chain,
    )
