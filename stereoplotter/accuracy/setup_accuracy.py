r"""Accuracy of model building from setup data, §27, Eqs. (6.19)-(6.61).

Pure, broadcasting functions. Lengths in mm (photo scale unless stated), angles in rad.
``n`` is the counter scale coefficient D/f_пр; ``m_x``, ``m_y`` the counter reading errors (model
scale, mm); ``l`` the fiducial-mark distance from the photo centre (85 mm in the book).

Two problems (OCR L3829-3831):

1. setup data without correction on control points: (6.19)-(6.46); domain of (6.27):
   x_л ∈ [0, c], y ∈ [−c, +c], with x_п = x_л − p and c − p = a;
2. setup data corrected by geodetic orientation on control points: (6.47)-(6.61); domain of
   chapter 5, x_п ∈ [−c, 0], y ∈ [−c, +c] (see :mod:`stereoplotter.accuracy.chapter5`).

The ω sign of (6.20) is opposite to (3.22) (``conventions.md`` §6 caveat 2); it does not
affect any variance here. The simulator (:mod:`stereoplotter.verification.linear_mc`) uses (3.22).

References
----------
.. [1] Куштин И.Ф., Лыськов Г.Д. Фотограмметрия снимка и стереоскопических моделей.
   М.: Недра, 1984. Ch. 6, §27 (OCR lines 3827-4030).
"""

from __future__ import annotations

import numpy as np

from stereoplotter.accuracy.chapter5 import (
    check_mode,
    geodetic_orientation_parallax_rms,
    mean_shifted_square,
    relative_orientation_parallax_rms,
)

#: The setup-element error sources of (6.21)/(6.22), in the order of every error vector here.
SETUP_SOURCES = (
    "base_x",
    "alpha_left",
    "alpha_right",
    "omega_left",
    "omega_right",
    "kappa_left",
    "kappa_right",
    "base_z",
)

__all__ = [
    "conventional_parallax_rms",
    "height_from_parallax",
    "parallax_error_field_setup",
    "setup_element_sigmas",
    "setup_parallax_rms_from_pointing",
    "setup_parallax_rms_printed_60",
    "setup_parallax_rms_printed_80",
    "setup_parallax_rms_rounded_60",
    "setup_parallax_rms_rounded_80",
    "setup_parallax_rms_unadjusted",
    "setup_parallax_rms_unadjusted_printed",
    "setup_relative_residual_rms",
    "setup_relative_residual_rms_printed",
    "sigma_alpha_setup",
    "sigma_base_x_setup",
    "sigma_base_z_setup",
    "sigma_base_z_setup_photo",
    "sigma_kappa_setup",
    "sigma_omega_setup",
    "sigma_shift_y_setup",
    "total_parallax_rms",
]

SQRT5 = np.sqrt(5.0)


def height_from_parallax(focal_length_mm, base_mm, x_parallax_mm):
    r"""Model height Z = −f b/p⁰ at photo scale, Eq. (6.19) [mm].

    Notes
    -----
    Implements (6.19) of [1]_: :math:`Z_i = -f\,b/(x^0_{лi} - x^0_{пi}) = -f b/p^0_i`.

    Examples
    --------
    >>> float(height_from_parallax(70.0, 70.0, 70.0))
    -70.0
    """
    return -focal_length_mm * base_mm / np.asarray(x_parallax_mm, float)


def parallax_error_field_setup(
    x_left_mm, y_mm, x_parallax_mm, focal_length_mm, errors, *, omega_sign="3.22"
):
    r"""First-order x-parallax error caused by errors of the setup elements, Eq. (6.22) [mm].

    Parameters
    ----------
    x_left_mm, y_mm : array_like
        x_л, y of the model point; x_п = x_л − p [mm].
    x_parallax_mm, focal_length_mm : float
        p, f [mm].
    errors : mapping
        Errors (each broadcastable): ``base_x`` [mm], ``alpha_left``, ``alpha_right``,
        ``omega_left``, ``omega_right``, ``kappa_left``, ``kappa_right`` [rad],
        ``base_z`` [mm]; missing keys are zero.
    omega_sign : {"3.22", "6.20"}
        ω terms with the sign of the first-order form (3.22) (default) or as printed in (6.20).

    Notes
    -----
    Implements (6.22) of [1]_ with |y_л| = |y_п| = y and the decentration terms fα dropped
    (absorbed by scaling, OCR L3857):

    .. math:: δp = δb_x + \frac{x_л^2 α_л - x_п^2 α_п}{f}
              \pm y\frac{x_л ω_л - x_п ω_п}{f} - yκ_л + yκ_п + \frac{x_п}{f} δb_z

    Examples
    --------
    >>> float(parallax_error_field_setup(70.0, 0.0, 70.0, 70.0, {"alpha_left": 1e-3}))
    0.07
    """
    x_l = np.asarray(x_left_mm, float)
    y = np.asarray(y_mm, float)
    x_r = x_l - x_parallax_mm
    f = focal_length_mm
    e = {k: errors.get(k, 0.0) for k in SETUP_SOURCES}
    s = 1.0 if omega_sign == "3.22" else -1.0
    return (
        e["base_x"]
        + (x_l**2 * e["alpha_left"] - x_r**2 * e["alpha_right"]) / f
        + s * y * (x_l * e["omega_left"] - x_r * e["omega_right"]) / f
        - y * e["kappa_left"]
        + y * e["kappa_right"]
        + x_r / f * e["base_z"]
    )


def setup_parallax_rms_unadjusted(
    focal_length_mm,
    x_parallax_mm,
    c_mm,
    sigma_base_x_mm,
    sigma_alpha,
    sigma_omega,
    sigma_kappa,
    sigma_base_z_mm,
):
    r"""RMS over the stereopair of the x-parallax error of a setup-data model, (6.26)-(6.27) [mm].

    Parameters
    ----------
    focal_length_mm, x_parallax_mm, c_mm : float
        f, p, c [mm] (a = c − p).
    sigma_base_x_mm, sigma_base_z_mm : float
        m_bx, m_bz [mm].
    sigma_alpha, sigma_omega, sigma_kappa : float
        m_α, m_ω, m_κ, each for both photos (6.24) [rad].

    Notes
    -----
    Implements the integral (6.27) of (6.26) over x_л ∈ [0, c], y ∈ [−c, c] in closed form [1]_:
    mean x_л⁴ = c⁴/5, mean x_п⁴ = ((c − p)⁵ + p⁵)/(5c), mean x_л² = c²/3,
    mean x_п² = ((c − p)³ + p³)/(3c), mean y² = c²/3. Equal to the printed (6.28), see
    :func:`setup_parallax_rms_unadjusted_printed`.

    Examples
    --------
    >>> round(float(setup_parallax_rms_unadjusted(70.0, 70.0, 70.0, 0.0, 0.0, 0.0, 1e-3, 0.0)), 5)
    0.05715
    """
    f, p, c = focal_length_mm, x_parallax_mm, c_mm
    a = c - p
    mxl4 = c**4 / 5.0
    mxr4 = (a**5 + p**5) / (5.0 * c)
    mxl2 = c**2 / 3.0
    mxr2 = (a**3 + p**3) / (3.0 * c)
    my2 = c**2 / 3.0
    var = (
        sigma_base_x_mm**2
        + (mxl4 + mxr4) / f**2 * sigma_alpha**2
        + my2 * (mxl2 + mxr2) / f**2 * sigma_omega**2
        + 2.0 * my2 * sigma_kappa**2
        + mxr2 / f**2 * sigma_base_z_mm**2
    )
    return np.sqrt(var)


def setup_parallax_rms_unadjusted_printed(
    focal_length_mm,
    x_parallax_mm,
    a_mm,
    c_mm,
    sigma_base_x_mm,
    sigma_alpha,
    sigma_omega,
    sigma_kappa,
    sigma_base_z_mm,
):
    r"""Eq. (6.28) as printed (with c − p = a), generic in a, c, p [mm].

    Notes
    -----
    Implements (6.28) of [1]_:

    .. math:: m_p = \frac{1}{3\sqrt5 f}\big\{45m_{bx}^2f^2
              + 9[c^3(2a - 3p) + 5p^2(2ac + p^2)]m_α^2 + 5c^2[c(2a - p) + 3p^2]m_ω^2
              + 30c^2f^2m_κ^2 + 15m_{bz}^2[c(a - 2p) + 3p^2]\big\}^{1/2}

    (6.29) (a = 0, c = p) and (6.30) (a = p, c = 2p) are its special cases.

    Examples
    --------
    >>> round(float(setup_parallax_rms_unadjusted_printed(
    ...     70.0, 70.0, 0.0, 70.0, 0.0, 0.0, 0.0, 1e-3, 0.0)), 5)
    0.05715
    """
    f, p, a, c = focal_length_mm, x_parallax_mm, a_mm, c_mm
    s = (
        45 * sigma_base_x_mm**2 * f**2
        + 9 * (c**3 * (2 * a - 3 * p) + 5 * p**2 * (2 * a * c + p**2)) * sigma_alpha**2
        + 5 * c**2 * (c * (2 * a - p) + 3 * p**2) * sigma_omega**2
        + 30 * c**2 * f**2 * sigma_kappa**2
        + 15 * sigma_base_z_mm**2 * (c * (a - 2 * p) + 3 * p**2)
    )
    return np.sqrt(s) / (3 * SQRT5 * f)


def sigma_alpha_setup(focal_length_mm, mark_distance_mm, n, sigma_counter_mm):
    r"""m_α of a tilt introduced from counter readings at a mark, Eq. (6.32) [rad].

    Notes
    -----
    Implements (6.32) of [1]_, the solution of (6.31) (one reading at the centre gives the
    decentration Δx, one at the mark x = l gives (l²/f)α + Δx; readings divided by n):

    .. math:: m_α = \frac{f\sqrt2}{n l_x^2} m_x

    Examples
    --------
    >>> round(float(sigma_alpha_setup(70.0, 85.0, 1.42, 0.01)) * 1e6, 2)
    96.49
    """
    return focal_length_mm * np.sqrt(2.0) / (n * mark_distance_mm**2) * sigma_counter_mm


def sigma_shift_y_setup(n, sigma_counter_mm):
    """m_Δy of (6.35): m_y/n [mm] (Q_ΔyΔy = 1/n² of (6.34)).

    Examples
    --------
    >>> float(sigma_shift_y_setup(2.0, 0.01))
    0.005
    """
    return sigma_counter_mm / n


def sigma_omega_setup(focal_length_mm, mark_distance_mm, n, sigma_counter_mm, mode="book"):
    r"""m_ω of a transverse tilt introduced from counter readings, Eqs. (6.33)-(6.35) [rad].

    Parameters
    ----------
    mode : {"printed", "book", "rigorous"}
        ``printed``: (6.35) as printed, f√3/(2l²n)·m_y (Q_ωω = 3f²/(4l⁴n²) of (6.34));
        ``book``/``rigorous``: the least-squares solution of (6.33),
        Q_ωω = 3f²/(2l⁴n²), i.e. m_ω = f√(3/2)/(l²n)·m_y — the value the book's own (6.39) and
        (6.40) use.

    Notes
    -----
    Implements (6.35) of [1]_ from the observation equations (6.33)
    (δΔy + δy₁/n = v₁; (l²/f)δω + δΔy + δy_{3,4}/n = v_{3,4}).

    Examples
    --------
    >>> r = sigma_omega_setup(70.0, 85.0, 1.42, 1.0, "book") / sigma_omega_setup(
    ...     70.0, 85.0, 1.42, 1.0, "printed")
    >>> round(float(r), 6)
    1.414214
    """
    check_mode(mode)
    k = np.sqrt(3.0) / 2.0 if mode == "printed" else np.sqrt(1.5)
    return k * focal_length_mm / (mark_distance_mm**2 * n) * sigma_counter_mm


def sigma_kappa_setup(mark_distance_mm, n, sigma_counter_mm):
    r"""m_κ of a swing introduced from x readings at two marks y = ±l_y, Eq. (6.36) [rad].

    Notes
    -----
    Implements (6.36) of [1]_: :math:`m_κ = m_x/(l_y\sqrt2\,n)`.

    Examples
    --------
    >>> round(float(sigma_kappa_setup(85.0, 1.0, 85.0 * 2**0.5)), 6)
    1.0
    """
    return sigma_counter_mm / (mark_distance_mm * np.sqrt(2.0) * n)


def sigma_base_z_setup(f_instrument_mm, mark_distance_mm, sigma_counter_mm):
    r"""m_bz of the vertical base component as the book prints it, Eq. (6.37) [mm, instrument].

    Notes
    -----
    Implements (6.37) of [1]_, :math:`m_{b_z} = f_{пр} m_y / l_y`, in instrument units: mm of
    the instrument's vertical at model scale, m_y the counter error (model scale). The book gives
    no observation equations; the formula follows from one y reading at a mark at distance l_y:
    raising the projection centre by δb_z moves the projected mark by δY = l_y δb_z/f_пр. It is
    *not* in the photo-scale units of (6.26); for those see :func:`sigma_base_z_setup_photo`.
    The book's (6.39)/(6.40) substitute it with f_пр = f (their 15p²n²/l² term), which is what
    ``mode="book"`` of :func:`setup_element_sigmas` keeps.

    Examples
    --------
    >>> float(sigma_base_z_setup(170.0, 85.0, 0.01))
    0.02
    """
    return f_instrument_mm / mark_distance_mm * sigma_counter_mm


def sigma_base_z_setup_photo(focal_length_mm, mark_distance_mm, n, sigma_counter_mm):
    r"""m_bz of (6.37) converted to photo scale, the units of (6.22)/(6.26) [mm, photo].

    Notes
    -----
    Unit-consistent form of (6.37) of [1]_ (``docs/errata.md``). The instrument value
    f_пр m_y/l_y (:func:`sigma_base_z_setup`) is a length of the instrument's vertical at model
    scale. Model → instrument photo scale divides by n = D/f_пр (as every other counter row,
    (6.31)-(6.38), divides the reading by n); the instrument's vertical f_пр → the photo's
    vertical f multiplies by f/f_пр. Hence

    .. math:: m_{b_z} = \frac{f}{f_{пр}\,n}\cdot\frac{f_{пр}}{l_y}m_y = \frac{f}{n\,l_y}m_y,

    [mm] = [mm]·[mm]/[mm] with n dimensionless. Equivalently: one reading δy/n (photo scale) of
    a mark at l_y moved by (l_y/f)δb_z. f_пр cancels; the book form differs from this one only
    by the factor n f_пр/f.

    Examples
    --------
    >>> round(float(sigma_base_z_setup_photo(70.0, 85.0, 1.42, 1.0)), 4)
    0.58
    """
    return focal_length_mm / (n * mark_distance_mm) * sigma_counter_mm


def sigma_base_x_setup(n, sigma_counter_mm):
    r"""m_bx from two x readings, Eq. (6.38): √2·m_x/n [mm].

    Examples
    --------
    >>> round(float(sigma_base_x_setup(2**0.5, 1.0)), 6)
    1.0
    """
    return sigma_counter_mm * np.sqrt(2.0) / n


def setup_element_sigmas(
    focal_length_mm, mark_distance_mm, n, sigma_counter_mm, f_instrument_mm=None, mode="book"
):
    """The standard errors (6.32)-(6.38) of all setup elements, as a dict (photo scale).

    ``mode="printed"``/``"book"``: m_bz is the book's (6.37) f_пр m_y/l taken as a photo-scale
    length, ``f_instrument_mm`` defaulting to f (the book's implicit f_пр = f in
    (6.39)-(6.42)). ``mode="rigorous"``: m_bz = f m_y/(n l) (:func:`sigma_base_z_setup_photo`,
    ``f_instrument_mm`` is not needed) and the least-squares m_ω.

    Examples
    --------
    >>> sorted(setup_element_sigmas(70.0, 85.0, 1.42, 0.01))[:3]
    ['alpha', 'base_x', 'base_z']
    """
    fi = focal_length_mm if f_instrument_mm is None else f_instrument_mm
    f, ll, m = focal_length_mm, mark_distance_mm, sigma_counter_mm
    return {
        "alpha": sigma_alpha_setup(f, ll, n, m),
        "omega": sigma_omega_setup(f, ll, n, m, mode),
        "kappa": sigma_kappa_setup(ll, n, m),
        "base_z": (
            sigma_base_z_setup_photo(f, ll, n, m)
            if mode == "rigorous"
            else sigma_base_z_setup(fi, ll, m)
        ),
        "base_x": sigma_base_x_setup(n, m),
    }


def setup_parallax_rms_from_pointing(
    focal_length_mm,
    x_parallax_mm,
    c_mm,
    mark_distance_mm,
    n,
    sigma_counter_mm,
    f_instrument_mm=None,
    mode="book",
):
    r"""(6.28) with the element errors (6.32)-(6.38) substituted: the general (6.39)/(6.40) [mm].

    Notes
    -----
    Generalises (6.39) (a = 0, c = p) and (6.40) (a = p, c = 2p) of [1]_ with l_x = l_y = l,
    m_x = m_y. With ``mode="printed"`` the printed m_ω of (6.35) is used (which the book's own
    (6.39)/(6.40) do *not* use). f_пр defaults to f, which is what reproduces the printed
    15p²n²/l² term. With ``mode="rigorous"`` m_bz is the photo-scale f m_y/(n l) of
    :func:`sigma_base_z_setup_photo` and the term becomes 15p²/l² (60 %) — the (6.39)/(6.40) of
    ``docs/errata.md``.

    Examples
    --------
    >>> round(float(setup_parallax_rms_from_pointing(70.0, 70.0, 70.0, 85.0, 1.42, 1.0)), 4)
    1.2604
    >>> round(float(setup_parallax_rms_from_pointing(
    ...     70.0, 70.0, 70.0, 85.0, 1.42, 1.0, mode="rigorous")), 4)
    1.2143
    """
    s = setup_element_sigmas(
        focal_length_mm, mark_distance_mm, n, sigma_counter_mm, f_instrument_mm, mode
    )
    return setup_parallax_rms_unadjusted(
        focal_length_mm,
        x_parallax_mm,
        c_mm,
        s["base_x"],
        s["alpha"],
        s["omega"],
        s["kappa"],
        s["base_z"],
    )


def setup_parallax_rms_printed_60(x_parallax_mm, mark_distance_mm, n, sigma_counter_mm):
    r"""Eq. (6.39) as printed (60 % overlap, c = p, a = 0) [mm].

    .. math:: m_{p^0} = \frac{1}{3\sqrt5 n}\sqrt{90 + 51\frac{p^4}{l^4} + 15\frac{p^2}{l^2}
              + 15\frac{p^2n^2}{l^2}}\,m_{x,y}

    Examples
    --------
    >>> round(float(setup_parallax_rms_printed_60(70.0, 85.0, 1.42, 1.0)), 4)
    1.2604
    """
    r2 = (x_parallax_mm / mark_distance_mm) ** 2
    return np.sqrt(90 + 51 * r2**2 + 15 * r2 + 15 * r2 * n**2) / (3 * SQRT5 * n) * sigma_counter_mm


def setup_parallax_rms_printed_80(x_parallax_mm, mark_distance_mm, n, sigma_counter_mm):
    r"""Eq. (6.40) as printed (80 % overlap, a = p, c = 2p) [mm].

    .. math:: m_{p^0} = \frac{1}{3\sqrt5 n}\sqrt{90 + 456\frac{p^4}{l^4} + 60\frac{p^2}{l^2}
              + 15\frac{p^2n^2}{l^2}}\,m_{x,y}

    Examples
    --------
    >>> round(float(setup_parallax_rms_printed_80(35.0, 85.0, 1.42, 1.0)), 4)
    1.1424
    """
    r2 = (x_parallax_mm / mark_distance_mm) ** 2
    return np.sqrt(90 + 456 * r2**2 + 60 * r2 + 15 * r2 * n**2) / (3 * SQRT5 * n) * sigma_counter_mm


def setup_parallax_rms_rounded_60(n, sigma_counter_mm):
    r"""Eq. (6.41), the book's rounded (6.39) for l = 85 mm, p = 70 mm [mm].

    .. math:: m_{p^0} = \frac{1}{6.7n}\sqrt{124 + 10n^2}\,m_{x,y}

    Examples
    --------
    >>> round(float(setup_parallax_rms_rounded_60(1.42, 1.0)), 3)
    1.262
    """
    return np.sqrt(124 + 10 * n**2) / (6.7 * n) * sigma_counter_mm


def setup_parallax_rms_rounded_80(n, sigma_counter_mm):
    r"""Eq. (6.42), the book's rounded (6.40) for l = 85 mm, p = 35 mm [mm].

    .. math:: m_{p^0} = \frac{1}{6.7n}\sqrt{113 + 2.5n^2}\,m_{x,y}

    Examples
    --------
    >>> round(float(setup_parallax_rms_rounded_80(1.42, 1.0)), 3)
    1.142
    """
    return np.sqrt(113 + 2.5 * n**2) / (6.7 * n) * sigma_counter_mm


def conventional_parallax_rms(
    a_mm,
    c_mm,
    x_parallax_mm,
    focal_length_mm,
    sigma_y_parallax_mm,
    sigma_x_parallax_mm,
    mode="book",
):
    r"""RMS x-parallax error of a conventionally built, levelled model, (6.45)/(6.46), (6.53) [mm].

    Notes
    -----
    (6.45)/(6.46) of [1]_: :math:`\sqrt{m_{p,во}^2 + m_{p,го}^2}` with m_p,во from (5.54) and
    m_p,го from (5.55) in parallax form (see :mod:`stereoplotter.accuracy.chapter5`).

    Examples
    --------
    >>> round(float(conventional_parallax_rms(0.0, 70.0, 70.0, 70.0, 1.0, 1.0, "printed")), 4)
    0.9853
    """
    ro = relative_orientation_parallax_rms(a_mm, c_mm, x_parallax_mm, sigma_y_parallax_mm, mode)
    go = geodetic_orientation_parallax_rms(
        a_mm, c_mm, x_parallax_mm, focal_length_mm, sigma_x_parallax_mm, mode
    )
    return np.sqrt(ro**2 + go**2)


def setup_relative_residual_rms(
    a_mm, c_mm, focal_length_mm, mark_distance_mm, n, sigma_counter_mm, mode="book"
):
    r"""RMS residual x-parallax error of setup-data angles after levelling, (6.47)/(6.48) [mm].

    Parameters
    ----------
    mode : {"printed", "book", "rigorous"}
        ``printed``: :func:`setup_relative_residual_rms_printed`;
        ``book``: the integral of (6.47) over the chapter-5 domain with one m_α, m_ω
        (the book's printed intermediates: (6.32) and (6.35) as printed, f√3/(2l²n)) and the
        ω residual y(x + c/2);
        ``rigorous``: the least-squares m_ω of (6.33), both photos' independent errors
        (variance doubled: the residual depends on α_л − α_п and ω_л − ω_п) and the exact plane
        residual y(x − (a − c)/2).

    Notes
    -----
    Implements (6.47) of [1]_:

    .. math:: m_{p,во} = \frac1f\sqrt{y^2(x_п + c/2)^2m_ω^2 + (x_п - a)^2(x_п + c)^2m_α^2}

    Mean over x_п ∈ [−c, 0], y ∈ [−c, c]: mean y²(x + s)² = (c²/3)·((s³ − (s − c)³)/(3c)),
    mean (x − a)²(x + c)² = c²(10a² + 5ac + c²)/30.

    Examples
    --------
    >>> round(float(setup_relative_residual_rms(0.0, 70.0, 70.0, 85.0, 1.42, 1.0)), 4)
    0.1413
    """
    if mode == "printed":
        return setup_relative_residual_rms_printed(
            a_mm, c_mm, mark_distance_mm, n, sigma_counter_mm
        )
    check_mode(mode)
    a, c, f = a_mm, c_mm, focal_length_mm
    m_a = sigma_alpha_setup(f, mark_distance_mm, n, sigma_counter_mm)
    m_w = sigma_omega_setup(
        f, mark_distance_mm, n, sigma_counter_mm, "printed" if mode == "book" else "rigorous"
    )
    shift = c / 2.0 if mode == "book" else (c - a) / 2.0
    mean_w = c**2 / 3.0 * mean_shifted_square(shift, c)
    mean_a = c**2 * (10 * a**2 + 5 * a * c + c**2) / 30.0
    var = (mean_w * m_w**2 + mean_a * m_a**2) / f**2
    if mode == "rigorous":
        var = 2.0 * var
    return np.sqrt(var)


def setup_relative_residual_rms_printed(a_mm, c_mm, mark_distance_mm, n, sigma_counter_mm):
    r"""Eq. (6.48) as printed (read with the dimensionally needed c²: "…/(21c²)") [mm].

    .. math:: m_{p,во} \approx \frac{c^2}{nl^2}\sqrt{\frac1{48}
              + \frac{6c^2 + 10ac - 5p(2a + c)}{21c^2}}\,m_{x,y}

    With p = c − a. The printed "21" is read as 21c² (otherwise not dimensionless); the
    integral gives 15c² and, with the least-squares m_ω of (6.35), 1/24 instead of 1/48.

    Examples
    --------
    >>> round(float(setup_relative_residual_rms_printed(0.0, 70.0, 85.0, 1.42, 1.0)), 4)
    0.125
    """
    a, c = a_mm, c_mm
    p = c - a
    term = (6 * c**2 + 10 * a * c - 5 * p * (2 * a + c)) / (21.0 * c**2)
    return c**2 / (n * mark_distance_mm**2) * np.sqrt(1.0 / 48.0 + term) * sigma_counter_mm


def total_parallax_rms(relative_mm, levelling_mm):
    r"""Total error of a levelled model, Eq. (6.53): M_p = √(m²_p,во + m²_p,го) [mm].

    Examples
    --------
    >>> float(total_parallax_rms(3.0, 4.0))
    5.0
    """
    return np.hypot(relative_mm, levelling_mm)
