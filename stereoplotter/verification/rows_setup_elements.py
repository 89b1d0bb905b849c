"""Rows of §27 problem 1, the formula and the setup elements: (6.28)–(6.30) the parallax of
unadjusted setup data at generic σ's, (6.31)–(6.38) the σ's of the setup elements from the
fiducial readings (m_x = m_y = 1)."""

from __future__ import annotations

import numpy as np

from stereoplotter.accuracy import setup_accuracy as sa
from stereoplotter.verification import linear_mc as mc
from stereoplotter.verification.entry import GENERIC_SIGMAS, RULE, Entry, Setting, both_photos

__all__ = ["setup_element_entries", "unadjusted_generic_entries"]


def _unadjusted_generic(s: Setting, eq: str, a: float, p: float, label: str) -> Entry:
    gs = GENERIC_SIGMAS
    f, cc = s.f, a + p
    sig = (gs["base_x"], gs["alpha"], gs["omega"], gs["kappa"], gs["base_z"])
    bk = sa.setup_parallax_rms_unadjusted(f, p, cc, *sig)
    return Entry(
        eq,
        f"m_p⁰ [mm], {label}, c = {cc:g}, generic σ's"
        + (" (the book's example geometry, fixed)" if eq == "(6.28)" else ""),
        sa.setup_parallax_rms_unadjusted_printed(f, p, a, cc, *sig),
        bk,
        bk,
        mc.setup_model(f, p, a, cc, both_photos(gs), levelled=False),
        RULE,
        "integral (6.27) of (6.26) over x_л ∈ [0,c], y ∈ [−c,c]; σ's "
        + ", ".join(f"{k}={v:g}" for k, v in gs.items()),
    )


def unadjusted_generic_entries(s: Setting) -> list[Entry]:
    """(6.28) at the book's example geometry a = 20, p = 50; (6.29), (6.30) at 60 %, 80 %."""
    return [
        _unadjusted_generic(s, "(6.28)", 20.0, 50.0, "a = 20, p = 50"),
        _unadjusted_generic(s, "(6.29)", s.a60, s.p60, "60 %"),
        _unadjusted_generic(s, "(6.30)", s.a80, s.p80, "80 %"),
    ]


def _design_31(s: Setting):
    """(6.31)/(6.32): x readings at the centre mark and a mark at x = l."""
    return np.array([[1.0, 0.0], [1.0, s.l**2 / s.f]])


def _design_33(s: Setting):
    """(6.33)–(6.35): y readings at the centre mark and two marks at ±l."""
    return np.array([[1.0, 0.0], [1.0, s.l**2 / s.f], [1.0, s.l**2 / s.f]])


def eq_6_31(s: Setting) -> Entry:
    n = s.n
    return Entry(
        "(6.31)",
        "m_Δx per m_x (decentration)",
        1 / n,
        1 / n,
        1 / n,
        mc.least_squares_model(_design_31(s), 1 / n, 0),
        RULE,
        "observation equations; mark at x = l gives (l²/f)α, fα joins Δx ((3.22))",
    )


def eq_6_32(s: Setting) -> Entry:
    m_a = sa.sigma_alpha_setup(s.f, s.l, s.n, 1.0)
    return Entry(
        "(6.32)",
        "m_α per m_x [rad/mm]",
        m_a,
        m_a,
        m_a,
        mc.least_squares_model(_design_31(s), 1 / s.n, 1),
        RULE,
        "f√2/(n l²)",
    )


def eq_6_33(s: Setting) -> Entry:
    n = s.n
    return Entry(
        "(6.33)",
        "m_Δy per m_y",
        1 / n,
        1 / n,
        1 / n,
        mc.least_squares_model(_design_33(s), 1 / n, 0),
        RULE,
        "least squares of (6.33)",
    )


def eq_6_34(s: Setting) -> Entry:
    f, ll, n = s.f, s.l, s.n
    return Entry(
        "(6.34)",
        "Q_ωω [rad²/mm²]",
        3 * f**2 / (4 * ll**4 * n**2),
        3 * f**2 / (2 * ll**4 * n**2),
        3 * f**2 / (2 * ll**4 * n**2),
        mc.least_squares_model(_design_33(s), 1 / n, 1),
        RULE,
        "least squares of (6.33) gives 3f²/(2l⁴n²), not 3f²/(4l⁴n²); Q_ΔyΔy = 1/n² reproduces",
        squared=True,
    )


def eq_6_35(s: Setting) -> Entry:
    w_b = sa.sigma_omega_setup(s.f, s.l, s.n, 1.0, "book")
    return Entry(
        "(6.35)",
        "m_ω per m_y [rad/mm]",
        sa.sigma_omega_setup(s.f, s.l, s.n, 1.0, "printed"),
        w_b,
        w_b,
        mc.least_squares_model(_design_33(s), 1 / s.n, 1),
        RULE,
        "f√3/(2l²n) printed; (6.33) gives f√(3/2)/(l²n), which the book's own (6.39) (51 = "
        "36 + 15) and (6.40) (456 = 306 + 150) use",
    )


def eq_6_36(s: Setting) -> Entry:
    m_k = sa.sigma_kappa_setup(s.l, s.n, 1.0)
    return Entry(
        "(6.36)",
        "m_κ per m_x [rad/mm]",
        m_k,
        m_k,
        m_k,
        mc.least_squares_model(np.array([[1.0, -s.l], [1.0, s.l]]), 1 / s.n, 1),
        RULE,
        "x readings at marks y = ±l_y",
    )


def eq_6_37(s: Setting) -> Entry:
    m_bz = sa.sigma_base_z_setup(s.f, s.l, 1.0)
    m_bz_photo = sa.sigma_base_z_setup_photo(s.f, s.l, s.n, 1.0)
    return Entry(
        "(6.37)",
        f"m_bz per m_y, photo scale (printed/book: f_пр = f = {s.f:g}, instrument units)",
        m_bz,
        m_bz,
        m_bz_photo,
        mc.least_squares_model(np.array([[s.l / s.f]]), 1 / s.n, 0),
        RULE,
        "printed f_пр m_y/l_y is in instrument units (model scale; one y reading at a mark at "
        "l_y, δY = l_y δb_z/f_пр); at the photo scale of (6.26) divide by n (as the other "
        f"counter rows) and multiply by f/f_пр: f m_y/(n l_y) = {m_bz_photo:.4f} "
        "(docs/errata.md)",
    )


def eq_6_38(s: Setting) -> Entry:
    m_bx = sa.sigma_base_x_setup(s.n, 1.0)
    return Entry(
        "(6.38)",
        "m_bx per m_x",
        m_bx,
        m_bx,
        m_bx,
        mc.least_squares_model(np.array([[1.0, 0.0], [1.0, 1.0]]), 1 / s.n, 1),
        RULE,
        "difference of two readings",
    )


def setup_element_entries(s: Setting) -> list[Entry]:
    """(6.31)–(6.38), in the table's order."""
    return [
        eq_6_31(s),
        eq_6_32(s),
        eq_6_33(s),
        eq_6_34(s),
        eq_6_35(s),
        eq_6_36(s),
        eq_6_37(s),
        eq_6_38(s),
    ]
