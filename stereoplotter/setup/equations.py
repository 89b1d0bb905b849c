r"""The setup-data equations of chapter 6, §26: Eqs. (6.3)–(6.18), pure and vectorised.

Reference
---------
.. [1] Kushtin I. F. & Lyskov G. A., *Фотограмметрия снимка и стереоскопических моделей*,
   Moscow: Nedra, 1984, ch. 6, §26 "Построение модели по установочным данным на универсальных
   приборах", pp. 153–158 (OCR L3682–3826).

The transformed fiducial coordinates (6.1)/(6.2) live in :mod:`stereoplotter.geometry.transformed`
(n-free). Our reading of the damaged OCR — every sign, unit and subscript decision — is
``docs/setup-data.md``; the book-literal forms are behind explicit options named ``book_*``.

Units: model and instrument quantities in mm, ground quantities in m, angles in rad; M_г, M_в
are scale denominators; n, k are dimensionless. Every function broadcasts over its arguments, so
a whole block of stereopairs is computed in one call.

Conventions used throughout
---------------------------
* k = f_пр / f′ (the transformation coefficient); M_в = M_г / k: the model is the affine image of
  the ground with heights exaggerated k times (``kinematics.md`` §2).
* The absolute height counter reads the projection distance D, the depth below S_л in model mm.
* Readings are MO + signed value: the functions for (6.12)–(6.18) return the signed value to add to
  the zero reading MO of the photo concerned.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.constants import MM_PER_M
from stereoplotter.geometry.arrays import floats
from stereoplotter.geometry.similarity import SimilarityFit, apply_similarity
from stereoplotter.geometry.tilt_correction import correction_inclination, decentration

__all__ = [
    "base_components",
    "base_z_correction",
    "corner_offsets_book_form_mm",
    "corner_offsets_mm",
    "correction_inclination",
    "counter_scale_left",
    "counter_scale_right",
    "decentration",
    "height_correction",
    "height_scale_reading",
    "instrument_principal_distance",
    "mark_span",
    "model_height",
    "projection_distance",
    "sheet_corner_instrument_coordinates",
    "sheet_corner_instrument_coordinates_book_form",
    "transformation_coefficient",
]


def instrument_principal_distance(
    focal_length_corrected_mm: ArrayLike,
    horizontal_scale_denominator: ArrayLike,
    vertical_scale_denominator: ArrayLike,
) -> NDArray[np.float64]:
    r"""Instrument principal distance f_пр for the chosen model scales.

    Parameters
    ----------
    focal_length_corrected_mm : float or ndarray
        f′, the camera focal length corrected for film deformation. [mm]
    horizontal_scale_denominator, vertical_scale_denominator : float or ndarray
        M_г and M_в of the model. [—]

    Returns
    -------
    ndarray
        f_пр = f′·M_г/M_в. [mm]

    Notes
    -----
    Item 1 of [1]_ (OCR L3701: "вычисляются также f_пр"): the model is the affine image of the
    ground, so k = f_пр/f′ = M_г/M_в (``docs/setup-data.md``, item 1).

    Examples
    --------
    >>> float(instrument_principal_distance(70.0, 12500, 8000))
    109.375
    """
    return (
        floats(focal_length_corrected_mm)
        * floats(horizontal_scale_denominator)
        / floats(vertical_scale_denominator)
    )


def transformation_coefficient(
    f_instrument_mm: ArrayLike, focal_length_corrected_mm: ArrayLike
) -> NDArray[np.float64]:
    """k = f_пр / f′, the vertical exaggeration of the model (DRO60 "F/f_k"). [—]"""
    return floats(f_instrument_mm) / floats(focal_length_corrected_mm)


def counter_scale_left(
    projection_distance_max_mm: ArrayLike, f_instrument_mm: ArrayLike
) -> NDArray[np.float64]:
    r"""Scale coefficient n_л of the left photo's coordinate counters.

    Parameters
    ----------
    projection_distance_max_mm : float or ndarray
        D_max, the largest projection distance of the instrument (SC-1: 185 mm, OCR L3715). [mm]
    f_instrument_mm : float or ndarray
        f_пр (the book's f′_пр; ``docs/setup-data.md`` decision: one symbol). [mm]

    Returns
    -------
    ndarray
        n_л = D_max / f_пр. [—]

    Notes
    -----
    Implements Eq. (6.3) of [1]_ (OCR L3713). n_л is the counter coefficient at the locked bottom
    position of stages 1–2, i.e. on the plane Z_ref = Z_Sл − D_max·M_в/1000.

    Examples
    --------
    >>> round(float(counter_scale_left(185.0, 130.0)), 4)  # the book's SC-1 example, n ≈ 1.42
    1.4231
    """
    return floats(projection_distance_max_mm) / floats(f_instrument_mm)


def counter_scale_right(
    n_left: ArrayLike,
    projection_centre_height_left_m: ArrayLike,
    projection_centre_height_right_m: ArrayLike,
    f_instrument_mm: ArrayLike,
    vertical_scale_denominator: ArrayLike,
    *,
    book_sign: bool = False,
) -> NDArray[np.float64]:
    r"""Scale coefficient n_п of the right photo's coordinate counters.

    Parameters
    ----------
    n_left : float or ndarray
        n_л from Eq. (6.3). [—]
    projection_centre_height_left_m, projection_centre_height_right_m : float or ndarray
        Z_Sл, Z_Sп. [m]
    f_instrument_mm : float or ndarray
        f_пр. [mm]
    vertical_scale_denominator : float or ndarray
        M_в. [—]
    book_sign : bool
        Use the printed sign (Z_Sл − Z_Sп). Default False: the geometric sign.

    Returns
    -------
    ndarray
        n_п. [—]

    Notes
    -----
    Implements Eq. (6.4) of [1]_ (OCR L3719) with the geometric sign (a decision,
    ``docs/setup-data.md``):

    .. math:: n_п = n_л + \frac{Z_{Sп} - Z_{Sл}}{f_{пр} M_в}\,1000

    A higher right station has a longer projection distance to the common model datum
    (D_п = D_л + b_z′), so n_п > n_л. The printed (6.4) has (Z_Sл − Z_Sп): ``book_sign=True``
    reproduces it.

    Examples
    --------
    Right station 20 m higher, M_в = 5000, f_пр = 130 mm: n_п − n_л = +0.0308 (book sign −0.0308).

    >>> round(float(counter_scale_right(1.4231, 1000.0, 1020.0, 130.0, 5000) - 1.4231), 4)
    0.0308
    >>> round(float(counter_scale_right(1.4231, 1000.0, 1020.0, 130.0, 5000, book_sign=True)
    ...             - 1.4231), 4)
    -0.0308
    """
    dz = floats(projection_centre_height_right_m) - floats(projection_centre_height_left_m)
    if book_sign:
        dz = -dz
    scale = floats(f_instrument_mm) * floats(vertical_scale_denominator)
    return floats(n_left) + dz * MM_PER_M / scale


def mark_span(
    n: ArrayLike, y3_transformed_mm: ArrayLike, y4_transformed_mm: ArrayLike
) -> NDArray[np.float64]:
    r"""Computed distance L between fiducial marks 3 and 4 in counter units.

    Parameters
    ----------
    n : float or ndarray
        n_л or n_п of the photo. [—]
    y3_transformed_mm, y4_transformed_mm : float or ndarray
        y⁰ of marks 3 and 4 of the same photo, from (6.2) **without** n. [mm]

    Returns
    -------
    ndarray
        L = n·(y⁰₃ − y⁰₄). [mm]

    Notes
    -----
    Implements Eq. (6.5) of [1]_ (OCR L3725). The printed (6.1)/(6.2) already contain n and (6.5)
    multiplies by n again; n is applied exactly once here (``docs/setup-data.md``).
    """
    return floats(n) * (floats(y3_transformed_mm) - floats(y4_transformed_mm))


def model_height(
    flying_height_above_point_m: ArrayLike, vertical_scale_denominator: ArrayLike
) -> NDArray[np.float64]:
    r"""Model height of flight Z_i over a height control point.

    Parameters
    ----------
    flying_height_above_point_m : float or ndarray
        H_Фi = Z_Sл − Z_Фi, the height of the **left** station above point i. [m]
    vertical_scale_denominator : float or ndarray
        M_в. [—]

    Returns
    -------
    ndarray
        Z_i = H_Фi·1000/M_в, the projection distance D of point i. [mm]

    Notes
    -----
    Implements Eq. (6.6) of [1]_ (OCR L3731).

    Examples
    --------
    >>> float(model_height(1400.0, 8000))
    175.0
    """
    return floats(flying_height_above_point_m) * MM_PER_M / floats(vertical_scale_denominator)


#: The same relation read the other way: the projection distance D of a ground point [mm].
projection_distance = model_height


def base_components(
    centre_left_m: ArrayLike,
    centre_right_m: ArrayLike,
    horizontal_scale_denominator: ArrayLike,
    vertical_scale_denominator: ArrayLike,
) -> NDArray[np.float64]:
    r"""Base components b_x, b_y, b_z′ as set on the instrument.

    Parameters
    ----------
    centre_left_m, centre_right_m : array_like, shape (..., 3)
        S_л, S_п in a photogrammetric system whose X runs along the strip. [m]
    horizontal_scale_denominator, vertical_scale_denominator : float or ndarray
        M_г, M_в. [—]

    Returns
    -------
    ndarray, shape (..., 3)
        b_x = ΔX_S·1000/M_г, b_y = ΔY_S·1000/M_г, b_z′ = ΔZ_S·1000/M_в = k·b_z. [mm]

    Notes
    -----
    Item 1 of [1]_ (OCR L3701) with DRO60's "b_x, b_y, k·b_z": the vertical component as set is
    at the vertical scale (``docs/setup-data.md``, item 1). b_z′ > 0 when the right station is
    higher.
    """
    d = floats(centre_right_m) - floats(centre_left_m)
    mg = floats(horizontal_scale_denominator)[..., None]
    mv = floats(vertical_scale_denominator)
    out = d * MM_PER_M / mg
    out[..., 2] = d[..., 2] * MM_PER_M / mv
    return out


def height_correction(
    projection_distance_mm: ArrayLike,
    mark_span_error_left_mm: ArrayLike,
    mark_span_left_mm: ArrayLike,
    vertical_scale_denominator: ArrayLike,
) -> NDArray[np.float64]:
    r"""Stage 1 height correction ΔZ from the left photo's mark-span error.

    Parameters
    ----------
    projection_distance_mm : float or ndarray
        D, the reading of the absolute height counter. [mm]
    mark_span_error_left_mm : float or ndarray
        ΔL_л = L_л − L′_л (computed − measured). [mm]
    mark_span_left_mm : float or ndarray
        L_л of (6.5). [mm]
    vertical_scale_denominator : float or ndarray
        M_в. [—]

    Returns
    -------
    ndarray
        ΔZ = D·ΔL_л·M_в/(1000·L_л) in terrain metres. [m]

    Notes
    -----
    Implements Eq. (6.9) of [1]_ (OCR L3765). ΔL > 0 means the photo must go deeper: on the
    absolute counter D′ = D + D·ΔL_л/L_л (6.11); on the metre height scale the reading *decreases*
    by ΔZ (``docs/setup-data.md``, stage readings).
    """
    return (
        floats(projection_distance_mm)
        * floats(mark_span_error_left_mm)
        * floats(vertical_scale_denominator)
        / (MM_PER_M * floats(mark_span_left_mm))
    )


def base_z_correction(
    projection_distance_mm: ArrayLike,
    mark_span_error_right_mm: ArrayLike,
    mark_span_right_mm: ArrayLike,
) -> NDArray[np.float64]:
    r"""Stage 1 vertical-base correction Δb_z from the right photo's mark-span error.

    Parameters
    ----------
    projection_distance_mm : float or ndarray
        D. [mm]
    mark_span_error_right_mm : float or ndarray
        ΔL_п = L_п − L′_п. [mm]
    mark_span_right_mm : float or ndarray
        L_п of (6.5). [mm]

    Returns
    -------
    ndarray
        Δb_z = D·ΔL_п/L_п. [mm]

    Notes
    -----
    Implements Eq. (6.10) of [1]_ (OCR L3767). With a b_z scale that increases when the right
    pivot rises, the new reading is O′_bz = O_bz **+** Δb_z; the printed minus of (6.11) belongs
    to a scale counting the other way (option ``bz_scale_sense = -1``, ``docs/setup-data.md``).
    """
    return (
        floats(projection_distance_mm)
        * floats(mark_span_error_right_mm)
        / floats(mark_span_right_mm)
    )


def height_scale_reading(
    zero_reading_height_scale_m: ArrayLike,
    model_height_mm: ArrayLike,
    n_left: ArrayLike,
    f_instrument_mm: ArrayLike,
    vertical_scale_denominator: ArrayLike,
) -> NDArray[np.float64]:
    r"""Stage 3 reading of the metre height scale for height control point i.

    Parameters
    ----------
    zero_reading_height_scale_m : float or ndarray
        MO_Z, the height-scale reading recorded at D = n_л·f_пр at the end of stage 1. [m]
    model_height_mm : float or ndarray
        Z_i of (6.6). [mm]
    n_left, f_instrument_mm, vertical_scale_denominator
        n_л, f_пр [mm], M_в.

    Returns
    -------
    ndarray
        O_Zi = MO_Z − (Z_i − n_л·f_пр)·M_в/1000. [m]

    Notes
    -----
    Implements Eq. (6.15) of [1]_ (OCR L3799); the OCR's "n_p f′" is n_л·f_пр
    (``docs/setup-data.md``). The height scale reads const − D·M_в/1000, hence the minus.
    """
    return (
        floats(zero_reading_height_scale_m)
        - (floats(model_height_mm) - floats(n_left) * floats(f_instrument_mm))
        * floats(vertical_scale_denominator)
        / MM_PER_M
    )


def sheet_corner_instrument_coordinates(
    fit: SimilarityFit,
    gk_north_m: ArrayLike,
    gk_east_m: ArrayLike,
    horizontal_scale_denominator: float,
    origin_m: ArrayLike = (0.0, 0.0),
) -> NDArray[np.float64]:
    r"""Instrument coordinates x′_i, y′_i of map-sheet corners.

    Parameters
    ----------
    fit : SimilarityFit
        a, b, c_X, c_Y of Eq. (6.8).
    gk_north_m, gk_east_m : float or ndarray
        Gauss–Krüger X_г (north), Y_г (east) of the corners. [m]
    horizontal_scale_denominator : float
        M_г of the **model**. [—]
    origin_m : array_like, shape (2,)
        X_Sл, Y_Sл in the photogrammetric system of the fit: the counters are read from the left
        plumb (MO). [m]

    Returns
    -------
    ndarray, shape (..., 2)
        x′, y′ to add to MO_X, MO_Y (stages 4–5, (6.16)–(6.18)). [mm]

    Notes
    -----
    Implements Eq. (6.7) of [1]_ (OCR L3735) with the model scale and without n
    (decision, ``docs/setup-data.md``):

    .. math::
        x'_i = (a X_{гi} + b Y_{гi} + c_X - X_{Sл})\frac{1000}{M_г},\quad
        y'_i = (-a Y_{гi} + b X_{гi} + c_Y - Y_{Sл})\frac{1000}{M_г}

    The printed form multiplies by n as well; it equals this one when its M_г is the photo-scale
    denominator M_photo = n_л·M_г (:func:`sheet_corner_instrument_coordinates_book_form`).
    """
    return corner_offsets_mm(
        apply_similarity(fit, gk_north_m, gk_east_m), horizontal_scale_denominator, origin_m
    )


def corner_offsets_mm(
    corners_ground_m: ArrayLike,
    horizontal_scale_denominator: ArrayLike,
    origin_m: ArrayLike = (0.0, 0.0),
) -> NDArray[np.float64]:
    r"""The scaling half of Eq. (6.7): x′, y′ of corners already on the ground by (6.8).

    ``corners_ground_m`` shape (..., 2): X_Ф, Y_Ф of the corners [m] (the sheet computes them
    once for the carriage extent and the readings); ``horizontal_scale_denominator`` M_г, one or
    one per pair (broadcast against the corners); returns x′, y′ [mm] as
    :func:`sheet_corner_instrument_coordinates`.
    """
    xy = floats(corners_ground_m) - floats(origin_m)
    return xy * MM_PER_M / floats(horizontal_scale_denominator)


def sheet_corner_instrument_coordinates_book_form(
    fit: SimilarityFit,
    gk_north_m: ArrayLike,
    gk_east_m: ArrayLike,
    n: float,
    photo_scale_denominator: float,
    origin_m: ArrayLike = (0.0, 0.0),
) -> NDArray[np.float64]:
    r"""Eq. (6.7) as printed: x′ = n·(a X_г + b Y_г + c_X)·1000/M (OCR L3735).

    With M the photo-scale denominator at the plane of n (M_photo = n_л·M_г) it gives the same x′
    as :func:`sheet_corner_instrument_coordinates`; with the model M_г it would be n times too
    large. Kept for reproducing the book.
    """
    return corner_offsets_book_form_mm(
        apply_similarity(fit, gk_north_m, gk_east_m), n, photo_scale_denominator, origin_m
    )


def corner_offsets_book_form_mm(
    corners_ground_m: ArrayLike,
    n: ArrayLike,
    photo_scale_denominator: ArrayLike,
    origin_m: ArrayLike = (0.0, 0.0),
) -> NDArray[np.float64]:
    """The printed (6.7) of corners already on the ground by (6.8), as
    :func:`sheet_corner_instrument_coordinates_book_form` (``n`` and the denominator one or one
    per pair, broadcast against the corners). [mm]"""
    xy = floats(corners_ground_m) - floats(origin_m)
    return floats(n) * xy * MM_PER_M / floats(photo_scale_denominator)
