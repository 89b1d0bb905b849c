"""Reference tests: Kushtin & Lyskov 1984, ch. 5 §22-§24 (OCR L2836-3451) and §27 (L3827-4030).

Printed values are typed as printed; tolerance half a unit of the last printed digit unless a
comment says otherwise. Where the book is wrong the corrected value is pinned with ``ERRATA:``.
Closed forms are checked against sympy integrals (the derivation, not hand algebra).
"""

import math

import numpy as np
import pytest
import sympy as sp

from stereoplotter.accuracy import chapter5 as c5
from stereoplotter.accuracy import setup_accuracy as sa
from stereoplotter.geometry import rotation
from stereoplotter.verification.verdicts import printed_agreement

F, L, N, C = 70.0, 85.0, 1.42, 70.0  # §27 book geometry (OCR L3973-3990)
P60, A60, P80, A80 = 70.0, 0.0, 35.0, 35.0
R2 = math.sqrt(2.0)

x, y, a, c, p, f = sp.symbols("x y a c p f", real=True)


def _mean(expr, xlo, xhi):
    return sp.integrate(sp.integrate(expr, (x, xlo, xhi)), (y, -c, c)) / (2 * c * (xhi - xlo))


# --- derivations (sympy) ------------------------------------------------------------------


def test_628_printed_polynomial_is_the_integral_627():
    # (6.26) integrated over x_л ∈ [0, c], y ∈ [−c, c] (6.27), with x_п = x_л − p, a = c − p
    ma, mw, mk, mbx, mbz = sp.symbols("ma mw mk mbx mbz", positive=True)
    xr = x - p
    var = (
        mbx**2
        + (x**4 + xr**4) / f**2 * ma**2
        + y**2 * (x**2 + xr**2) / f**2 * mw**2
        + 2 * y**2 * mk**2
        + xr**2 / f**2 * mbz**2
    )
    integral = _mean(var, 0, c)
    printed = (
        45 * mbx**2 * f**2
        + 9 * (c**3 * (2 * a - 3 * p) + 5 * p**2 * (2 * a * c + p**2)) * ma**2
        + 5 * c**2 * (c * (2 * a - p) + 3 * p**2) * mw**2
        + 30 * c**2 * f**2 * mk**2
        + 15 * mbz**2 * (c * (a - 2 * p) + 3 * p**2)
    ) / (45 * f**2)
    assert sp.simplify(sp.expand(integral - printed.subs(a, c - p))) == 0


def test_654_alpha_term_of_554_is_the_integral_552():
    # the α term of (5.54) is the integral (5.52) of (x² + xp − ac)²/(c²(a + c)²) over
    # x_п ∈ [−c, 0] (sympy); the project's (5.54) is that term plus the ω term 1/48
    integral = sp.integrate((x**2 + x * p - a * c) ** 2, (x, -c, 0)) / c / c**2 / (a + c) ** 2
    printed = (6 * c**2 + 10 * a * c - 5 * p * (2 * a + c)) / (30 * (a + c) ** 2)
    assert sp.simplify((integral - printed).subs(p, c - a)) == 0
    for aa, cc in ((0.0, 70.0), (35.0, 70.0), (20.0, 70.0)):
        alpha_term = float(integral.subs({a: aa, c: cc, p: cc - aa}))
        got = c5.relative_orientation_parallax_rms(aa, cc, cc - aa, 1.0, "book")
        assert got**2 == pytest.approx(1 / 48 + alpha_term, rel=1e-12)


def test_555_printed_is_not_the_integral_553():
    # ERRATA: (5.55) prints (7a² + 11c² − 4ac); the integral of (5.53) over its stated domain
    # x_п ∈ [−c, 0] gives (7a² + 8ac + 5c²). They agree only at c = 2a (80 % overlap).
    g = (
        x**2 / (a + c) ** 2
        + y**2 / (4 * c**2)
        + (a**2 + c**2) / (2 * (a + c) ** 2)
        + x * (c - a) / (a + c) ** 2
    )
    k = sp.factor(sp.simplify(_mean(g, -c, 0) * 12 * (a + c) ** 2))
    assert sp.expand(k - (7 * a**2 + 8 * a * c + 5 * c**2)) == 0
    assert sp.expand(k - (7 * a**2 + 11 * c**2 - 4 * a * c)).subs(c, 2 * a) == 0


def test_648_is_the_integral_of_647():
    # ERRATA: (6.47) with the printed m_α = f√2/(n l²) (6.32) and m_ω = f√3/(2 l² n) (6.35),
    # integrated over x_п ∈ [−c, 0], y ∈ [−c, c] (sympy): c²/(n l²)·√(1/48 + (6c² + 10ac −
    # 5p(2a + c))/(15c²)) with p = c − a; the book prints /21 for /(15c²). The project's book
    # mode is that integral.
    ll, nn = sp.symbols("l n", positive=True)
    m_a, m_w = f * sp.sqrt(2) / (nn * ll**2), f * sp.sqrt(3) / (2 * ll**2 * nn)
    var = (y**2 * (x + c / 2) ** 2 * m_w**2 + (x - a) ** 2 * (x + c) ** 2 * m_a**2) / f**2
    integral = _mean(var, -c, 0)
    closed = (c**2 / (nn * ll**2)) ** 2 * (
        sp.Rational(1, 48) + (6 * c**2 + 10 * a * c - 5 * p * (2 * a + c)) / (15 * c**2)
    )
    assert sp.simplify(sp.expand(integral - closed.subs(p, c - a))) == 0
    for aa in (A60, A80, 20.0):
        v = float(sp.sqrt(integral.subs({a: aa, c: C, f: F, ll: L, nn: N})))
        assert sa.setup_relative_residual_rms(aa, C, F, L, N, 1.0, "book") == pytest.approx(
            v, rel=1e-12
        )


def test_634_least_squares_of_633():
    # ERRATA: (6.34) prints Q_ωω = 3f²/(4l⁴n²); (6.33) solved by least squares gives 3f²/(2l⁴n²)
    Lq, n = sp.symbols("L n", positive=True)  # L = l²/f
    A = sp.Matrix([[1, 0], [1, Lq], [1, Lq]])
    Q = (A.T * A).inv() / n**2
    assert sp.simplify(Q[0, 0] - 1 / n**2) == 0
    assert sp.simplify(Q[1, 1] - sp.Rational(3, 2) / (Lq**2 * n**2)) == 0
    # the project's m_ω: rigorous = √Q_ωω; the printed (6.35) is √(Q_ωω/2)
    q11 = float(Q[1, 1].subs({Lq: L**2 / F, n: N}))
    assert sa.sigma_omega_setup(F, L, N, 1.0, "rigorous") ** 2 == pytest.approx(q11, rel=1e-12)
    assert sa.sigma_omega_setup(F, L, N, 1.0, "printed") ** 2 == pytest.approx(q11 / 2, rel=1e-12)


def test_table19_by_least_squares():
    Q = c5.relative_orientation_cofactors(A80, P80, C, F)
    np.testing.assert_allclose(Q[2, 2], c5.cofactor_alpha_relative(F, A80, C), rtol=1e-12)
    # ERRATA: Table 19 prints Q_ωω = 3f²/(4c²) (OCR L3162); dimensionally 3f²/(4c⁴)
    np.testing.assert_allclose(Q[3, 3], c5.cofactor_omega_relative(F, C), rtol=1e-12)
    np.testing.assert_allclose(Q[4, 4], c5.cofactor_kappa_relative(A80, C), rtol=1e-12)
    assert abs(Q[2, 3]) < 1e-18  # Q_αω = 0 as used in (5.19)


def test_table20_by_least_squares():
    Q = c5.cofactors_levelling(A80, C)
    assert Q[1, 1] == pytest.approx(1 / (A80 + C) ** 2, rel=1e-12)
    # ERRATA: Table 20 prints Q_ξξ = f/(4c²) (OCR L3170); least squares gives 1/(4c²)
    assert Q[2, 2] == pytest.approx(1 / (4 * C**2), rel=1e-12)
    assert Q[0, 0] == pytest.approx((A80**2 + C**2) / (2 * (A80 + C) ** 2), rel=1e-12)


def test_620_omega_sign_against_322():
    # conventions.md §6 caveat 2: (6.20) prints −x_л y ω_л/f; (3.22) gives +x y ω/f for x⁰.
    # Independent: collinearity with the direction cosines of (2.50) (geometry.rotation). The
    # point imaged at (x⁰, y⁰) on the vertical photo falls at x on the photo tilted by ω; the
    # error field carries x⁰ − x (first order; ω = 1e-4 leaves a relative 1e-4 second order).
    x0, y0, f, w = 50.0, 30.0, 70.0, 1e-4
    m = rotation.rotation_matrix(0.0, w, 0.0)
    d = np.array([x0, y0, -f]) @ m  # the ray in the tilted photo's axes
    x_tilted = -f * d[0] / d[2]
    dp = sa.parallax_error_field_setup(x0, y0, f, 70.0, {"omega_left": w})
    assert dp == pytest.approx(x0 - x_tilted, rel=2e-3)


# --- printed values --------------------------------------------------------------------------


def test_629_630_special_cases_of_628():
    s = dict(
        sigma_base_x_mm=0.005,
        sigma_alpha=1e-4,
        sigma_omega=2e-4,
        sigma_kappa=1e-4,
        sigma_base_z_mm=0.02,
    )
    for pp, aa in ((P60, A60), (P80, A80)):
        pr = sa.setup_parallax_rms_unadjusted_printed(F, pp, aa, aa + pp, *s.values())
        assert pr == pytest.approx(sa.setup_parallax_rms_unadjusted(F, pp, aa + pp, *s.values()))
    # (6.29): 18p⁴, 10p⁴, 30p²f², 15p²; (6.30): 153p⁴, 100p⁴, 120p²f², 15p²  (OCR L3899-3915)
    v29 = math.sqrt(
        45 * F**2 * 0.005**2
        + 18 * P60**4 * 1e-8
        + 10 * P60**4 * 4e-8
        + 30 * P60**2 * F**2 * 1e-8
        + 15 * P60**2 * 0.02**2
    ) / (3 * 5**0.5 * F)
    assert sa.setup_parallax_rms_unadjusted(F, P60, C, *s.values()) == pytest.approx(v29)
    v30 = math.sqrt(
        45 * F**2 * 0.005**2
        + 153 * P80**4 * 1e-8
        + 100 * P80**4 * 4e-8
        + 120 * P80**2 * F**2 * 1e-8
        + 15 * P80**2 * 0.02**2
    ) / (3 * 5**0.5 * F)
    assert sa.setup_parallax_rms_unadjusted(F, P80, C, *s.values()) == pytest.approx(v30)


# (6.31)-(6.38): the element σ's are checked against the least squares of their observation
# equations by the covariance column of the verification table
# (tests/properties/test_accuracy_mc.py::test_mc_and_covariance_agree_with_rigorous); the sympy
# derivations of (6.34)/(6.35) and (6.37) are here.

def test_637_base_z_units_derived():
    # ERRATA: (6.37) prints m_bz = f_пр m_y/l_y, a length of the instrument (model scale); (6.26)
    # needs it at photo scale. Transformed bundle: instrument X, Y = n·(x, y), Z = n(f_пр/f)·z,
    # n = D/f_пр. A mark at photo y = l projects to Y = l(D + B_z)/f_пр; the counter reads Y.
    f, fpr, dist, ll, m = sp.symbols("f f_pr D l m", positive=True)
    bz_photo, big_b = sp.symbols("b_z B_z")
    n = dist / fpr
    y_counter = ll * (dist + big_b) / fpr
    m_bz_instrument = sp.simplify(m / sp.diff(y_counter, big_b))  # one reading, error m
    # photo-scale b_z in the instrument's vertical: B_z = n (f_пр/f) b_z
    y_photo = y_counter.subs(big_b, n * fpr / f * bz_photo)
    m_bz_photo = sp.simplify(m / sp.diff(y_photo, bz_photo))
    nn = sp.symbols("n", positive=True)
    assert sp.simplify(m_bz_instrument - fpr * m / ll) == 0  # the printed (6.37)
    assert sp.simplify(m_bz_photo.subs(dist, nn * fpr) - f * m / (nn * ll)) == 0
    # the two differ only by n·f_пр/f
    assert sp.simplify(m_bz_instrument / m_bz_photo - n * fpr / f) == 0
    assert sa.sigma_base_z_setup_photo(F, L, N, 1.0) == pytest.approx(0.5800, abs=5e-5)
    for fpr_v in (70.0, 109.4, 170.0):
        ratio = sa.sigma_base_z_setup(fpr_v, L, 1.0) / sa.sigma_base_z_setup_photo(F, L, N, 1.0)
        assert ratio == pytest.approx(N * fpr_v / F, rel=1e-12)
    assert sa.setup_element_sigmas(F, L, N, 1.0, mode="rigorous")["base_z"] == pytest.approx(
        F / (N * L)
    )


def test_639_640_rigorous_unit_consistent():
    # ERRATA: with m_bz of (6.37) at photo scale, f m/(n l), the 15p²n²/l² of (6.39)/(6.40)
    # becomes 15p²/l²: every term carries the 1/n of the counter readings.
    xl, y, p, c, f, ll, nn, m = sp.symbols("x_l y p c f l n m", positive=True)

    def mean(expr):
        return sp.integrate(expr, (xl, 0, c), (y, -c, c)) / (2 * c**2)

    xr = xl - p
    m_a, m_w = f * sp.sqrt(2) / (nn * ll**2) * m, f * sp.sqrt(sp.Rational(3, 2)) / (ll**2 * nn) * m
    m_k, m_bx, m_bz = m / (ll * sp.sqrt(2) * nn), m * sp.sqrt(2) / nn, f * m / (nn * ll)
    var = (
        m_bx**2
        + mean(xl**4 + xr**4) / f**2 * m_a**2
        + mean(y**2 * (xl**2 + xr**2)) / f**2 * m_w**2
        + 2 * mean(y**2) * m_k**2
        + mean(xr**2) / f**2 * m_bz**2
    )
    r = p / ll
    closed60 = (90 + 51 * r**4 + 30 * r**2) * m**2 / (45 * nn**2)
    closed80 = (90 + 456 * r**4 + 75 * r**2) * m**2 / (45 * nn**2)
    assert sp.simplify(var.subs(c, p) - closed60) == 0
    assert sp.simplify(var.subs(c, 2 * p) - closed80) == 0
    for pp, cc, closed in ((P60, C, closed60), (P80, 2 * P80, closed80)):
        for n in (1.0, 1.42, 3.0):
            v = float(sp.sqrt(closed.subs({p: pp, ll: L, nn: n, m: 1})))
            got = sa.setup_parallax_rms_from_pointing(F, pp, cc, L, n, 1.0, mode="rigorous")
            assert got == pytest.approx(v, rel=1e-12)
    # book geometry: 1.2604 → 1.2143 (60 %), 1.1424 → 1.1298 (80 %)
    assert sa.setup_parallax_rms_from_pointing(F, P60, C, L, N, 1.0, mode="rigorous") == (
        pytest.approx(1.2143, abs=5e-5)
    )
    assert sa.setup_parallax_rms_from_pointing(F, P80, C, L, N, 1.0, mode="rigorous") == (
        pytest.approx(1.1298, abs=5e-5)
    )


def test_639_640_coefficients_follow_from_628():
    for pp, fn in (
        (P60, sa.setup_parallax_rms_printed_60),
        (P80, sa.setup_parallax_rms_printed_80),
    ):
        for n in (1.0, 1.42, 3.0):
            assert sa.setup_parallax_rms_from_pointing(F, pp, C, L, n, 1.0) == pytest.approx(
                fn(pp, L, n, 1.0), rel=1e-12
            )


@pytest.mark.parametrize("n", [1.0, 1.42, 1.69, 2.0])
def test_641_642_rounded_coefficients(n):
    # (6.41)/(6.42): (6.39)/(6.40) with the coefficients rounded for l = 85 (124, 10, 113, 2.5,
    # 6.7): within 0.5 % of the exact book-mode (6.39)/(6.40) over the instruments' n
    exact60 = sa.setup_parallax_rms_from_pointing(F, P60, C, L, n, 1.0)
    exact80 = sa.setup_parallax_rms_from_pointing(F, P80, C, L, n, 1.0)
    assert sa.setup_parallax_rms_rounded_60(n, 1.0) == pytest.approx(exact60, rel=5e-3)
    assert sa.setup_parallax_rms_rounded_80(n, 1.0) == pytest.approx(exact80, rel=5e-3)

def test_643_printed():
    assert abs(sa.setup_parallax_rms_printed_60(P60, L, N, 1.0) - 1.26) < 0.005
    assert abs(sa.setup_parallax_rms_rounded_60(N, 1.0) - 1.26) < 0.005


def test_644_printed_is_a_misprint():
    # ERRATA: (6.44) prints 1.11; the book's own (6.42) and (6.40) give 1.14
    assert abs(sa.setup_parallax_rms_rounded_80(N, 1.0) - 1.14) < 0.005
    assert abs(sa.setup_parallax_rms_printed_80(P80, L, N, 1.0) - 1.14) < 0.005
    assert abs(sa.setup_parallax_rms_printed_80(P80, L, N, 1.0) - 1.11) > 0.03


def _how(printed, value):
    """"rounded", "truncated" or None: both readings checked (verification/verdicts.py)."""
    return printed_agreement(printed, value, 2)[0]


def test_645_from_printed_chain_and_corrected():
    # (6.45) 0.98: the unrounded printed (5.54)+(5.55) give 0.9853, which truncates to 0.98 and
    # rounds to 0.99; from the printed (6.51) 0.24, (6.54) 0.95 it is √0.9601 = 0.9798 (rounded)
    pr = sa.conventional_parallax_rms(A60, C, P60, F, 1.0, 1.0, "printed")
    assert pr == pytest.approx(0.9853, abs=5e-5) and _how(0.98, pr) == "truncated"
    # ERRATA: with (5.55) integrated over its stated domain: 0.686
    assert sa.conventional_parallax_rms(A60, C, P60, F, 1.0, 1.0, "book") == pytest.approx(
        0.6862, abs=5e-5
    )


def test_646_not_reproducible():
    # the printed (5.54) and (5.55) at a = p = 35, c = 70 by hand: 1/48 + 29400/330750 and
    # (p/f)²·52675/132300, √0.2092593 = 0.457449; neither rounding nor truncation gives 0.67
    pr = sa.conventional_parallax_rms(A80, C, P80, F, 1.0, 1.0, "printed")
    assert pr == pytest.approx(math.sqrt(1 / 48 + 29400 / 330750 + 0.25 * 52675 / 132300))
    assert pr == pytest.approx(0.457449, abs=5e-7)
    assert _how(0.67, pr) is None


def test_649_650_651_552():
    # (6.49) 0.12: the printed (6.48) gives 0.12496 (rounds and truncates to 0.12)
    assert sa.setup_relative_residual_rms_printed(A60, C, L, N, 1.0) == pytest.approx(
        0.12496, abs=5e-6
    )
    # ERRATA: (6.48) integrated: c²/(n l²)·√(1/48 + 1/15) = 0.141278 at 60 % and
    # c²/(n l²)·√(1/48 + 0.4) = 0.309828 at 80 % (test_648_is_the_integral_of_647); the printed
    # 0.12 of (6.50) is neither this nor the printed (6.48) (0.2644): not reproducible
    assert sa.setup_relative_residual_rms(A60, C, F, L, N, 1.0, "book") == pytest.approx(
        0.141278, abs=5e-6
    )
    assert sa.setup_relative_residual_rms(A80, C, F, L, N, 1.0, "book") == pytest.approx(
        0.309828, abs=5e-6
    )
    assert _how(0.12, sa.setup_relative_residual_rms_printed(A80, C, L, N, 1.0)) is None
    # ERRATA: (6.51) prints 0.24; (5.54) gives 0.2327 and (6.56) prints 0.23
    ro60 = c5.relative_orientation_parallax_rms(A60, C, P60, 1.0)
    assert abs(ro60 - 0.23) < 0.005
    assert abs(c5.relative_orientation_parallax_rms(A80, C, P80, 1.0) - 0.33) < 0.005  # (6.52)


def test_654_657_coefficients():
    # ERRATA: 0.95 of (6.54)/(6.56) is the truncated 0.9574 of the printed (5.55); the integral
    # (5.53) gives 0.6455
    g = c5.geodetic_orientation_parallax_rms(A60, C, P60, F, 1.0, "printed")
    assert g == pytest.approx(0.9574, abs=5e-5) and _how(0.95, g) == "truncated"
    assert c5.geodetic_orientation_parallax_rms(A60, C, P60, F, 1.0, "book") == pytest.approx(
        0.6455, abs=5e-5
    )
    g80 = c5.geodetic_orientation_parallax_rms(A80, C, P80, F, 1.0, "book") * F / P80
    assert abs(g80 - 0.63) < 0.005  # (6.55), (6.57)


# (6.58)-(6.61): the arithmetic from the printed intermediates is the from_printed_inputs
# column, checked in tests/properties/test_verdicts.py.

def test_557_558():
    # (5.57) 11p²/(12f²) + 1; (5.58) 43p²/(108f²) + 1 (OCR L3380-3384), m_p coefficient, Δr = 0
    v = c5.single_model_height_rms(0.0, C, P60, F, 1.0, "printed")
    assert v == pytest.approx(math.sqrt(11 / 12 + 1))
    v = c5.single_model_height_rms(A80, C, P80, F, 1.0, "printed")
    assert v == pytest.approx(math.sqrt(43 / 108 * (P80 / F) ** 2 + 1))


def test_table18_row_5556_f70():
    # Table 18 (OCR L3111), P_x = 55.6 %, f = 70, m_q = 0.015, c = 80: m_ω 29.3″ (half a unit)
    rho = 648000 / math.pi
    assert abs(math.sqrt(c5.cofactor_omega_relative(70.0, 80.0)) * 0.015 * rho - 29.3) < 0.05
