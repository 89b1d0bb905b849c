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
from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace
from functools import partial
from typing import Any

import numpy as np
from numpy.typing import NDArray

from stereoplotter.constants import MM_PER_M
from stereoplotter.scenario.exterior import known_exterior_orientation
from stereoplotter.scenario.model import MapSheet, Point, Scenario
from stereoplotter.scenario.summary import flying_height_and_relief
from stereoplotter.scenario.synthetic import (
    synthesize_measurements,
    working_area_grid_m,
)
from stereoplotter.setup.equations import decentration
from stereoplotter.setup.readings import stage_readings
from stereoplotter.setup.records import (
    PhotoSetup,
    ScaleCandidate,
    SetupOptions,
    SetupRefusal,
    SetupSheet,
)
from stereoplotter.setup.scale_choice import describe_candidate
from stereoplotter.setup.sheet_block import CORNER_ORDER, SheetBlock, compute_sheet_block
from stereoplotter.setup.table24 import (
    SCALE_FLAGS,
    X_MARK_NAME,
    BlockResult,
    Refusal,
    instrument_frame_m,
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
    "block_refusals",
    "compute_setup_sheet",
    "compute_sheet_from_measurements",
    "compute_sheets_from_measurements",
    "deferred_sheets",
    "instrument_frame_m",
    "sheet_of_block",
]

CORNER_NAMES = {"1": "SW", "2": "SE", "3": "NE", "4": "NW"}


# --- helpers --------------------------------------------------------------------------------


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
    marks = marks_mm.tolist()
    angles, fid = table.angles[0].tolist(), table.fiducials_transformed_mm[0].tolist()
    rigorous, spans = table.fiducials_rigorous_mm[0].tolist(), table.mark_span_mm[0].tolist()
    dec, incl = table.decentration_mm[0].tolist(), table.correction_inclination[0].tolist()
    for j, (name, n) in enumerate((("left", table.n_left[0]), ("right", table.n_right[0]))):
        x_mark = X_MARK_NAME[j]
        photos.append(
            PhotoSetup(
                name,
                *angles[j],
                {str(i + 1): (m[0], m[1]) for i, m in enumerate(marks[j])},
                {f"x{x_mark}": fid[j][0], "y3": fid[j][1], "y4": fid[j][2]},
                {key: tuple(rigorous[j][m]) for m, key in enumerate((x_mark, "3", "4"))},
                spans[j],
                tuple(dec[j]),
                tuple(incl[j]),
                float(n),
            )
        )
    return tuple(photos)


def _corners(block: SheetBlock, i: int) -> tuple[dict[str, object], ...]:
    """(6.7): pair ``i``'s sheet corners in instrument coordinates from the left plumb, from their
    ground X, Y by (6.8), both computed for the block (:func:`compute_sheet_block`)."""
    if block.inputs[i]["map_sheet"] is None or block.fit_row[i] < 0:
        return ()
    gk = block.corners_gk[i].tolist()
    xy, xy_book = block.corners_mm[i].tolist(), block.corners_book_form_mm[i].tolist()
    return tuple(
        {
            "corner": key,
            "position": CORNER_NAMES[key],
            "gk_north_m": gk[j][0],
            "gk_east_m": gk[j][1],
            "x_mm": xy[j][0],
            "y_mm": xy[j][1],
            "x_book_form_mm": xy_book[j][0],
            "y_book_form_mm": xy_book[j][1],
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


def _tolerances(spec: InstrumentSpec, n_left: float, depth_mean_m: float) -> dict[str, float]:
    return {
        "mark_span_mm": spec.tolerance_L_numerator_mm / n_left,
        "mark_fit_mm": spec.tolerance_mark_fit_per_n_mm * n_left,
        "residual_y_parallax_mm": spec.residual_q_fraction_of_mark * spec.mark_diameter_mm,
        "control_height_m": spec.control_height_fraction_of_H * depth_mean_m,
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


def _checked_table(block: SheetBlock, i: int) -> BlockResult:
    """Table 24 of pair ``i`` of a block as a block of one, or the pair's refusal (raised): the
    range checks run again only for a pair Table 24's reason code (or a tilt) refuses, for the
    words of its refusal."""
    refusal = block.refusals[i]
    if refusal is not None:
        raise refusal
    group, row = (int(v) for v in block.table_of[i])
    table = block.tables[group].take(row)
    code = int(table.reason_code[0])
    if code & SCALE_FLAGS:
        _refuse_scales(table, block.extent_m[i][None])
    if code or float(np.abs(table.angles[0, :, :2]).max()) > block.spec.tilt_max:
        _check_settings(table)  # the words of the refusal (_check_tilt has no slack)
    return table


def block_refusals(block: SheetBlock) -> list[SetupRefusal | None]:
    """The refusal :func:`sheet_of_block` raises for each pair, or None, read from the block's
    columns without building the records (the checks run again only for a pair Table 24's
    reason code or a tilt refuses, for the words of its refusal)."""
    tilt_max = block.spec.tilt_max
    flagged = [
        (table.reason_code != 0) | (np.abs(table.angles[:, :, :2]).max(axis=(1, 2)) > tilt_max)
        for table in block.tables
    ]
    out: list[SetupRefusal | None] = []
    for i in range(len(block)):
        refusal = block.refusals[i]
        if refusal is None:
            group, row = (int(v) for v in block.table_of[i])
            if flagged[group][row]:
                try:
                    _checked_table(block, i)
                except SetupRefusal as exc:
                    refusal = exc
        out.append(refusal)
    return out


def deferred_sheets(
    pairs: Sequence[Mapping[str, Any]],
    *,
    spec: InstrumentSpec,
    options: SetupOptions,
    source: str,
    name: str = "job",
) -> list[SetupRefusal | Callable[[], SetupSheet]]:
    """:func:`compute_sheets_from_measurements` with each pair's record built when it is first
    asked for: the block's columns and every refusal now, for a pair set up a function that
    returns its sheet (the same sheet, built from the same columns by :func:`sheet_of_block`).

    A job's records (the stage readings as rows of text, the settings per photo, the corners
    and points as mappings) are what only its printed files read."""
    block = compute_sheet_block(pairs, spec=spec, options=options, source=source, name=name)
    assumed = assumed_parameters(spec)
    return [
        refusal if refusal is not None else partial(sheet_of_block, block, i, assumed)
        for i, refusal in enumerate(block_refusals(block))
    ]


def sheet_of_block(
    block: SheetBlock, i: int, assumed: dict[str, tuple[str, ...]] | None = None
) -> SetupSheet:
    """The sheet of pair ``i`` of a block (:func:`compute_sheet_block`), built from its columns
    with the stage readings, or its refusal (raised).

    The range checks are Table 24's reason code, computed once for all pairs: only a refused
    pair goes through the checks again, for the words of its refusal."""
    table = _checked_table(block, i)
    spec, options, inputs = block.spec, block.options, block.inputs[i]
    points, points_m = tuple(inputs["points"]), block.points_of(i)
    mg, mv = int(table.horizontal_scale_denominator[0]), int(table.vertical_scale_denominator[0])
    n_left = float(table.n_left[0])
    fit = None if block.fits is None or block.fit_row[i] < 0 else block.fits.fit(block.fit_row[i])
    centre_z = float(np.asarray(inputs["centres_m"], float)[0, 2])
    heights_mm = table.control_heights_model_mm[0].tolist()
    sheet = SetupSheet(
        scenario=inputs["name"],
        instrument=spec.key,
        instrument_title=spec.title,
        instrument_principle=spec.principle,
        frame_rotation=float(table.frame_rotation[0]),
        frame_origin_m=tuple(float(v) for v in table.frame_origin_m[0]),
        focal_length_corrected_mm=table.focal_length_of(0),
        focal_length_corrected_per_photo_mm=tuple(inputs["focal_length_corrected_per_photo_mm"]),
        map_scale_denominator=block.map_scales[i],
        horizontal_scale_denominator=mg,
        vertical_scale_denominator=mv,
        f_instrument_mm=float(table.f_instrument_mm[0]),
        transformation_coefficient=float(table.transformation_coefficient[0]),
        n_left=n_left,
        n_right=float(table.n_right[0]),
        base_mm=tuple(float(v) for v in table.base_mm[0]),
        photos=_photo_setups(table, np.asarray(inputs["marks_mm"], float)),
        control_heights=tuple(
            {
                "id": p.id,
                "Z_m": p.local_m[2],
                "flying_height_m": float(centre_z - p.local_m[2]),
                "model_height_mm": float(z),
            }
            for p, z in zip(block.heights[i], heights_mm, strict=True)
        ),  # (6.6)
        similarity=fit,
        similarity_point_ids=tuple(points[j].id for j in block.plan[i]),
        corners=_corners(block, i),
        readings=(),
        tolerances=_tolerances(spec, n_left, float(block.depth_mean_m[i])),
        assumed=assumed_parameters(spec) if assumed is None else assumed,
        options=options,
        depth_range_used_mm=tuple(float(v) for v in table.depth_range_mm[0]),
        exterior_sources=tuple(inputs["exterior_sources"]),
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
    same sheet. A block of one (:func:`compute_sheet_block`).

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
    pair = {
        "name": name,
        "focal_length_corrected_mm": focal_length_corrected_mm,
        "focal_length_corrected_per_photo_mm": focal_length_corrected_per_photo_mm,
        "marks_mm": marks_mm,
        "centres_m": centres_m,
        "rotations": rotations,
        "points": points,
        "working_area_m": working_area_m,
        "map_sheet": map_sheet,
        "exterior_sources": exterior_sources,
    }
    block = compute_sheet_block([pair], spec=spec, options=options, source=source, name=name)
    return sheet_of_block(block, 0)


def compute_sheets_from_measurements(
    pairs: Sequence[Mapping[str, Any]],
    *,
    spec: InstrumentSpec,
    options: SetupOptions,
    source: str,
    name: str = "job",
) -> list[SetupSheet | SetupRefusal]:
    """The sheets of many pairs from their measurements: the block's columns in one pass
    (:func:`compute_sheet_block`), then each pair's sheet built from them.

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
        :func:`compute_sheet_from_measurements` would raise for that pair.
    """
    block = compute_sheet_block(pairs, spec=spec, options=options, source=source, name=name)
    assumed = assumed_parameters(spec)
    out: list[SetupSheet | SetupRefusal] = []
    for i in range(len(block)):
        try:
            out.append(sheet_of_block(block, i, assumed))
        except SetupRefusal as exc:
            out.append(exc)
    return out


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
