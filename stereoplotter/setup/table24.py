r"""Table 24 of the book for N stereopairs at once: the one computation of the setup data.

Both the single-pair sheet (:func:`stereoplotter.setup.sheet.compute_setup_sheet`, a block of one)
and block mode (:func:`stereoplotter.setup.block.compute_block`) call :func:`compute_table24`. It
chains, with numpy broadcasting over the N pairs (and over the (M_г, M_в) candidate grid of the
scale choice):

* frame: θ = atan2(ΔY_S, ΔX_S), M′ = R_Z(−θ)·M, α, ω, κ from M′ (inverse of (2.50));
* item 1: the scale choice (:mod:`stereoplotter.setup.scale_choice`), f_пр = f′·M_г/M_в, b_x, b_y,
  b_z′;
* (6.3) n_л, (6.4) n_п; (6.1)/(6.2) x⁰, y⁰ of the marks (n-free) and (3.17) with κ = 0;
* (6.5) L_л, L_п; decentrations f′·tan α, f′·tan ω and the correction-plane inclinations;
  (6.6) Z_i of the height points.

A pair the instrument cannot take gets NaN and a :class:`Refusal` code instead of raising
(``style.md`` §10); the single-pair sheet turns the code into its refusal message. The sheet
corners (6.7)/(6.8) and the stage readings need per-pair data a block file lacks; they are added
by :mod:`stereoplotter.setup.sheet`.

Shapes: N pairs; photo axis 0 = left, 1 = right; C scale candidates; P height points (padded with
NaN). Units: ground m, model and photo mm, angles rad.

Reference
---------
.. [1] Kushtin I. F. & Lyskov G. A., *Фотограмметрия снимка и стереоскопических моделей*,
   Moscow: Nedra, 1984, ch. 6, §26, pp. 153–158 (OCR L3682–3826): Eqs. (6.1)–(6.6), Table 24.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.geometry.grouped import group_sums
from stereoplotter.geometry.rotation import angles_from_matrix, rotation_matrix, rotation_z
from stereoplotter.geometry.transformed import (
    transformed_coordinates,
    transformed_x_single_tilt,
    transformed_y_single_tilt,
)
from stereoplotter.setup.equations import (
    base_components,
    correction_inclination,
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
    ScaleCandidate,
    ScaleCheck,
    candidate_flags,
    choose_candidates,
    describe_candidate,
    scale_candidates,
)
from stereoplotter.spec.instrument_spec import InstrumentSpec
from stereoplotter.spec.range_checks import RangeRefusal, check_in_range

__all__ = [
    "SCALE_FLAGS",
    "X_MARK_NAME",
    "BlockResult",
    "PairFrames",
    "Refusal",
    "candidates_of",
    "compute_table24",
    "instrument_frame_m",
    "instrument_frames",
    "pair_frames",
    "reason_text",
]

#: Marks used per photo (Table 24 reading, docs/setup-data.md): left x of mark 2, right x of mark 1,
#: both y of marks 3 and 4. Indices into marks 1..4.
_X_MARK = (1, 0)
X_MARK_NAME = ("2", "1")


class Refusal(enum.IntFlag):
    """Reason codes of a refused pair (bit flags; 0 = accepted).

    The scale-dependent codes (``F_INSTRUMENT`` … ``BASE_Z``, ``MODEL_X``, ``MODEL_Y``; the values
    of :class:`~stereoplotter.setup.scale_choice.ScaleCheck`) are those of the *closest*
    (M_г, M_в) candidate when no candidate is feasible: fewest violated conditions, then the
    largest model scale.
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
    MODEL_X = 512  #: X extent of the model or sheet corners outside model_x_offset_range_mm
    MODEL_Y = 1024  #: Y extent outside model_y_offset_range_mm


#: The codes that come from the scale choice.
SCALE_FLAGS = int(sum(int(flag) for flag in ScaleCheck))


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
    focal_length_corrected_mm : ndarray, shape (N,)
        f′ of each pair (:meth:`focal_length_of` reads one). [mm]
    book_sign : bool
        (6.4) with the printed sign.
    candidate_scales : ndarray, shape (C, 2)
        The (M_г, M_в) grid of the scale choice. [—]
    candidate_flags : ndarray of int, shape (N, C)
        :class:`~stereoplotter.setup.scale_choice.ScaleCheck` bits of every candidate.
    feasible_candidates : ndarray of bool, shape (N, C)
    candidate_index : ndarray of int, shape (N,)
        The chosen candidate, or the closest one of a pair with no feasible candidate.
    reason_code : ndarray of int, shape (N,)
        :class:`Refusal` flags; 0 = accepted.
    frame_rotation : ndarray, shape (N,)
        θ, azimuth of the horizontal base. [rad]
    frame_origin_m : ndarray, shape (N, 3)
        S_л, the origin of the instrument frame, in the photogrammetric frame. [m]
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
    correction_inclination : ndarray, shape (N, 2, 2)
        Per photo the inclinations atan(k·tan α), atan(k·tan ω) of the correction planes. [rad]
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
    focal_length_corrected_mm: NDArray[np.float64]
    book_sign: bool
    candidate_scales: NDArray[np.float64]
    candidate_flags: NDArray[np.int64]
    feasible_candidates: NDArray[np.bool_]
    candidate_index: NDArray[np.int64]
    reason_code: NDArray[np.int64]
    frame_rotation: NDArray[np.float64]
    frame_origin_m: NDArray[np.float64]
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
    correction_inclination: NDArray[np.float64]
    depth_range_mm: NDArray[np.float64]
    height_point_ids: tuple[tuple[str, ...], ...]
    control_heights_model_mm: NDArray[np.float64]

    def __len__(self) -> int:
        return len(self.model_names)

    @property
    def accepted(self) -> NDArray[np.bool_]:
        """True where the instrument takes the pair."""
        return self.reason_code == 0

    def focal_length_of(self, i: int) -> float:
        """f′ of pair ``i``. [mm]"""
        return float(np.broadcast_to(self.focal_length_corrected_mm, (len(self),))[i])

    def take(self, i: int) -> BlockResult:
        """Pair ``i`` as a block of one (its height points without the padding of the block),
        the same values as :func:`compute_table24` of that pair alone."""
        p = len(self.height_point_ids[i])
        one = slice(i, i + 1)
        arrays = {
            name: getattr(self, name)[one]
            for name in _PER_PAIR_ARRAYS
        }
        arrays["control_heights_model_mm"] = self.control_heights_model_mm[one, :p]
        return replace(
            self,
            model_names=self.model_names[one],
            height_point_ids=self.height_point_ids[one],
            focal_length_corrected_mm=np.broadcast_to(
                self.focal_length_corrected_mm, (len(self),)
            )[one].copy(),
            **arrays,
        )

    def reason(self, i: int) -> str:
        """The refusal of pair ``i`` in words ("" when accepted): values, ranges, way out."""
        return reason_text(self, int(i))


#: The fields of :class:`BlockResult` with one row per pair (besides f′ and the padded Z_i).
_PER_PAIR_ARRAYS = (
    "candidate_flags", "feasible_candidates", "candidate_index", "reason_code", "frame_rotation",
    "frame_origin_m", "base_ground_m", "depth_ground_m", "angles", "horizontal_scale_denominator",
    "vertical_scale_denominator", "f_instrument_mm", "transformation_coefficient", "n_left",
    "n_right", "base_mm", "fiducials_transformed_mm", "fiducials_rigorous_mm", "mark_span_mm",
    "decentration_mm", "correction_inclination", "depth_range_mm",
)  # fmt: skip


# --- computation ------------------------------------------------------------------------------


def instrument_frames(
    centres_m: NDArray, rotations: NDArray
) -> tuple[NDArray, NDArray, tuple[NDArray, NDArray, NDArray]]:
    """The instrument frame of each pair: base along +X, origin S_л (docs/setup-data.md, Frame).

    Parameters
    ----------
    centres_m : ndarray, shape (N, 2, 3)
        S_л, S_п in the photogrammetric frame. [m]
    rotations : ndarray, shape (N, 2, 3, 3)
        M of Eq. (2.50) of the left and right photo in that frame. [—]

    Returns
    -------
    theta : ndarray, shape (N,)
        Azimuth of the horizontal base. [rad]
    base_m : ndarray, shape (N, 3)
        S_п − S_л turned into the instrument frame. [m]
    (alpha, omega, kappa) : ndarrays, shape (N, 2)
        Angles of M′ = R_Z(−θ)·M. [rad]
    """
    theta, _, base_m, angles = _turns(centres_m, rotations)
    return theta, base_m, angles


def _turns(
    centres_m: NDArray, rotations: NDArray
) -> tuple[NDArray, NDArray, NDArray, tuple[NDArray, NDArray, NDArray]]:
    """θ, R_Z(−θ), the base and the angles of :func:`instrument_frames`."""
    base_vector = centres_m[:, 1] - centres_m[:, 0]
    theta = np.arctan2(base_vector[:, 1], base_vector[:, 0])
    turn = rotation_z(-theta)  # (N, 3, 3)
    angles = angles_from_matrix(turn[:, None] @ rotations)
    base_m = (turn @ base_vector[:, :, None])[:, :, 0]  # not einsum: it rounds differently
    return theta, turn, base_m, angles


def instrument_frame_m(
    points_m: ArrayLike,
    frame_origin_m: ArrayLike,
    frame_rotation: ArrayLike,
    *,
    inverse: bool = False,
) -> NDArray[np.float64]:
    r"""Ground points in the instrument frame of the setup sheet (or back).

    Parameters
    ----------
    points_m : array_like, shape (..., 3)
        X, Y, Z in the photogrammetric frame of the scenario (``inverse=False``) or in the
        instrument frame (``inverse=True``). [m]
    frame_origin_m : array_like, shape (3,) or (..., 3)
        S_л, the origin of the instrument frame in the photogrammetric frame: one, or one per
        point (the points of many pairs at once). [m]
    frame_rotation : float or array_like, shape (...)
        θ, the azimuth of the horizontal base in the photogrammetric frame: one, or one per
        point. [rad]
    inverse : bool
        Map instrument-frame points back to the photogrammetric frame.

    Returns
    -------
    ndarray, shape (..., 3)
        The points in the other frame. [m]

    Notes
    -----
    ``docs/setup-data.md``, "The frame turn": the photogrammetric frame moved to S_л and turned
    by −θ about Z, p = R_Z(−θ)(P − S_л), so that the base runs along +X.

    Examples
    --------
    >>> import numpy as np
    >>> p = instrument_frame_m([10.0, 10.0, 0.0], [0.0, 0.0, 100.0], np.pi / 4)
    >>> (np.round(p, 6) + 0.0).tolist()
    [14.142136, 0.0, -100.0]
    >>> back = instrument_frame_m(p, [0.0, 0.0, 100.0], np.pi / 4, inverse=True)
    >>> (np.round(back, 9) + 0.0).tolist()
    [10.0, 10.0, 0.0]
    """
    origin = np.asarray(frame_origin_m, float)
    theta = np.asarray(frame_rotation, float)
    points = np.asarray(points_m, float)
    if theta.ndim == 0:
        if inverse:
            return points @ rotation_z(float(theta)).T + origin
        return (points - origin) @ rotation_z(-float(theta)).T
    turn = rotation_z(theta if inverse else -theta)  # (..., 3, 3), one per point
    if inverse:
        return (turn @ points[..., :, None])[..., 0] + origin
    return (turn @ (points - origin)[..., :, None])[..., 0]


@dataclass(frozen=True, slots=True)
class PairFrames:
    """The instrument frames of N pairs and their ground in them (:func:`pair_frames`).

    ``theta`` (N,) [rad], ``base_m`` (N, 3) [m], ``angles`` α, ω, κ each (N, 2) [rad] as
    :func:`instrument_frames` gives them; ``ground_m`` the runs of ground points in their pair's
    frame [m]; ``depth_m`` (N, 2) Z_Sл − Z of each pair's shallowest and deepest ground and
    ``depth_mean_m`` (N,) its mean [m].
    """

    theta: NDArray[np.float64]
    base_m: NDArray[np.float64]
    angles: tuple[NDArray, NDArray, NDArray]
    ground_m: NDArray[np.float64]
    depth_m: NDArray[np.float64]
    depth_mean_m: NDArray[np.float64]

    def take(self, rows: NDArray) -> tuple[NDArray, NDArray, tuple[NDArray, NDArray, NDArray]]:
        """(θ, base, angles) of the pairs ``rows``: the ``frames`` argument of
        :func:`compute_table24`."""
        return self.theta[rows], self.base_m[rows], tuple(a[rows] for a in self.angles)


def pair_frames(
    centres_m: NDArray, rotations: NDArray, ground_local_m: NDArray, run_start: NDArray
) -> PairFrames:
    """The instrument frame of each pair (:func:`instrument_frames`) and its ground in it.

    Parameters
    ----------
    centres_m, rotations : ndarray, shape (N, 2, 3) and (N, 2, 3, 3)
        As for :func:`instrument_frames`.
    ground_local_m : ndarray, shape (g, 3)
        Ground points of the pairs in the photogrammetric frame, in runs: pair ``i``'s are the
        runs ``r·i`` to ``r·i + r − 1`` (``r`` runs a pair, e.g. its working area and its
        points), run ``k`` the rows ``run_start[k]`` to ``run_start[k + 1]``. [m]
    run_start : ndarray of int, shape (r·N + 1,)

    Returns
    -------
    PairFrames

    Notes
    -----
    Each run is turned by :func:`instrument_frame_m`'s product p = (P − S_л)·R_Z(−θ)ᵀ of that
    run alone: a product over all runs at once, or over another number of rows, rounds
    differently in the last bit (the residuals of an exact (6.8) fit then print −0.000 for
    +0.000, ``jobs/block3x6``). The mean depth is ``numpy.mean`` of the pair alone, to the bit.
    """
    theta, turn, base_m, angles = _turns(centres_m, rotations)
    count = len(theta)
    runs = max((len(run_start) - 1) // max(count, 1), 1)
    out = np.empty_like(ground_local_m)
    transposed = turn.transpose(0, 2, 1)  # R_Z(−θ)ᵀ of each pair
    origins = centres_m[:, 0]
    for k, (a, b) in enumerate(zip(run_start[:-1].tolist(), run_start[1:].tolist(), strict=True)):
        if b > a:
            out[a:b] = (ground_local_m[a:b] - origins[k // runs]) @ transposed[k // runs]
    start = run_start[::runs]
    depths = -out[:, 2]  # Z_Sл − Z (S_л is the origin)
    cuts = start[:-1]
    if count == 0:  # no pair: reduceat takes no empty list of cuts
        return PairFrames(theta, base_m, angles, out, np.zeros((0, 2)), np.zeros(0))
    depth = np.stack([np.minimum.reduceat(depths, cuts), np.maximum.reduceat(depths, cuts)], -1)
    mean = group_sums(depths, start) / np.diff(start)
    return PairFrames(theta, base_m, angles, out, depth, mean)


def _inside_with_slack(v: NDArray, lo: float, hi: float) -> NDArray[np.bool_]:
    """lo ≤ v ≤ hi with the 1e-9 relative slack of ``spec.range_checks.check_in_range``."""
    eps = 1e-9 * max(1.0, abs(lo), abs(hi))
    with np.errstate(invalid="ignore"):
        return (v >= lo - eps) & (v <= hi + eps)


def _stop_codes(
    spec: InstrumentSpec, alpha: NDArray, omega: NDArray, kappa: NDArray, dec: NDArray
) -> NDArray[np.int64]:
    """KAPPA, TILT, DECENTRATION codes: the settings that do not depend on the scale."""
    k_lo, k_hi = spec.kappa_range
    code = np.where(~_inside_with_slack(kappa, k_lo, k_hi).all(axis=1), int(Refusal.KAPPA), 0)
    tilts = np.concatenate([alpha, omega], axis=1)
    t_ok = _inside_with_slack(tilts, -spec.tilt_max, spec.tilt_max).all(axis=1)
    code |= np.where(~t_ok, int(Refusal.TILT), 0)
    dc_ok = _inside_with_slack(dec, *spec.decentration_range_mm).all(axis=(1, 2))
    return code | np.where(~dc_ok, int(Refusal.DECENTRATION), 0)


def _marks(
    f: NDArray, marks: NDArray, alpha: NDArray, omega: NDArray, mask: NDArray
) -> tuple[NDArray, NDArray]:
    """(6.1)/(6.2) without n and (3.17) with κ = 0 for the marks of Table 24, shape (N, 2, 3) and
    (N, 2, 3, 2); ``f`` has shape (N, 1) (f′ of each pair), ``marks`` shape (..., 2, 4, 2) (per
    photo, marks 1–4, x and y)."""
    x0 = transformed_x_single_tilt(marks[..., (0, 1), _X_MARK, 0], alpha, f)  # (6.1)
    y3 = transformed_y_single_tilt(marks[..., :, 2, 1], omega, f)  # (6.2)
    y4 = transformed_y_single_tilt(marks[..., :, 3, 1], omega, f)
    rig_marks = marks[..., [[0], [1]], [[1, 2, 3], [0, 2, 3]], :]  # (..., 2, 3, 2)
    untwisted = rotation_matrix(alpha, omega, 0.0)  # the cassette κ is 0 in stage 2
    rigorous = transformed_coordinates(rig_marks, untwisted[:, :, None], f[:, :, None])  # (3.17)
    return np.stack([x0, y3, y4], axis=-1) * mask[..., None], rigorous * mask[..., None, None]


def _pair_inputs(
    focal_length_corrected_mm: ArrayLike,
    marks_mm: ArrayLike,
    centres_m: NDArray,
    rotations: NDArray,
    depth_m: NDArray,
    invalid: NDArray | None,
) -> tuple[NDArray, NDArray, NDArray]:
    """f′ per pair (N,), the marks per pair and photo (N, 2, 4, 2), and the unusable pairs (a
    non-finite input or a depth range upside down, unless given)."""
    n = centres_m.shape[0]
    f_pairs = np.array(np.broadcast_to(np.asarray(focal_length_corrected_mm, float), (n,)))
    marks = np.asarray(marks_mm, float)
    if marks.ndim == 2:
        marks = np.broadcast_to(marks, (2, *marks.shape))
    marks = np.broadcast_to(marks, (n, 2, 4, 2))  # f′ per pair: the marks of (3.17) per pair too
    if invalid is None:
        invalid = ~(
            np.isfinite(centres_m).all(axis=(1, 2))
            & np.isfinite(rotations).all(axis=(1, 2, 3))
            & np.isfinite(depth_m).all(axis=1)
        )
        with np.errstate(invalid="ignore"):
            invalid |= depth_m[:, 0] > depth_m[:, 1]
    return f_pairs, marks, invalid


def _choice_and_stops(
    spec: InstrumentSpec,
    f: NDArray,
    grid: NDArray,
    depth_m: NDArray,
    frames: tuple[NDArray, NDArray, tuple[NDArray, NDArray, NDArray]],
    extent_m: NDArray | None,
    invalid: NDArray,
) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """Item 1 on the (pair × candidate) grid, then the stops that do not depend on the scale:
    the candidate flags (N, C), the chosen candidate (N,), the reason code (N,) and the
    decentrations (N, 2, 2). ``f`` has shape (N, 1): it broadcasts against the (C,) candidates
    in f_пр = f′·M_г/M_в."""
    _, base_m, (alpha, omega, kappa) = frames
    flags_c = candidate_flags(spec, f, grid, depth_m, base_m, extent_m)  # (N, C)
    chosen, any_ok = choose_candidates(flags_c, grid)
    reason = np.where(any_ok, 0, flags_c[np.arange(len(f)), chosen])
    dec = np.stack([decentration(f, alpha), decentration(f, omega)], axis=-1)  # (N, 2, 2)
    reason |= _stop_codes(spec, alpha, omega, kappa, dec)
    reason = np.where(invalid, int(Refusal.INVALID_INPUT), reason)
    return flags_c, chosen, reason.astype(np.int64), dec


def _settings(
    spec: InstrumentSpec,
    f_pairs: NDArray,
    marks: NDArray,
    mg: NDArray,
    mv: NDArray,
    ok: NDArray,
    frames: tuple[NDArray, NDArray, tuple[NDArray, NDArray, NDArray]],
    book_sign: bool,
) -> dict[str, NDArray]:
    """f_пр, k, (6.3) n_л, (6.4) n_п, the base, (6.1)/(6.2) and (3.17) of the marks, (6.5) and the
    correction-plane inclinations of the pairs at their chosen scales (NaN where refused)."""
    _, base_m, (alpha, omega, _) = frames
    f_pr = instrument_principal_distance(f_pairs, mg, mv)
    k = transformation_coefficient(f_pr, f_pairs)
    n_left = counter_scale_left(spec.projection_distance_max_mm, f_pr)  # (6.3)
    n_right = counter_scale_right(n_left, 0.0, base_m[:, 2], f_pr, mv, book_sign=book_sign)  # (6.4)
    mask2 = np.where(ok, 1.0, np.nan)[:, None]
    fiducials, rigorous = _marks(f_pairs[:, None], marks, alpha, omega, mask2)
    inclination = np.stack(
        [correction_inclination(k[:, None], alpha), correction_inclination(k[:, None], omega)],
        axis=-1,
    )
    return {
        "f_instrument_mm": f_pr,
        "transformation_coefficient": k,
        "n_left": n_left,
        "n_right": n_right,
        "base_mm": base_components(np.zeros(3), base_m, mg, mv),
        "fiducials_transformed_mm": fiducials,
        "fiducials_rigorous_mm": rigorous,
        "mark_span_mm": mark_span(
            np.stack([n_left, n_right], axis=1), fiducials[..., 1], fiducials[..., 2]
        ),  # (6.5)
        "correction_inclination": inclination,
    }


def compute_table24(
    focal_length_corrected_mm: ArrayLike,
    marks_mm: ArrayLike,
    centres_m: NDArray,
    rotations: NDArray,
    depth_m: NDArray,
    grid: NDArray,
    spec: InstrumentSpec,
    *,
    heights_m: NDArray,
    extent_m: NDArray | None = None,
    invalid: NDArray | None = None,
    map_scale_denominator: int | None = None,
    book_sign: bool = False,
    model_names: tuple[str, ...],
    height_point_ids: tuple[tuple[str, ...], ...],
    name: str = "block",
    frames: tuple[NDArray, NDArray, tuple[NDArray, NDArray, NDArray]] | None = None,
) -> BlockResult:
    """Table 24 (Eqs. (6.1)–(6.6) of [1]_ and item 1) of N pairs, vectorised.

    Parameters
    ----------
    focal_length_corrected_mm : float or array_like, shape (N,)
        f′, shared or per pair (each pair's film). [mm]
    marks_mm : array_like, shape (4, 2) or (N, 2, 4, 2)
        Marks 1–4 relative to the principal point, shared or per pair and photo. [mm]
    centres_m, rotations : ndarray, shape (N, 2, 3) and (N, 2, 3, 3)
        S_л, S_п [m] and M of the left and right photo [—].
    depth_m : ndarray, shape (N, 2)
        Z_Sл − highest, Z_Sл − lowest ground of the working area. [m]
    grid : ndarray, shape (C, 2)
        (M_г, M_в) candidates (:func:`~stereoplotter.setup.scale_choice.candidate_scales`).
    spec : InstrumentSpec
    heights_m : ndarray, shape (N, P)
        Z of the height control points, NaN-padded. [m]
    extent_m : ndarray, shape (N, 2, 2), optional
        Plan extent of model and sheet corners from S_л in the instrument frame (checked against
        the carriage travel when given). [m]
    invalid : ndarray of bool, shape (N,), optional
        Unusable pairs; by default those with a non-finite input or a depth range upside down.
    map_scale_denominator, book_sign, model_names, height_point_ids, name
        Carried into the result; ``book_sign`` chooses the printed sign of (6.4).
    frames : tuple, optional
        :func:`instrument_frames` of these pairs when the caller has it already (computed once).

    Returns
    -------
    BlockResult
    """
    f_pairs, marks, invalid = _pair_inputs(
        focal_length_corrected_mm, marks_mm, centres_m, rotations, depth_m, invalid
    )
    frames = instrument_frames(centres_m, rotations) if frames is None else frames
    theta, base_m, angles = frames
    flags_c, chosen, reason, dec = _choice_and_stops(
        spec, f_pairs[:, None], grid, depth_m, frames, extent_m, invalid
    )
    ok = reason == 0
    mg = np.where(ok, grid[chosen, 0], np.nan)
    mv = np.where(ok, grid[chosen, 1], np.nan)
    flying = centres_m[:, 0, 2:3] - heights_m  # H_Фi = Z_Sл − Z_Фi
    return BlockResult(
        name=name, instrument=spec.key, model_names=model_names, spec=spec,
        map_scale_denominator=map_scale_denominator, focal_length_corrected_mm=f_pairs,
        book_sign=book_sign, candidate_scales=grid, candidate_flags=flags_c,
        feasible_candidates=flags_c == 0, candidate_index=chosen, reason_code=reason,
        frame_rotation=theta, frame_origin_m=centres_m[:, 0].copy(), base_ground_m=base_m,
        depth_ground_m=depth_m, angles=np.stack(angles, axis=-1),
        horizontal_scale_denominator=mg, vertical_scale_denominator=mv,
        decentration_mm=dec * np.where(ok, 1.0, np.nan)[:, None, None],
        depth_range_mm=projection_distance(depth_m, mv[:, None]),
        height_point_ids=height_point_ids,
        control_heights_model_mm=model_height(flying, mv[:, None]),  # (6.6)
        **_settings(spec, f_pairs, marks, mg, mv, ok, frames, book_sign),
    )  # fmt: skip


def candidates_of(result: BlockResult, i: int) -> tuple[ScaleCandidate, ...]:
    """Every (M_г, M_в) candidate of pair ``i`` with the conditions it fails."""
    return scale_candidates(
        result.focal_length_of(i),
        result.candidate_scales,
        result.candidate_flags[i],
        result.map_scale_denominator,
    )


# --- refusal messages -------------------------------------------------------------------------


def reason_text(result: BlockResult, i: int) -> str:
    """The refusal of pair ``i`` in words ("" when accepted)."""
    code = Refusal(int(result.reason_code[i]))
    if not code:
        return ""
    spec = result.spec
    if Refusal.INVALID_INPUT in code:
        return "invalid input: a non-finite value, or terrain lowest > highest"
    parts = []
    if code & SCALE_FLAGS:
        candidate = result.candidate_scales[result.candidate_index[i]]
        texts = describe_candidate(
            spec,
            result.focal_length_of(i),
            candidate,
            int(code & SCALE_FLAGS),
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
                    decentration(result.focal_length_of(i), result.angles[i, p, j]),
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
