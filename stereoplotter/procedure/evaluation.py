r"""Evaluation of a built stereo model against the ground truth (``procedure.md``, "What a run
returns").

The instrument is described only by its physical kinematic state, an
:class:`~stereoplotter.instrument.kinematics.InstrumentSetting` and the two
:class:`~stereoplotter.instrument.kinematics.CorrectionUnit`\ s, so the evaluation does not depend
on how the model was built (setup-data method, conventional orientation, or exact settings).
Every field may carry a leading trial dimension (T,) (vectorised Monte Carlo); the results then
carry it too. Pure numpy, no state.

Definitions
-----------
Frame
    The *instrument frame* of the setup sheet: the photogrammetric frame of the scenario moved to
    the left projection centre S_л (``sheet.frame_origin_m``) and turned by −θ about Z
    (``sheet.frame_rotation``), so that the base runs along +X (``setup-data.md``, Inputs,
    "Frame"). Ground coordinates below are in this frame [m]; heights Z are those of the
    photogrammetric frame (the turn is about Z).
Ideal model
    The affine image of the ground (``kinematics.md`` §2.1, §3.5), in counter terms:
    X = MO_X + X_g·1000/M_г, Y = MO_Y + Y_g·1000/M_г, D = (Z_Sл − Z)·1000/M_в (Eq. (6.6) of [1]_,
    :func:`~stereoplotter.setup.equations.model_height`), with M_в = M_г/k.
Parallax errors (at the ideal position)
    The counters are put on the ideal model point, the photo points under the marks are taken
    (:func:`~stereoplotter.instrument.kinematics.marks_from_counters`, ``kinematics.md`` §3.3)
    and compared with the true image points (x⁰, y⁰) on the film (rigorous collinearity, Eq. (2.53)
    of [1]_, with the film deformation of the scenario, ``conventions.md`` §7):
    δp = (x_л − x⁰_л) − (x_п − x⁰_п) (x-parallax error), q = (y_л − y⁰_л) − (y_п − y⁰_п)
    (y-parallax), both in photo mm. δp > 0: the marks are further apart along the base than the
    images, i.e. the ideal point lies off the built model surface.
Built model
    The true image points intersected on the instrument
    (:func:`~stereoplotter.instrument.kinematics.counters_from_homologous_points`, §3.4: x-parallax
    cleared, Y as the mean of the two rays). Plan errors are (built − ideal)·M_г/1000 [m] along
    the instrument-frame axes, and ×1000/M_map in mm on the map. The height of the built point is
    read as the metre height scale shows it, height_zero − D·M_в/1000 (the scale of (6.15),
    :func:`~stereoplotter.setup.equations.height_scale_reading`); ΔH = built − true [m], positive
    when
    the built point is too high; in ‰ of the mean flying height H̄ = Z_Sл − mean Z of the
    working-area grid.
After plane removal
    The least-squares plane a + b·X_g + c·Y_g fitted at the plane control points (by default the
    control points of kind "full", the four corner points of the book's levelling, ch. 5
    L3152; ``accuracy.md``, Monte Carlo protocol) is subtracted from the height errors and from δp
    of every point set ("after geodetic orientation").
Standard points
    The six points of Fig. 39 of [1]_ (ch. 5, L2958): point 1 on the ground nadir of the left
    photo (the plumb of S_л), point 2 on that of the right photo, 3 and 5 at Y_g = +c·m̄ and −c·m̄
    from point 1, 4 and 6 likewise from point 2, with c the photo ordinate of the standard points
    (80 mm by default, ch. 5 L3080) and m̄ = H̄/f the mean photo scale in ground metres per photo
    millimetre (f the calibrated camera principal distance); Z from the terrain.

Shapes: with a single instrument every per-point array has shape (n,) and every summary value
is a float; with T trials they have shapes (T, n) and (T,).

References
----------
.. [1] Kushtin I. F. & Lyskov G. A., *Фотограмметрия снимка и стереоскопических моделей*,
   Moscow: Nedra, 1984, ch. 5 §22 (Fig. 39, standard points) and ch. 6 §26–§27.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.constants import MM_PER_M, UM_PER_MM
from stereoplotter.errors import StereoplotterError
from stereoplotter.geometry.collinearity import object_to_photo
from stereoplotter.instrument.kinematics import (
    CorrectionUnit,
    InstrumentSetting,
    counters_from_homologous_points,
    parallaxes_at_marks,
    x_parallaxes_at_marks,
)
from stereoplotter.procedure.evaluation_results import ModelEvaluation, PointSetEvaluation
from stereoplotter.scenario.model import Camera, Photo, Scenario
from stereoplotter.scenario.synthetic import film_deformed, working_area_grid_m
from stereoplotter.setup.equations import height_scale_reading, model_height
from stereoplotter.setup.sheet import instrument_frame_m

__all__ = [
    "STANDARD_POINTS_C_MM",
    "ModelEvaluation",
    "ModelTruth",
    "PointSetEvaluation",
    "PointSetTruth",
    "evaluate_against",
    "evaluate_instrument",
    "evaluate_model",
    "film_points_mm",
    "ideal_model_mm",
    "instrument_frame_m",
    "model_truth",
    "parallax_errors_at_ideal",
    "parallax_map_data",
    "photo_points_mm",
    "plane_residuals",
    "standard_points_m",
]

#: Photo ordinate c of the standard points 3–6 (ch. 5, Table 18 inputs, OCR L3080). [mm]
STANDARD_POINTS_C_MM = 80.0

_F = NDArray[np.float64]


# --------------------------------------------------------------------------------------------
# Pure pieces
# --------------------------------------------------------------------------------------------


def ideal_model_mm(
    frame_points_m: ArrayLike,
    horizontal_scale_denominator: float,
    vertical_scale_denominator: float,
) -> _F:
    r"""The ideal (affine) model of ground points: counter offsets from the plumb of S_л and depth.

    Parameters
    ----------
    frame_points_m : array_like, shape (..., 3)
        Ground points in the instrument frame (origin S_л, base along +X). [m]
    horizontal_scale_denominator, vertical_scale_denominator : float
        M_г and M_в = M_г/k. [—]

    Returns
    -------
    ndarray, shape (..., 3)
        (X − MO_X, Y − MO_Y, D): X_g·1000/M_г, Y_g·1000/M_г and D = (Z_Sл − Z)·1000/M_в. [mm]

    Notes
    -----
    ``kinematics.md`` §2.1 (the model is A(X, Y, Z) = (X/M_г, Y/M_г, Z/M_в)) and §3.5 (counters ↔
    ground); the depth is Eq. (6.6) of [1]_ (:func:`~stereoplotter.setup.equations.model_height`).

    Examples
    --------
    >>> ideal_model_mm([700.0, -70.0, -1400.0], 7000, 8000).tolist()
    [100.0, -10.0, 175.0]
    """
    p = np.asarray(frame_points_m, float)
    plan = p[..., :2] * MM_PER_M / float(horizontal_scale_denominator)
    depth = model_height(-p[..., 2], vertical_scale_denominator)  # (6.6), H_Ф = Z_Sл − Z
    return np.concatenate([plan, depth[..., None]], axis=-1)


def film_points_mm(scenario: Scenario, photo_name: str, points_m: ArrayLike) -> _F:
    r"""True image points on the film in the cassette: rigorous collinearity plus film deformation.

    Parameters
    ----------
    scenario : Scenario
        The ground truth (camera, exterior orientation, film deformation).
    photo_name : {"left", "right"}
        Which photo.
    points_m : array_like, shape (..., 3)
        Ground points in the photogrammetric frame of the scenario. [m]

    Returns
    -------
    ndarray, shape (..., 2)
        (x⁰, y⁰) in the fiducial system. [mm]

    Notes
    -----
    Eq. (2.53) of [1]_ (:func:`~stereoplotter.geometry.collinearity.object_to_photo`) on the true
    exterior orientation, then the uniform film deformation (1 + s_x·10⁻⁶, 1 + s_y·10⁻⁶) of the
    negative (``conventions.md`` §7), exactly as
    :func:`~stereoplotter.scenario.synthetic.synthesize_measurements` without noise. A non-zero
    principal point stays in the coordinates: the instrument carries it as a centring error
    (``setup-data.md``, Inputs).
    """
    return photo_points_mm(scenario.camera, scenario.photo(photo_name), points_m)


def photo_points_mm(camera: Camera, photo: Photo, points_m: ArrayLike) -> _F:
    """:func:`film_points_mm` on one photo of the truth (its camera, exterior orientation and
    film deformation). [m → mm]"""
    ext = photo.exterior
    xy = object_to_photo(
        points_m, ext.centre, ext.rotation, camera.focal_length_mm, camera.principal_point_mm
    )
    return film_deformed(photo, xy)


def standard_points_m(
    scenario: Scenario,
    frame_origin_m: ArrayLike,
    frame_rotation: float,
    flying_height_m: float,
    c_mm: float = STANDARD_POINTS_C_MM,
) -> _F:
    r"""Ground positions of the six standard points of Fig. 39 of [1]_, in the instrument frame.

    Parameters
    ----------
    scenario : Scenario
        The ground truth (true projection centres, terrain, camera f).
    frame_origin_m, frame_rotation
        S_л [m] and θ [rad] of the instrument frame (:func:`instrument_frame_m`).
    flying_height_m : float
        H̄, the mean flying height of S_л above the working area. [m]
    c_mm : float
        c, the photo ordinate of points 3–6. [mm]

    Returns
    -------
    ndarray, shape (6, 3)
        Points 1–6 in the instrument frame; Z from the terrain. [m]

    Notes
    -----
    Ch. 5, L2958 of [1]_: point 1 (x₁, 0), 2 (x₂, 0), 3 (x₁, c), 4 (x₂, c), 5 (x₁, −c),
    6 (x₂, −c). Here x₁, x₂ are the ground nadirs of the left and right photos (the plumbs of the
    true S_л, S_п) and c is taken to the ground at the mean photo scale, c·H̄/f.
    """
    return _standard_points(scenario, frame_origin_m, frame_rotation, flying_height_m, c_mm)[1]


def _standard_points(
    scenario: Scenario,
    frame_origin_m: ArrayLike,
    frame_rotation: float,
    flying_height_m: float,
    c_mm: float,
) -> tuple[_F, _F]:
    """:func:`standard_points_m` in the local frame (heights from the terrain) and in the
    instrument frame, shape (6, 3) each. [m]"""
    origin = np.asarray(frame_origin_m, float)
    nadirs = instrument_frame_m(
        np.array([p.exterior.centre for p in (scenario.photo("left"), scenario.photo("right"))]),
        origin,
        frame_rotation,
    )[:, :2]
    c_m = float(c_mm) * float(flying_height_m) / scenario.camera.focal_length_mm
    plan = np.array(
        [
            nadirs[0],
            nadirs[1],
            nadirs[0] + (0.0, c_m),
            nadirs[1] + (0.0, c_m),
            nadirs[0] - (0.0, c_m),
            nadirs[1] - (0.0, c_m),
        ]
    )
    local = instrument_frame_m(
        np.column_stack([plan, np.zeros(6)]), origin, frame_rotation, inverse=True
    )
    local[:, 2] = scenario.terrain.height_m(local[:, 0], local[:, 1])
    return local, instrument_frame_m(local, origin, frame_rotation)


def _counters_at_ideal(model_mm: ArrayLike, setting: InstrumentSetting) -> tuple[_F, _F, _F]:
    """The X, Y and D counters on ideal model points (X − MO_X, Y − MO_Y, D). [mm]"""
    m = np.asarray(model_mm, float)
    x = np.asarray(setting.model_origin_x_mm, float) + m[..., 0]
    y = np.asarray(setting.model_origin_y_mm, float) + m[..., 1]
    return x, y, m[..., 2]


def parallax_errors_at_ideal(
    model_mm: ArrayLike,
    photo_left_mm: ArrayLike,
    photo_right_mm: ArrayLike,
    setting: InstrumentSetting,
    left: CorrectionUnit,
    right: CorrectionUnit,
) -> tuple[_F, _F]:
    r"""x- and y-parallax errors of the instrument at ideal model points.

    Parameters
    ----------
    model_mm : array_like, shape (..., 3)
        Ideal model points (X − MO_X, Y − MO_Y, D) from :func:`ideal_model_mm`. [mm]
    photo_left_mm, photo_right_mm : array_like, shape (..., 2)
        True image points (x⁰, y⁰) on the two photos. [mm]
    setting : InstrumentSetting
        f_пр, base, MO (fields scalar or broadcasting against the points' leading dims).
    left, right : CorrectionUnit
        The correction units.

    Returns
    -------
    x_parallax_error_mm, y_parallax_mm : ndarray, shape (...)
        δp = (x_л − x⁰_л) − (x_п − x⁰_п), q = (y_л − y⁰_л) − (y_п − y⁰_п), photo mm. [mm]

    Notes
    -----
    The photo points (x, y) under the marks with the counters on the ideal point:
    ``kinematics.md`` §3.3 (:func:`~stereoplotter.instrument.kinematics.marks_from_counters`).

    Examples
    --------
    An ideal vertical pair (k = 1, f′ = f_пр = 100 mm, b_x = 80 mm) has no parallax errors:

    >>> setting = InstrumentSetting(100.0, base_x_mm=80.0)
    >>> unit = CorrectionUnit(100.0)
    >>> dp, q = parallax_errors_at_ideal([40.0, 10.0, 100.0], [40.0, 10.0], [-40.0, 10.0],
    ...                                  setting, unit, unit)
    >>> float(dp), float(q)
    (0.0, 0.0)
    """
    x, y, depth = _counters_at_ideal(model_mm, setting)
    return parallaxes_at_marks(x, y, depth, setting, left, right, photo_left_mm, photo_right_mm)


def x_parallax_errors_at_ideal(
    model_mm: ArrayLike,
    photo_left_mm: ArrayLike,
    photo_right_mm: ArrayLike,
    setting: InstrumentSetting,
    left: CorrectionUnit,
    right: CorrectionUnit,
) -> _F:
    """δp of :func:`parallax_errors_at_ideal` alone (the same numbers; q not computed). [mm]

    Examples
    --------
    >>> setting = InstrumentSetting(100.0, base_x_mm=80.0)
    >>> unit = CorrectionUnit(100.0, tan_alpha=0.01)
    >>> args = ([40.0, 10.0, 100.0], [40.0, 10.0], [-40.0, 10.0], setting, unit, unit)
    >>> bool(x_parallax_errors_at_ideal(*args) == parallax_errors_at_ideal(*args)[0])
    True
    """
    x, y, depth = _counters_at_ideal(model_mm, setting)
    pl, pr = np.asarray(photo_left_mm, float), np.asarray(photo_right_mm, float)
    return x_parallaxes_at_marks(x, y, depth, setting, left, right, pl[..., 0], pr[..., 0])


def plane_residuals(
    values: ArrayLike, plane_xy: ArrayLike, plane_values: ArrayLike, xy: ArrayLike
) -> _F:
    r"""Values minus the least-squares plane fitted at a few points (levelling).

    Parameters
    ----------
    values : array_like, shape (..., n)
        The quantity at the evaluation points (trial dims leading).
    plane_xy : array_like, shape (m, 2)
        Plan positions of the m ≥ 3 fitting points. [m]
    plane_values : array_like, shape (..., m)
        The quantity at the fitting points.
    xy : array_like, shape (n, 2)
        Plan positions of the evaluation points. [m]

    Returns
    -------
    ndarray, shape (..., n)
        values − (a + b·X + c·Y), with (a, b, c) fitted per trial.

    Notes
    -----
    ``accuracy.md`` (Monte Carlo protocol): results "after geodetic orientation" remove the
    least-squares plane fitted at the four control points; ch. 5 L3152 of [1]_ (levelling on four
    control points near the standard points 3–6 removes every error linear in x and y).

    Examples
    --------
    >>> xy = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]]
    >>> plane_residuals([3.0, 4.0, 5.0, 6.5], xy, [3.0, 4.0, 5.0, 6.5], xy).round(3).tolist()
    [0.125, -0.125, -0.125, 0.125]
    """
    a = np.asarray(plane_xy, float)
    pinv = np.linalg.pinv(np.column_stack([np.ones(len(a)), a]))  # (3, m)
    v = np.asarray(plane_values, float)
    # element-wise products and sums (not BLAS) so that a (T, m) batch gives bit-identical rows
    # to T single calls
    c0, c1, c2 = (np.sum(v * row, axis=-1)[..., None] for row in pinv)
    e = np.asarray(xy, float)
    residual: NDArray[np.float64] = np.asarray(values, float) - (c0 + c1 * e[:, 0] + c2 * e[:, 1])
    return residual


# --------------------------------------------------------------------------------------------
# Trial dimension
# --------------------------------------------------------------------------------------------


def trial_count(setting: InstrumentSetting, units: Sequence[CorrectionUnit]) -> int | None:
    """T when any field carries a trial dimension (shape (T,)), else None."""
    trials: set[int] = set()
    objs: tuple[Any, ...] = (setting, *units)
    for obj in objs:
        for f in fields(obj):
            v = getattr(obj, f.name)
            if v is None or isinstance(v, bool | str):
                continue
            shape = np.shape(v)
            if len(shape) > 1:
                raise StereoplotterError(
                    f"{type(obj).__name__}.{f.name}: expected a scalar or an array of shape (T,), "
                    f"found shape {shape}"
                )
            if shape and shape[0] != 1:
                trials.add(shape[0])
            elif shape:
                trials.add(1)
    if len(trials) > 1:
        raise StereoplotterError(
            f"the instrument state mixes trial counts {sorted(trials)}; every array field must "
            "have the same shape (T,)"
        )
    return trials.pop() if trials else None


def with_point_axis(obj: Any) -> Any:
    """The dataclass with every (T,) field reshaped to (T, 1) to broadcast against (n,) points."""
    changes = {}
    for f in fields(obj):
        v = getattr(obj, f.name)
        if v is None or isinstance(v, bool | str):
            continue
        if np.ndim(v) == 1:
            changes[f.name] = np.asarray(v, float)[:, None]
    return replace(obj, **changes)


# --------------------------------------------------------------------------------------------
# The evaluation
# --------------------------------------------------------------------------------------------


def _imaged(format_mm: float, *xy: _F) -> NDArray[np.bool_]:
    half = format_mm / 2.0
    ok = np.ones(xy[0].shape[:-1], bool)
    for v in xy:
        with np.errstate(invalid="ignore"):
            ok &= np.all(np.abs(v) <= half, axis=-1)
    return ok


def _plane_index(
    scenario: Scenario, plane_point_ids: Sequence[str] | None, imaged: NDArray[np.bool_]
) -> list[int]:
    """Indices of the imaged points the levelling plane is fitted at (:func:`evaluate_model`)."""
    if plane_point_ids is None:
        plane_idx = [
            i for i, p in enumerate(scenario.points) if p.role == "control" and p.kind == "full"
        ]
    else:
        known = {p.id: i for i, p in enumerate(scenario.points)}
        missing = [pid for pid in plane_point_ids if pid not in known]
        if missing:
            raise StereoplotterError(
                f"plane_point_ids: {missing} are not points of scenario {scenario.name!r}; "
                f"it has {sorted(known)}"
            )
        plane_idx = [known[pid] for pid in plane_point_ids]
    return [i for i in plane_idx if imaged[i]]


@dataclass(frozen=True, slots=True)
class PointSetTruth:
    """One point set of the evaluation as the ground truth fixes it, whatever the instrument.

    Attributes
    ----------
    ids : tuple of str
    frame_m : ndarray, shape (n, 3)
        The points in the instrument frame (origin S_л, base along +X). [m]
    height_m : ndarray, shape (n,)
        Their true heights Z (photogrammetric frame). [m]
    images_mm : (ndarray, ndarray)
        Their true images (x⁰, y⁰) on the left and right film, shape (n, 2) each. [mm]
    """

    ids: tuple[str, ...]
    frame_m: _F
    height_m: _F
    images_mm: tuple[_F, _F]


def _pair_images(scenario: Scenario, points_m: _F) -> tuple[_F, _F]:
    """True images of ground points (local frame) on the left and right film. [m → mm]"""
    return film_points_mm(scenario, "left", points_m), film_points_mm(scenario, "right", points_m)


@dataclass(frozen=True, slots=True)
class ModelTruth:
    """Everything :func:`evaluate_against` reads of the ground truth and the sheet, computed once
    (:func:`model_truth`): a run evaluates every chunk of its trials on it.

    Attributes
    ----------
    frame_origin_m, frame_rotation
        S_л [m] and θ [rad] of the sheet's instrument frame.
    horizontal_scale_denominator, vertical_scale_denominator, map_scale_denominator
        M_г, M_в and M_map of the sheet. [—]
    flying_height_m : float
        H̄ = Z_Sл − mean Z over the working-area grid. [m]
    standard_points_c_mm : float
        c of the standard points 3–6. [mm]
    grid, standard_points, control, check : PointSetTruth
        The point sets evaluated (control and check points imaged on both photos).
    plane : PointSetTruth or None
        The points the levelling plane is fitted at (None: no plane removal).
    not_imaged : tuple of str
        Control/check points outside the format of a photo.
    """

    frame_origin_m: _F
    frame_rotation: float
    horizontal_scale_denominator: int
    vertical_scale_denominator: int
    map_scale_denominator: int | None
    flying_height_m: float
    standard_points_c_mm: float
    grid: PointSetTruth
    standard_points: PointSetTruth
    control: PointSetTruth
    check: PointSetTruth
    plane: PointSetTruth | None
    not_imaged: tuple[str, ...]


def model_truth(
    scenario: Scenario,
    sheet: Any,
    grid_local_m: ArrayLike,
    *,
    standard_points_c_mm: float = STANDARD_POINTS_C_MM,
    plane_point_ids: Sequence[str] | None = None,
    grid_images_mm: tuple[ArrayLike, ArrayLike] | None = None,
) -> ModelTruth:
    """The ground truth of an evaluation on ``sheet`` over the working-area grid
    ``grid_local_m`` (local frame) [m] (other arguments as :func:`evaluate_model`): the point
    sets in the instrument frame with their true heights and images, the levelling plane's
    points, the mean flying height H̄ over the grid and the standard points at c·H̄/f.

    Each fact is computed once: the grid and the scenario's points are turned into the frame in
    one pass and imaged once, and every point set takes its rows; heights and images come from
    the local coordinates, never from a frame round trip. ``grid_images_mm``: the grid's true
    images on the left and right film if the caller has them already (the prepared scene's). [mm]
    """
    origin = np.asarray(sheet.frame_origin_m, float)
    theta = float(sheet.frame_rotation)
    c_mm = standard_points_c_mm
    grid_local = np.asarray(grid_local_m, float).reshape(-1, 3)
    pts_local = np.array([p.local_m for p in scenario.points], float).reshape(-1, 3)
    # every ground point of the pair in the instrument frame, in one turn
    grid_frame, pts_frame = np.split(
        instrument_frame_m(np.concatenate([grid_local, pts_local]), origin, theta),
        [len(grid_local)],
    )
    flying_height = float(-np.mean(grid_frame[:, 2]))  # Z_Sл − mean Z
    images = _pair_images(scenario, pts_local)
    if grid_images_mm is None:
        grid_images_mm = _pair_images(scenario, grid_local)
    imaged = _imaged(scenario.camera.format_mm, *images)
    plane_idx = _plane_index(scenario, plane_point_ids, imaged)
    plane_xy = np.column_stack([np.ones(len(plane_idx)), pts_frame[plane_idx, :2]])
    use_plane = len(plane_idx) >= 3 and np.linalg.matrix_rank(plane_xy) == 3

    def point_set(idx: Sequence[int]) -> PointSetTruth:
        rows = list(idx)
        return PointSetTruth(
            tuple(scenario.points[i].id for i in rows),
            pts_frame[rows],
            pts_local[rows, 2],
            (images[0][rows], images[1][rows]),
        )

    def role(name: str) -> PointSetTruth:
        return point_set([i for i, p in enumerate(scenario.points) if p.role == name and imaged[i]])

    std_local, std_frame = _standard_points(scenario, origin, theta, flying_height, c_mm)
    return ModelTruth(
        frame_origin_m=origin,
        frame_rotation=theta,
        horizontal_scale_denominator=int(sheet.horizontal_scale_denominator),
        vertical_scale_denominator=int(sheet.vertical_scale_denominator),
        map_scale_denominator=sheet.map_scale_denominator,
        flying_height_m=flying_height,
        standard_points_c_mm=float(c_mm),
        grid=PointSetTruth(
            tuple(f"g{i}" for i in range(len(grid_frame))),
            grid_frame,
            grid_local[:, 2],
            (np.asarray(grid_images_mm[0], float), np.asarray(grid_images_mm[1], float)),
        ),
        standard_points=PointSetTruth(
            tuple(str(i) for i in range(1, 7)),
            std_frame,
            std_local[:, 2],
            _pair_images(scenario, std_local),
        ),
        control=role("control"),
        check=role("check"),
        plane=point_set(plane_idx) if use_plane else None,
        not_imaged=tuple(p.id for p, ok in zip(scenario.points, imaged, strict=True) if not ok),
    )


def evaluate_model(
    scenario: Scenario,
    sheet: Any,
    setting: InstrumentSetting,
    left_unit: CorrectionUnit,
    right_unit: CorrectionUnit,
    *,
    height_zero: ArrayLike | None = None,
    grid_shape: tuple[int, int] = (9, 9),
    standard_points_c_mm: float = STANDARD_POINTS_C_MM,
    plane_point_ids: Sequence[str] | None = None,
    corner4_misclosure_mm: ArrayLike | None = None,
    grid_local_m: ArrayLike | None = None,
) -> ModelEvaluation:
    r"""Evaluate the model built on an instrument against the ground truth of the scenario.

    Parameters
    ----------
    scenario : Scenario
        The ground truth: true exterior orientation, terrain, control and check points.
    sheet : SetupSheet
        Supplies the instrument frame (``frame_origin_m`` = S_л, ``frame_rotation`` = θ), the
        scales M_г, M_в of the ideal model and the map scale.
    setting, left_unit, right_unit, height_zero, corner4_misclosure_mm
        The built instrument and its readings (:func:`evaluate_against`).
    grid_shape : (int, int)
        Rows and columns of the uniform grid over the working area
        (:func:`~stereoplotter.scenario.synthetic.working_area_grid_m`; points not imaged on both
        photos are dropped).
    standard_points_c_mm : float
        c of the standard points 3–6; pass ``spec.standard_points_c_mm``. [mm]
    plane_point_ids : sequence of str, optional
        Control points the levelling plane is fitted at; default the control points of kind
        "full" (plan and height). Fewer than 3 usable points: no plane removal.
    grid_local_m : array_like, shape (g, 3), optional
        That grid if the caller computed it already (a prepared run's ``grid_m``, local frame);
        ``grid_shape`` is then ignored. [m]

    Returns
    -------
    ModelEvaluation
        Per point set (grid, standard points, control, check): δp, q at the ideal position;
        plan and height errors of the built points, raw and after plane removal; summaries via
        :meth:`ModelEvaluation.summary`, JSON via :meth:`ModelEvaluation.to_dict`.

    Notes
    -----
    :func:`model_truth` (the ground-truth part, which a prepared run computes once) and
    :func:`evaluate_against` (the instrument part).
    """
    if grid_local_m is None:
        grid_local_m = working_area_grid_m(scenario, grid_shape)
    truth = model_truth(
        scenario,
        sheet,
        grid_local_m,
        standard_points_c_mm=standard_points_c_mm,
        plane_point_ids=plane_point_ids,
    )
    return evaluate_against(
        truth,
        setting,
        left_unit,
        right_unit,
        height_zero=height_zero,
        corner4_misclosure_mm=corner4_misclosure_mm,
    )


def _raw(
    t: PointSetTruth,
    setting: InstrumentSetting,
    units: tuple[CorrectionUnit, CorrectionUnit],
    scales: tuple[int, int],
    h0: Any,
) -> dict[str, _F]:
    """δp, q at the ideal position and the built point's errors at the points of ``t``."""
    mg, mv = scales
    gl, gr = t.images_mm
    model = ideal_model_mm(t.frame_m, mg, mv)
    dp, q = parallax_errors_at_ideal(model, gl, gr, setting, *units)
    built = counters_from_homologous_points(gl, gr, setting, *units)
    mo_x = np.asarray(setting.model_origin_x_mm, float)
    mo_y = np.asarray(setting.model_origin_y_mm, float)
    dx = (built.x_mm - mo_x - model[:, 0]) * mg / MM_PER_M
    dy = (built.y_mm - mo_y - model[:, 1]) * mg / MM_PER_M
    height = height_scale_reading(h0, built.depth_mm, 0.0, 0.0, mv)  # (6.15) scale
    dh = height - t.height_m
    shape = np.broadcast_shapes(np.shape(dp), np.shape(dx), (len(t.frame_m),))
    out = {"ground_m": t.frame_m, "model_mm": model}
    for name, v in (("dp", dp), ("q", q), ("dx", dx), ("dy", dy), ("dh", dh)):
        out[name] = _own(v, shape)
    out["q_seen"] = _own(built.y_parallax_mm, shape)
    return out


def _own(v: Any, shape: tuple[int, ...]) -> _F:
    """``v`` broadcast to ``shape`` as an array of its own: ``v`` itself where it is one
    already (an array computed above, of that shape, owning its data), else a copy."""
    if isinstance(v, np.ndarray) and v.shape == shape and v.base is None and v.flags.writeable:
        return v
    return np.broadcast_to(v, shape).copy()


def _point_set(
    r: dict[str, _F], plane: tuple[_F, dict[str, _F]] | None, ids: tuple[str, ...]
) -> PointSetEvaluation:
    """A point set's evaluation from its :func:`_raw` values (and the plane's, if any)."""
    dh_plane = dp_plane = None
    if plane is not None:
        plane_xy, p = plane
        xy = r["ground_m"][:, :2]
        dh_plane = plane_residuals(r["dh"], plane_xy, p["dh"], xy)
        dp_plane = plane_residuals(r["dp"], plane_xy, p["dp"], xy)
    return PointSetEvaluation(
        ids=ids,
        ground_m=r["ground_m"],
        model_mm=r["model_mm"],
        x_parallax_error_mm=r["dp"],
        y_parallax_mm=r["q"],
        x_error_m=r["dx"],
        y_error_m=r["dy"],
        height_error_m=r["dh"],
        y_parallax_seen_mm=r["q_seen"],
        height_error_after_plane_m=dh_plane,
        x_parallax_error_after_plane_mm=dp_plane,
    )


def _check_trial_shapes(trials: int | None, **values: Any) -> None:
    """Refuse a value that is neither a scalar (or None) nor of the instrument state's (T,)."""
    for what, value in values.items():
        shape = np.shape(value) if value is not None else ()
        if shape and shape != (trials,):
            raise StereoplotterError(
                f"{what}: expected a scalar or an array of shape (T,) = ({trials},) like the "
                f"instrument state, found shape {shape}"
            )


def evaluate_against(
    truth: ModelTruth,
    setting: InstrumentSetting,
    left_unit: CorrectionUnit,
    right_unit: CorrectionUnit,
    *,
    height_zero: ArrayLike | None = None,
    corner4_misclosure_mm: ArrayLike | None = None,
) -> ModelEvaluation:
    r"""Evaluate the model built on an instrument against a prepared ground truth.

    Parameters
    ----------
    truth : ModelTruth
        The point sets, frame and scales (:func:`model_truth`).
    setting : InstrumentSetting
        f_пр, b_x, b_y, b_z′, MO of the built instrument (e.g. ``Instrument.setting``); fields
        scalar or of shape (T,).
    left_unit, right_unit : CorrectionUnit
        The correction units as built (``Instrument.state()["units"]``); scalar or (T,) fields.
    height_zero : float or array_like (T,), optional
        The reading of the metre height scale at D = 0 (the scale reads
        height_zero − D·M_в/1000, cf. Eq. (6.15)); default the height Z_Sл of the sheet's S_л,
        i.e. heights from the physical depth. Pass the slipped scale of stage 3 to judge the
        heights as the operator reads them. [m]
    corner4_misclosure_mm : float or array_like (T,), optional
        Corner-4 misclosure from stage 5, passed through. [mm]

    Notes
    -----
    Definitions in the module docstring. ``kinematics.md`` §3.3 (counters → marks) gives the
    parallax errors, §3.4 (homologous points → counters) the built model, §3.5 and §2.1 the ideal
    model (M_в = M_г/k, D below S_л, Eq. (6.6) of [1]_). The result depends on the instrument
    only through ``setting`` and the units, so a model built by the setup-data method and one
    built by the conventional method are judged alike. Vectorised: all trials in one pass;
    identical to a loop over single instruments.
    """
    units = (left_unit, right_unit)
    trials = trial_count(setting, units)
    if trials is not None:
        setting = with_point_axis(setting)
        units = tuple(with_point_axis(u) for u in units)
    h0 = truth.frame_origin_m[2] if height_zero is None else np.asarray(height_zero, float)
    _check_trial_shapes(trials, height_zero=h0, corner4_misclosure_mm=corner4_misclosure_mm)
    h0_b = h0[:, None] if np.ndim(h0) == 1 else h0
    scales = truth.horizontal_scale_denominator, truth.vertical_scale_denominator

    def raw(t: PointSetTruth) -> dict[str, _F]:
        return _raw(t, setting, units, scales, h0_b)

    plane = None
    if truth.plane is not None:
        plane = truth.plane.frame_m[:, :2], raw(truth.plane)
    sets = {
        name: _point_set(raw(t), plane, t.ids)
        for name, t in (
            ("grid", truth.grid),
            ("standard_points", truth.standard_points),
            ("control", truth.control),
            ("check", truth.check),
        )
    }
    c4: Any = corner4_misclosure_mm
    if c4 is not None:
        c4 = float(c4) if np.ndim(c4) == 0 else np.asarray(c4, float)
    return ModelEvaluation(
        trials=trials,
        horizontal_scale_denominator=scales[0],
        vertical_scale_denominator=scales[1],
        map_scale_denominator=truth.map_scale_denominator,
        flying_height_m=truth.flying_height_m,
        height_zero_m=float(h0) if np.ndim(h0) == 0 else h0,
        standard_points_c_mm=truth.standard_points_c_mm,
        plane_point_ids=() if truth.plane is None else truth.plane.ids,
        **sets,
        not_imaged=truth.not_imaged,
        corner4_misclosure_mm=c4,
    )


def evaluate_instrument(
    scenario: Scenario, sheet: Any, instrument: Any, **kwargs: Any
) -> ModelEvaluation:
    r""":func:`evaluate_model` on the physical state of a virtual instrument.

    Parameters
    ----------
    scenario, sheet
        As for :func:`evaluate_model`.
    instrument : stereoplotter.instrument.virtual.Instrument
        Any object with a ``setting`` (:class:`InstrumentSetting`, plumb of S_л at 0) and a
        ``state()`` whose ``"units"`` maps "left"/"right" to :class:`CorrectionUnit` (single or
        vectorised over trials).
    **kwargs
        Passed to :func:`evaluate_model` (``height_zero``, ``grid_shape``, …).

    Returns
    -------
    ModelEvaluation
    """
    units = instrument.state()["units"]
    return evaluate_model(
        scenario, sheet, instrument.setting, units["left"], units["right"], **kwargs
    )


def parallax_map_data(evaluation: ModelEvaluation, *, after_plane: bool = False) -> dict[str, Any]:
    r"""The data of the x-parallax error map (for :mod:`stereoplotter.plotting.evaluation`).

    Parameters
    ----------
    evaluation : ModelEvaluation
    after_plane : bool
        Map δp after removing the levelling plane (if the evaluation has one).

    Returns
    -------
    dict
        ``grid_m`` (g, 2), ``x_parallax_error_um`` (g,) and ``y_parallax_um`` (g,) over the
        working-area grid; ``standard_m`` (6, 2) with ``standard_ids``; ``control_m``,
        ``check_m`` (n, 2) with their ids; ``title`` (str). Plan positions in the instrument
        frame [m]; parallaxes in photo µm. For T trials every value is the RMS over trials at
        the point, sqrt(mean_T δp²) (``accuracy.md``, Monte Carlo protocol).
    """
    g = evaluation.grid
    dp = g.x_parallax_error_mm
    if after_plane and g.x_parallax_error_after_plane_mm is not None:
        dp = g.x_parallax_error_after_plane_mm
    else:
        after_plane = False
    q = g.y_parallax_mm
    if evaluation.trials is not None:
        dp = np.sqrt(np.mean(np.square(dp), axis=0))
        q = np.sqrt(np.mean(np.square(q), axis=0))
    what = "RMS over trials of " if evaluation.trials is not None else ""
    plane = " after plane removal" if after_plane else ""
    return {
        "grid_m": g.ground_m[:, :2],
        "x_parallax_error_um": np.asarray(dp) * UM_PER_MM,
        "y_parallax_um": np.asarray(q) * UM_PER_MM,
        "standard_m": evaluation.standard_points.ground_m[:, :2],
        "standard_ids": evaluation.standard_points.ids,
        "control_m": evaluation.control.ground_m[:, :2],
        "control_ids": evaluation.control.ids,
        "check_m": evaluation.check.ground_m[:, :2],
        "check_ids": evaluation.check.ids,
        "title": f"{what}x-parallax error δp{plane} [µm, photo]",
    }
