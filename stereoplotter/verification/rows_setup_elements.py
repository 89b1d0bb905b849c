"""Rows of §27 problem 1, the formula and the setup elements: (6.28)–(6.30) the parallax of
unadjusted setup data at generic σ's, (6.31)–(6.38) the σ's of the setup elements from the
fiducial readings (m_x = m_y = 1)."""

from __future__ import annotations

import numpy as np

from stereoplotter.accuracy import setup_accuracy as sa
from stereoplotter.verification import linear_mc as mc
from stereoplotter.verification.entry import (
    GENERIC_SIGMAS,
    RULE,
    DeclaredRows,
    Entry,
    Setting,
    both_photos,
)
from stereoplotter.verification.linear_mc import FloatArray

__all__ = ["ROWS"]

#: The rows of (6.28)–(6.38), in the table's order.
ROWS = DeclaredRows()


def _unadjusted_generic(s: Setting, eq: str, a: float, p: float, label: str) -> Entry:
    gs = GENERIC_SIGMAS
    f, cc = s.f, a + p
    sig = (gs["base_x"], gs["alpha"], gs["omega"], gs["kappa"], gs["base_z"])
    bk = sa.setup_parallax_rms_unadjusted(f, p, cc, *sig)
    return Entry(
        eq=eq,
        quantity=f"m_p⁰ [mm], {label}, c = {cc:g}, generic σ's"
        + (" (the book's example geometry, fixed)" if eq == "(6.28)" else ""),
        printed=sa.setup_parallax_rms_unadjusted_printed(f, p, a, cc, *sig),
        book=bk,
        rigorous=bk,
        model=mc.setup_model(f, p, a, cc, both_photos(gs), levelled=False),
        verdict=RULE,
        note="integral (6.27) of (6.26) over x_л ∈ [0,c], y ∈ [−c,c]; σ's "
        + ", ".join(f"{k}={v:g}" for k, v in gs.items()),
    )


@ROWS.row
def eq_6_28(s: Setting) -> Entry:
    """(6.28) at the book's example geometry a = 20, p = 50."""
    return _unadjusted_generic(s, "(6.28)", 20.0, 50.0, "a = 20, p = 50")


@ROWS.row
def eq_6_29(s: Setting) -> Entry:
    return _unadjusted_generic(s, "(6.29)", s.a60, s.p60, "60 %")


@ROWS.row
def eq_6_30(s: Setting) -> Entry:
    return _unadjusted_generic(s, "(6.30)", s.a80, s.p80, "80 %")


def _design_31(s: Setting) -> FloatArray:
    """(6.31)/(6.32): x readings at the centre mark and a mark at x = l."""
    return np.array([[1.0, 0.0], [1.0, s.l**2 / s.f]])


def _design_33(s: Setting) -> FloatArray:
    """(6.33)–(6.35): y readings at the centre mark and two marks at ±l."""
    return np.array([[1.0, 0.0], [1.0, s.l**2 / s.f], [1.0, s.l**2 / s.f]])


@ROWS.row
def eq_6_31(s: Setting) -> Entry:
    n = s.n
    return Entry(
        eq="(6.31)",
        quantity="m_Δx per m_x (decentration)",
        printed=1 / n,
        book=1 / n,
        rigorous=1 / n,
        model=mc.least_squares_model(_design_31(s), 1 / n, 0),
        verdict=RULE,
        note="observation equations; mark at x = l gives (l²/f)α, fα joins Δx ((3.22))",
    )


@ROWS.row
def eq_6_32(s: Setting) -> Entry:
    m_a = sa.sigma_alpha_setup(s.f, s.l, s.n, 1.0)
    return Entry(
        eq="(6.32)",
        quantity="m_α per m_x [rad/mm]",
        printed=m_a,
        book=m_a,
        rigorous=m_a,
        model=mc.least_squares_model(_design_31(s), 1 / s.n, 1),
        verdict=RULE,
        note="f√2/(n l²)",
    )


@ROWS.row
def eq_6_33(s: Setting) -> Entry:
    n = s.n
    return Entry(
        eq="(6.33)",
        quantity="m_Δy per m_y",
        printed=1 / n,
        book=1 / n,
        rigorous=1 / n,
        model=mc.least_squares_model(_design_33(s), 1 / n, 0),
        verdict=RULE,
        note="least squares of (6.33)",
    )


@ROWS.row
def eq_6_34(s: Setting) -> Entry:
    f, ll, n = s.f, s.l, s.n
    return Entry(
        eq="(6.34)",
        quantity="Q_ωω [rad²/mm²]",
        printed=3 * f**2 / (4 * ll**4 * n**2),
        book=3 * f**2 / (2 * ll**4 * n**2),
        rigorous=3 * f**2 / (2 * ll**4 * n**2),
        model=mc.least_squares_model(_design_33(s), 1 / n, 1),
        verdict=RULE,
        note="least squares of (6.33) gives 3f²/(2l⁴n²), not 3f²/(4l⁴n²); Q_ΔyΔy = 1/n² reproduces",
        squared=True,
    )


@ROWS.row
def eq_6_35(s: Setting) -> Entry:
    w_b = sa.sigma_omega_setup(s.f, s.l, s.n, 1.0, "book")
    return Entry(
        eq="(6.35)",
        quantity="m_ω per m_y [rad/mm]",
        printed=sa.sigma_omega_setup(s.f, s.l, s.n, 1.0, "printed"),
        book=w_b,
        rigorous=w_b,
        model=mc.least_squares_model(_design_33(s), 1 / s.n, 1),
        verdict=RULE,
        note="f√3/(2l²n) printed; (6.33) gives f√(3/2)/(l²n), which the book's own (6.39) (51 = "
        "36 + 15) and (6.40) (456 = 306 + 150) use",
    )


@ROWS.row
def eq_6_36(s: Setting) -> Entry:
    m_k = sa.sigma_kappa_setup(s.l, s.n, 1.0)
    return Entry(
        eq="(6.36)",
        quantity="m_κ per m_x [rad/mm]",
        printed=m_k,
        book=m_k,
        rigorous=m_k,
        model=mc.least_squares_model(np.array([[1.0, -s.l], [1.0, s.l]]), 1 / s.n, 1),
        verdict=RULE,
        note="x readings at marks y = ±l_y",
    )


@ROWS.row
def eq_6_37(s: Setting) -> Entry:
    m_bz = sa.sigma_base_z_setup(s.f, s.l, 1.0)
    m_bz_photo = sa.sigma_base_z_setup_photo(s.f, s.l, s.n, 1.0)
    return Entry(
        eq="(6.37)",
        quantity=f"m_bz per m_y, photo scale (printed/book: f_пр = f = {s.f:g}, instrument units)",
        printed=m_bz,
        book=m_bz,
        rigorous=m_bz_photo,
        model=mc.least_squares_model(np.array([[s.l / s.f]]), 1 / s.n, 0),
        verdict=RULE,
        note="printed f_пр m_y/l_y is in instrument units (model scale; one y reading at a mark at "
        "l_y, δY = l_y δb_z/f_пр); at the photo scale of (6.26) divide by n (as the other "
        f"counter rows) and multiply by f/f_пр: f m_y/(n l_y) = {m_bz_photo:.4f} "
        "(docs/errata.md)",
    )


@ROWS.row
def eq_6_38(s: Setting) -> Entry:
    m_bx = sa.sigma_base_x_setup(s.n, 1.0)
    return Entry(
        eq="(6.38)",
        quantity="m_bx per m_x",
        printed=m_bx,
        book=m_bx,
        rigorous=m_bx,
        model=mc.least_squares_model(np.array([[1.0, 0.0], [1.0, 1.0]]), 1 / s.n, 1),
        verdict=RULE,
        note="difference of two readings",
    )
