"""The sheets of many pairs as columns: frame, ground, (6.8), sheet corners and Table 24.

One pass over the pairs of a job, in stages that each take the whole block (numpy over the pairs;
the pairs' points, of unequal counts, concatenated with each point's pair index):

1. **inputs** — each pair's measured inputs gathered into arrays (:func:`_gather`);
2. **frames** — θ and the turned angles of every pair, the working-area ground and the points in
   each pair's instrument frame and their depth range
   (:func:`~stereoplotter.setup.table24.pair_frames`);
3. **plan control** — (6.8) from Gauss–Krüger to each pair's frame over its plan control
   (:func:`~stereoplotter.geometry.similarity.fit_similarities_with_reflection`), the sheet
   corners on the ground by (6.8), the plan extent of ground, points and corners;
4. **Table 24** — :func:`~stereoplotter.setup.table24.compute_table24` of all pairs that share
   the scale candidates (one call per map scale), and the sheet corners' x′, y′ by (6.7).

The per-pair records an operator reads (:class:`~stereoplotter.setup.records.SetupSheet` with its
stage readings) are built from these columns only when asked for
(:func:`stereoplotter.setup.sheet.sheet_of_block`). The decisions behind every value are in
``docs/setup-data.md``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from stereoplotter.errors import StereoplotterError
from stereoplotter.geometry.similarity import (
    SimilarityFits,
    fit_similarities_with_reflection,
)
from stereoplotter.scenario.model import Point
from stereoplotter.setup.equations import corner_offsets_book_form_mm, corner_offsets_mm
from stereoplotter.setup.records import SetupOptions, SetupRefusal
from stereoplotter.setup.scale_choice import candidate_scales
from stereoplotter.setup.table24 import BlockResult, compute_table24, pair_frames
from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = ["CORNER_ORDER", "SheetBlock", "compute_sheet_block"]

#: Sheet-corner numbering (decision, docs/setup-data.md): 1 = lower left, then counter-clockwise
#: in map view, north up. The scenario stores corners NW, NE, SE, SW; this maps 1..4 to them.
CORNER_ORDER = {"1": 3, "2": 2, "3": 1, "4": 0}
_CORNERS = [CORNER_ORDER[k] for k in ("1", "2", "3", "4")]


@dataclass(frozen=True, slots=True)
class SheetBlock:
    """The columns of the sheets of P pairs (:func:`compute_sheet_block`).

    Per pair (axis 0 of length P): ``frame_rotation`` θ [rad], ``depth_m`` (shallowest, deepest)
    Z_Sл − Z and ``depth_mean_m`` of the ground samples and points [m], ``extent_m`` (X, Y) ×
    (min, max) of them and the sheet corners [m], ``corners_gk`` and ``corners_m`` the sheet
    corners 1–4 in Gauss–Krüger and on the ground by (6.8) (NaN without a map sheet or two plan
    points) [m], ``corners_mm`` and ``corners_book_form_mm`` their x′, y′ by (6.7) and by (6.7)
    as printed (:mod:`stereoplotter.setup.equations`) [mm], ``fit_row`` the pair's row of
    ``fits`` (−1: no fit). The points of all pairs are concatenated: ``points_m`` (n, 3) in each
    pair's instrument frame [m], pair ``i``'s from ``point_start[i]`` to ``point_start[i + 1]``.
    ``refusals`` holds the refusal of a pair refused before Table 24 (else None); ``tables`` the
    Table 24 of each group of pairs sharing the scale candidates, ``table_of[i]`` = (group, row)
    of pair ``i`` (−1, −1 when refused before).
    """

    spec: InstrumentSpec
    options: SetupOptions
    source: str
    inputs: tuple[Mapping[str, Any], ...]
    refusals: tuple[SetupRefusal | None, ...]
    frame_rotation: NDArray[np.float64]
    points_m: NDArray[np.float64]
    point_start: NDArray[np.intp]
    plan: tuple[tuple[int, ...], ...]
    heights: tuple[tuple[Point, ...], ...]
    depth_m: NDArray[np.float64]
    depth_mean_m: NDArray[np.float64]
    extent_m: NDArray[np.float64]
    corners_gk: NDArray[np.float64]
    corners_m: NDArray[np.float64]
    corners_mm: NDArray[np.float64]
    corners_book_form_mm: NDArray[np.float64]
    fits: SimilarityFits | None
    fit_row: NDArray[np.intp]
    map_scales: tuple[int | None, ...]
    tables: tuple[BlockResult, ...]
    table_of: NDArray[np.intp]

    def __len__(self) -> int:
        return len(self.inputs)

    def points_of(self, i: int) -> NDArray[np.float64]:
        """Pair ``i``'s points in its instrument frame, shape (p, 3). [m]"""
        return self.points_m[self.point_start[i] : self.point_start[i + 1]]


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


@dataclass(frozen=True, slots=True)
class _Gathered:
    """Stage 1: the measured inputs of the pairs as arrays (points and ground concatenated), and
    the pairs grouped by their scale candidates."""

    centres_m: NDArray  # (P, 2, 3)
    rotations: NDArray  # (P, 2, 3, 3)
    focal_length_mm: NDArray  # (P,) f′
    marks_mm: NDArray  # (P, 2, 4, 2)
    point_start: NDArray  # (P + 1,)
    ground_local_m: NDArray  # (g, 3): each pair's working area, then its points
    ground_start: NDArray  # (2P + 1,): pair i's working area from 2i, its points from 2i + 1
    point_rows: NDArray  # (n,) the rows of the points in the ground
    plan: tuple[tuple[int, ...], ...]
    plan_gk: NDArray  # (m, 2) north, east of the plan control of the pairs with a sheet
    corners_gk: NDArray  # (P, 4, 2), NaN without a map sheet
    heights: tuple[tuple[Point, ...], ...]
    heights_m: NDArray  # (P, W) Z of the height control, NaN-padded
    map_scales: tuple[int | None, ...]
    refusals: tuple[SetupRefusal | None, ...]
    groups: dict[int | None, tuple[NDArray, NDArray]]  # map scale → (pairs, scale candidates)


def _gather(
    pairs: Sequence[Mapping[str, Any]], spec: InstrumentSpec, options: SetupOptions, source: str
) -> _Gathered:
    """Stage 1: each pair's inputs into the block's arrays (the only loop over the pairs), and
    the scale candidates of each map scale (item 1 of §26), once."""
    count = len(pairs)
    ground, plans, plan_gk, heights, scales = [], [], [], [], []
    corners = np.full((count, 4, 2), np.nan)
    for i, pair in enumerate(pairs):
        points: tuple[Point, ...] = tuple(pair["points"])
        xyz = np.array([p.local_m for p in points], float).reshape(-1, 3)
        ground += [np.asarray(pair["working_area_m"], float).reshape(-1, 3), xyz]
        sheet = pair["map_sheet"]
        plan = tuple(
            j
            for j, p in enumerate(points)
            if p.role == "control" and p.kind in ("full", "plan") and p.sk42_m is not None
        )
        plans.append(plan)
        if sheet is not None:
            corners[i] = np.asarray(sheet.corners_sk42_m, float)[_CORNERS, :2]
            if len(plan) >= 2:
                plan_gk += [points[j].sk42_m[:2] for j in plan]
        heights.append(
            tuple(p for p in points if p.role == "control" and p.kind in ("full", "height"))
        )
        scales.append(sheet.scale_denominator if sheet is not None else None)
    runs = np.array([len(v) for v in ground], np.intp)
    ground_start = np.concatenate([[0], np.cumsum(runs)]).astype(np.intp)
    sizes = runs[1::2]
    first = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.intp)  # a pair's first point
    heights_m = np.full((count, max((len(h) for h in heights), default=0)), np.nan)
    for i, h in enumerate(heights):
        heights_m[i, : len(h)] = [p.local_m[2] for p in h]
    refusals, groups = _scale_groups(scales, spec, options, source)
    return _Gathered(
        centres_m=np.array([p["centres_m"] for p in pairs], float).reshape(count, 2, 3),
        rotations=np.array([p["rotations"] for p in pairs], float).reshape(count, 2, 3, 3),
        focal_length_mm=np.array([float(p["focal_length_corrected_mm"]) for p in pairs]),
        marks_mm=np.array([p["marks_mm"] for p in pairs], float).reshape(count, 2, 4, 2),
        point_start=np.concatenate([[0], np.cumsum(sizes)]).astype(np.intp),
        ground_local_m=np.concatenate(ground) if ground else np.zeros((0, 3)),
        ground_start=ground_start,
        point_rows=np.repeat(ground_start[1:-1:2] - first, sizes) + np.arange(int(sizes.sum())),
        plan=tuple(plans),
        plan_gk=np.array(plan_gk, float).reshape(-1, 2),
        corners_gk=corners,
        heights=tuple(heights),
        heights_m=heights_m,
        map_scales=tuple(scales),
        refusals=refusals,
        groups=groups,
    )


def _scale_groups(
    scales: Sequence[int | None], spec: InstrumentSpec, options: SetupOptions, source: str
) -> tuple[tuple[SetupRefusal | None, ...], dict[int | None, tuple[NDArray, NDArray]]]:
    """The pairs of each map scale with its scale candidates, and the refusal of a pair without
    a map sheet (and no forced M_г) or whose map scale has no candidates."""
    refusals: list[SetupRefusal | None] = [None] * len(scales)
    grids: dict[int | None, NDArray | SetupRefusal] = {}
    members: dict[int | None, list[int]] = {}
    for i, scale in enumerate(scales):
        if scale is None and options.horizontal_scale_denominator is None:
            refusals[i] = SetupRefusal(
                f"{source}: map_sheet: expected a map sheet, whose scale chooses the "
                "horizontal model scale M_г from the coordinatograph gears, found nothing (or "
                "force M_г with --horizontal-scale)"
            )
            continue
        if scale not in grids:
            try:
                grids[scale] = _candidate_grid(spec, options, scale)
            except SetupRefusal as exc:
                grids[scale] = exc
        grid = grids[scale]
        if isinstance(grid, SetupRefusal):
            refusals[i] = grid
            continue
        members.setdefault(scale, []).append(i)
    groups = {k: (np.array(v, np.intp), grids[k]) for k, v in members.items()}
    return tuple(refusals), groups  # type: ignore[return-value]


def _plan_control(
    gathered: _Gathered, points_m: NDArray, ground_m: NDArray
) -> tuple[SimilarityFits | None, NDArray, NDArray, NDArray]:
    """Stage 3: (6.8) over the plan control of each pair with a map sheet and two plan points,
    its sheet corners on the ground by (6.8) (NaN for the other pairs), and the plan extent
    (X, Y) × (min, max) of each pair's ground samples, points and corners. [m]"""
    count = len(gathered.plan)
    fitted = [
        i
        for i, plan in enumerate(gathered.plan)
        if len(plan) >= 2 and not np.isnan(gathered.corners_gk[i, 0, 0])
    ]
    row = np.full(count, -1, np.intp)
    corners_m = np.full((count, 4, 2), np.nan)
    fits = None
    if fitted:
        row[fitted] = np.arange(len(fitted))
        sizes = [len(gathered.plan[i]) for i in fitted]
        index = np.concatenate(
            [gathered.point_start[i] + np.array(gathered.plan[i], np.intp) for i in fitted]
        )
        group = np.repeat(np.arange(len(fitted)), sizes)
        north, east = gathered.plan_gk[:, 0], gathered.plan_gk[:, 1]
        fits = fit_similarities_with_reflection(
            group, north, east, points_m[index, 0], points_m[index, 1], groups=len(fitted)
        )
        gk = gathered.corners_gk[fitted]  # (f, 4, 2)
        a, b = fits.a[:, None], fits.b[:, None]
        corners_m[fitted] = np.stack(  # Eq. (6.8), apply_similarity's expressions per pair
            [a * gk[..., 0] + b * gk[..., 1] + fits.cx_m[:, None],
             -a * gk[..., 1] + b * gk[..., 0] + fits.cy_m[:, None]], axis=-1,
        )  # fmt: skip
    cuts = gathered.ground_start[:-1:2]
    if count == 0:  # reduceat takes no empty list of cuts
        return fits, row, corners_m, np.zeros((0, 2, 2))
    low = np.minimum.reduceat(ground_m[:, :2], cuts)
    high = np.maximum.reduceat(ground_m[:, :2], cuts)
    low = np.fmin(low, np.min(np.where(np.isnan(corners_m), np.inf, corners_m), axis=1))
    high = np.fmax(high, np.max(np.where(np.isnan(corners_m), -np.inf, corners_m), axis=1))
    return fits, row, corners_m, np.stack([low, high], axis=-1)


def compute_sheet_block(
    pairs: Sequence[Mapping[str, Any]],
    *,
    spec: InstrumentSpec,
    options: SetupOptions,
    source: str,
    name: str = "job",
) -> SheetBlock:
    """The columns of the sheets of many pairs from their measurements (stages 1–4 above):
    ``pairs`` holds per pair the keyword arguments of
    :func:`stereoplotter.setup.sheet.compute_sheet_from_measurements` but ``spec``, ``options``
    and ``source`` (the file named in refusals), shared by the pairs; ``name``: the block's."""
    gathered = _gather(pairs, spec, options, source)
    frames = pair_frames(
        gathered.centres_m, gathered.rotations, gathered.ground_local_m, gathered.ground_start
    )
    points_m = frames.ground_m[gathered.point_rows]
    fits, fit_row, corners_m, extent = _plan_control(gathered, points_m, frames.ground_m)
    count, tables = len(pairs), []
    table_of = np.full((count, 2), -1, np.intp)
    mg, n_left = np.full(count, np.nan), np.full(count, np.nan)
    for k, (scale, (rows, grid)) in enumerate(gathered.groups.items()):  # stage 4: Table 24
        table_of[rows, 0], table_of[rows, 1] = k, np.arange(len(rows))
        table = compute_table24(
            gathered.focal_length_mm[rows], gathered.marks_mm[rows], gathered.centres_m[rows],
            gathered.rotations[rows], frames.depth_m[rows], grid, spec,
            heights_m=gathered.heights_m[rows], extent_m=extent[rows],
            map_scale_denominator=scale, book_sign=options.book_sign_n_right,
            model_names=tuple(pairs[i]["name"] for i in rows),
            height_point_ids=tuple(tuple(p.id for p in gathered.heights[i]) for i in rows),
            name=name, frames=frames.take(rows),
        )  # fmt: skip
        tables.append(table)
        mg[rows], n_left[rows] = table.horizontal_scale_denominator, table.n_left
    m, n = mg[:, None, None], n_left[:, None, None]  # (6.7) of the ground corners, per pair
    return SheetBlock(
        spec=spec,
        options=options,
        source=source,
        inputs=tuple(pairs),
        refusals=gathered.refusals,
        frame_rotation=frames.theta,
        points_m=points_m,
        point_start=gathered.point_start,
        plan=gathered.plan,
        heights=gathered.heights,
        depth_m=frames.depth_m,
        depth_mean_m=frames.depth_mean_m,
        extent_m=extent,
        corners_gk=gathered.corners_gk,
        corners_m=corners_m,
        corners_mm=corner_offsets_mm(corners_m, m),
        corners_book_form_mm=corner_offsets_book_form_mm(corners_m, n, n * m),
        fits=fits,
        fit_row=fit_row,
        map_scales=gathered.map_scales,
        tables=tuple(tables),
        table_of=table_of,
    )
