r"""Block mode of the setup-data computer: one setup sheet per model of a block, vectorised.

A *block file* (YAML, ``docs/scenarios.md``) lists many stereopairs of one camera, each with its
exterior orientation, the lowest and highest ground of its working area and optional height control
points. :func:`compute_block` takes them as arrays and hands them to the one Table 24 computation,
:func:`stereoplotter.setup.table24.compute_table24` (the single-pair sheet calls it with a block of
one); a pair the instrument cannot take gets NaN and a reason code instead of raising
(``style.md`` §10). The per-pair scalar oracle of the tests and the benchmark is
``tests/oracles/setup_pair_oracle.py``.

Reference
---------
.. [1] Kushtin I. F. & Lyskov G. A., *Фотограмметрия снимка и стереоскопических моделей*,
   Moscow: Nedra, 1984, ch. 6, §26, pp. 153–158 (OCR L3682–3826): Eqs. (6.1)–(6.6), Table 24.

**Not in block mode:** the sheet corners (6.7) and the similarity (6.8) need the map sheet and
plan control of each model; compute those per model with
:func:`stereoplotter.setup.sheet.compute_setup_sheet`. Likewise the X, Y travel of the model
(``model_x_offset_range_mm``) is not checked here, since a block file gives no plan extent of the
working area; the single-pair sheet checks it.

The chain, per pair and all at once: the frame rotation θ = atan2(ΔY_S, ΔX_S), M′ = R_Z(−θ)·M
and α, ω, κ from M′ (``docs/setup-data.md``, Frame); the scale choice of item 1 of [1]_ on the
(pair × candidate) grid — feasible when f_пр = f′·M_г/M_в is in range, the projection distances
(Z_Sл − Z)·1000/M_в of the lowest and highest ground, and the same plus b_z′ for the right rod,
are inside [D_min, D_max], and b_x, b_y, b_z′ are in range; the largest model scale (smallest
M_г) wins, then the smallest M_в, as in :func:`stereoplotter.setup.sheet.compute_setup_sheet`;
then Eqs. (6.3), (6.4), (6.1)/(6.2) (n-free) and (3.17) with κ = 0 for the marks, (6.5), the
decentrations and (6.6).

Example — the model of the book's §27 setting (f = 70 mm, 60 % overlap, photo scale 1:20 000):

>>> from stereoplotter.io.instrument_file import load_instrument
>>> marks = [[-85.0, 0.0], [85.0, 0.0], [0.0, 85.0], [0.0, -85.0]]
>>> r = compute_block(70.0, marks, [[-720.0, 0.0, 1550.0]], [[0.0, 0.0, 0.0]],
...                   [[720.0, 0.0, 1560.0]], [[0.0, 0.0, 0.0]], [[120.0, 210.0]],
...                   load_instrument("sc1"), 10000)
>>> float(r.horizontal_scale_denominator[0]), float(r.vertical_scale_denominator[0])
(12500.0, 8000.0)
>>> round(float(r.n_left[0]), 5), round(float(r.base_mm[0, 0]), 3)
(1.69143, 115.2)

Decisions (``docs/setup-data.md``): f′ is the camera's calibrated f unless the caller passes a
corrected one (a block file has no measured fiducial spans); the marks of (6.1)/(6.2) are the
calibrated ones, taken relative to the principal point.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.errors import StereoplotterError
from stereoplotter.geometry.rotation import rotation_matrix
from stereoplotter.setup.scale_choice import candidate_scales
from stereoplotter.setup.table24 import (
    X_MARK_NAME,
    BlockResult,
    Refusal,
    compute_table24,
    reason_text,
)
from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = [
    "X_MARK_NAME",
    "BlockResult",
    "Refusal",
    "candidate_grid",
    "compute_block",
    "prepare_block_arrays",
    "reason_text",
]


def candidate_grid(
    spec: InstrumentSpec, map_scale: int | None, horizontal: int | None, vertical: int | None
) -> NDArray[np.float64]:
    """(M_г, M_в) candidates, shape (C, 2)
    (:func:`stereoplotter.setup.scale_choice.candidate_scales`); ValueError without a map scale
    and a forced M_г."""
    try:
        return candidate_scales(spec, map_scale, horizontal, vertical)
    except StereoplotterError as exc:
        raise ValueError(str(exc)) from None

def prepare_block_arrays(
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
    """Check the shapes of :func:`compute_block`'s arguments; (f′, marks relative to the principal
    point (4, 2), centres (N, 2, 3), angles (N, 2, 3), terrain (N, 2), heights (N, P))."""
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


def _labels_and_invalid(
    n: int,
    centres: NDArray,
    angles: NDArray,
    terrain: NDArray,
    heights: NDArray,
    model_names: tuple[str, ...] | None,
    height_point_ids: tuple[tuple[str, ...], ...] | None,
) -> tuple[tuple[str, ...], tuple[tuple[str, ...], ...], NDArray[np.bool_]]:
    """The model names (1, 2, … by default), the height point ids (1, 2, … per model by
    default), and the unusable pairs: a non-finite input or terrain lowest > highest."""
    invalid = ~(
        np.isfinite(centres).all(axis=(1, 2))
        & np.isfinite(angles).all(axis=(1, 2))
        & np.isfinite(terrain).all(axis=1)
    )
    with np.errstate(invalid="ignore"):
        invalid |= terrain[:, 0] > terrain[:, 1]
    names = tuple(model_names) if model_names is not None else tuple(f"{i + 1}" for i in range(n))
    ids = (
        height_point_ids
        if height_point_ids is not None
        else tuple(tuple(str(j + 1) for j in range(heights.shape[1])) for _ in range(n))
    )
    return names, ids, invalid


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
    The chain is the module's (with its example); (6.7)/(6.8) — the sheet corners — are **not**
    computed in block mode (they need a map sheet and plan control per model), nor is the X, Y
    travel checked.
    """
    f, marks, centres, angles, terrain, heights = prepare_block_arrays(
        focal_length_corrected_mm, fiducials_mm, principal_point_mm, centre_left_m, angles_left,
        centre_right_m, angles_right, terrain_m, height_points_m,
    )  # fmt: skip
    names, ids, invalid = _labels_and_invalid(
        centres.shape[0], centres, angles, terrain, heights, model_names, height_point_ids
    )
    grid = candidate_grid(
        spec, map_scale_denominator, horizontal_scale_denominator, vertical_scale_denominator
    )
    return compute_table24(
        f, marks, centres, rotation_matrix(angles[..., 0], angles[..., 1], angles[..., 2]),
        centres[:, 0, 2:3] - terrain[:, ::-1],  # Z_Sл − highest, Z_Sл − lowest ground
        grid, spec, heights_m=heights, invalid=invalid,
        map_scale_denominator=map_scale_denominator, book_sign=book_sign, model_names=names,
        height_point_ids=ids, name=name,
    )  # fmt: skip
