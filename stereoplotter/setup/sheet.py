"""The setup sheet (Table 24 of the book): everything an operator needs to build an oriented,
scaled model on the instrument without plotting control first.

Orchestration only: the Table 24 values come from the one vectorised computation,
:func:`stereoplotter.setup.table24.compute_table24`, called with a block of one; this module adds
what a single scenario allows beyond a block: f′ from the measured fiducial spans, the measured
marks, the ground of the whole working area, plan control and the sheet corners (6.7)/(6.8), the
carriage travel, the tolerances and the stage readings (:mod:`stereoplotter.setup.readings`). The
decisions behind it are in ``docs/setup-data.md``. The sheet is computed from the scenario *as
measured*: f′ from the measured fiducial spans, the measured mark coordinates, and the exterior
orientation as given (aerotriangulation) or by resection from the measured control — with the
scenario's seed, so a sheet is reproducible.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.constants import MM_PER_M
from stereoplotter.errors import StereoplotterError
from stereoplotter.geometry.rotation import rotation_z
from stereoplotter.geometry.similarity import (
    SimilarityFit,
    apply_similarity,
    fit_similarity_with_reflection,
)
from stereoplotter.scenario.exterior import known_exterior_orientation
from stereoplotter.scenario.model import MapSheet, Point, Scenario
from stereoplotter.scenario.summary import flying_height_and_relief
from stereoplotter.scenario.synthetic import (
    synthesize_measurements,
    working_area_grid_m,
)
from stereoplotter.setup.equations import (
    corner_offsets_book_form_mm,
    corner_offsets_mm,
    decentration,
)
from stereoplotter.setup.readings import stage_readings
from stereoplotter.setup.records import (
    PhotoSetup,
    ScaleCandidate,
    SetupOptions,
    SetupRefusal,
    SetupSheet,
)
from stereoplotter.setup.scale_choice import candidate_scales, describe_candidate
from stereoplotter.setup.table24 import (
    SCALE_FLAGS,
    X_MARK_NAME,
    BlockResult,
    Refusal,
    compute_table24,
    instrument_frames,
)
from stereoplotter.spec.instrument_spec import InstrumentSpec
from stereoplotter.spec.limits import (
    check_material_limits,
    check_model_to_photo_scale,
    check_photo_to_map_ratio,
)
from stereoplotter.spec.range_checks import RangeRefusal, check_in_range

__all__ = [
    "CORNER_ORDER",
    "PhotoSetup",
    "ScaleCandidate",
    "SetupOptions",
    "SetupRefusal",
    "SetupSheet",
    "assumed_parameters",
    "compute_setup_sheet",
    "compute_sheet_from_measurements",
    "compute_sheets_from_measurements",
    "instrument_frame_m",
]

#: Sheet-corner numbering (decision, docs/setup-data.md): 1 = lower left, then counter-clockwise
#: in map view, north up. The scenario stores corners NW, NE, SE, SW; this maps 1..4 to them.
CORNER_ORDER = {"1": 3, "2": 2, "3": 1, "4": 0}
CORNER_NAMES = {"1": "SW", "2": "SE", "3": "NE", "4": "NW"}


# --- helpers --------------------------------------------------------------------------------


def instrument_frame_m(
    points_m: ArrayLike, frame_origin_m: ArrayLike, frame_rotation: float, *, inverse: bool = False
) -> NDArray[np.float64]:
    r"""Ground points in the instrument frame of the setup sheet (or back).

    Parameters
    ----------
    points_m : array_like, shape (..., 3)
        X, Y, Z in the photogrammetric frame of the scenario (``inverse=False``) or in the
        instrument frame (``inverse=True``). [m]
    frame_origin_m : array_like, shape (3,)
        S_л, the origin of the instrument frame in the photogrammetric frame. [m]
    frame_rotation : float
        θ, the azimuth of the horizontal base in the photogrammetric frame. [rad]
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
    if inverse:
        return np.asarray(points_m, float) @ rotation_z(frame_rotation).T + origin
    return (np.asarray(points_m, float) - origin) @ rotation_z(-frame_rotation).T


def _sheet_corners_gk(sheet: MapSheet) -> NDArray:
    return np.array([sheet.corners_sk42_m[CORNER_ORDER[k]] for k in ("1", "2", "3", "4")])


def _candidate_grid(
    spec: InstrumentSpec, options: SetupOptions, map_scale: int | None
) -> NDArray[np.float64]:
    """Item 1 of §26: the (M_г, M_в) candidates (:mod:`stereoplotter.setup.scale_choice`)."""
    try:
        return candidate_scales(
            spec,
            map_scale,
            options.horizontal_scale_denominator,
            options.vertical_scale_denominator,
        )
    except StereoplotterError as exc:
        raise SetupRefusal(f"{exc} (--horizontal-scale)") from None


def _refuse_scales(table: BlockResult, extent_m: NDArray) -> None:
    """Raise the refusal of a pair with no feasible (M_г, M_в), naming the closest one."""
    spec, grid = table.spec, table.candidate_scales
    best = int(table.candidate_index[0])
    reasons = describe_candidate(
        spec,
        table.focal_length_of(0),
        grid[best],
        int(table.candidate_flags[0, best]),
        table.depth_ground_m[0],
        table.base_ground_m[0],
        extent_m[0],
    )
    raise SetupRefusal(
        f"instrument {spec.key} cannot take this stereopair: none of the {len(grid)} scale "
        "pairs (M_г = r·M_map for the coordinatograph ratios r, M_в from the height-counter "
        f"gears) fits every range. Closest: M_г = 1:{grid[best, 0]:.0f}, "
        f"M_в = 1:{grid[best, 1]:.0f}: "
        + "; ".join(reasons)
        + ". Way out: another instrument, another map scale or forced scales, or widen the "
        f"assumed ranges in {spec.source}."
    )


def _check_tilt(spec: InstrumentSpec, value: float, what: str) -> None:
    """Refuse a tilt the correction mechanisms cannot take (|α|, |ω| ≤ tilt_max)."""
    if abs(value) > spec.tilt_max:
        key = spec.key_of("tilt_max")
        status = "assumed" if spec.is_assumed(key) else "documented"
        raise SetupRefusal(
            f"{what} = {math.degrees(value):.4f}° is beyond the {status} correction range "
            f"±{math.degrees(spec.tilt_max):g}° of {spec.source}: {key} (the correction mechanism "
            "stops there); such a photo needs another instrument or rectification first"
        )


def _assumed(spec: InstrumentSpec, *attributes: str) -> tuple[str, ...]:
    keys = [spec.key_of(a) for a in attributes]
    return tuple(k for k in keys if spec.is_assumed(k))


def _check_settings(table: BlockResult) -> None:
    """Refuse a pair :func:`compute_table24` refused, with the message of the first setting
    beyond a stop (scale choice, then κ, tilts and decentrations, left photo first)."""
    code = int(table.reason_code[0])
    if code & Refusal.INVALID_INPUT:
        raise SetupRefusal(
            "the exterior orientation or the working area of this stereopair is not finite"
        )
    spec, f_prime = table.spec, table.focal_length_of(0)
    for j, name in enumerate(("left", "right")):
        alpha, omega, kappa = (float(v) for v in table.angles[0, j])
        check_in_range(spec, "kappa_range", kappa, f"κ_{name} (cassette rotation)")
        for value, what in ((alpha, f"α_{name}"), (omega, f"ω_{name}")):
            _check_tilt(spec, value, what)
        for value, what in (
            (float(decentration(f_prime, alpha)), f"decentration d_x,{name}"),
            (float(decentration(f_prime, omega)), f"decentration d_y,{name}"),
        ):
            check_in_range(spec, "decentration_range_mm", value, what)


def _photo_setups(table: BlockResult, marks_mm: NDArray) -> tuple[PhotoSetup, ...]:
    """The per-photo settings of pair 0 of ``table``; ``marks_mm`` shape (2, 4, 2)."""
    photos = []
    for j, (name, n) in enumerate((("left", table.n_left[0]), ("right", table.n_right[0]))):
        x_mark = X_MARK_NAME[j]
        fid = table.fiducials_transformed_mm[0, j]
        photos.append(
            PhotoSetup(
                name,
                *(float(v) for v in table.angles[0, j]),
                {str(i + 1): (float(m[0]), float(m[1])) for i, m in enumerate(marks_mm[j])},
                {f"x{x_mark}": float(fid[0]), "y3": float(fid[1]), "y4": float(fid[2])},
                {
                    key: tuple(float(v) for v in table.fiducials_rigorous_mm[0, j, m])
                    for m, key in enumerate((x_mark, "3", "4"))
                },
                float(table.mark_span_mm[0, j]),
                tuple(float(v) for v in table.decentration_mm[0, j]),
                tuple(float(v) for v in table.correction_inclination[0, j]),
                float(n),
            )
        )
    return tuple(photos)


def _plan_control(
    points: tuple[Point, ...], map_sheet: MapSheet | None, points_m: NDArray
) -> tuple[SimilarityFit | None, list[int], NDArray | None, NDArray]:
    """(6.8): the similarity from Gauss–Krüger to the instrument frame over the plan control, and
    the sheet corners on the ground (empty without a map sheet or two plan points)."""
    corners_gk = _sheet_corners_gk(map_sheet) if map_sheet is not None else None
    plan = [
        i
        for i, p in enumerate(points)
        if p.role == "control" and p.kind in ("full", "plan") and p.sk42_m is not None
    ]
    fit = None
    corners_m = np.zeros((0, 2))
    if corners_gk is not None and len(plan) >= 2:
        north = np.array([points[i].sk42_m[0] for i in plan])
        east = np.array([points[i].sk42_m[1] for i in plan])
        fit = fit_similarity_with_reflection(north, east, points_m[plan, 0], points_m[plan, 1])
        corners_m = apply_similarity(fit, corners_gk[:, 0], corners_gk[:, 1])  # (6.8), ground m
    return fit, plan, corners_gk, corners_m


def _corners(
    corners_gk: NDArray | None, corners_m: NDArray, mg: int, n_left: float
) -> tuple[dict[str, object], ...]:
    """(6.7): the sheet corners in instrument coordinates from the left plumb, from their ground
    X, Y by (6.8) (computed once, in :func:`_plan_control`)."""
    if corners_gk is None or len(corners_m) == 0:
        return ()
    xy = corner_offsets_mm(corners_m, mg)
    xy_book = corner_offsets_book_form_mm(corners_m, n_left, n_left * mg)
    return tuple(
        {
            "corner": key,
            "position": CORNER_NAMES[key],
            "gk_north_m": float(corners_gk[j, 0]),
            "gk_east_m": float(corners_gk[j, 1]),
            "x_mm": float(xy[j, 0]),
            "y_mm": float(xy[j, 1]),
            "x_book_form_mm": float(xy_book[j, 0]),
            "y_book_form_mm": float(xy_book[j, 1]),
        }
        for j, key in enumerate(("1", "2", "3", "4"))
    )


def _points_model(points: tuple[Point, ...], points_m: NDArray, mg: int) -> tuple[dict, ...]:
    """The pair's points in model mm from the left plumb (X, Y ·1000/M_г), for the drawing."""
    xy = (points_m[:, :2] * MM_PER_M / mg).tolist()
    return tuple(
        {"id": p.id, "role": p.role, "kind": p.kind, "x_mm": x, "y_mm": y}
        for p, (x, y) in zip(points, xy, strict=True)
    )


def _tolerances(spec: InstrumentSpec, n_left: float, depths_m: NDArray) -> dict[str, float]:
    return {
        "mark_span_mm": spec.tolerance_L_numerator_mm / n_left,
        "mark_fit_mm": spec.tolerance_mark_fit_per_n_mm * n_left,
        "residual_y_parallax_mm": spec.residual_q_fraction_of_mark * spec.mark_diameter_mm,
        "control_height_m": spec.control_height_fraction_of_H * float(np.mean(depths_m)),
        "corner_mm": spec.corner_tolerance_mm,
    }


# --- the computation ----------------------------------------------------------------------------


def _check_material(scenario: Scenario, spec: InstrumentSpec, grid_m: NDArray) -> float:
    """Documented limits on the pair (relief/H, f_k; :mod:`stereoplotter.spec.limits`) with H
    and the relief as the scenario summary prints them; returns the mean flying height H. [m]"""
    height, relief = flying_height_and_relief(scenario, grid_m)
    try:
        check_material_limits(
            spec,
            relief_m=relief,
            flying_height_m=height,
            camera_f_mm=float(scenario.camera.focal_length_mm),
            what=scenario.source,
        )
    except RangeRefusal as exc:
        raise SetupRefusal(str(exc)) from exc
    return height


def _check_model_scale(scenario: Scenario, spec: InstrumentSpec, sheet, height_m: float) -> None:
    """SPR-3: model scale 0.5–2 × photo scale; SD-3: map scale 0.5–3 × photo scale
    (m = 1000·H/f_k; :mod:`stereoplotter.spec.limits`)."""
    photo = MM_PER_M * height_m / float(scenario.camera.focal_length_mm)
    try:
        check_model_to_photo_scale(
            spec,
            photo_scale_denominator=photo,
            model_scale_denominator=float(sheet.horizontal_scale_denominator),
        )
        if sheet.map_scale_denominator is not None:
            check_photo_to_map_ratio(
                spec,
                photo_scale_denominator=photo,
                map_scale_denominator=float(sheet.map_scale_denominator),
            )
    except RangeRefusal as exc:
        raise SetupRefusal(f"{scenario.source}: {exc}") from exc


def compute_setup_sheet(
    scenario: Scenario,
    spec: InstrumentSpec,
    options: SetupOptions | None = None,
    rng: np.random.Generator | None = None,
) -> SetupSheet:
    """Compute the setup sheet of a stereopair for an instrument.

    Parameters
    ----------
    scenario : Scenario
        A stereopair (photos "left" and "right").
    spec : InstrumentSpec
    options : SetupOptions, optional
    rng : numpy.random.Generator, optional
        Noise of the synthetic measurements the sheet is computed from; by default
        ``numpy.random.default_rng(scenario.seed)``.

    Returns
    -------
    SetupSheet

    Raises
    ------
    SetupRefusal
        Not a stereopair, no feasible scale pair, or a setting outside an instrument range
        (the message names the value, the range and the way out).
    """
    options = options or SetupOptions()
    if not scenario.is_stereopair:
        raise SetupRefusal(
            f"{scenario.source}: photos: expected two photos named left and right, found "
            f"{', '.join(p.name for p in scenario.photos)}: scenario {scenario.name!r} is not a "
            "stereopair"
        )
    working_area_m = working_area_grid_m(scenario, (15, 15))  # once: relief and working area
    height_m = _check_material(scenario, spec, working_area_m)
    rng = np.random.default_rng(scenario.seed) if rng is None else rng
    measurements = synthesize_measurements(scenario, rng)
    known = known_exterior_orientation(scenario, measurements)
    marks = np.array(
        [measurements.photo(n).fiducials_mm for n in ("left", "right")]
    ) - np.asarray(scenario.camera.principal_point_mm, float)
    sheet = compute_sheet_from_measurements(
        name=scenario.name,
        source=scenario.source,
        spec=spec,
        options=options,
        focal_length_corrected_mm=measurements.focal_length_corrected_mm,
        focal_length_corrected_per_photo_mm=measurements.focal_length_corrected_per_photo_mm,
        marks_mm=marks,
        centres_m=np.array([k.centre_m for k in known]),
        rotations=np.array([k.rotation for k in known]),
        points=scenario.points,
        working_area_m=working_area_m,
        map_sheet=scenario.map_sheet,
        exterior_sources=tuple(p.exterior.source for p in scenario.photos),
    )
    _check_model_scale(scenario, spec, sheet, height_m)
    return sheet


@dataclass(frozen=True, slots=True)
class _Prepared:
    """One pair's measured inputs turned into what Table 24 and the sheet need (no scales yet)."""

    name: str
    spec: InstrumentSpec
    options: SetupOptions
    focal_length_corrected_mm: float
    focal_length_corrected_per_photo_mm: tuple[float, ...]
    marks_mm: NDArray  # (2, 4, 2)
    centres_m: NDArray  # (2, 3)
    rotations: NDArray  # (2, 3, 3)
    frames: tuple[NDArray, NDArray, tuple[NDArray, NDArray, NDArray]]  # of a block of one
    points: tuple[Point, ...]
    points_m: NDArray  # (p, 3) in the instrument frame
    heights: tuple[Point, ...]
    depths_m: NDArray  # (g,) Z_Sл − Z of the ground samples and points
    depth_m: NDArray  # (2,) the shallowest, deepest
    extent_m: NDArray  # (2, 2)
    similarity: SimilarityFit | None
    plan: list[int]
    corners_gk: NDArray | None
    corners_m: NDArray  # (4, 2) the sheet corners on the ground by (6.8), or (0, 2)
    map_scale: int | None
    grid: NDArray  # (C, 2)
    exterior_sources: tuple[str, ...]


def _prepare(
    *,
    name: str,
    source: str,
    spec: InstrumentSpec,
    options: SetupOptions,
    focal_length_corrected_mm: float,
    focal_length_corrected_per_photo_mm: tuple[float, ...],
    marks_mm: NDArray,
    centres_m: NDArray,
    rotations: NDArray,
    points: tuple[Point, ...],
    working_area_m: NDArray,
    map_sheet: MapSheet | None,
    exterior_sources: tuple[str, ...],
    grids: dict[int | None, NDArray] | None = None,
) -> _Prepared:
    """The frame, the ground in it, the plan control (6.8) and the scale candidates of one pair
    (``grids``: the candidates already built, by map scale, shared by the pairs of a call)."""
    centres = np.asarray(centres_m, float)[None]  # (1, 2, 3)
    rots = np.asarray(rotations, float)[None]  # (1, 2, 3, 3)
    frames = instrument_frames(centres, rots)  # once: Table 24 takes it from here
    theta = float(frames[0][0])
    points_m = instrument_frame_m(
        np.array([p.local_m for p in points], float).reshape(-1, 3), centres[0, 0], theta
    )
    grid_m = instrument_frame_m(working_area_m, centres[0, 0], theta)
    ground = np.vstack([grid_m, points_m])
    depths_m = -ground[:, 2]  # Z_Sл − Z (S_л is the origin)
    fit, plan, corners_gk, corners_m = _plan_control(points, map_sheet, points_m)
    offsets_m = np.vstack([ground[:, :2], corners_m])
    map_scale = map_sheet.scale_denominator if map_sheet else None
    if map_scale is None and options.horizontal_scale_denominator is None:
        raise SetupRefusal(
            f"{source}: map_sheet: expected a map sheet, whose scale chooses the "
            "horizontal model scale M_г from the coordinatograph gears, found nothing (or force "
            "M_г with --horizontal-scale)"
        )
    grids = {} if grids is None else grids
    if map_scale not in grids:
        grids[map_scale] = _candidate_grid(spec, options, map_scale)
    grid = grids[map_scale]
    return _Prepared(
        name=name,
        spec=spec,
        options=options,
        focal_length_corrected_mm=float(focal_length_corrected_mm),
        focal_length_corrected_per_photo_mm=tuple(focal_length_corrected_per_photo_mm),
        marks_mm=np.asarray(marks_mm, float),
        centres_m=centres[0],
        rotations=rots[0],
        frames=frames,
        points=tuple(points),
        points_m=points_m,
        heights=tuple(
            p for p in points if p.role == "control" and p.kind in ("full", "height")
        ),
        depths_m=depths_m,
        depth_m=np.array([depths_m.min(), depths_m.max()]),
        extent_m=np.array([[offsets_m[:, j].min(), offsets_m[:, j].max()] for j in (0, 1)]),
        similarity=fit,
        plan=plan,
        corners_gk=corners_gk,
        corners_m=corners_m,
        map_scale=map_scale,
        grid=grid,
        exterior_sources=tuple(exterior_sources),
    )


def _table24(pairs: Sequence[_Prepared], name: str) -> BlockResult:
    """Table 24 of pairs that share the instrument, the options and the scale candidates, in one
    :func:`compute_table24` call (per-pair f′ and marks)."""
    first = pairs[0]
    width = max(len(p.heights) for p in pairs)
    heights = np.full((len(pairs), width), np.nan)
    for i, p in enumerate(pairs):
        heights[i, : len(p.heights)] = [h.local_m[2] for h in p.heights]
    return compute_table24(
        np.array([p.focal_length_corrected_mm for p in pairs]),
        np.array([p.marks_mm for p in pairs]),
        np.array([p.centres_m for p in pairs]),
        np.array([p.rotations for p in pairs]),
        np.array([p.depth_m for p in pairs]),
        first.grid,
        first.spec,
        heights_m=heights,
        extent_m=np.array([p.extent_m for p in pairs]),
        map_scale_denominator=first.map_scale,
        book_sign=first.options.book_sign_n_right,
        model_names=tuple(p.name for p in pairs),
        height_point_ids=tuple(tuple(h.id for h in p.heights) for p in pairs),
        name=name,
        frames=(
            np.concatenate([p.frames[0] for p in pairs]),
            np.concatenate([p.frames[1] for p in pairs]),
            tuple(np.concatenate([p.frames[2][j] for p in pairs]) for j in range(3)),
        ),
    )


def _finish(
    prep: _Prepared, table: BlockResult, assumed: dict[str, tuple[str, ...]] | None = None
) -> SetupSheet:
    """The sheet of a prepared pair from its Table 24 (a block of one), or its refusal.

    The range checks are Table 24's reason code, computed once for all pairs: only a refused
    pair goes through the checks again, for the words of its refusal."""
    code = int(table.reason_code[0])
    if code & SCALE_FLAGS:
        _refuse_scales(table, prep.extent_m[None])
    if code or float(np.abs(table.angles[0, :, :2]).max()) > prep.spec.tilt_max:
        _check_settings(table)  # the words of the refusal (_check_tilt has no slack)
    spec, options, points, points_m = prep.spec, prep.options, prep.points, prep.points_m
    mg, mv = int(table.horizontal_scale_denominator[0]), int(table.vertical_scale_denominator[0])
    n_left = float(table.n_left[0])
    tolerances = _tolerances(spec, n_left, prep.depths_m)
    assumed = assumed_parameters(spec) if assumed is None else assumed
    sheet = SetupSheet(
        scenario=prep.name,
        instrument=spec.key,
        instrument_title=spec.title,
        instrument_principle=spec.principle,
        frame_rotation=float(table.frame_rotation[0]),
        frame_origin_m=tuple(float(v) for v in table.frame_origin_m[0]),
        focal_length_corrected_mm=table.focal_length_of(0),
        focal_length_corrected_per_photo_mm=prep.focal_length_corrected_per_photo_mm,
        map_scale_denominator=prep.map_scale,
        horizontal_scale_denominator=mg,
        vertical_scale_denominator=mv,
        f_instrument_mm=float(table.f_instrument_mm[0]),
        transformation_coefficient=float(table.transformation_coefficient[0]),
        n_left=n_left,
        n_right=float(table.n_right[0]),
        base_mm=tuple(float(v) for v in table.base_mm[0]),
        photos=_photo_setups(table, prep.marks_mm),
        control_heights=tuple(
            {
                "id": p.id,
                "Z_m": p.local_m[2],
                "flying_height_m": float(prep.centres_m[0, 2] - p.local_m[2]),
                "model_height_mm": float(z),
            }
            for p, z in zip(prep.heights, table.control_heights_model_mm[0], strict=True)
        ),  # (6.6)
        similarity=prep.similarity,
        similarity_point_ids=tuple(points[i].id for i in prep.plan),
        corners=_corners(prep.corners_gk, prep.corners_m, mg, n_left),
        readings=(),
        tolerances=tolerances,
        assumed=assumed,
        options=options,
        depth_range_used_mm=tuple(float(v) for v in table.depth_range_mm[0]),
        exterior_sources=prep.exterior_sources,
        points_model_mm=_points_model(points, points_m, mg),
        table24=table,
    )
    return replace(sheet, readings=stage_readings(sheet))


def compute_sheet_from_measurements(
    *,
    name: str,
    source: str,
    spec: InstrumentSpec,
    options: SetupOptions,
    focal_length_corrected_mm: float,
    focal_length_corrected_per_photo_mm: tuple[float, ...],
    marks_mm: NDArray,
    centres_m: NDArray,
    rotations: NDArray,
    points: tuple[Point, ...],
    working_area_m: NDArray,
    map_sheet: MapSheet | None,
    exterior_sources: tuple[str, ...],
) -> SetupSheet:
    """The setup sheet of one stereopair from what was measured, not from a ground truth.

    :func:`compute_setup_sheet` calls it with the synthetic measurements of a scenario; a
    production job (``stereoplotter.io.job_file``) with the measured fiducial spans and the
    exterior orientation of the aerotriangulation. No random numbers: the same inputs give the
    same sheet.

    Parameters
    ----------
    name, source : str
        The pair's name (``SetupSheet.scenario``) and the file named in refusals.
    spec : InstrumentSpec
    options : SetupOptions
    focal_length_corrected_mm : float
        f′ of the pair. [mm]
    focal_length_corrected_per_photo_mm : tuple of float
        f′ of each photo. [mm]
    marks_mm : ndarray, shape (2, 4, 2)
        Measured marks 1–4 of the left and right photo, relative to the principal point. [mm]
    centres_m : ndarray, shape (2, 3)
        S_л, S_п in the photogrammetric frame. [m]
    rotations : ndarray, shape (2, 3, 3)
        M of Eq. (2.50) of the left and right photo in that frame. [—]
    points : tuple of Point
        Control and check points of the pair (``local_m`` in the same frame; ``sk42_m`` for
        the plan control of (6.8)).
    working_area_m : ndarray, shape (g, 3)
        Ground samples of the working area (with the points: the depth range and the plan
        extent of the model). [m]
    map_sheet : MapSheet or None
    exterior_sources : tuple of str
        Where each photo's exterior orientation came from (printed on the sheet).
    """
    prep = _prepare(
        name=name,
        source=source,
        spec=spec,
        options=options,
        focal_length_corrected_mm=focal_length_corrected_mm,
        focal_length_corrected_per_photo_mm=focal_length_corrected_per_photo_mm,
        marks_mm=marks_mm,
        centres_m=centres_m,
        rotations=rotations,
        points=points,
        working_area_m=working_area_m,
        map_sheet=map_sheet,
        exterior_sources=exterior_sources,
    )
    table = _table24([prep], name)
    return _finish(prep, table)


def compute_sheets_from_measurements(
    pairs: Sequence[Mapping[str, Any]],
    *,
    spec: InstrumentSpec,
    options: SetupOptions,
    source: str,
    name: str = "job",
) -> list[SetupSheet | SetupRefusal]:
    """The sheets of many pairs from their measurements, Table 24 of all of them in one call.

    Parameters
    ----------
    pairs : sequence of mapping
        Per pair the keyword arguments of :func:`compute_sheet_from_measurements` other than
        ``spec``, ``options`` and ``source`` (f′ and the marks are each pair's own).
    spec, options, source
        As for :func:`compute_sheet_from_measurements`, shared by the pairs.
    name : str
        The name of the block the pairs are computed in.

    Returns
    -------
    list of SetupSheet or SetupRefusal
        In the order of ``pairs``: the sheet, or the refusal
        :func:`compute_sheet_from_measurements` would raise for that pair. Each sheet is the one
        :func:`compute_sheet_from_measurements` gives for the pair alone, to the bit: the pairs
        go through :func:`compute_table24` together (one call per set of scale candidates, i.e.
        per map scale) and each is taken out as a block of one (:meth:`BlockResult.take`).
    """
    out: list[SetupSheet | SetupRefusal | None] = [None] * len(pairs)
    groups: dict[bytes, list[tuple[int, _Prepared]]] = {}
    grids: dict[int | None, NDArray] = {}  # the scale candidates of each map scale, once
    assumed = assumed_parameters(spec)
    for i, arguments in enumerate(pairs):
        try:
            prep = _prepare(spec=spec, options=options, source=source, grids=grids, **arguments)
        except SetupRefusal as exc:
            out[i] = exc
            continue
        groups.setdefault(prep.grid.tobytes(), []).append((i, prep))
    for members in groups.values():
        table = _table24([p for _, p in members], name)
        for j, (i, prep) in enumerate(members):
            try:
                out[i] = _finish(prep, table.take(j), assumed)
            except SetupRefusal as exc:
                out[i] = exc
    return [r for r in out if r is not None]


def assumed_parameters(spec: InstrumentSpec) -> dict[str, tuple[str, ...]]:
    """For each sheet quantity (the ``--json`` key), the assumed instrument parameters it rests on.

    Shared by the single-pair sheet and block mode.
    """
    scales = _assumed(
        spec,
        "coordinatograph_ratios",
        "vertical_scale_denominators",
        "f_instrument_range_mm",
        "projection_distance_range_mm",
        "model_x_offset_range_mm",
        "model_y_offset_range_mm",
    )
    d_max = _assumed(spec, "projection_distance_max_mm")
    return {
        "scale_horizontal": scales,
        "scale_vertical": scales,
        "f_instrument_mm": scales,
        "n_left": tuple(sorted(set(scales) | set(d_max))),
        "n_right": tuple(sorted(set(scales) | set(d_max))),
        "base_mm": scales,
        "L_mm": tuple(sorted(set(scales) | set(d_max))),
        "control_heights_model_mm": scales,
        "sheet_corners_mm": scales,
        "tolerances": _assumed(
            spec,
            "mark_diameter_mm",
            "tolerance_L_numerator_mm",
            "tolerance_mark_fit_per_n_mm",
            "residual_q_fraction_of_mark",
            "control_height_fraction_of_H",
            "corner_tolerance_mm",
        ),
    }
