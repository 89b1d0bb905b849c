r"""Block mode of the setup-data computer: one setup sheet per model of a block, vectorised.

A *block file* (YAML, ``docs/scenarios.md``) lists many stereopairs of one camera, each with its
exterior orientation, the lowest and highest ground of its working area and optional height control
points. :func:`compute_block` computes the Table 24 values of every pair in one pass of numpy
broadcasting over the N pairs (and over the (M_г, M_в) candidate grid of the scale choice); a pair
the instrument cannot take gets NaN and a reason code instead of raising (``style.md`` §10).
:func:`per_pair_loop` computes the same with a plain Python loop over the pairs: it is the test
oracle and the benchmark's comparison (``benchmarks/bench_setup_block.py``).

Reference
---------
.. [1] Kushtin I. F. & Lyskov G. A., *Фотограмметрия снимка и стереоскопических моделей*,
   Moscow: Nedra, 1984, ch. 6, §26, pp. 153–158 (OCR L3682–3826): Eqs. (6.1)–(6.6), Table 24.

Equations chained (each lives in one place: :mod:`stereoplotter.setup.equations`,
:mod:`stereoplotter.geometry.transformed`, :mod:`stereoplotter.geometry.rotation`):

* frame: θ = atan2(ΔY_S, ΔX_S), M′ = R_Z(−θ)·M, α, ω, κ from M′ (inverse of (2.50));
* item 1: the scale choice, f_пр = f′·M_г/M_в, b_x, b_y, b_z′;
* (6.3) n_л, (6.4) n_п; (6.1)/(6.2) x⁰, y⁰ of the marks (n-free) and (3.17) with κ = 0;
* (6.5) L_л, L_п; decentrations f′·tan α, f′·tan ω; (6.6) Z_i of the height points.

**Not in block mode:** the sheet corners (6.7) and the similarity (6.8) need the map sheet and
plan control of each model; compute those per model with
:func:`stereoplotter.setup.sheet.compute_setup_sheet`. Likewise the X, Y travel of the model
(``model_x_offset_range_mm``) is not checked here, since a block file gives no plan extent of the
working area; the single-pair sheet checks it.

Shapes: N pairs; photo axis 0 = left, 1 = right; C scale candidates; P height points (padded with
NaN). Units: ground m, model and photo mm, angles rad.

Decisions (``docs/setup-data.md``): f′ is the camera's calibrated f unless the caller passes a
corrected one (a block file has no measured fiducial spans); the marks of (6.1)/(6.2) are the
calibrated ones, taken relative to the principal point.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.errors import StereoplotterError
from stereoplotter.geometry.rotation import angles_from_matrix, rotation_matrix, rotation_z
from stereoplotter.geometry.transformed import (
    transformed_coordinates,
    transformed_x_single_tilt,
    transformed_y_single_tilt,
)
from stereoplotter.instrument.spec import InstrumentSpec, RangeRefusal, check_in_range
from stereoplotter.setup.equations import (
    base_components,
    counter_scale_left,
    counter_scale_right,
    decentration,
    instrument_principal_distance,
    mark_span,
    model_height,
    projection_distance,
    transformation_coefficient,
)
from stereoplotter.setup.scale_choice import (
    candidate_flags,
    candidate_scales,
    choose_candidates,
    describe_candidate,
)

__all__ = [
    "X_MARK_NAME",
    "BlockResult",
    "Refusal",
    "compute_block",
    "per_pair_loop",
    "reason_text",
]

#: Marks used per photo (Table 24 reading, docs/setup-data.md): left x of mark 2, right x of mark 1,
#: both y of marks 3 and 4. Indices into marks 1..4.
_X_MARK = (1, 0)
X_MARK_NAME = ("2", "1")


class Refusal(enum.IntFlag):
    """Reason codes of a refused pair (bit flags; 0 = accepted).

    The scale-dependent codes (``F_INSTRUMENT`` … ``BASE_Z``) are those of the *closest* (M_г,
    M_в) candidate when no candidate is feasible: fewest violated conditions, then the largest
    model scale, as :mod:`stereoplotter.setup.sheet` reports it.
    """

    NONE = 0
    INVALID_INPUT = 1  #: a non-finite input or terrain lowest > highest
    F_INSTRUMENT = 2  #: f_пр outside f_instrument_range_mm
    PROJECTION_DISTANCE = 4  #: depth of the working area (and + b_z′) outside [D_min, D_max]
    BASE_X = 8  #: b_x outside base_x_range_mm
    BASE_Y = 16  #: b_y outside base_y_range_mm
    BASE_Z = 32  #: b_z′ outside base_z_range_mm
    KAPPA = 64  #: κ of a photo (instrument frame) outside kappa_range
    TILT = 128  #: |α| or |ω| above tilt_max
    DECENTRATION = 256  #: f′·tan α or f′·tan ω outside decentration_range_mm


_SCALE_FLAGS = (
    Refusal.F_INSTRUMENT,
    Refusal.PROJECTION_DISTANCE,
    Refusal.BASE_X,
    Refusal.BASE_Y,
    Refusal.BASE_Z,
)


# --- the result -------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class BlockResult:
    """Setup data of N pairs (Table 24 without (6.7)/(6.8)). Refused pairs hold NaN.

    Attributes
    ----------
    name, instrument : str
        Block name; instrument key.
    model_names : tuple of str
    spec : InstrumentSpec
        The instrument (for the refusal messages).
    map_scale_denominator : int or None
    focal_length_corrected_mm : float
        f′. [mm]
    book_sign : bool
        (6.4) with the printed sign.
    candidate_scales : ndarray, shape (C, 2)
        The (M_г, M_в) grid of the scale choice. [—]
    feasible_candidates : ndarray of bool, shape (N, C)
    candidate_index : ndarray of int, shape (N,)
        The chosen candidate, or the closest one of a pair with no feasible candidate.
    reason_code : ndarray of int, shape (N,)
        :class:`Refusal` flags; 0 = accepted.
    frame_rotation : ndarray, shape (N,)
        θ, azimuth of the horizontal base. [rad]
    base_ground_m : ndarray, shape (N, 3)
        S_п − S_л in the instrument frame (X along the base). [m]
    depth_ground_m : ndarray, shape (N, 2)
        Z_Sл − highest, Z_Sл − lowest ground. [m]
    angles : ndarray, shape (N, 2, 3)
        α, ω, κ of the left, right photo in the instrument frame. [rad]
    horizontal_scale_denominator, vertical_scale_denominator : ndarray, shape (N,)
        M_г, M_в (float, NaN when refused). [—]
    f_instrument_mm, transformation_coefficient, n_left, n_right : ndarray, shape (N,)
        f_пр [mm], k [—], n_л, n_п [—].
    base_mm : ndarray, shape (N, 3)
        b_x, b_y, b_z′. [mm]
    fiducials_transformed_mm : ndarray, shape (N, 2, 3)
        Per photo: x⁰ of its x mark (left 2, right 1), y⁰₃, y⁰₄, from (6.1)/(6.2) without n. [mm]
    fiducials_rigorous_mm : ndarray, shape (N, 2, 3, 2)
        (3.17) x⁰, y⁰ of the same marks with κ = 0. [mm]
    mark_span_mm : ndarray, shape (N, 2)
        L_л, L_п of (6.5). [mm]
    decentration_mm : ndarray, shape (N, 2, 2)
        Per photo f′·tan α, f′·tan ω. [mm]
    depth_range_mm : ndarray, shape (N, 2)
        Projection distances of the highest and lowest ground at M_в. [mm]
    height_point_ids : tuple of tuple of str
    control_heights_model_mm : ndarray, shape (N, P)
        Z_i of (6.6), NaN-padded. [mm]
    """

    name: str
    instrument: str
    model_names: tuple[str, ...]
    spec: InstrumentSpec = field(repr=False)
    map_scale_denominator: int | None
    focal_length_corrected_mm: float
    book_sign: bool
    candidate_scales: NDArray[np.float64]
    feasible_candidates: NDArray[np.bool_]
    candidate_index: NDArray[np.int64]
    reason_code: NDArray[np.int64]
    frame_rotation: NDArray[np.float64]
    base_ground_m: NDArray[np.float64]
    depth_ground_m: NDArray[np.float64]
    angles: NDArray[np.float64]
    horizontal_scale_denominator: NDArray[np.float64]
    vertical_scale_denominator: NDArray[np.float64]
    f_instrument_mm: NDArray[np.float64]
    transformation_coefficient: NDArray[np.float64]
    n_left: NDArray[np.float64]
    n_right: NDArray[np.float64]
    base_mm: NDArray[np.float64]
    fiducials_transformed_mm: NDArray[np.float64]
    fiducials_rigorous_mm: NDArray[np.float64]
    mark_span_mm: NDArray[np.float64]
    decentration_mm: NDArray[np.float64]
    depth_range_mm: NDArray[np.float64]
    height_point_ids: tuple[tuple[str, ...], ...]
    control_heights_model_mm: NDArray[np.float64]

    def __len__(self) -> int:
        return len(self.model_names)

    @property
    def accepted(self) -> NDArray[np.bool_]:
        """True where the instrument takes the pair."""
        return self.reason_code == 0

    def reason(self, i: int) -> str:
        """The refusal of pair ``i`` in words ("" when accepted): values, ranges, way out."""
        return reason_text(self, int(i))


_ARRAY_FIELDS = tuple(
    f
    for f in BlockResult.__slots__
    if f
    not in (
        "name",
        "instrument",
        "model_names",
        "spec",
        "map_scale_denominator",
        "focal_length_corrected_mm",
        "book_sign",
        "candidate_scales",
        "height_point_ids",
    )
)


# --- computation ------------------------------------------------------------------------------


def _candidate_grid(
    spec: InstrumentSpec, map_scale: int | None, horizontal: int | None, vertical: int | None
) -> NDArray[np.float64]:
    """(M_г, M_в) candidates, shape (C, 2)
    (:func:`stereoplotter.setup.scale_choice.candidate_scales`)."""
    try:
        return candidate_scales(spec, map_scale, horizontal, vertical)
    except StereoplotterError as exc:
        raise ValueError(str(exc)) from None


def _inside_with_slack(v: NDArray, lo: float, hi: float) -> NDArray[np.bool_]:
    """lo ≤ v ≤ hi with the 1e-9 relative slack of ``instrument.spec.check_in_range``."""
    eps = 1e-9 * max(1.0, abs(lo), abs(hi))
    with np.errstate(invalid="ignore"):
        return (v >= lo - eps) & (v <= hi + eps)


def _prepare(
    focal_length_corrected_mm: float,
    fiducials_mm: ArrayLike,
    principal_point_mm: ArrayLike,
    centre_left_m: ArrayLike,
    angles_left: ArrayLike,
    centre_right_m: ArrayLike,
    angles_right: ArrayLike,
    terrain_m: ArrayLike,
    height_points_m: ArrayLike | None,
) -> tuple[float, NDArray, NDArray, NDArray, NDArray, NDArray]:
    f = float(focal_length_corrected_mm)
    marks = np.asarray(fiducials_mm, float) - np.asarray(principal_point_mm, float)
    if marks.shape != (4, 2):
        raise ValueError(f"fiducials_mm: expected shape (4, 2) (marks 1–4), found {marks.shape}")
    centres = np.stack(
        [np.asarray(centre_left_m, float), np.asarray(centre_right_m, float)], axis=1
    )
    angles = np.stack([np.asarray(angles_left, float), np.asarray(angles_right, float)], axis=1)
    if centres.ndim != 3 or centres.shape[2] != 3 or angles.shape != centres.shape:
        raise ValueError(
            "centre_*_m and angles_* must have shape (N, 3); found "
            f"{centres.shape[::2]} and {angles.shape[::2]}"
        )
    n = centres.shape[0]
    terrain = np.asarray(terrain_m, float)
    if terrain.shape != (n, 2):
        raise ValueError(f"terrain_m: expected shape ({n}, 2), found {terrain.shape}")
    heights = np.zeros((n, 0)) if height_points_m is None else np.asarray(height_points_m, float)
    if heights.ndim != 2 or heights.shape[0] != n:
        raise ValueError(f"height_points_m: expected shape ({n}, P), found {heights.shape}")
    return f, marks, centres, angles, terrain, heights


def compute_block(
    focal_length_corrected_mm: float,
    fiducials_mm: ArrayLike,
    centre_left_m: ArrayLike,
    angles_left: ArrayLike,
    centre_right_m: ArrayLike,
    angles_right: ArrayLike,
    terrain_m: ArrayLike,
    spec: InstrumentSpec,
    map_scale_denominator: int | None,
    *,
    principal_point_mm: ArrayLike = (0.0, 0.0),
    height_points_m: ArrayLike | None = None,
    horizontal_scale_denominator: int | None = None,
    vertical_scale_denominator: int | None = None,
    book_sign: bool = False,
    model_names: tuple[str, ...] | None = None,
    height_point_ids: tuple[tuple[str, ...], ...] | None = None,
    name: str = "block",
) -> BlockResult:
    r"""Setup data of N stereopairs of one camera, vectorised over the pairs.

    Parameters
    ----------
    focal_length_corrected_mm : float
        f′ (the calibrated f when no film deformation is known). [mm]
    fiducials_mm : array_like, shape (4, 2)
        Calibrated marks 1–4 (1 at −x, 2 at +x, 3 at +y, 4 at −y). [mm]
    centre_left_m, centre_right_m : array_like, shape (N, 3)
        X_S, Y_S, Z_S of the left and right photo, in any photogrammetric system with Z up. [m]
    angles_left, angles_right : array_like, shape (N, 3)
        α, ω, κ of Eq. (2.50) in that system. [rad]
    terrain_m : array_like, shape (N, 2)
        Lowest and highest ground height of each model's working area. [m]
    spec : InstrumentSpec
        The instrument (ranges, gear sets, D_max).
    map_scale_denominator : int or None
        M_map; M_г = r·M_map for the coordinatograph ratios r. [—]
    principal_point_mm : array_like, shape (2,)
        x₀, y₀; the marks are taken relative to it. [mm]
    height_points_m : array_like, shape (N, P), optional
        Z of the height control points of each model, NaN-padded. [m]
    horizontal_scale_denominator, vertical_scale_denominator : int, optional
        Force M_г and/or M_в (still range-checked). [—]
    book_sign : bool
        (6.4) with the printed sign (Z_Sл − Z_Sп).
    model_names, height_point_ids, name
        Labels carried into the result.

    Returns
    -------
    BlockResult
        Pairs with no feasible scale pair, or a tilt, κ or decentration beyond a stop, hold NaN in
        every sheet value and a :class:`Refusal` code; nothing raises mid-batch.

    Notes
    -----
    Chains, per pair and all at once: the frame rotation θ = atan2(ΔY_S, ΔX_S),
    M′ = R_Z(−θ)·M and α, ω, κ from M′ (``docs/setup-data.md``, Frame); the scale choice of item 1
    of [1]_ on the (pair × candidate) grid — feasible when f_пр = f′·M_г/M_в is in range, the
    projection distances (Z_Sл − Z)·1000/M_в of the lowest and highest ground, and the same plus
    b_z′ for the right rod, are inside [D_min, D_max], and b_x, b_y, b_z′ are in range; the largest
    model scale (smallest M_г) wins, then the smallest M_в, as in
    :func:`stereoplotter.setup.sheet.compute_setup_sheet`; then Eqs. (6.3), (6.4), (6.1)/(6.2)
    (n-free) and (3.17) with κ = 0 for the marks, (6.5), the decentrations and (6.6).

    (6.7)/(6.8) — the sheet corners — are **not** computed in block mode (they need a map sheet
    and plan control per model), nor is the X, Y travel of the model checked.

    Examples
    --------
    The model of the book's §27 setting (f = 70 mm, 60 % overlap, photo scale 1:20 000):

    >>> import numpy as np
    >>> from stereoplotter.io.instrument_file import load_instrument
    >>> marks = [[-85.0, 0.0], [85.0, 0.0], [0.0, 85.0], [0.0, -85.0]]
    >>> r = compute_block(70.0, marks, [[-720.0, 0.0, 1550.0]], [[0.0, 0.0, 0.0]],
    ...                   [[720.0, 0.0, 1560.0]], [[0.0, 0.0, 0.0]], [[120.0, 210.0]],
    ...                   load_instrument("sc1"), 10000)
    >>> float(r.horizontal_scale_denominator[0]), float(r.vertical_scale_denominator[0])
    (12500.0, 8000.0)
    >>> round(float(r.n_left[0]), 5), round(float(r.base_mm[0, 0]), 3)
    (1.69143, 115.2)
    """
    f, marks, centres, angles, terrain, heights = _prepare(
        focal_length_corrected_mm,
        fiducials_mm,
        principal_point_mm,
        centre_left_m,
        angles_left,
        centre_right_m,
        angles_right,
        terrain_m,
        height_points_m,
    )
    n = centres.shape[0]
    invalid = ~(
        np.isfinite(centres).all(axis=(1, 2))
        & np.isfinite(angles).all(axis=(1, 2))
        & np.isfinite(terrain).all(axis=1)
    )
    with np.errstate(invalid="ignore"):
        invalid |= terrain[:, 0] > terrain[:, 1]

    # Frame: base along +X, origin S_л (docs/setup-data.md, Inputs, "Frame").
    base_vector = centres[:, 1] - centres[:, 0]
    theta = np.arctan2(base_vector[:, 1], base_vector[:, 0])
    turn = rotation_z(-theta)  # (N, 3, 3)
    rotations = turn[:, None] @ rotation_matrix(angles[..., 0], angles[..., 1], angles[..., 2])
    alpha, omega, kappa = angles_from_matrix(rotations)  # (N, 2) each
    base_m = np.einsum("nij,nj->ni", turn, base_vector)
    depth_m = centres[:, 0, 2:3] - terrain[:, ::-1]  # (N, 2): Z_Sл − highest, Z_Sл − lowest

    # Item 1: scale choice on the (pair × candidate) grid.
    grid = _candidate_grid(
        spec, map_scale_denominator, horizontal_scale_denominator, vertical_scale_denominator
    )
    mg_c, mv_c = grid[:, 0], grid[:, 1]
    flags_c = candidate_flags(spec, f, grid, depth_m, base_m)  # (N, C)
    feasible = flags_c == 0
    chosen, any_ok = choose_candidates(flags_c, grid)
    reason = np.where(any_ok, 0, flags_c[np.arange(n), chosen])

    # Settings that do not depend on the scale: κ, tilts, decentrations (the stops).
    dec = np.stack([decentration(f, alpha), decentration(f, omega)], axis=-1)  # (N, 2, 2)
    k_lo, k_hi = spec.kappa_range
    reason |= np.where(~_inside_with_slack(kappa, k_lo, k_hi).all(axis=1), int(Refusal.KAPPA), 0)
    tilts = np.concatenate([alpha, omega], axis=1)
    t_ok = _inside_with_slack(tilts, -spec.tilt_max, spec.tilt_max).all(axis=1)
    reason |= np.where(~t_ok, int(Refusal.TILT), 0)
    dc_ok = _inside_with_slack(dec, *spec.decentration_range_mm).all(axis=(1, 2))
    reason |= np.where(~dc_ok, int(Refusal.DECENTRATION), 0)
    reason = np.where(invalid, int(Refusal.INVALID_INPUT), reason)
    ok = reason == 0

    mg = np.where(ok, mg_c[chosen], np.nan)
    mv = np.where(ok, mv_c[chosen], np.nan)
    f_pr = instrument_principal_distance(f, mg, mv)
    k = transformation_coefficient(f_pr, f)
    n_left = counter_scale_left(spec.projection_distance_max_mm, f_pr)  # (6.3)
    n_right = counter_scale_right(n_left, 0.0, base_m[:, 2], f_pr, mv, book_sign=book_sign)  # (6.4)
    b = base_components(np.zeros(3), base_m, mg, mv)
    mask2 = np.where(ok, 1.0, np.nan)[:, None]
    x0 = transformed_x_single_tilt(marks[list(_X_MARK), 0], alpha, f) * mask2  # (6.1)
    y3 = transformed_y_single_tilt(marks[2, 1], omega, f) * mask2  # (6.2)
    y4 = transformed_y_single_tilt(marks[3, 1], omega, f) * mask2
    rig_marks = marks[[[1, 2, 3], [0, 2, 3]]]  # (2, 3, 2)
    untwisted = rotation_matrix(alpha, omega, 0.0)  # the cassette κ is 0 in stage 2
    rigorous = transformed_coordinates(rig_marks, untwisted[:, :, None], f)  # (3.17)
    rigorous = rigorous * mask2[..., None, None]
    spans = mark_span(np.stack([n_left, n_right], axis=1), y3, y4)  # (6.5)
    flying = centres[:, 0, 2:3] - heights  # H_Фi = Z_Sл − Z_Фi
    control = model_height(flying, mv[:, None])  # (6.6)
    depth_used = projection_distance(depth_m, mv[:, None])

    names = tuple(model_names) if model_names is not None else tuple(f"{i + 1}" for i in range(n))
    ids = (
        height_point_ids
        if height_point_ids is not None
        else tuple(tuple(str(j + 1) for j in range(heights.shape[1])) for _ in range(n))
    )
    return BlockResult(
        name=name,
        instrument=spec.key,
        model_names=names,
        spec=spec,
        map_scale_denominator=map_scale_denominator,
        focal_length_corrected_mm=f,
        book_sign=book_sign,
        candidate_scales=grid,
        feasible_candidates=feasible,
        candidate_index=chosen,
        reason_code=reason.astype(np.int64),
        frame_rotation=theta,
        base_ground_m=base_m,
        depth_ground_m=depth_m,
        angles=np.stack([alpha, omega, kappa], axis=-1),
        horizontal_scale_denominator=mg,
        vertical_scale_denominator=mv,
        f_instrument_mm=f_pr,
        transformation_coefficient=k,
        n_left=n_left,
        n_right=n_right,
        base_mm=b,
        fiducials_transformed_mm=np.stack([x0, y3, y4], axis=-1),
        fiducials_rigorous_mm=rigorous,
        mark_span_mm=spans,
        decentration_mm=dec * mask2[..., None],
        depth_range_mm=depth_used,
        height_point_ids=ids,
        control_heights_model_mm=control,
    )


def per_pair_loop(
    focal_length_corrected_mm: float,
    fiducials_mm: ArrayLike,
    centre_left_m: ArrayLike,
    angles_left: ArrayLike,
    centre_right_m: ArrayLike,
    angles_right: ArrayLike,
    terrain_m: ArrayLike,
    spec: InstrumentSpec,
    map_scale_denominator: int | None,
    **options: Any,
) -> BlockResult:
    """The same as :func:`compute_block`, one pair at a time (a plain Python loop on scalars).

    Parameters
    ----------
    focal_length_corrected_mm, fiducials_mm, centre_left_m, angles_left, centre_right_m, \
angles_right, terrain_m, spec, map_scale_denominator, **options
        As for :func:`compute_block`. [mm, m, rad]

    Returns
    -------
    BlockResult
        Equal to :func:`compute_block` to rounding (the test oracle and the benchmark's
        comparison; not meant for production use).

    Notes
    -----
    Calls the same equation functions — frame rotation, item 1 of [1]_, (6.1)–(6.6), (3.17) —
    with scalars, and chooses the scales by a loop over the candidates written after
    ``setup_sheet._choose_scales``.
    """
    f, marks, centres, angles, terrain, heights = _prepare(
        focal_length_corrected_mm,
        fiducials_mm,
        options.get("principal_point_mm", (0.0, 0.0)),
        centre_left_m,
        angles_left,
        centre_right_m,
        angles_right,
        terrain_m,
        options.get("height_points_m"),
    )
    grid = _candidate_grid(
        spec,
        map_scale_denominator,
        options.get("horizontal_scale_denominator"),
        options.get("vertical_scale_denominator"),
    )
    book_sign = bool(options.get("book_sign", False))
    rows = [
        _one_pair(f, marks, centres[i], angles[i], terrain[i], heights[i], grid, spec, book_sign)
        for i in range(centres.shape[0])
    ]
    n = len(rows)
    stacked = {key: np.array([r[key] for r in rows]) for key in rows[0]} if rows else {}
    names = options.get("model_names") or tuple(f"{i + 1}" for i in range(n))
    ids = options.get("height_point_ids") or tuple(
        tuple(str(j + 1) for j in range(heights.shape[1])) for _ in range(n)
    )
    return BlockResult(
        name=options.get("name", "block"),
        instrument=spec.key,
        model_names=tuple(names),
        spec=spec,
        map_scale_denominator=map_scale_denominator,
        focal_length_corrected_mm=f,
        book_sign=book_sign,
        candidate_scales=grid,
        height_point_ids=ids,
        **stacked,
    )


def _one_pair(
    f: float,
    marks: NDArray,
    centres: NDArray,
    angles: NDArray,
    terrain: NDArray,
    heights: NDArray,
    grid: NDArray,
    spec: InstrumentSpec,
    book_sign: bool,
) -> dict[str, Any]:
    """One pair with scalars: the oracle of :func:`compute_block`."""
    c_left, c_right = centres
    invalid = not (
        np.isfinite(centres).all() and np.isfinite(angles).all() and np.isfinite(terrain).all()
    ) or bool(terrain[0] > terrain[1])
    base_vector = c_right - c_left
    theta = math.atan2(base_vector[1], base_vector[0])
    turn = rotation_z(-theta)
    photo_angles = []
    for a in angles:
        rot = turn @ rotation_matrix(a[0], a[1], a[2])
        photo_angles.append(tuple(float(v) for v in angles_from_matrix(rot)))
    base_m = turn @ base_vector
    depth = [float(c_left[2] - terrain[1]), float(c_left[2] - terrain[0])]

    # Item 1, as setup_sheet._candidate / _choose_scales.
    candidates = []
    for index, (mg, mv) in enumerate(grid):
        failed = []
        f_pr = float(instrument_principal_distance(f, mg, mv))
        lo, hi = spec.f_instrument_range_mm
        if not lo <= f_pr <= hi:
            failed.append(Refusal.F_INSTRUMENT)
        b = base_components(np.zeros(3), base_m, mg, mv)
        d = [float(projection_distance(v, mv)) for v in depth]
        values = [d[0], d[1], d[0] + b[2], d[1] + b[2]]
        d_lo, d_hi = spec.projection_distance_range_mm
        if min(values) < d_lo or max(values) > d_hi or any(math.isnan(v) for v in values):
            failed.append(Refusal.PROJECTION_DISTANCE)
        for flag, j, attribute in (
            (Refusal.BASE_X, 0, "base_x_range_mm"),
            (Refusal.BASE_Y, 1, "base_y_range_mm"),
            (Refusal.BASE_Z, 2, "base_z_range_mm"),
        ):
            b_lo, b_hi = getattr(spec, attribute)
            if not b_lo <= b[j] <= b_hi:
                failed.append(flag)
        candidates.append((index, float(mg), float(mv), failed))
    feasible = [c for c in candidates if not c[3]]
    if feasible:
        chosen = min(feasible, key=lambda c: (c[1], c[2]))
        reason = 0
    else:
        chosen = min(candidates, key=lambda c: (len(c[3]), c[1]))
        reason = int(sum(chosen[3]))

    decs = [(float(decentration(f, a)), float(decentration(f, w))) for a, w, _ in photo_angles]
    for (a, w, kap), dxy in zip(photo_angles, decs, strict=True):
        for value, attribute, flag in (
            (kap, "kappa_range", Refusal.KAPPA),
            (a, "tilt_max", Refusal.TILT),
            (w, "tilt_max", Refusal.TILT),
            (dxy[0], "decentration_range_mm", Refusal.DECENTRATION),
            (dxy[1], "decentration_range_mm", Refusal.DECENTRATION),
        ):
            try:
                check_in_range(spec, attribute, value, "")
            except RangeRefusal:
                reason |= int(flag)
    if invalid:
        reason = int(Refusal.INVALID_INPUT)
    ok = reason == 0
    nan = math.nan
    mg, mv = (chosen[1], chosen[2]) if ok else (nan, nan)
    f_pr = float(instrument_principal_distance(f, mg, mv))
    n_left = float(counter_scale_left(spec.projection_distance_max_mm, f_pr))  # (6.3)
    n_right = float(
        counter_scale_right(n_left, c_left[2], c_right[2], f_pr, mv, book_sign=book_sign)
    )  # (6.4)
    fid, rig, spans = [], [], []
    for p, ((a, w, _), n) in enumerate(zip(photo_angles, (n_left, n_right), strict=True)):
        x_mark = marks[_X_MARK[p]]
        x0 = float(transformed_x_single_tilt(x_mark[0], a, f))  # (6.1)
        y3 = float(transformed_y_single_tilt(marks[2, 1], w, f))  # (6.2)
        y4 = float(transformed_y_single_tilt(marks[3, 1], w, f))
        fid.append([x0, y3, y4] if ok else [nan] * 3)
        untwisted = rotation_matrix(a, w, 0.0)
        rig.append(
            [
                transformed_coordinates(m, untwisted, f) if ok else [nan, nan]
                for m in (x_mark, marks[2], marks[3])
            ]
        )  # (3.17)
        spans.append(float(mark_span(n, y3, y4)))  # (6.5)
    return {
        "feasible_candidates": np.array([not c[3] for c in candidates]),
        "candidate_index": chosen[0],
        "reason_code": reason,
        "frame_rotation": theta,
        "base_ground_m": base_m,
        "depth_ground_m": depth,
        "angles": photo_angles,
        "horizontal_scale_denominator": mg,
        "vertical_scale_denominator": mv,
        "f_instrument_mm": f_pr,
        "transformation_coefficient": float(transformation_coefficient(f_pr, f)),
        "n_left": n_left,
        "n_right": n_right,
        "base_mm": base_components(np.zeros(3), base_m, mg, mv),
        "fiducials_transformed_mm": fid,
        "fiducials_rigorous_mm": rig,
        "mark_span_mm": spans,
        "decentration_mm": decs if ok else [[nan, nan], [nan, nan]],
        "depth_range_mm": [float(projection_distance(v, mv)) for v in depth],
        "control_heights_model_mm": [
            float(model_height(c_left[2] - z, mv)) for z in heights
        ],  # (6.6)
    }


# --- refusal messages -------------------------------------------------------------------------


def reason_text(result: BlockResult, i: int) -> str:
    code = Refusal(int(result.reason_code[i]))
    if not code:
        return ""
    spec = result.spec
    if Refusal.INVALID_INPUT in code:
        return "invalid input: a non-finite value, or terrain lowest > highest"
    parts = []
    if code & sum(_SCALE_FLAGS):
        candidate = result.candidate_scales[result.candidate_index[i]]
        texts = describe_candidate(
            spec,
            result.focal_length_corrected_mm,
            candidate,
            int(code & sum(_SCALE_FLAGS)),
            result.depth_ground_m[i],
            result.base_ground_m[i],
        )
        parts.append(
            f"none of the {len(result.candidate_scales)} scale pairs fits (way out: another "
            f"instrument or map scale); closest M_г = 1:{candidate[0]:.0f}, "
            f"M_в = 1:{candidate[1]:.0f}: " + "; ".join(texts)
        )
    names = ("left", "right")
    for flag, attribute, getter in (
        (Refusal.KAPPA, "kappa_range", lambda p: [(result.angles[i, p, 2], f"κ_{names[p]}")]),
        (
            Refusal.TILT,
            "tilt_max",
            lambda p: [
                (result.angles[i, p, 0], f"α_{names[p]}"),
                (result.angles[i, p, 1], f"ω_{names[p]}"),
            ],
        ),
        (
            Refusal.DECENTRATION,
            "decentration_range_mm",
            lambda p: [
                (
                    decentration(result.focal_length_corrected_mm, result.angles[i, p, j]),
                    f"decentration d_{'xy'[j]},{names[p]}",
                )
                for j in (0, 1)
            ],
        ),
    ):
        if flag in code:
            checks = [(attribute, v, w) for p in (0, 1) for v, w in getter(p)]
            parts.append(_first_refusal(spec, checks, flag.name or ""))
    return "; ".join(parts)


def _first_refusal(spec: InstrumentSpec, checks: list[tuple[str, Any, str]], name: str) -> str:
    for attribute, value, what in checks:
        try:
            check_in_range(spec, attribute, float(value), what)
        except RangeRefusal as exc:
            return str(exc)
    return name.lower()  # within the slack of check_in_range: name the condition only


