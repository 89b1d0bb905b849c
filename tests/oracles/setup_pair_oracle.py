"""Per-pair scalar oracle of the Table 24 computation (block mode and the single-pair sheet).

:func:`per_pair_loop` computes what :func:`stereoplotter.setup.block.compute_block` computes, one
pair at a time with a plain Python loop on scalars, through the same equation functions but with
its own scale choice (a loop over the candidates) and its own range checks. It is the reference of
``tests/properties/test_block.py`` and the comparison of ``benchmarks/bench_setup_block.py``; it is
not part of the package.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.geometry.rotation import angles_from_matrix, rotation_matrix, rotation_z
from stereoplotter.geometry.transformed import (
    transformed_coordinates,
    transformed_x_single_tilt,
    transformed_y_single_tilt,
)
from stereoplotter.setup.block import (
    BlockResult,
    Refusal,
    candidate_grid,
    prepare_block_arrays,
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
from stereoplotter.spec.instrument_spec import InstrumentSpec
from stereoplotter.spec.range_checks import RangeRefusal, check_in_range

__all__ = ["per_pair_loop"]

#: Marks used per photo: left x of mark 2, right x of mark 1 (indices into marks 1..4).
_X_MARK = (1, 0)


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
    Calls the same equation functions — frame rotation, item 1 of the book's §26, (6.1)–(6.6),
    (3.17) — with scalars, and chooses the scales by a loop over the candidates.
    """
    f, marks, centres, angles, terrain, heights = prepare_block_arrays(
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
    grid = candidate_grid(
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
    k = float(transformation_coefficient(f_pr, f))
    return {
        "candidate_flags": np.array([int(sum(c[3])) for c in candidates], dtype=np.int64),
        "feasible_candidates": np.array([not c[3] for c in candidates]),
        "candidate_index": chosen[0],
        "reason_code": reason,
        "frame_rotation": theta,
        "frame_origin_m": c_left,
        "base_ground_m": base_m,
        "depth_ground_m": depth,
        "angles": photo_angles,
        "horizontal_scale_denominator": mg,
        "vertical_scale_denominator": mv,
        "f_instrument_mm": f_pr,
        "transformation_coefficient": k,
        "n_left": n_left,
        "n_right": n_right,
        "base_mm": base_components(np.zeros(3), base_m, mg, mv),
        "fiducials_transformed_mm": fid,
        "fiducials_rigorous_mm": rig,
        "mark_span_mm": spans,
        "decentration_mm": decs if ok else [[nan, nan], [nan, nan]],
        "correction_inclination": [
            [float(correction_inclination(k, a)), float(correction_inclination(k, w))]
            for a, w, _ in photo_angles
        ],
        "depth_range_mm": [float(projection_distance(v, mv)) for v in depth],
        "control_heights_model_mm": [
            float(model_height(c_left[2] - z, mv)) for z in heights
        ],  # (6.6)
    }
