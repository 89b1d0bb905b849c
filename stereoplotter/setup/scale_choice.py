"""The choice of the model scales M_г, M_в (item 1 of §26), vectorised over stereopairs.

One implementation serves the single-pair sheet (:mod:`stereoplotter.setup.sheet`) and block mode
(:mod:`stereoplotter.setup.block`). Candidates are M_г = r·M_map for the coordinatograph ratios r
and
M_в from the height-counter gears (or forced values); a candidate is feasible when every
condition below holds, and the chosen one has the largest model scale (smallest M_г), then the
smallest M_в (``docs/setup-data.md``, item 1):

* f_пр = f′·M_г/M_в inside the instrument's f_пр range;
* the projection distances of the working area, D = (Z_Sл − Z)·1000/M_в for its deepest and
  shallowest ground, and the same plus b_z′ for the right rod, inside [D_min, D_max];
* b_x, b_y, b_z′ inside their ranges;
* optionally, the plan extent of the model and the sheet corners, ·1000/M_г, inside the carriage
  travel (model X, Y offsets from the left plumb).

Where no candidate is feasible, the *closest* one is reported: fewest violated conditions, then
the largest model scale.
"""

from __future__ import annotations

import enum
import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.errors import StereoplotterError
from stereoplotter.setup.equations import (
    base_components,
    instrument_principal_distance,
    projection_distance,
)
from stereoplotter.spec.instrument_spec import InstrumentSpec
from stereoplotter.spec.range_checks import RangeRefusal, check_in_range

__all__ = [
    "ScaleCandidate",
    "ScaleCheck",
    "candidate_flags",
    "candidate_scales",
    "choose_candidates",
    "describe_candidate",
    "reason_names",
    "scale_candidates",
]


class ScaleCheck(enum.IntFlag):
    """Conditions a (M_г, M_в) candidate can fail (bit flags; 0 = feasible)."""

    NONE = 0
    F_INSTRUMENT = 2  #: f_пр outside f_instrument_range_mm
    PROJECTION_DISTANCE = 4  #: depth of the working area (and + b_z′) outside [D_min, D_max]
    BASE_X = 8  #: b_x outside base_x_range_mm
    BASE_Y = 16  #: b_y outside base_y_range_mm
    BASE_Z = 32  #: b_z′ outside base_z_range_mm
    MODEL_X = 512  #: X extent of the model or sheet corners outside model_x_offset_range_mm
    MODEL_Y = 1024  #: Y extent outside model_y_offset_range_mm


@dataclass(frozen=True, slots=True)
class ScaleCandidate:
    """One (M_г, M_в) pair considered by the scale choice, with the conditions it fails
    (:class:`ScaleCheck` names; empty = feasible)."""

    horizontal: int
    vertical: int
    ratio: float
    f_instrument_mm: float
    reasons: tuple[str, ...]

    @property
    def feasible(self) -> bool:
        return not self.reasons


def scale_candidates(
    focal_length_corrected_mm: float,
    candidates: ArrayLike,
    flags: ArrayLike,
    map_scale_denominator: int | None,
) -> tuple[ScaleCandidate, ...]:
    """The candidates of one pair as :class:`ScaleCandidate` records (f_пр of every candidate
    in one array expression, the reason names of each flag code computed once).

    Parameters
    ----------
    focal_length_corrected_mm : float
        f′. [mm]
    candidates : array_like, shape (C, 2)
        (M_г, M_в) from :func:`candidate_scales`.
    flags : array_like of int, shape (C,)
        This pair's row of :func:`candidate_flags`.
    map_scale_denominator : int or None
        M_map, for the coordinatograph ratio M_г/M_map (NaN without a map).
    """
    grid = np.asarray(candidates, float)
    f_instrument = instrument_principal_distance(focal_length_corrected_mm, grid[:, 0], grid[:, 1])
    ratios = (
        (grid[:, 0] / map_scale_denominator).tolist()
        if map_scale_denominator
        else [math.nan] * len(grid)
    )
    return tuple(
        ScaleCandidate(int(mg), int(mv), ratio, f_pr, reason_names(code))
        for (mg, mv), ratio, f_pr, code in zip(
            grid.tolist(), ratios, f_instrument.tolist(), np.asarray(flags).tolist(), strict=True
        )
    )


@functools.lru_cache(maxsize=256)
def reason_names(code: int) -> tuple[str, ...]:
    """The :class:`ScaleCheck` names (lower case) of the bits set in ``code``, in flag order.

    >>> reason_names(2 | 512)
    ('f_instrument', 'model_x')
    """
    return tuple((flag.name or "").lower() for flag in ScaleCheck if flag and code & int(flag))


def candidate_scales(
    spec: InstrumentSpec,
    map_scale_denominator: int | None,
    horizontal_scale_denominator: int | None = None,
    vertical_scale_denominator: int | None = None,
) -> NDArray[np.float64]:
    """(M_г, M_в) candidates, shape (C, 2), M_г-major in the instrument's gear order.

    Raises
    ------
    StereoplotterError
        No map scale and no forced M_г: the horizontal scale cannot be chosen.
    """
    if horizontal_scale_denominator is not None:
        horizontals = [int(horizontal_scale_denominator)]
    elif map_scale_denominator is None:
        raise StereoplotterError(
            "no map scale, so the horizontal model scale cannot be chosen from the "
            "coordinatograph gears: give a map sheet (map scale) or force M_г"
        )
    else:
        horizontals = [round(r * map_scale_denominator) for r in spec.coordinatograph_ratios]
    verticals = (
        [int(vertical_scale_denominator)]
        if vertical_scale_denominator is not None
        else list(spec.vertical_scale_denominators)
    )
    return np.array([(mg, mv) for mg in horizontals for mv in verticals], dtype=float)


def _outside(v: NDArray, lo: float, hi: float) -> NDArray[np.bool_]:
    with np.errstate(invalid="ignore"):
        return ~((v >= lo) & (v <= hi))


def candidate_flags(
    spec: InstrumentSpec,
    focal_length_corrected_mm: float,
    candidates: ArrayLike,
    depth_m: ArrayLike,
    base_m: ArrayLike,
    extent_m: ArrayLike | None = None,
) -> NDArray[np.int64]:
    """Which conditions each candidate fails, for each pair.

    Parameters
    ----------
    spec : InstrumentSpec
    focal_length_corrected_mm : float
        f′. [mm]
    candidates : array_like, shape (C, 2)
        (M_г, M_в) from :func:`candidate_scales`.
    depth_m : array_like, shape (N, 2)
        Z_Sл − Z of the highest and of the lowest ground of each working area. [m]
    base_m : array_like, shape (N, 3)
        Ground base S_п − S_л in the instrument frame (X along the base). [m]
    extent_m : array_like, shape (N, 2, 2), optional
        [[X_min, X_max], [Y_min, Y_max]] of the model and sheet corners, from S_л. [m]

    Returns
    -------
    ndarray of int, shape (N, C)
        :class:`ScaleCheck` bits; NaN inputs fail every condition they enter.
    """
    grid = np.asarray(candidates, float)
    mg, mv = grid[:, 0], grid[:, 1]
    depth = np.asarray(depth_m, float)
    base = np.asarray(base_m, float)
    n, c = depth.shape[0], grid.shape[0]
    flags = np.zeros((n, c), dtype=np.int64)

    def add(flag: ScaleCheck, mask: NDArray) -> None:
        flags[...] |= np.where(np.broadcast_to(mask, (n, c)), int(flag), 0)

    add(
        ScaleCheck.F_INSTRUMENT,
        _outside(
            instrument_principal_distance(focal_length_corrected_mm, mg, mv),
            *spec.f_instrument_range_mm,
        ),
    )
    b = base_components(np.zeros(3), base[:, None, :], mg, mv)  # (N, C, 3)
    near = projection_distance(depth[:, 0:1], mv)
    far = projection_distance(depth[:, 1:2], mv)
    d_lo, d_hi = spec.projection_distance_range_mm
    with np.errstate(invalid="ignore"):
        shallow = np.minimum(near, near + b[..., 2])
        deep = np.maximum(far, far + b[..., 2])
    add(ScaleCheck.PROJECTION_DISTANCE, _outside(shallow, d_lo, d_hi) | _outside(deep, d_lo, d_hi))
    for flag, j, attribute in (
        (ScaleCheck.BASE_X, 0, "base_x_range_mm"),
        (ScaleCheck.BASE_Y, 1, "base_y_range_mm"),
        (ScaleCheck.BASE_Z, 2, "base_z_range_mm"),
    ):
        add(flag, _outside(b[..., j], *getattr(spec, attribute)))
    if extent_m is not None:
        extent = np.asarray(extent_m, float)[:, :, :, None] * 1000.0 / mg  # (N, 2, 2, C)
        for flag, j, attribute in (
            (ScaleCheck.MODEL_X, 0, "model_x_offset_range_mm"),
            (ScaleCheck.MODEL_Y, 1, "model_y_offset_range_mm"),
        ):
            add(flag, _outside(extent[:, j], *getattr(spec, attribute)).any(axis=1))
    return flags


def choose_candidates(
    flags: ArrayLike, candidates: ArrayLike
) -> tuple[NDArray[np.int64], NDArray[np.bool_]]:
    """The chosen candidate of each pair, and whether it is feasible.

    Returns
    -------
    chosen : ndarray of int, shape (N,)
        The feasible candidate with the smallest M_г, then the smallest M_в; where none is
        feasible, the closest: fewest failed conditions, then the smallest M_г.
    feasible : ndarray of bool, shape (N,)
    """
    flags = np.asarray(flags)
    grid = np.asarray(candidates, float)
    ok = flags == 0
    order = np.lexsort((grid[:, 1], grid[:, 0]))
    first = order[np.argmax(ok[:, order], axis=1)]
    failures = np.zeros(flags.shape, dtype=np.int64)
    for flag in ScaleCheck:
        if flag:
            failures += (flags & int(flag)) != 0
    rank = np.empty(len(grid), dtype=np.int64)
    rank[np.lexsort((np.arange(len(grid)), grid[:, 0]))] = np.arange(len(grid))
    closest = np.argmin(failures * len(grid) + rank, axis=1)
    any_ok = ok.any(axis=1)
    return np.where(any_ok, first, closest), any_ok


def describe_candidate(
    spec: InstrumentSpec,
    focal_length_corrected_mm: float,
    candidate: ArrayLike,
    flags: int,
    depth_m: ArrayLike,
    base_m: ArrayLike,
    extent_m: ArrayLike | None = None,
) -> list[str]:
    """The failed conditions of one candidate of one pair, in the words of
    :func:`~stereoplotter.spec.range_checks.check_in_range` (value, range, status, file, key)."""
    mg, mv = (float(v) for v in candidate)
    b = base_components(np.zeros(3), np.asarray(base_m, float), mg, mv)
    d = projection_distance(np.asarray(depth_m, float), mv)
    checks: dict[ScaleCheck, list[tuple[str, float, str]]] = {
        ScaleCheck.F_INSTRUMENT: [
            (
                "f_instrument_range_mm",
                float(instrument_principal_distance(focal_length_corrected_mm, mg, mv)),
                "f_пр",
            )
        ],
        ScaleCheck.PROJECTION_DISTANCE: [
            ("projection_distance_range_mm", float(v), what)
            for v, what in (
                (d[0], "D of the highest ground"),
                (d[1], "D of the lowest ground"),
                (d[0] + b[2], "D_п of the highest ground"),
                (d[1] + b[2], "D_п of the lowest ground"),
            )
        ],
        ScaleCheck.BASE_X: [("base_x_range_mm", float(b[0]), "b_x")],
        ScaleCheck.BASE_Y: [("base_y_range_mm", float(b[1]), "b_y")],
        ScaleCheck.BASE_Z: [("base_z_range_mm", float(b[2]), "b_z′")],
    }
    if extent_m is not None:
        e = np.asarray(extent_m, float) * 1000.0 / mg
        checks[ScaleCheck.MODEL_X] = [
            ("model_x_offset_range_mm", float(v), "model X offset") for v in e[0]
        ]
        checks[ScaleCheck.MODEL_Y] = [
            ("model_y_offset_range_mm", float(v), "model Y offset") for v in e[1]
        ]
    texts = []
    for flag, items in checks.items():
        if not flags & int(flag):
            continue
        for attribute, value, what in items:
            try:
                check_in_range(spec, attribute, value, what)
            except RangeRefusal as exc:
                texts.append(str(exc))
                break
        else:  # within check_in_range's slack at a boundary: name the condition and its range
            key = spec.key_of(items[0][0])
            texts.append(
                f"{flag.name.lower().replace('_', ' ')} at the edge of its range (of "
                f"{spec.parameters[key].file}: {key})"
            )
    return texts
