r"""Chapter-5 accuracy results used by §27: relative orientation by six standard points,
geodetic orientation (levelling) by four control points and their residual model deformation.

All functions are pure and broadcast over numpy arrays. Lengths in mm (photo scale), angles in
rad, heights ``H`` in m. Parallax errors are returned in mm (photo scale); a height error follows
from (5.42), m_h = (H/p)·m_p.

Geometry (Fig. 39, OCR L2996-3006). Standard points 1-6 have left/right abscissae
x_л ∈ {−a, b + a}, x_п ∈ {−(b + a), a}, ordinates y ∈ {0, +c, −c}; the base (parallax) is b = p.
From (5.15) on the book identifies c = a + b, i.e. c − p = a (also (6.27)). The four control points
used to level the model lie at the standard points 3-6: x_п ∈ {−c, a}, y = ±c.

Integration domain of (5.52)-(5.53) (and so of (5.54), (5.55), (6.47)-(6.52)):
x_п ∈ [−c, 0], y ∈ [−c, +c] (area 2c²).

Modes: ``"printed"`` is the closed form as the book prints it (after OCR repair),
``"book"`` is the book's own model with its integrals and coefficients re-derived,
``"rigorous"`` is derived from first principles (exact least-squares plane residual, control
heights observed with the parallax error of (5.42)). See ``docs/accuracy.md``.

References
----------
.. [1] Куштин И.Ф., Лыськов Г.Д. Фотограмметрия снимка и стереоскопических моделей.
   М.: Недра, 1984. Ch. 5, §22-§24 (OCR lines 2836-3451).
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "check_mode",
    "cofactor_alpha_relative",
    "cofactor_kappa_relative",
    "cofactor_omega_relative",
    "cofactors_levelling",
    "control_points",
    "geodetic_orientation_parallax_rms",
    "geodetic_orientation_parallax_sigma",
    "levelling_design",
    "mean_shifted_square",
    "relative_orientation_cofactors",
    "relative_orientation_design",
    "relative_orientation_parallax_rms",
    "relative_orientation_residual_sigma",
    "single_model_height_rms",
    "standard_points",
]

_MODES = ("printed", "book", "rigorous")


def check_mode(mode: str) -> None:
    if mode not in _MODES:
        raise ValueError(f"mode = {mode!r} is not one of {_MODES}")


def standard_points(a_mm: float, base_mm: float, c_mm: float):
    """Photo coordinates of the six standard points of Fig. 39.

    Parameters
    ----------
    a_mm : float
        a, offset of the standard points from the principal points [mm].
    base_mm : float
        b = p, the photo base (x-parallax) [mm].
    c_mm : float
        c, ordinate of points 3-6 [mm].

    Returns
    -------
    x_left, x_right, y : ndarray, shape (6,)
        x_л, x_п, y of points 1..6 [mm].

    Notes
    -----
    Implements the point list of §22 (OCR L2996-3006) with x₁₁ = −a, x₁₂ = b + a, x₂₁ = −(b + a),
    x₂₂ = a [1]_.

    Examples
    --------
    >>> standard_points(0.0, 70.0, 70.0)[1]
    array([-70.,   0., -70.,   0., -70.,   0.])
    """
    xl = np.array([-a_mm, base_mm + a_mm] * 3, dtype=float)
    xr = np.array([-(base_mm + a_mm), a_mm] * 3, dtype=float)
    y = np.array([0.0, 0.0, c_mm, c_mm, -c_mm, -c_mm])
    return xl, xr, y


def control_points(a_mm: float, c_mm: float):
    """Right-photo coordinates of the four levelling control points (near standard points 3-6).

    Returns
    -------
    x_right, y : ndarray, shape (4,)
        [mm]

    Notes
    -----
    §23 (OCR L3118): "при горизонтировании модели по четырем опорным точкам, расположенным вблизи
    стандартных точек 3, 4, 5 и 6" [1]_.

    Examples
    --------
    >>> control_points(0.0, 70.0)[0]
    array([-70.,   0., -70.,   0.])
    """
    return np.array([-c_mm, a_mm, -c_mm, a_mm], dtype=float), np.array(
        [c_mm, c_mm, -c_mm, -c_mm], dtype=float
    )


def relative_orientation_design(x_right_mm, y_mm, base_mm: float, focal_length_mm: float):
    r"""Design matrix of the first-order y-parallax equation (5.10), left-photo system.

    Unknowns (columns): τ, ν, Δα, Δω, Δκ [rad]; rows: observations q [mm].

    Notes
    -----
    Implements the second equation of (5.10) of [1]_ with y_л = y_п = y:

    .. math:: p\tau + y p \nu/f + x_п y\,\Delta\alpha/f + (f + y^2/f)\Delta\omega
              + x_п\Delta\kappa - q = 0

    Examples
    --------
    >>> _, xr, y = standard_points(0.0, 70.0, 70.0)
    >>> relative_orientation_design(xr, y, 70.0, 70.0).shape
    (6, 5)
    """
    x = np.asarray(x_right_mm, float)
    y = np.asarray(y_mm, float)
    f = focal_length_mm
    return np.stack(
        [np.full_like(x, base_mm), y * base_mm / f, x * y / f, f + y**2 / f, x], axis=-1
    )


def relative_orientation_cofactors(a_mm, base_mm, c_mm, focal_length_mm):
    """Least-squares cofactor matrix Q (5 × 5) of τ, ν, Δα, Δω, Δκ from the six standard points.

    Notes
    -----
    Implements (5.18), Q = N⁻¹, for the design of (5.10) at the points of Fig. 39 [1]_; Table 19
    prints closed forms of its elements (see :func:`cofactor_alpha_relative` …). Units: rad²/mm².

    Examples
    --------
    >>> Q = relative_orientation_cofactors(0.0, 70.0, 70.0, 70.0)
    >>> bool(abs(Q[2, 3]) < 1e-15)
    True
    """
    _, xr, y = standard_points(a_mm, base_mm, c_mm)
    A = relative_orientation_design(xr, y, base_mm, focal_length_mm)
    return np.linalg.inv(A.T @ A)


def cofactor_alpha_relative(focal_length_mm, a_mm, c_mm):
    r"""Q_αα of Table 19: f²/(c²(a + c)²) [rad²/mm²].

    Notes
    -----
    Table 19 of [1]_ (OCR L3162), with a + c = 2a + b (c = a + b). Reproduced by
    :func:`relative_orientation_cofactors`.

    Examples
    --------
    >>> round(cofactor_alpha_relative(70.0, 0.0, 70.0) * 70.0**2, 6)
    1.0
    """
    return focal_length_mm**2 / (c_mm**2 * (a_mm + c_mm) ** 2)


def cofactor_omega_relative(focal_length_mm, c_mm):
    r"""Q_ωω of Table 19: 3f²/(4c⁴) [rad²/mm²].

    Notes
    -----
    Table 19 of [1]_ prints 3f²/(4c²) (OCR L3162), dimensionally impossible; the text's
    m_ω₂′ = f√3 m_q/(2c²) (OCR L3103) and the least-squares solution give 3f²/(4c⁴)
    (OCR damage, see ``docs/errata.md``).

    Examples
    --------
    >>> round(cofactor_omega_relative(70.0, 70.0) * 70.0**2, 6)
    0.75
    """
    return 3.0 * focal_length_mm**2 / (4.0 * c_mm**4)


def cofactor_kappa_relative(a_mm, c_mm):
    """Q_κκ of Table 19: 2/(3(a + c)²) [rad²/mm²].

    Examples
    --------
    >>> round(cofactor_kappa_relative(0.0, 1.0), 6)
    0.666667
    """
    return 2.0 / (3.0 * (a_mm + c_mm) ** 2)


def levelling_design(x_right_mm, y_mm):
    """Design matrix (1, x, y) of the levelling plane fitted at the control points.

    Examples
    --------
    >>> levelling_design(*control_points(0.0, 70.0)).shape
    (4, 3)
    """
    x = np.asarray(x_right_mm, float)
    return np.stack([np.ones_like(x), x, np.asarray(y_mm, float)], axis=-1)


def cofactors_levelling(a_mm, c_mm):
    """Cofactors of the levelling plane (A₀, x-slope, y-slope) from four control points.

    Returns
    -------
    ndarray, shape (3, 3)
        Q in parallax units: multiply by σ² of a control observation.

    Notes
    -----
    Table 20 of [1]_ (OCR L3170) in parallax units: Q_ηη = 1/(a + c)², Q_ξξ = 1/(4c²) (printed
    "f/4c²": OCR damage), Q_A₀A₀ = (a² + c²)/(2(a + c)²), Q_ηA₀ = (c − a)/(2(a + c)²); the
    printed H/f factors convert the book's height units.

    Examples
    --------
    >>> Q = cofactors_levelling(0.0, 70.0)
    >>> round(float(Q[1, 1] * 70.0**2), 6), round(float(Q[2, 2] * 4 * 70.0**2), 6)
    (1.0, 1.0)
    """
    A = levelling_design(*control_points(a_mm, c_mm))
    return np.linalg.inv(A.T @ A)


def relative_orientation_residual_sigma(
    x_right_mm, y_mm, a_mm, c_mm, focal_length_mm, sigma_y_parallax_mm, mode="book"
):
    r"""Residual x-parallax error after relative orientation and levelling, (5.15)-(5.19) [mm].

    Parameters
    ----------
    x_right_mm, y_mm : array_like
        x_п, y of the model point [mm].
    a_mm, c_mm : float
        a, c of Fig. 39 (c = a + p) [mm].
    focal_length_mm : float
        f [mm].
    sigma_y_parallax_mm : float
        m_q [mm].
    mode : {"printed", "book", "rigorous"}
        ``printed``/``book``: the ω residual y(x + c/2) of (5.15); ``rigorous``: the exact
        least-squares plane residual y(x − x̄), x̄ = (a − c)/2 (equal when a = 0).

    Notes
    -----
    Implements (5.19) of [1]_ in parallax form (m_p = (p/H) m_h):

    .. math:: m_p = \frac{m_q}{c}\sqrt{\frac{3(2x_п + c)^2 y^2}{16c^2}
              + \frac{(x_п^2 + x_п p - ac)^2}{(a + c)^2}}

    with Q_αα, Q_ωω of Table 19 and Q_αω = 0.

    Examples
    --------
    >>> s = relative_orientation_residual_sigma(-35.0, 0.0, 0.0, 70.0, 70.0, 1.0)
    >>> round(float(s), 4)
    0.25
    """
    check_mode(mode)
    x = np.asarray(x_right_mm, float)
    y = np.asarray(y_mm, float)
    shift = c_mm / 2.0 if mode != "rigorous" else (c_mm - a_mm) / 2.0
    f = focal_length_mm
    var = (
        y**2 * (x + shift) ** 2 * cofactor_omega_relative(f, c_mm)
        + ((x - a_mm) * (x + c_mm)) ** 2 * cofactor_alpha_relative(f, a_mm, c_mm)
    ) / f**2
    return np.sqrt(var) * sigma_y_parallax_mm


def mean_shifted_square(shift, c_mm):
    """Mean of (x + shift)² over x ∈ [−c, 0]."""
    return (shift**3 - (shift - c_mm) ** 3) / (3.0 * c_mm)


def relative_orientation_parallax_rms(a_mm, c_mm, x_parallax_mm, sigma_y_parallax_mm, mode="book"):
    r"""RMS over the stereopair of the residual x-parallax error of relative orientation [mm].

    Parameters
    ----------
    a_mm, c_mm, x_parallax_mm : float
        a, c, p (c − p = a) [mm].
    sigma_y_parallax_mm : float
        m_q [mm].
    mode : {"printed", "book", "rigorous"}
        ``printed`` and ``book`` coincide (the printed closed form is the integral of (5.52));
        ``rigorous`` uses the exact plane residual (see
        :func:`relative_orientation_residual_sigma`).

    Notes
    -----
    Implements (5.54) of [1]_ in parallax form (m_h′_в = (H/p) m_p):

    .. math:: m_p = m_q\sqrt{\frac{1}{48} + \frac{6c^2 + 10ac - 5p(2a + c)}{30(a + c)^2}}

    The OCR prints "+ 1/48" outside the root (L3364); the integral (5.52) puts it inside.
    Domain x_п ∈ [−c, 0], y ∈ [−c, c]. Independent of f.

    Examples
    --------
    >>> round(float(relative_orientation_parallax_rms(0.0, 70.0, 70.0, 1.0)), 4)
    0.2327
    """
    check_mode(mode)
    a, c, p = a_mm, c_mm, x_parallax_mm
    alpha_term = (6 * c**2 + 10 * a * c - 5 * p * (2 * a + c)) / (30.0 * (a + c) ** 2)
    if mode == "rigorous":
        omega_term = mean_shifted_square((c - a) / 2.0, c) / (4.0 * c**2)
    else:
        omega_term = 1.0 / 48.0
    return np.sqrt(omega_term + alpha_term) * sigma_y_parallax_mm


def geodetic_orientation_parallax_sigma(x_right_mm, y_mm, a_mm, c_mm, sigma_control_mm):
    r"""Pointwise x-parallax error of the levelling plane fitted at four control points [mm].

    Notes
    -----
    Implements (5.20) of [1]_ with m_p′ = the error of one control observation in parallax units:

    .. math:: \sigma = m\sqrt{\frac{x_п^2}{(a + c)^2} + \frac{y^2}{4c^2}
              + \frac{a^2 + c^2}{2(a + c)^2} + \frac{x_п(c - a)}{(a + c)^2}}

    Reproduced exactly by the least-squares plane (Table 20).

    Examples
    --------
    >>> round(float(geodetic_orientation_parallax_sigma(0.0, 0.0, 0.0, 70.0, 1.0)), 4)
    0.7071
    """
    x = np.asarray(x_right_mm, float)
    y = np.asarray(y_mm, float)
    a, c = a_mm, c_mm
    var = (
        x**2 / (a + c) ** 2
        + y**2 / (4 * c**2)
        + (a**2 + c**2) / (2 * (a + c) ** 2)
        + x * (c - a) / (a + c) ** 2
    )
    return np.sqrt(var) * sigma_control_mm


def geodetic_orientation_parallax_rms(
    a_mm, c_mm, x_parallax_mm, focal_length_mm, sigma_x_parallax_mm, mode="book"
):
    r"""RMS over the stereopair of the x-parallax error left by levelling, (5.53)/(5.55) [mm].

    Parameters
    ----------
    a_mm, c_mm, x_parallax_mm, focal_length_mm : float
        a, c, p, f [mm].
    sigma_x_parallax_mm : float
        m_p [mm].
    mode : {"printed", "book", "rigorous"}
        ``printed``: (5.55) as printed, coefficient (7a² + 11c² − 4ac)/(12(a + c)²);
        ``book``: the integral (5.53) over its stated domain, (7a² + 8ac + 5c²)/(12(a + c)²),
        both with the book's scale B/p = H/f, i.e. a factor p/f in parallax units;
        ``rigorous``: control heights observed with the parallax error m_p of (5.42), so no p/f.

    Notes
    -----
    Implements (5.55) of [1]_ in parallax form, m_p = (p/H) m_h′_г:

    .. math:: m_p = \frac{p}{2(a + c)f}\sqrt{\frac{7a^2 + 11c^2 - 4ac}{3}}\,m_p

    The printed closed form is not the integral (5.53) over x_п ∈ [−c, 0] (it differs by
    6c(c − 2a)/(12(a + c)²); equal at 80 % overlap, c = 2a); see ``docs/errata.md``.

    Examples
    --------
    >>> round(float(geodetic_orientation_parallax_rms(0.0, 70.0, 70.0, 70.0, 1.0, "printed")), 4)
    0.9574
    >>> round(float(geodetic_orientation_parallax_rms(0.0, 70.0, 70.0, 70.0, 1.0, "book")), 4)
    0.6455
    """
    check_mode(mode)
    a, c, p, f = a_mm, c_mm, x_parallax_mm, focal_length_mm
    if mode == "printed":
        k2 = (7 * a**2 + 11 * c**2 - 4 * a * c) / (12.0 * (a + c) ** 2)
    else:
        k2 = (7 * a**2 + 8 * a * c + 5 * c**2) / (12.0 * (a + c) ** 2)
    scale = 1.0 if mode == "rigorous" else p / f
    return scale * np.sqrt(k2) * sigma_x_parallax_mm


def single_model_height_rms(
    a_mm, c_mm, x_parallax_mm, focal_length_mm, sigma_x_parallax_mm, mode="book"
):
    r"""RMS x-parallax error of a single model without distortion, (5.43)/(5.56)-(5.58) [mm].

    Multiply by H/p for the height error m_h.

    Notes
    -----
    (5.43) adds independent errors in quadrature; (5.56) of [1]_ takes m_q = m_p/√2 and
    Δr_max = 0:

    .. math:: m_h = \frac{H}{p}\sqrt{m_{p,в}^2 + m_{p,г}^2 + m_p^2}

    ``printed`` mode reproduces (5.57)/(5.58), which keep (p²/f²)·k + 1 and drop the relative
    orientation term (≈ 0.03 m_p²); ``book`` keeps it and uses the re-derived (5.55).

    Examples
    --------
    >>> round(float(single_model_height_rms(0.0, 70.0, 70.0, 70.0, 1.0, "printed")), 4)
    1.3844
    """
    check_mode(mode)
    mp = sigma_x_parallax_mm
    go = geodetic_orientation_parallax_rms(a_mm, c_mm, x_parallax_mm, focal_length_mm, mp, mode)
    if mode == "printed":
        return np.sqrt(go**2 + mp**2)
    ro = relative_orientation_parallax_rms(a_mm, c_mm, x_parallax_mm, mp / np.sqrt(2.0), mode)
    return np.sqrt(ro**2 + go**2 + mp**2)
