"""The setup sheet (Table 24 of the book): everything an operator needs to build an oriented,
scaled model on the instrument without plotting control first.

Orchestration only: the equations live in :mod:`stereoplotter.setup.equations` and
:mod:`stereoplotter.geometry`; the decisions behind them in ``docs/setup-data.md``. The sheet is
computed from the scenario *as measured*: f′ from the measured fiducial spans, the measured mark
coordinates, and the exterior orientation as given (aerotriangulation) or by resection from the
measured control — with the scenario's seed, so a sheet is reproducible.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.constants import MM_PER_M
from stereoplotter.errors import StereoplotterError
from stereoplotter.geometry.rotation import angles_from_matrix, rotation_matrix, rotation_z
from stereoplotter.geometry.similarity import (
    SimilarityFit,
    apply_similarity,
    fit_similarity_with_reflection,
)
from stereoplotter.geometry.transformed import (
    transformed_coordinates,
    transformed_x_single_tilt,
    transformed_y_single_tilt,
)
from stereoplotter.instrument.spec import InstrumentSpec, check_in_range
from stereoplotter.scenario.exterior import known_exterior_orientation
from stereoplotter.scenario.model import Scenario
from stereoplotter.scenario.synthetic import (
    synthesize_measurements,
    working_area_grid_m,
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
    sheet_corner_instrument_coordinates,
    sheet_corner_instrument_coordinates_book_form,
)
from stereoplotter.setup.readings import stage_readings
from stereoplotter.setup.scale_choice import (
    ScaleCheck,
    candidate_flags,
    candidate_scales,
    choose_candidates,
    describe_candidate,
)

__all__ = [
    "CORNER_ORDER",
    "ScaleCandidate",
    "SetupOptions",
    "SetupRefusal",
    "SetupSheet",
    "assumed_parameters",
    "compute_setup_sheet",
    "instrument_frame_m",
]

#: Sheet-corner numbering (decision, docs/setup-data.md): 1 = lower left, then counter-clockwise
#: in map view, north up. The scenario stores corners NW, NE, SE, SW; this maps 1..4 to them.
CORNER_ORDER = {"1": 3, "2": 2, "3": 1, "4": 0}
CORNER_NAMES = {"1": "SW", "2": "SE", "3": "NE", "4": "NW"}


class SetupRefusal(StereoplotterError):
    """The instrument cannot take the scenario (no feasible scale pair, a setting beyond a stop)."""


@dataclass(frozen=True, slots=True)
class SetupOptions:
    """Choices behind the sheet; the defaults are the decisions of ``docs/setup-data.md``.

    Attributes
    ----------
    book_sign_n_right : bool
        Use the printed sign of (6.4) (n_п < n_л for a higher right station).
    horizontal_scale_denominator, vertical_scale_denominator : int or None
        Force M_г and/or M_в instead of choosing them (still range-checked).
    bz_scale_sense : int
        +1 (default): the b_z scale grows when the right pivot rises, so (6.11) reads
        O′_bz = O_bz + Δb_z and (6.14) O_bz = MO_bz + b_z′. −1: a scale counting the other way,
        which makes the printed minus of (6.11) right and turns (6.14) into MO_bz − b_z′.
    """

    book_sign_n_right: bool = False
    horizontal_scale_denominator: int | None = None
    vertical_scale_denominator: int | None = None
    bz_scale_sense: int = 1

    def __post_init__(self) -> None:
        if self.bz_scale_sense not in (1, -1):
            raise StereoplotterError(
                f"bz_scale_sense: expected +1 or -1, found {self.bz_scale_sense!r}"
            )


@dataclass(frozen=True, slots=True)
class ScaleCandidate:
    """One (M_г, M_в) pair considered by the scale choice, with the conditions it fails
    (:class:`~stereoplotter.setup.scale_choice.ScaleCheck` names; empty = feasible)."""

    horizontal: int
    vertical: int
    ratio: float
    f_instrument_mm: float
    reasons: tuple[str, ...]

    @property
    def feasible(self) -> bool:
        return not self.reasons


@dataclass(frozen=True, slots=True)
class PhotoSetup:
    """Per-photo settings of the sheet (angles in the instrument frame)."""

    name: str
    alpha: float
    omega: float
    kappa: float
    marks_measured_mm: dict[str, tuple[float, float]]
    transformed_book_mm: dict[str, float]
    transformed_rigorous_mm: dict[str, tuple[float, float]]
    mark_span_mm: float
    decentration_mm: tuple[float, float]
    correction_inclination: tuple[float, float]
    n: float


@dataclass(frozen=True, slots=True)
class SetupSheet:
    """The computed setup sheet (Table 24 plus the readings of the five stages)."""

    scenario: str
    instrument: str
    instrument_title: str
    frame_rotation: float
    frame_origin_m: tuple[float, float, float]
    focal_length_corrected_mm: float
    focal_length_corrected_per_photo_mm: tuple[float, ...]
    map_scale_denominator: int | None
    horizontal_scale_denominator: int
    vertical_scale_denominator: int
    f_instrument_mm: float
    transformation_coefficient: float
    n_left: float
    n_right: float
    base_mm: tuple[float, float, float]
    photos: tuple[PhotoSetup, ...]
    control_heights: tuple[dict[str, Any], ...]
    similarity: SimilarityFit | None
    similarity_point_ids: tuple[str, ...]
    corners: tuple[dict[str, Any], ...]
    readings: tuple[dict[str, Any], ...]
    tolerances: dict[str, float]
    candidates: tuple[ScaleCandidate, ...]
    assumed: dict[str, tuple[str, ...]]
    options: SetupOptions = field(default_factory=SetupOptions)
    depth_range_used_mm: tuple[float, float] = (math.nan, math.nan)
    exterior_sources: tuple[str, ...] = ()
    points_model_mm: tuple[dict[str, Any], ...] = ()


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


def _sheet_corners_gk(scenario: Scenario) -> NDArray:
    sheet = scenario.map_sheet
    return np.array([sheet.corners_sk42_m[CORNER_ORDER[k]] for k in ("1", "2", "3", "4")])


def _choose_scales(
    spec: InstrumentSpec,
    options: SetupOptions,
    map_scale: int | None,
    f_prime: float,
    depths_m: NDArray,
    base_m: NDArray,
    offsets_m: NDArray,
) -> tuple[ScaleCandidate, tuple[ScaleCandidate, ...]]:
    """Item 1 of §26 through :mod:`stereoplotter.setup.scale_choice`, for one pair."""
    try:
        grid = candidate_scales(
            spec,
            map_scale,
            options.horizontal_scale_denominator,
            options.vertical_scale_denominator,
        )
    except StereoplotterError as exc:
        raise SetupRefusal(f"{exc} (--horizontal-scale)") from None
    depth = np.array([[depths_m.min(), depths_m.max()]])
    extent = np.array(
        [
            [
                [offsets_m[:, 0].min(), offsets_m[:, 0].max()],
                [offsets_m[:, 1].min(), offsets_m[:, 1].max()],
            ]
        ]
    )
    flags = candidate_flags(spec, f_prime, grid, depth, base_m[None], extent)
    chosen, feasible = choose_candidates(flags, grid)
    best = int(chosen[0])
    if not feasible[0]:
        reasons = describe_candidate(
            spec, f_prime, grid[best], int(flags[0, best]), depth[0], base_m, extent[0]
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
    candidates = tuple(
        ScaleCandidate(
            int(mg),
            int(mv),
            mg / map_scale if map_scale else math.nan,
            float(instrument_principal_distance(f_prime, mg, mv)),
            tuple((flag.name or "").lower() for flag in ScaleCheck if flag and code & int(flag)),
        )
        for (mg, mv), code in zip(grid, flags[0], strict=True)
    )
    return candidates[best], candidates


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


# --- the computation ----------------------------------------------------------------------------


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
    rng = np.random.default_rng(scenario.seed) if rng is None else rng
    measurements = synthesize_measurements(scenario, rng)
    f_prime = measurements.focal_length_corrected_mm
    known = known_exterior_orientation(scenario, measurements)
    (c_left, m_left), (c_right, m_right) = ((k.centre_m, k.rotation) for k in known)

    # Frame: base along +X, origin at S_л (docs/setup-data.md, Inputs, "Frame").
    base_vector = c_right - c_left
    theta = float(math.atan2(base_vector[1], base_vector[0]))
    turn = rotation_z(-theta)
    rotations = [turn @ m_left, turn @ m_right]
    base_m = turn @ base_vector
    points_local = np.array([p.local_m for p in scenario.points])
    points_m = instrument_frame_m(points_local, c_left, theta)
    grid_m = instrument_frame_m(working_area_grid_m(scenario, (15, 15)), c_left, theta)
    ground = np.vstack([grid_m, points_m])
    depths_m = -ground[:, 2]  # Z_Sл − Z (S_л is the origin)

    corners_gk = _sheet_corners_gk(scenario) if scenario.map_sheet is not None else None
    plan = [
        i
        for i, p in enumerate(scenario.points)
        if p.role == "control" and p.kind in ("full", "plan") and p.sk42_m is not None
    ]
    fit = None
    corners_m = np.zeros((0, 2))
    if corners_gk is not None and len(plan) >= 2:
        north = np.array([scenario.points[i].sk42_m[0] for i in plan])
        east = np.array([scenario.points[i].sk42_m[1] for i in plan])
        fit = fit_similarity_with_reflection(north, east, points_m[plan, 0], points_m[plan, 1])
        corners_m = apply_similarity(fit, corners_gk[:, 0], corners_gk[:, 1])  # (6.8), ground m
    offsets_m = np.vstack([ground[:, :2], corners_m])
    map_scale = scenario.map_sheet.scale_denominator if scenario.map_sheet else None
    if map_scale is None and options.horizontal_scale_denominator is None:
        raise SetupRefusal(
            f"{scenario.source}: map_sheet: expected a map sheet, whose scale chooses the "
            "horizontal model scale M_г from the coordinatograph gears, found nothing (or force "
            "M_г with --horizontal-scale)"
        )
    chosen, candidates = _choose_scales(
        spec, options, map_scale, f_prime, depths_m, base_m, offsets_m
    )
    mg, mv, f_pr = chosen.horizontal, chosen.vertical, chosen.f_instrument_mm
    k = f_pr / f_prime

    # (6.3), (6.4)
    n_left = float(counter_scale_left(spec.projection_distance_max_mm, f_pr))
    n_right = float(
        counter_scale_right(n_left, 0.0, base_m[2], f_pr, mv, book_sign=options.book_sign_n_right)
    )
    b = base_components(np.zeros(3), base_m, mg, mv)

    photos = []
    for name, rot, n in (("left", rotations[0], n_left), ("right", rotations[1], n_right)):
        alpha, omega, kappa = (float(v) for v in angles_from_matrix(rot))
        check_in_range(spec, "kappa_range", kappa, f"κ_{name} (cassette rotation)")
        for value, what in ((alpha, f"α_{name}"), (omega, f"ω_{name}")):
            _check_tilt(spec, value, what)
        marks = measurements.photo(name).fiducials_mm - scenario.camera.principal_point_mm
        marks_d = {str(i + 1): (float(m[0]), float(m[1])) for i, m in enumerate(marks)}
        x_mark = "2" if name == "left" else "1"
        book = {  # (6.1)/(6.2) without n
            f"x{x_mark}": float(transformed_x_single_tilt(marks_d[x_mark][0], alpha, f_prime)),
            "y3": float(transformed_y_single_tilt(marks_d["3"][1], omega, f_prime)),
            "y4": float(transformed_y_single_tilt(marks_d["4"][1], omega, f_prime)),
        }
        untwisted = rotation_matrix(alpha, omega, 0.0)  # the cassette κ is 0 in stage 2
        rigorous = {
            key: tuple(float(v) for v in transformed_coordinates(marks_d[key], untwisted, f_prime))
            for key in (x_mark, "3", "4")
        }
        d = (float(decentration(f_prime, alpha)), float(decentration(f_prime, omega)))
        for value, what in zip(
            d, (f"decentration d_x,{name}", f"decentration d_y,{name}"), strict=True
        ):
            check_in_range(spec, "decentration_range_mm", value, what)
        photos.append(
            PhotoSetup(
                name,
                alpha,
                omega,
                kappa,
                marks_d,
                book,
                rigorous,
                float(mark_span(n, book["y3"], book["y4"])),
                d,
                (float(correction_inclination(k, alpha)), float(correction_inclination(k, omega))),
                n,
            )
        )
    # (6.6) model heights over height control
    heights = []
    for i, p in enumerate(scenario.points):
        if p.role == "control" and p.kind in ("full", "height"):
            flying = -float(points_m[i, 2])
            heights.append(
                {
                    "id": p.id,
                    "Z_m": p.local_m[2],
                    "flying_height_m": flying,
                    "model_height_mm": float(model_height(flying, mv)),
                }
            )

    # (6.7) corners
    corners = []
    if fit is not None:
        xy = sheet_corner_instrument_coordinates(fit, corners_gk[:, 0], corners_gk[:, 1], mg)
        photo_scale = n_left * mg
        xy_book = sheet_corner_instrument_coordinates_book_form(
            fit, corners_gk[:, 0], corners_gk[:, 1], n_left, photo_scale
        )
        for j, key in enumerate(("1", "2", "3", "4")):
            corners.append(
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
            )

    tolerances = {
        "mark_span_mm": spec.tolerance_L_numerator_mm / n_left,
        "mark_fit_mm": spec.tolerance_mark_fit_per_n_mm * n_left,
        "residual_y_parallax_mm": spec.residual_q_fraction_of_mark * spec.mark_diameter_mm,
        "control_height_m": spec.control_height_fraction_of_H * float(np.mean(depths_m)),
        "corner_mm": spec.corner_tolerance_mm,
    }
    sheet = SetupSheet(
        scenario=scenario.name,
        instrument=spec.key,
        instrument_title=spec.title,
        frame_rotation=theta,
        frame_origin_m=tuple(float(v) for v in c_left),
        focal_length_corrected_mm=f_prime,
        focal_length_corrected_per_photo_mm=measurements.focal_length_corrected_per_photo_mm,
        map_scale_denominator=map_scale,
        horizontal_scale_denominator=mg,
        vertical_scale_denominator=mv,
        f_instrument_mm=f_pr,
        transformation_coefficient=k,
        n_left=n_left,
        n_right=n_right,
        base_mm=tuple(float(v) for v in b),
        photos=tuple(photos),
        control_heights=tuple(heights),
        similarity=fit,
        similarity_point_ids=tuple(scenario.points[i].id for i in plan),
        corners=tuple(corners),
        readings=(),
        tolerances=tolerances,
        candidates=candidates,
        assumed=assumed_parameters(spec),
        options=options,
        depth_range_used_mm=(
            float(depths_m.min() * MM_PER_M / mv),
            float(depths_m.max() * MM_PER_M / mv),
        ),
        exterior_sources=tuple(p.exterior.source for p in scenario.photos),
        points_model_mm=tuple(
            {
                "id": p.id,
                "role": p.role,
                "kind": p.kind,
                "x_mm": float(points_m[i, 0] * MM_PER_M / mg),
                "y_mm": float(points_m[i, 1] * MM_PER_M / mg),
            }
            for i, p in enumerate(scenario.points)
        ),
    )
    return replace(sheet, readings=stage_readings(sheet))


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
