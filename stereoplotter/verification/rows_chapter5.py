"""Rows of chapter 5: Tables 19 and 20 (cofactors of relative orientation and levelling) and
(5.19)–(5.58) (parallax and height errors of a single model)."""

from __future__ import annotations

import math

import numpy as np

from stereoplotter.accuracy import chapter5 as c5
from stereoplotter.verification import linear_mc as mc
from stereoplotter.verification.entry import RULE, DeclaredRows, Entry, Setting
from stereoplotter.verification.linear_mc import FloatArray

__all__ = ["ROWS"]

#: The rows of chapter 5, in the table's order.
ROWS = DeclaredRows()


def _relative_design(s: Setting) -> FloatArray:
    _, xs, ys = c5.standard_points(s.a60, s.p60, s.c)
    design: FloatArray = c5.relative_orientation_design(xs, ys, s.p60, s.f)
    return design


@ROWS.row
def table19_alpha(s: Setting) -> Entry:
    q_aa = math.sqrt(c5.cofactor_alpha_relative(s.f, s.a60, s.c))
    return Entry(
        eq="Table 19",
        quantity="√Q_αα, m_Δα per m_q [rad/mm], 60 %",
        printed=None,
        book=q_aa,
        rigorous=q_aa,
        model=mc.least_squares_model(_relative_design(s), 1.0, 2),
        verdict=RULE,
        note="f/(c(a+c)); least squares on the six standard points of Fig. 39, (5.10) left system",
    )


@ROWS.row
def table19_omega(s: Setting) -> Entry:
    f, c = s.f, s.c
    q_ww = math.sqrt(c5.cofactor_omega_relative(f, c))
    return Entry(
        eq="Table 19",
        quantity="√Q_ωω, m_Δω per m_q [rad/mm]",
        printed=math.sqrt(3 * f**2 / (4 * c**2)),
        book=q_ww,
        rigorous=q_ww,
        model=mc.least_squares_model(_relative_design(s), 1.0, 3),
        verdict=RULE,
        note="printed 3f²/(4c²) is not dimensionless; 3f²/(4c⁴) as the text's "
        "m_ω₂′ = f√3 m_q/(2c²)",
    )


def _levelling_design(s: Setting) -> FloatArray:
    design: FloatArray = c5.levelling_design(*c5.control_points(s.a80, s.c))
    return design


@ROWS.row
def table20_eta(s: Setting) -> Entry:
    q_ee = math.sqrt(c5.cofactors_levelling(s.a80, s.c)[1, 1])
    return Entry(
        eq="Table 20",
        quantity="√Q_ηη, slope per unit control error [1/mm], 80 %",
        printed=1 / (s.a80 + s.c),
        book=q_ee,
        rigorous=q_ee,
        model=mc.least_squares_model(_levelling_design(s), 1.0, 1),
        verdict=RULE,
        note="1/(a + c)",
    )


@ROWS.row
def table20_xi(s: Setting) -> Entry:
    q_xx = math.sqrt(c5.cofactors_levelling(s.a80, s.c)[2, 2])
    return Entry(
        eq="Table 20",
        quantity="√Q_ξξ [1/mm], 80 %",
        printed=math.sqrt(s.f / (4 * s.c**2)),
        book=q_xx,
        rigorous=q_xx,
        model=mc.least_squares_model(_levelling_design(s), 1.0, 2),
        verdict=RULE,
        note="printed f/(4c²) (not dimensionless); least squares gives 1/(4c²)",
    )


def _book_point(s: Setting) -> tuple[FloatArray, FloatArray]:
    """The point of (5.19)/(5.20): book (−35, 35) at c = 70."""
    return (np.array([-s.c / 2]), np.array([s.c / 2]))


def _at_point(
    model: mc.LinearModel,
    a: float,
    c: float,
    p: float,
    f: float,
    pt: tuple[FloatArray, FloatArray],
) -> mc.LinearModel:
    G = mc.relative_field_basis(pt[0], pt[1], p, f)
    Hg = c5.levelling_design(*pt)
    Ac = c5.levelling_design(*c5.control_points(a, c))
    return mc.LinearModel(G, model.M, model.Gc, Hg @ np.linalg.pinv(Ac))


def _levelling_point_model(a: float, c: float, pt: tuple[FloatArray, FloatArray]) -> mc.LinearModel:
    G = np.zeros((1, 1))
    Hg = c5.levelling_design(*pt)
    Ac = c5.levelling_design(*c5.control_points(a, c))
    return mc.LinearModel(G, np.zeros((1, 1)), np.zeros((1, 4)), Hg @ np.linalg.pinv(Ac), 1.0)


@ROWS.row
def eq_5_19(s: Setting) -> Entry:
    a8, c, p8, f = s.a80, s.c, s.p80, s.f
    pt = _book_point(s)
    b519 = c5.relative_orientation_residual_sigma(*pt, a8, c, f, 1.0, "book")[0]
    r519 = c5.relative_orientation_residual_sigma(*pt, a8, c, f, 1.0, "rigorous")[0]
    m519 = mc.relative_orientation_model(a8, c, p8, f, 1.0, grid=(1, 1))
    return Entry(
        eq="(5.19)",
        quantity=f"m_p,в/m_q at x_п = {-c / 2:g}, y = {c / 2:g} mm, 80 %",
        printed=None,
        book=b519,
        rigorous=r519,
        model=_at_point(m519, a8, c, p8, f, pt),
        verdict=RULE,
        note="(5.15) ω residual y(x_п + c/2) is the least-squares plane residual only for a = 0; "
        "exact: y(x_п + (c − a)/2)",
    )


@ROWS.row
def eq_5_20(s: Setting) -> Entry:
    c = s.c
    pt = _book_point(s)
    lv_pt = c5.geodetic_orientation_parallax_sigma(*pt, s.a80, c, 1.0)[0]
    return Entry(
        eq="(5.20)",
        quantity=f"levelling σ/m at x_п = {-c / 2:g}, y = {c / 2:g} mm, 80 %",
        printed=lv_pt,
        book=lv_pt,
        rigorous=lv_pt,
        model=_levelling_point_model(s.a80, c, pt),
        verdict=RULE,
        note="variance of the plane fitted at 4 control points (Table 20)",
    )


@ROWS.each_overlap
def eq_5_54(s: Setting, overlap: str) -> Entry:
    a, p = s.slot(overlap)
    bk = c5.relative_orientation_parallax_rms(a, s.c, p, 1.0, "book")
    rg = c5.relative_orientation_parallax_rms(a, s.c, p, 1.0, "rigorous")
    note = "integral (5.52) reproduces (1/48 inside the root)"
    if overlap == "80":
        note += f"; rigorous {rg:.4f} from the exact plane residual (5.19)"
    return Entry(
        eq="(5.54)",
        quantity=f"m_p,в/m_q over the pair, {overlap} %",
        printed=bk,
        book=bk,
        rigorous=rg,
        model=mc.relative_orientation_model(a, s.c, p, s.f, 1.0),
        verdict=RULE,
        note=note,
        upstream="(5.19)",
    )


_NOTE_5_55 = {
    "60": (
        "not reproducible",
        "printed (7a²+11c²−4ac)/(12(a+c)²) is not the integral (5.53): domain "
        "[−c,0] gives (7a²+8ac+5c²), [−c,c] (7a²+2ac+11c²), [0,c] (7a²−4ac+17c²); "
        "equal only for c = 2a",
    ),
    "80": (
        "convention",
        "c = 2a: printed = integral. Two readings of the control heights' error: the book's "
        "(p/f)·m_p and the rigorous m_p of (5.42), which gives k·m_p without the factor p/f "
        "(docs/errata.md (5.17)/(5.20))",
    ),
}


@ROWS.each_overlap
def eq_5_55(s: Setting, overlap: str) -> Entry:
    a, p = s.slot(overlap)
    verdict, note = _NOTE_5_55[overlap]
    return Entry(
        eq="(5.55)",
        quantity=f"m_p,г/m_p over the pair, {overlap} %, f = {s.f:g}",
        printed=s.geodetic(a, p, "printed"),
        book=s.geodetic(a, p, "book"),
        rigorous=s.geodetic(a, p, "rigorous"),
        model=mc.relative_orientation_model(a, s.c, p, s.f, 0.0, sigma_control_mm=1.0),
        verdict=verdict,
        note=note,
    )


@ROWS.each_overlap
def eq_5_57_58(s: Setting, overlap: str) -> Entry:
    """(5.57) at 60 %, (5.58) at 80 %: height error of a single model."""
    a, p = s.slot(overlap)
    c, f = s.c, s.f
    note = "Δr_max = 0, m_q = m_p/√2; printed form drops the relative-orientation term of (5.56)"
    if overlap == "60":
        note += "; and inherits the printed (5.55)"
    return Entry(
        eq="(5.57)" if overlap == "60" else "(5.58)",
        quantity=f"m_h·p/(H·m_p), {overlap} %, f = {f:g}, p = {p:g}",
        printed=c5.single_model_height_rms(a, c, p, f, 1.0, "printed"),
        book=c5.single_model_height_rms(a, c, p, f, 1.0, "book"),
        rigorous=c5.single_model_height_rms(a, c, p, f, 1.0, "rigorous"),
        model=s.single_model(a, p),
        verdict="not reproducible" if overlap == "60" else RULE,
        note=note,
    )


@ROWS.row
def eq_5_43(s: Setting) -> Entry:
    rg43 = c5.single_model_height_rms(s.a60, s.c, s.p60, s.f, 1.0, "rigorous")
    return Entry(
        eq="(5.43)",
        quantity="quadrature sum of independent errors, 60 % (as (5.57))",
        printed=None,
        book=rg43,
        rigorous=rg43,
        model=s.single_model(s.a60, s.p60),
        verdict=RULE,
        note="MC of the summed fields confirms independence (no cross terms)",
    )
