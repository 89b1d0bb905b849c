r"""Kinematic acceptance of the virtual instrument: ``kinematics.md`` §5 and §6 as data.

The reference check of the design document, re-run on this package's own kinematics
(:mod:`stereoplotter.instrument.kinematics`): a synthetic stereopair is photographed by rigorous
collinearity (``object_to_photo``, Eq. (2.53) of [1]_), the correction units are set either to the
true settings (§6) or by a scripted operator running stage 2 of §26 in each decentration variant
(§5), and the y-parallax q left at 49 model points is reported, before and after a least-squares
relative-orientation touch-up, with the height deformation after levelling and scaling.

Everything is pure: :func:`run_kinematic_selftest` returns plain Python data (JSON-ready) and
:func:`format_selftest` renders it as text tables laid out like ``kinematics.md``.

Reference
---------
.. [1] Kushtin I. F. & Lyskov G. A., *Фотограмметрия снимка и стереоскопических моделей*,
   Moscow: Nedra, 1984, ch. 2, §13 (Eq. (2.50), (2.53)) and ch. 6, §26 (stage 2, Eqs. (6.1),
   (6.2), (6.12), (6.13); OCR L3680–3826).

The synthetic pair (``kinematics.md`` §5 "Data")
------------------------------------------------
f′ = 100 mm, f_пр = 130 mm (k = 1.3), D_max = 185 mm (n_л = D_max/f_пр, Eq. (6.3)), fiducials at
l = 85 mm; S_л = (0, 0, 1000) m, S_п = (720, 12, 1015) m; 49 ground points X, Y on
``meshgrid(linspace(0, 720, 7), linspace(-800, 800, 7))`` (C order), Z from
``default_rng(1).uniform(-100, 100, 49)`` m; κ_л = 0.8°, κ_п = −1.2°. The datum Z = 0 lies at
D_max, so M_в = 1000·H/D_max (1:5405.4) and M_г = k·M_в (1:7027.0); the document prints these
rounded to 1:5405 and 1:7027. The unrounded, mutually consistent pair is used here: with the
rounded pair M_г ≠ k·M_в by 4e-6 relative and the exact-rectification check would no longer be an
exact affine image. Range checks are off: the terrain spans D ≈ 167–203 mm.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any, NamedTuple, cast

import numpy as np
from numpy.typing import NDArray

from stereoplotter.constants import DEG_PER_RAD, MM_PER_M, UM_PER_MM
from stereoplotter.geometry.collinearity import object_to_photo
from stereoplotter.geometry.rotation import rotation_matrix
from stereoplotter.geometry.transformed import (
    transformed_coordinates,
    transformed_x_single_tilt,
    transformed_y_single_tilt,
)
from stereoplotter.instrument.decentration_variants import decentration_variant
from stereoplotter.instrument.kinematics import (
    CorrectionUnit,
    InstrumentSetting,
    marks_from_counters,
    photo_from_rod,
    rod_from_photo,
    rods_intersection,
)
from stereoplotter.instrument.knobs import (
    set_decentrations,
    turn_correction_knob,
    unit_for_orientation,
)
from stereoplotter.instrument.principles import mechanism_for
from stereoplotter.setup.equations import (
    base_components,
    counter_scale_left,
    decentration,
    transformation_coefficient,
)

__all__ = [
    "STAGE2_SIGNS",
    "Stage2Result",
    "SyntheticPair",
    "format_selftest",
    "height_deformation_permille",
    "residual_table",
    "run_kinematic_selftest",
    "sanity_checks",
    "sign_combinations",
    "stage2_setting",
    "stage2_table",
    "touch_up",
    "y_parallax",
]

_DEG = 1.0 / DEG_PER_RAD  # radians per degree


@dataclass(frozen=True, slots=True)
class SyntheticPair:
    """The synthetic stereopair of ``kinematics.md`` §5 (defaults are the document's values).

    Attributes
    ----------
    focal_length_mm : float
        f′ of the camera (and known to the units). [mm]
    f_instrument_mm : float
        f_пр. [mm]
    projection_distance_max_mm : float
        D_max; the datum Z = 0 lies at D = D_max. [mm]
    mark_distance_mm : float
        l, the distance of the fiducials from the principal point. [mm]
    flying_height_m : float
        H of the left station above the datum. [m]
    base_m : tuple of float
        (B_x, B_y, B_z) from S_л to S_п. [m]
    kappa_left, kappa_right : float
        κ_л, κ_п. [rad]
    grid_size : int
        Points per side of the ground grid.
    grid_x_m, grid_y_m : tuple of float
        Extent (start, stop) of the grid. [m]
    relief_m : float
        Heights are uniform in [−relief, relief]. [m]
    seed : int
        Seed of ``numpy.random.default_rng`` for the heights.
    """

    focal_length_mm: float = 100.0
    f_instrument_mm: float = 130.0
    projection_distance_max_mm: float = 185.0
    mark_distance_mm: float = 85.0
    flying_height_m: float = 1000.0
    base_m: tuple[float, float, float] = (720.0, 12.0, 15.0)
    kappa_left: float = 0.8 * _DEG
    kappa_right: float = -1.2 * _DEG
    grid_size: int = 7
    grid_x_m: tuple[float, float] = (0.0, 720.0)
    grid_y_m: tuple[float, float] = (-800.0, 800.0)
    relief_m: float = 100.0
    seed: int = 1

    @property
    def k(self) -> float:
        """k = f_пр/f′. [—]"""
        return float(transformation_coefficient(self.f_instrument_mm, self.focal_length_mm))

    @property
    def n_left(self) -> float:
        """n_л = D_max/f_пр, Eq. (6.3). [—]"""
        return float(counter_scale_left(self.projection_distance_max_mm, self.f_instrument_mm))

    @property
    def vertical_scale_denominator(self) -> float:
        """M_в = 1000·H/D_max: the datum at D_max. [—]"""
        return MM_PER_M * self.flying_height_m / self.projection_distance_max_mm

    @property
    def horizontal_scale_denominator(self) -> float:
        """M_г = k·M_в. [—]"""
        return self.k * self.vertical_scale_denominator

    @property
    def station_left_m(self) -> NDArray[np.float64]:
        """S_л. [m]"""
        return np.array([0.0, 0.0, self.flying_height_m])

    @property
    def station_right_m(self) -> NDArray[np.float64]:
        """S_п = S_л + B. [m]"""
        station: NDArray[np.float64] = self.station_left_m + np.asarray(self.base_m, float)
        return station

    def ground_points_m(self) -> NDArray[np.float64]:
        """The 49 ground points, shape (grid_size², 3), exactly as §5 builds them. [m]"""
        n = self.grid_size
        gx, gy = np.meshgrid(np.linspace(*self.grid_x_m, n), np.linspace(*self.grid_y_m, n))
        z = np.random.default_rng(self.seed).uniform(-self.relief_m, self.relief_m, n * n)
        return np.stack([gx.ravel(), gy.ravel(), z], axis=-1)

    def setting(self) -> InstrumentSetting:
        """The instrument with the exact base (b_x, b_y, b_z′ = k·b_z) and MO = 0."""
        b = base_components(
            self.station_left_m,
            self.station_right_m,
            self.horizontal_scale_denominator,
            self.vertical_scale_denominator,
        )
        return InstrumentSetting(
            self.f_instrument_mm, base_x_mm=b[0], base_y_mm=b[1], base_z_mm=b[2]
        )

    def photos(self, tilts: NDArray[np.float64]) -> tuple[NDArray[Any], NDArray[Any]]:
        """Rigorous photo coordinates of the ground points, Eq. (2.53) via ``object_to_photo``.

        Parameters
        ----------
        tilts : ndarray, shape (..., 4)
            (α_л, ω_л, α_п, ω_п). [rad]

        Returns
        -------
        photo_left, photo_right : ndarray, shape (..., 49, 2)
            [mm]
        """
        t = np.asarray(tilts, float)
        g = self.ground_points_m()
        m_l = rotation_matrix(t[..., 0], t[..., 1], self.kappa_left)[..., None, :, :]
        m_r = rotation_matrix(t[..., 2], t[..., 3], self.kappa_right)[..., None, :, :]
        f = self.focal_length_mm
        return (
            object_to_photo(g, self.station_left_m, m_l, f),
            object_to_photo(g, self.station_right_m, m_r, f),
        )

    def true_depth_mm(self) -> NDArray[np.float64]:
        """D of the ground points: (Z_Sл − Z)·1000/M_в, Eq. (6.6). [mm]"""
        z = self.ground_points_m()[:, 2]
        return (self.flying_height_m - z) * MM_PER_M / self.vertical_scale_denominator


def sign_combinations() -> NDArray[np.float64]:
    """The 16 sign combinations (s₁, s₂, s₃, s₄) ∈ {±1}⁴ of (α_л, ω_л, α_п, ω_п), shape (16, 4).

    Examples
    --------
    >>> s = sign_combinations()
    >>> s.shape, s[0].tolist(), s[-1].tolist()
    ((16, 4), [1.0, 1.0, 1.0, 1.0], [-1.0, -1.0, -1.0, -1.0])
    """
    grid = np.array(np.meshgrid(*([[1.0, -1.0]] * 4), indexing="ij"))
    return grid.reshape(4, -1).T


# --------------------------------------------------------------------------------------------
# q, touch-up and height deformation
# --------------------------------------------------------------------------------------------


def y_parallax(
    photo_left: NDArray[Any],
    photo_right: NDArray[Any],
    setting: InstrumentSetting,
    left: CorrectionUnit,
    right: CorrectionUnit,
) -> Any:
    """Counters and q at the model points of homologous photo points (``kinematics.md`` §3.4).

    Thin alias of :func:`~stereoplotter.instrument.kinematics.rods_intersection` after
    :func:`~stereoplotter.instrument.kinematics.rod_from_photo`; returns a ``StereoReading``.
    """
    return rods_intersection(
        rod_from_photo(photo_left, left), rod_from_photo(photo_right, right), setting
    )


#: Parameters of the touch-up (``kinematics.md`` §5): κ_п, κ_л, T_ω,п, b_y, b_z′, with the
#: finite-difference steps of the Jacobian (q is nearly linear in them).
_TOUCH_UP_STEPS = np.array([1e-6, 1e-6, 1e-6, 1e-4, 1e-4])


def apply_touch_up(
    p: Any, setting: InstrumentSetting, left: CorrectionUnit, right: CorrectionUnit, linkage: str
) -> tuple[InstrumentSetting, CorrectionUnit, CorrectionUnit]:
    left = replace(left, kappa=left.kappa + p[..., 1:2])
    right = replace(right, kappa=right.kappa + p[..., 0:1])
    right = turn_correction_knob(right, "omega", right.tan_omega + p[..., 2:3], linkage)
    setting = replace(
        setting,
        base_y_mm=setting.base_y_mm + p[..., 3:4],
        base_z_mm=setting.base_z_mm + p[..., 4:5],
    )
    return setting, left, right


def _central_jacobian(
    q_of: Callable[[Any], Any], p: NDArray[Any], shape: tuple[int, ...]
) -> NDArray[Any]:
    """∂q/∂p by central differences with the steps ``_TOUCH_UP_STEPS``, shape (*shape, 5)."""
    jac = np.empty((*shape, 5))
    for i, h in enumerate(_TOUCH_UP_STEPS):
        dp = np.zeros(5)
        dp[i] = h
        jac[..., i] = (q_of(p + dp) - q_of(p - dp)) / (2 * h)
    return jac


def touch_up(
    photo_left: NDArray[Any],
    photo_right: NDArray[Any],
    setting: InstrumentSetting,
    left: CorrectionUnit,
    right: CorrectionUnit,
    linkage: str = "L",
    max_iterations: int = 100,
) -> Any:
    r"""Least-squares relative-orientation touch-up over κ_п, κ_л, θ_ω,п, b_y, b_z′.

    Parameters
    ----------
    photo_left, photo_right : ndarray, shape (B, N, 2)
        Homologous points, B independent cases (e.g. sign combinations) of N points. [mm]
    setting : InstrumentSetting
        The instrument; its fields broadcast against shape (B, 1).
    left, right : CorrectionUnit
        The units; fields broadcast against shape (B, 1).
    linkage : {"L", "A", "B"}
        How the change of k_ω,п drags the right decentrations (D1 in "L").
    max_iterations : int
        Upper limit of Levenberg–Marquardt iterations.

    Returns
    -------
    q : ndarray, shape (B, N)
        y-parallax after the touch-up. [mm]
    reading : StereoReading
        Counters after the touch-up, shape (B, N).
    parameters : ndarray, shape (B, 5)
        Changes Δκ_п, Δκ_л [rad], ΔT_ω,п [—], Δb_y, Δb_z′ [mm].

    Notes
    -----
    ``kinematics.md`` §5: the touch-up "is the usual relative orientation by y-parallax over κ_п,
    κ_л, k_ω,п, b_y and b_z′ (least squares over the 49 points)". Batched Levenberg–Marquardt
    (Marquardt's diagonal scaling, central-difference Jacobian), each case solved independently.
    Near the true settings the problem is almost linear; in variant "B" the minimum lies far away
    (κ changes of ≈ 0.3 rad), which a plain Gauss–Newton step does not reach.
    """
    nb = photo_left.shape[0]
    p = np.zeros((nb, 5))

    def q_of(params: Any) -> Any:
        s, lu, ru = apply_touch_up(params, setting, left, right, linkage)
        return y_parallax(photo_left, photo_right, s, lu, ru).y_parallax_mm

    r = q_of(p)
    cost = np.sum(r**2, axis=-1)
    lam = np.full(nb, 1e-4)
    eye = np.eye(5)
    for _ in range(max_iterations):
        jac = _central_jacobian(q_of, p, r.shape)
        a = np.einsum("bni,bnj->bij", jac, jac)
        g = np.einsum("bni,bn->bi", jac, r)
        diag = np.einsum("bii->bi", a)[..., None, :] * eye
        done = np.zeros(nb, bool)
        for _ in range(30):  # raise the damping until the cost decreases
            step = np.linalg.solve(a + lam[:, None, None] * diag, g[..., None])[..., 0]
            p_new = p - step
            r_new = q_of(p_new)
            cost_new = np.sum(r_new**2, axis=-1)
            better = (cost_new <= cost) & ~done
            p = np.where(better[:, None], p_new, p)
            r = np.where(better[:, None], r_new, r)
            small = np.abs(cost - cost_new) <= 1e-14 * cost + 1e-30
            cost = np.where(better, cost_new, cost)
            lam = np.where(better, lam / 5, np.where(done, lam, lam * 10))
            done |= better | small
            if np.all(done):
                break
        if np.all(np.max(np.abs(step) / _TOUCH_UP_STEPS, axis=-1) < 1e-3):
            break
    s, lu, ru = apply_touch_up(p, setting, left, right, linkage)
    reading = y_parallax(photo_left, photo_right, s, lu, ru)
    return reading.y_parallax_mm, reading, p


def height_deformation_permille(
    depth_mm: NDArray[Any], pair: SyntheticPair, axis: int = -1
) -> NDArray[np.float64]:
    r"""Height deformation after levelling and scaling, max |·| in ‰ of H.

    Parameters
    ----------
    depth_mm : ndarray, shape (..., N)
        D of the N model points as measured by the instrument. [mm]
    pair : SyntheticPair
        The ground truth.
    axis : int
        Axis of the points (must be the last).

    Returns
    -------
    ndarray, shape (...)
        max over the points of |e − (a + bX + cY + dZ)| / H · 1000, with e the model height error
        in metres ((D_true − D)·M_в/1000) and X, Y, Z the ground coordinates. [‰]

    Notes
    -----
    ``kinematics.md`` §5 "What is measured": levelling (a, b, c) and scaling of the heights (d)
    absorb what the book's stage 3 removes; the rest is the deformation.
    """
    if axis not in (-1, depth_mm.ndim - 1):
        raise ValueError("the points must be on the last axis")
    g = pair.ground_points_m()
    err_m = (pair.true_depth_mm() - depth_mm) * pair.vertical_scale_denominator / MM_PER_M
    design = np.column_stack([np.ones(len(g)), g[:, 0], g[:, 1], g[:, 2]])
    fitted = err_m @ np.linalg.pinv(design).T @ design.T
    worst: NDArray[np.float64] = (
        np.max(np.abs(err_m - fitted), axis=-1) / pair.flying_height_m * 1000.0
    )
    return worst


# --------------------------------------------------------------------------------------------
# §6: the unit at the true settings, worst case over the 16 sign combinations
# --------------------------------------------------------------------------------------------


def true_units(pair: SyntheticPair, tilts: NDArray[Any], strict: bool) -> Any:
    t = tilts[..., None]  # broadcast against the points
    f = pair.focal_length_mm
    left = unit_for_orientation(
        t[..., 0, :], t[..., 1, :], pair.kappa_left, f, strict_per_axis=strict
    )
    right = unit_for_orientation(
        t[..., 2, :], t[..., 3, :], pair.kappa_right, f, strict_per_axis=strict
    )
    return left, right


def _q_stats(q_mm: NDArray[Any]) -> tuple[NDArray[Any], NDArray[Any]]:
    return np.max(np.abs(q_mm), axis=-1), np.sqrt(np.mean(q_mm**2, axis=-1))


def residual_table(
    pair: SyntheticPair | None = None,
    tilts_deg: Sequence[float] = (0.5, 1.0, 3.0),
    mechanism: Any = None,
) -> list[dict[str, Any]]:
    r"""``kinematics.md`` §6: residual y-parallax of the per-axis approximation.

    Parameters
    ----------
    pair : SyntheticPair, optional
        Default: the §5 data.
    tilts_deg : sequence of float
        Tilt magnitudes t. [°]
    mechanism : CorrectionMechanism, optional
        The instrument's own correction mechanism
        (:mod:`stereoplotter.instrument.principles`); adds rows named by its ``key``.

    Returns
    -------
    list of dict
        One row per unit ("canonical", "strict per-axis") and tilt, with the worst case over the
        16 sign combinations of (α_л, ω_л, α_п, ω_п) = ±t of each column: ``max_q_um``,
        ``rms_q_um`` [µm], ``max_q_after_touch_up_um`` [µm], ``height_deformation_permille``
        [‰ H, before the touch-up; b, κ exact] and ``height_deformation_after_touch_up_permille``.

    Notes
    -----
    Units at the true settings (T = tan α, tan ω; e = c = f′ tan α, f′ tan ω; κ true), base
    exact. The touch-up uses the D1 linkage.
    """
    pair = pair or SyntheticPair()
    setting = pair.setting()
    signs = sign_combinations()
    rows = []
    kinds = [("canonical", False, None), ("strict per-axis", True, None)]
    if mechanism is not None:
        kinds.append((mechanism.key, False, mechanism))
    for name, strict, mech in kinds:
        for t_deg in tilts_deg:
            tilts = signs * (t_deg * _DEG)
            pl, pr = pair.photos(tilts)
            left, right = true_units(pair, tilts, strict)
            if mech is not None:
                left, right = replace(left, mechanism=mech), replace(right, mechanism=mech)
            reading = y_parallax(pl, pr, setting, left, right)
            max_q, rms_q = _q_stats(reading.y_parallax_mm)
            q_after, reading_after, _ = touch_up(pl, pr, setting, left, right, "L")
            max_after, _ = _q_stats(q_after)
            deform = height_deformation_permille(reading.depth_mm, pair)
            deform_after = height_deformation_permille(reading_after.depth_mm, pair)
            rows.append(
                {
                    "unit": name,
                    "tilt_deg": float(t_deg),
                    "max_q_um": float(max_q.max() * UM_PER_MM),
                    "rms_q_um": float(rms_q.max() * UM_PER_MM),
                    "max_q_after_touch_up_um": float(max_after.max() * UM_PER_MM),
                    "height_deformation_permille": float(deform.max()),
                    "height_deformation_after_touch_up_permille": float(deform_after.max()),
                }
            )
    return rows


# --------------------------------------------------------------------------------------------
# §5: the scripted stage 2 in each decentration variant
# --------------------------------------------------------------------------------------------


def _fit_knob(
    unit: CorrectionUnit,
    axis: str,
    fiducial_mm: Any,
    target_rod_mm: Any,
    linkage: str,
    iterations: int = 30,
) -> CorrectionUnit:
    """Turn one knob until the fiducial is under the mark at the target rod coordinate.

    Vectorised Newton iteration on T with a central-difference derivative; the coordinate that is
    compared is ξ for "alpha" (Y free onto the fiducial line) and η for "omega" (X free).
    """
    comp = 0 if axis == "alpha" else 1

    def g(t: Any) -> Any:
        u = turn_correction_knob(unit, axis, t, linkage)
        return rod_from_photo(fiducial_mm, u)[..., comp] - target_rod_mm

    t = np.zeros(np.shape(target_rod_mm))
    h = 1e-7
    for _ in range(iterations):
        r = g(t)
        step = r / ((g(t + h) - g(t - h)) / (2 * h))
        t = t - step
        if np.all(np.abs(step) < 1e-15):
            break
    return turn_correction_knob(unit, axis, t, linkage)


class Stage2Result(NamedTuple):
    """Outcome of the scripted stage 2 (:func:`stage2_setting`).

    Attributes
    ----------
    unit : CorrectionUnit
        The unit after stage 2 (κ = 0 as during the fits; computed decentrations set).
    mark4_mismatch_mm : ndarray
        The book's check after the k_ω fit: with the Y counter at MO_Y − n|y⁰₄| (Eq. (6.12)) and
        X on the fiducial line, the distance on the photo between the point under the mark and
        fiducial 4. [mm, photo]
    mark4_rod_mismatch_mm : ndarray
        The same as a rod coordinate: η of fiducial 4 minus y⁰(−l; ω); times n it is the Y
        counter change that would bring the mark onto fiducial 4. [mm]
    """

    unit: CorrectionUnit
    mark4_mismatch_mm: NDArray[np.float64]
    mark4_rod_mismatch_mm: NDArray[np.float64]


def stage2_setting(
    alpha: NDArray[Any],
    omega: NDArray[Any],
    side_sign: NDArray[Any],
    variant: str,
    pair: SyntheticPair | None = None,
) -> Stage2Result:
    r"""Scripted stage 2 of §26 for one photo (vectorised): fit k_ω, check mark 4, fit k_α.

    Parameters
    ----------
    alpha, omega : ndarray
        True tilts of the photos. [rad]
    side_sign : ndarray
        +1 for a left photo (k_α on mark 2 at +l), −1 for a right photo (mark 1 at −l).
    variant : {"L", "A", "B", "B2", "S"}
        Decentration variant (``decentration_variants.DECENTRATION_VARIANTS``).
    pair : SyntheticPair, optional
        f′ and l; default the §5 data.

    Returns
    -------
    Stage2Result
        The unit after stage 2 and the mark-4 mismatch.

    Notes
    -----
    ``kinematics.md`` §4.1–§4.2, §26 stage 2 of [1]_: with the decentrations at zero
    (or, in B2, at their computed values) and the nadir-referenced targets MO + n·y⁰₃ (6.12),
    turn k_ω until mark 3 is under the mark; check mark 4 at MO − n|y⁰₄|; then k_α on mark 2
    (left) or 1 (right) at MO + n·x⁰ (6.13); then set the computed decentrations (variant L
    overrides the dependent value, A and B set both decentrations, B2 has set them first).
    The targets are n-free rod coordinates: the fits are per photo and n and MO cancel.

    Examples
    --------
    Variant B at ω = 1°: the fit returns about 2.3 times the true ω, and mark 4 misses by
    0.12 mm against the tolerance 0.02·n_л = 0.028 mm.

    >>> import numpy as np
    >>> r = stage2_setting(0.0, np.radians(1.0), 1.0, "B")
    >>> omega_fitted_deg = np.degrees(np.arctan(r.unit.tan_omega))
    >>> round(float(omega_fitted_deg), 2), round(float(r.mark4_mismatch_mm), 3)
    (2.34, 0.123)
    """
    pair = pair or SyntheticPair()
    v = decentration_variant(variant)
    f, ell = pair.focal_length_mm, pair.mark_distance_mm
    alpha, omega, side_sign = np.broadcast_arrays(
        np.asarray(alpha, float), np.asarray(omega, float), np.asarray(side_sign, float)
    )
    zeros = np.zeros(alpha.shape)
    unit = CorrectionUnit(f, zeros, zeros, zeros, zeros, 0.0, strict_per_axis=v.strict_per_axis)
    dx, dy = decentration(f, alpha), decentration(f, omega)
    if v.decentrations_first:
        unit = set_decentrations(unit, dx, dy)
    # (6.12): mark 3 at MO_Y + n·y⁰(+l; ω), X free
    mark3 = np.stack([zeros, zeros + ell], axis=-1)
    unit = _fit_knob(unit, "omega", mark3, transformed_y_single_tilt(ell, omega, f), v.linkage)
    # check: mark 4 at MO_Y − n|y⁰₄| = MO_Y + n·y⁰(−l; ω), X on the fiducial line
    mark4 = np.stack([zeros, zeros - ell], axis=-1)
    rod4 = rod_from_photo(mark4, unit)
    target4 = transformed_y_single_tilt(-ell, omega, f)
    seen = photo_from_rod(np.stack([rod4[..., 0], target4], axis=-1), unit)
    mismatch = np.hypot(*np.moveaxis(seen - mark4, -1, 0))
    rod_mismatch = rod4[..., 1] - target4
    # (6.13): mark 2 (left, +l) or mark 1 (right, −l) at MO_X + n·x⁰, Y free
    x_mark = side_sign * ell
    mark_x = np.stack([x_mark, zeros], axis=-1)
    unit = _fit_knob(unit, "alpha", mark_x, transformed_x_single_tilt(x_mark, alpha, f), v.linkage)
    if not v.decentrations_first:
        unit = set_decentrations(unit, dx, dy)
    return Stage2Result(unit, mismatch, rod_mismatch)


#: Signs of (α_л, ω_л, α_п, ω_п) in ``kinematics.md`` §5 [1].
STAGE2_SIGNS = (1.0, -1.0, -1.0, 1.0)


def _photo_unit(unit: CorrectionUnit, i: int, kappa: Any) -> CorrectionUnit:
    """Photo ``i`` (0 left, 1 right) of a stage-2 unit fitted for both photos, shape (T, 1)."""
    fitted: Any = unit  # its fields (2, T), one row per photo
    return replace(
        unit,
        tan_alpha=fitted.tan_alpha[i][:, None],
        tan_omega=fitted.tan_omega[i][:, None],
        decentration_x_mm=fitted.decentration_x_mm[i][:, None],
        decentration_y_mm=fitted.decentration_y_mm[i][:, None],
        plane_decentration_x_mm=None,
        plane_decentration_y_mm=None,
        kappa=kappa,
    )


def stage2_table(
    pair: SyntheticPair | None = None,
    tilts_deg: Sequence[float] = (0.5, 1.0, 3.0),
    variants: Sequence[str] = ("L", "A", "B", "B2", "S"),
) -> list[dict[str, Any]]:
    r"""``kinematics.md`` §5 [1]: stage 2 in each decentration variant.

    Parameters
    ----------
    pair : SyntheticPair, optional
        Default: the §5 data.
    tilts_deg : sequence of float
        Tilt magnitudes t; signs (α_л +, ω_л −, α_п −, ω_п +). [°]
    variants : sequence of str
        Names from ``decentration_variants.DECENTRATION_VARIANTS``.

    Returns
    -------
    list of dict
        One row per variant and tilt: ``alpha_left_error_deg``, ``omega_left_error_deg``
        (fitted atan T − true) [°]; ``mark4_mismatch_mm`` (left photo, on the photo: the book's
        check against ±0.02·n_л) and ``mark4_mismatch_right_mm`` [mm];
        ``mark4_counter_mismatch_mm`` and ``..._right_mm`` (the same as a Y-counter difference,
        n·|Δη|) [mm]; ``mark4_tolerance_mm`` = 0.02·n_л [mm];
        ``max_q_um``, ``rms_q_um`` with b and κ exact [µm]; ``max_q_after_touch_up_um`` [µm].
    """
    pair = pair or SyntheticPair()
    setting = pair.setting()
    n_l = pair.n_left
    n_r = (pair.projection_distance_max_mm + float(cast(Any, setting.base_z_mm))) / (
        pair.f_instrument_mm
    )
    t = np.asarray(tilts_deg, float) * _DEG
    s = np.asarray(STAGE2_SIGNS)
    tilts = t[:, None] * s  # (T, 4)
    pl, pr = pair.photos(tilts)
    rows = []
    for name in variants:
        v = decentration_variant(name)
        # left and right photos of all tilts in one call: shape (2, T)
        alpha = np.stack([tilts[:, 0], tilts[:, 2]])
        omega = np.stack([tilts[:, 1], tilts[:, 3]])
        unit, mismatch, rod_mismatch = stage2_setting(
            alpha, omega, np.array([[1.0], [-1.0]]), name, pair
        )
        left = _photo_unit(unit, 0, pair.kappa_left)
        right = _photo_unit(unit, 1, pair.kappa_right)
        reading = y_parallax(pl, pr, setting, left, right)
        max_q, rms_q = _q_stats(reading.y_parallax_mm)
        q_after, _, _ = touch_up(pl, pr, setting, left, right, v.linkage)
        max_after, _ = _q_stats(q_after)
        fitted: Any = unit
        a_fit = np.arctan(fitted.tan_alpha[0])
        w_fit = np.arctan(fitted.tan_omega[0])
        for i, t_deg in enumerate(tilts_deg):
            rows.append(
                {
                    "variant": name,
                    "tilt_deg": float(t_deg),
                    "alpha_left_error_deg": float((a_fit[i] - tilts[i, 0]) * DEG_PER_RAD),
                    "omega_left_error_deg": float((w_fit[i] - tilts[i, 1]) * DEG_PER_RAD),
                    "mark4_mismatch_mm": float(mismatch[0, i]),
                    "mark4_mismatch_right_mm": float(mismatch[1, i]),
                    "mark4_counter_mismatch_mm": float(abs(rod_mismatch[0, i]) * n_l),
                    "mark4_counter_mismatch_right_mm": float(abs(rod_mismatch[1, i]) * n_r),
                    "mark4_tolerance_mm": 0.02 * n_l,
                    "max_q_um": float(max_q[i] * UM_PER_MM),
                    "rms_q_um": float(rms_q[i] * UM_PER_MM),
                    "max_q_after_touch_up_um": float(max_after[i] * UM_PER_MM),
                }
            )
    return rows


# --------------------------------------------------------------------------------------------
# Sanity checks and the whole self-test
# --------------------------------------------------------------------------------------------


def sanity_checks(pair: SyntheticPair | None = None, tilt_deg: float = 1.0) -> dict[str, float]:
    r"""The sanity checks of ``kinematics.md`` §5, at tilt t for all 16 sign combinations.

    Returns
    -------
    dict
        ``exact_rectification_max_q_um``: q when the rods get the rigorous rectified coordinates
        (3.17) (``transformed_coordinates``), µm; ``affine_model_max_error_um``: max |model −
        A(ground)| of that model, µm; ``unit_round_trip_mm``: photo → rod → photo;
        ``instrument_round_trip_mm``: counters → marks → counters.
    """
    pair = pair or SyntheticPair()
    setting = pair.setting()
    tilts = sign_combinations() * (tilt_deg * _DEG)
    pl, pr = pair.photos(tilts)
    f = pair.focal_length_mm
    m_l = rotation_matrix(tilts[:, 0], tilts[:, 1], pair.kappa_left)[:, None]
    m_r = rotation_matrix(tilts[:, 2], tilts[:, 3], pair.kappa_right)[:, None]
    exact = rods_intersection(
        transformed_coordinates(pl, m_l, f), transformed_coordinates(pr, m_r, f), setting
    )
    g = pair.ground_points_m()
    model = np.stack(
        [
            (g[:, 0] - pair.station_left_m[0]) * MM_PER_M / pair.horizontal_scale_denominator,
            (g[:, 1] - pair.station_left_m[1]) * MM_PER_M / pair.horizontal_scale_denominator,
            pair.true_depth_mm(),
        ],
        axis=-1,
    )
    measured = np.stack([exact.x_mm, exact.y_mm, exact.depth_mm], axis=-1)
    left, right = true_units(pair, tilts, strict=False)
    back = photo_from_rod(rod_from_photo(pl, left), left)
    ml, mr = marks_from_counters(exact.x_mm, exact.y_mm, exact.depth_mm, setting, left, right)
    again = rods_intersection(rod_from_photo(ml, left), rod_from_photo(mr, right), setting)
    counters = np.stack([again.x_mm, again.y_mm, again.depth_mm], axis=-1)
    return {
        "tilt_deg": float(tilt_deg),
        "exact_rectification_max_q_um": float(np.max(np.abs(exact.y_parallax_mm)) * UM_PER_MM),
        "affine_model_max_error_um": float(np.max(np.abs(measured - model)) * UM_PER_MM),
        "unit_round_trip_mm": float(np.max(np.abs(back - pl))),
        "instrument_round_trip_mm": float(np.max(np.abs(counters - measured))),
    }


def run_kinematic_selftest(
    tilts: Sequence[float] = (0.5 * _DEG, 1.0 * _DEG, 3.0 * _DEG),
    variants: Sequence[str] = ("L", "A", "B", "B2", "S"),
    instrument: Any = None,
) -> dict[str, Any]:
    r"""The kinematic acceptance of ``kinematics.md`` §5 and §6, as JSON-ready data.

    Parameters
    ----------
    tilts : sequence of float
        Tilt magnitudes t (default 0.5°, 1°, 3°). [rad]
    variants : sequence of str
        Decentration variants for the §5 table.
    instrument : InstrumentSpec, optional
        If given, D_max is taken from ``instrument.projection_distance_max_mm``; otherwise the §5
        data (D_max = 185 mm, the SC-1 example) are used, and its correction mechanism
        (:func:`~stereoplotter.instrument.principles.mechanism_for`) adds its own rows.

    Returns
    -------
    dict
        ``data`` (the synthetic pair), ``sanity`` (:func:`sanity_checks`), ``residuals``
        (:func:`residual_table`, §6) and ``stage2`` (:func:`stage2_table`, §5); plain floats,
        strings and lists only.

    Examples
    --------
    >>> r = run_kinematic_selftest(tilts=[0.01745329], variants=("L",))
    >>> row = r["residuals"][0]
    >>> row["unit"], round(row["max_q_um"], 1)
    ('canonical', 2.2)
    """
    pair = SyntheticPair()
    mechanism = None
    if instrument is not None:
        mechanism = mechanism_for(instrument)
        pair = replace(
            pair, projection_distance_max_mm=float(instrument.projection_distance_max_mm)
        )
    tilts_deg = [round(float(t) * DEG_PER_RAD, 9) for t in tilts]
    return {
        "data": {
            "focal_length_mm": pair.focal_length_mm,
            "f_instrument_mm": pair.f_instrument_mm,
            "projection_distance_max_mm": pair.projection_distance_max_mm,
            "n_left": pair.n_left,
            "mark_distance_mm": pair.mark_distance_mm,
            "horizontal_scale_denominator": pair.horizontal_scale_denominator,
            "vertical_scale_denominator": pair.vertical_scale_denominator,
            "base_mm": [
                float(b)
                for b in base_components(
                    pair.station_left_m,
                    pair.station_right_m,
                    pair.horizontal_scale_denominator,
                    pair.vertical_scale_denominator,
                )
            ],
            "points": int(pair.grid_size**2),
            "kappa_left_deg": pair.kappa_left * DEG_PER_RAD,
            "kappa_right_deg": pair.kappa_right * DEG_PER_RAD,
        },
        "sanity": sanity_checks(pair),
        "mechanism": None if mechanism is None else mechanism.key,
        "residuals": residual_table(pair, tilts_deg, mechanism),
        "stage2": stage2_table(pair, tilts_deg, variants),
    }


def format_selftest(result: dict[str, Any]) -> str:
    r"""Text tables of :func:`run_kinematic_selftest`, laid out like ``kinematics.md`` §5, §6.

    Examples
    --------
    >>> r = run_kinematic_selftest(tilts=[0.00872665], variants=("B",))
    >>> print(format_selftest(r).splitlines()[-1])
    B       0.5    +0.6798    -0.7043   0.0309  0.028    2587.7    999.2     725.7 FAIL
    """
    d = result["data"]
    s = result["sanity"]
    lines = [
        f"Kinematic self-test (kinematics.md §5, §6): f' = {d['focal_length_mm']:g} mm, "
        f"f_pr = {d['f_instrument_mm']:g} mm, D_max = {d['projection_distance_max_mm']:g} mm, "
        f"{d['points']} points",
        f"n_l = {d['n_left']:.4f}, M_g = 1:{d['horizontal_scale_denominator']:.1f}, "
        f"M_v = 1:{d['vertical_scale_denominator']:.1f}, b = ({d['base_mm'][0]:.3f}, "
        f"{d['base_mm'][1]:.3f}, {d['base_mm'][2]:.3f}) mm",
        "",
        f"Sanity (t = {s['tilt_deg']:g} deg, 16 sign combinations): exact rectification "
        f"max|q| = {s['exact_rectification_max_q_um']:.1e} um, model vs affine image "
        f"{s['affine_model_max_error_um']:.1e} um, unit round trip "
        f"{s['unit_round_trip_mm']:.1e} mm, instrument round trip "
        f"{s['instrument_round_trip_mm']:.1e} mm",
        "",
        "§6 Residual y-parallax, unit at the true settings, worst of 16 sign combinations",
        f"{'unit':<17}{'t':>6}{'max|q|':>10}{'RMS q':>9}{'touch-up':>10}"
        f"{'deform.':>10}{'(after)':>10}",
        f"{'':<17}{'deg':>6}{'um':>10}{'um':>9}{'um':>10}{'‰ H':>10}{'‰ H':>10}",
    ]
    for r in result["residuals"]:
        lines.append(
            f"{r['unit']:<17}{r['tilt_deg']:>6g}{r['max_q_um']:>10.1f}{r['rms_q_um']:>9.1f}"
            f"{r['max_q_after_touch_up_um']:>10.1f}{r['height_deformation_permille']:>10.3f}"
            f"{r['height_deformation_after_touch_up_permille']:>10.3f}"
        )
    lines += [
        "",
        "§5 Stage 2 in the decentration variants (alpha_l +, omega_l -, alpha_r -, omega_r +)",
        f"{'var':<5}{'t':>6}{'d alpha_l':>11}{'d omega_l':>11}{'mark 4':>9}{'tol':>7}"
        f"{'max|q|':>10}{'RMS q':>9}{'touch-up':>10}",
        f"{'':<5}{'deg':>6}{'deg':>11}{'deg':>11}{'mm':>9}{'mm':>7}{'um':>10}{'um':>9}{'um':>10}",
    ]
    for r in result["stage2"]:
        flag = " FAIL" if r["mark4_mismatch_mm"] > r["mark4_tolerance_mm"] else ""
        lines.append(
            f"{r['variant']:<5}{r['tilt_deg']:>6g}{r['alpha_left_error_deg']:>+11.4f}"
            f"{r['omega_left_error_deg']:>+11.4f}{r['mark4_mismatch_mm']:>9.4f}"
            f"{r['mark4_tolerance_mm']:>7.3f}{r['max_q_um']:>10.1f}{r['rms_q_um']:>9.1f}"
            f"{r['max_q_after_touch_up_um']:>10.1f}{flag}"
        )
    return "\n".join(lines) + "\n"
