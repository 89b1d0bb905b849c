"""The points and δp of the procedure Monte Carlo: a scenario's geometry in the book's terms
(:func:`scenario_geometry`), ground points under a photo-coordinate grid, the x-parallax error δp
of a built instrument at them (photo mm, at the ideal model position), the height read on the
slipped height scale, the procedure's and Fig. 39's levelling points, and the idealised scenario
and moved standard points of the formulas' own setting.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np

from stereoplotter.instrument.kinematics import depths_of_homologous_points
from stereoplotter.instrument.virtual import HEIGHT_SCALE
from stereoplotter.procedure import conventional as cv
from stereoplotter.procedure import evaluation as ev
from stereoplotter.procedure.evaluation import instrument_frame_m
from stereoplotter.scenario.model import Terrain
from stereoplotter.scenario.synthetic import working_area_grid_m
from stereoplotter.setup.sheet import compute_setup_sheet
from stereoplotter.verification import decomposition as dc
from stereoplotter.verification.linear_mc import FloatArray

if TYPE_CHECKING:
    from stereoplotter.instrument.kinematics import CorrectionUnit, InstrumentSetting
    from stereoplotter.instrument.virtual import Instrument
    from stereoplotter.procedure.run import PreparedRun
    from stereoplotter.scenario.model import Scenario
    from stereoplotter.setup.records import SetupSheet
    from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = [
    "control_frame_points",
    "domain_points",
    "dp_at",
    "dp_function",
    "height_errors_parallax",
    "idealised_geometry",
    "levelling_frame_points",
    "scenario_geometry",
    "standard_points_at_a",
]


def scenario_geometry(scenario: Scenario, spec: InstrumentSpec) -> dict[str, float]:
    """f, l, n_л, f_пр, photo base p = B·f/H̄, overlap and the book's c of a scenario.

    c follows the book's §27 convention: c = p below 70 % overlap (60 %: a = 0), c = 2p above
    (80 %: a = p). ``spec`` is the instrument whose setup sheet gives n_л and f_пр (the book's
    SC-1).

    Examples
    --------
    >>> from stereoplotter.io.paths import data_dir
    >>> from stereoplotter.io.scenario_file import load_scenario
    >>> from stereoplotter.io.instrument_file import load_instrument
    >>> sc = load_scenario(data_dir("scenarios") / "pair60.yaml")
    >>> g = scenario_geometry(sc, load_instrument("sc1"))
    >>> round(g["f"]), round(g["l"]), g["overlap"] < 0.7
    (70, 85, True)
    """
    return _scenario_geometry(scenario, spec)


def _scenario_geometry(scenario: Scenario, spec: InstrumentSpec) -> dict[str, float]:

    sheet = compute_setup_sheet(scenario, spec, rng=np.random.default_rng(scenario.seed))
    f = float(scenario.camera.focal_length_mm)
    pts = np.asarray(scenario.camera.fiducial_array_mm(), float)
    ll = float(np.mean(np.hypot(pts[:, 0], pts[:, 1])))  # mark distance l from the centre
    origin = np.asarray(sheet.frame_origin_m, float)
    theta = float(sheet.frame_rotation)
    grid = instrument_frame_m(working_area_grid_m(scenario, (9, 9)), origin, theta)
    height = float(-np.mean(grid[:, 2]))
    right = instrument_frame_m(
        np.asarray(scenario.photo("right").exterior.centre, float)[None], origin, theta
    )[0]
    p = float(right[0]) * f / height
    fmt = float(scenario.camera.format_mm)
    overlap = 1.0 - p / fmt
    c = p if overlap < 0.7 else 2.0 * p
    return {
        "f": f,
        "l": ll,
        "n": float(sheet.n_left),
        "f_instrument": float(sheet.f_instrument_mm),
        "p": p,
        "c": c,
        "a": c - p,
        "overlap": overlap,
        "flying_height_m": height,
        # the terrain's depth in the model, H̄/M_в, against the carriage's D = n_л·f_пр
        "terrain_depth_mm": height * 1000.0 / float(sheet.vertical_scale_denominator),
    }


def domain_points(
    scenario: Scenario,
    sheet: SetupSheet,
    x_left_range: tuple[float, float],
    c: float,
    p: float,
    f: float,
    height: float,
    grid: tuple[int, int] = (16, 32),
) -> FloatArray:
    """Ground points (instrument frame) under a midpoint grid of left-photo (x_л, y) [mm]."""

    nx, ny = grid
    x0, x1 = x_left_range
    xs = x0 + (np.arange(nx) + 0.5) * (x1 - x0) / nx
    ys = -c + (np.arange(ny) + 0.5) * 2 * c / ny
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    scale = height / f  # ground m per photo mm
    plan = np.column_stack([X.ravel() * scale, Y.ravel() * scale])
    origin = np.asarray(sheet.frame_origin_m, float)
    theta = float(sheet.frame_rotation)
    local = instrument_frame_m(
        np.column_stack([plan, np.zeros(len(plan))]), origin, theta, inverse=True
    )
    local[:, 2] = scenario.terrain.height_m(local[:, 0], local[:, 1])
    return instrument_frame_m(local, origin, theta)


def dp_at(
    scenario: Scenario, sheet: SetupSheet, inst: Instrument, frame_pts: FloatArray
) -> FloatArray:
    """δp [photo mm] of the built instrument ``inst`` at ``frame_pts`` (ideal model position)."""
    units = inst.state()["units"]
    return dp_function(scenario, sheet, frame_pts)(inst.setting, units["left"], units["right"])


def dp_function(scenario: Scenario, sheet: SetupSheet, frame_pts: FloatArray) -> dc.DpOf:
    """δp at ``frame_pts`` as a function of an instrument state (setting, left, right units)."""
    origin = np.asarray(sheet.frame_origin_m, float)
    theta = float(sheet.frame_rotation)
    local = ev.instrument_frame_m(frame_pts, origin, theta, inverse=True)
    gl = ev.film_points_mm(scenario, "left", local)
    gr = ev.film_points_mm(scenario, "right", local)
    model = ev.ideal_model_mm(
        frame_pts, sheet.horizontal_scale_denominator, sheet.vertical_scale_denominator
    )

    def dp(setting: InstrumentSetting, left: CorrectionUnit, right: CorrectionUnit) -> FloatArray:
        return _dp_state(model, gl, gr, setting, left, right)

    return dp


def _dp_state(
    model: FloatArray,
    gl: FloatArray,
    gr: FloatArray,
    setting: InstrumentSetting,
    left: CorrectionUnit,
    right: CorrectionUnit,
) -> FloatArray:
    if ev.trial_count(setting, (left, right)) is not None:
        setting = ev.with_point_axis(setting)
        left, right = ev.with_point_axis(left), ev.with_point_axis(right)
    return np.asarray(ev.x_parallax_errors_at_ideal(model, gl, gr, setting, left, right), float)


def height_errors_parallax(
    scenario: Scenario, sheet: SetupSheet, inst: Any, frame_pts: FloatArray
) -> FloatArray:
    """The error of the height read on the slipped height scale at ``frame_pts`` (the mark
    fused exactly on each point) [m], to be converted to x-parallax (photo mm) by
    dp/dH = B·f/(Z_S − Z)².

    This is what M_p measures ((5.42), (5.56)): the datum is carried by the height scale (its
    slip), not by the model's position; a model scale error of b_x moves every δp at the ideal
    model position by p·ε but a slipped height by only ε·ΔH.
    """

    origin = np.asarray(sheet.frame_origin_m, float)
    theta = float(sheet.frame_rotation)
    local = ev.instrument_frame_m(frame_pts, origin, theta, inverse=True)
    gl = ev.film_points_mm(scenario, "left", local)
    gr = ev.film_points_mm(scenario, "right", local)
    units = inst.state()["units"]
    setting, left, right = inst.setting, units["left"], units["right"]
    gear = float(sheet.vertical_scale_denominator)
    slip = (
        np.asarray(inst.read(HEIGHT_SCALE, exact=True), float)
        + np.asarray(inst.read("Z", exact=True), float) * gear / 1000.0
    )
    if ev.trial_count(setting, (left, right)) is not None:
        setting = ev.with_point_axis(setting)
        left, right = ev.with_point_axis(left), ev.with_point_axis(right)
        slip = slip[:, None]
    depth = depths_of_homologous_points(gl, gr, setting, left, right)
    dh: FloatArray = slip - depth * gear / 1000.0 - local[:, 2]
    return dh


def levelling_frame_points(prep: PreparedRun) -> tuple[list[str], FloatArray]:
    """The procedure's four levelling points (``conventional.levelling_points``) in the frame."""

    ids = list(cv.levelling_points(prep.scene, prep.sheet))
    local = np.array(
        [next(p for p in prep.scenario.points if p.id == i).local_m for i in ids], float
    )
    origin = np.asarray(prep.sheet.frame_origin_m, float)
    return ids, instrument_frame_m(local, origin, float(prep.sheet.frame_rotation))


def idealised_geometry(scenario: Scenario) -> Scenario:
    """``scenario`` with vertical photos at the left photo's height, flat terrain at the base
    height and no film deformation: the geometry (5.54) assumes (points exactly at Fig. 39)."""

    z = float(scenario.photo("left").exterior.centre[2])
    photos = tuple(
        replace(
            ph,
            exterior=replace(
                ph.exterior,
                alpha=0.0,
                omega=0.0,
                kappa=0.0,
                projection_centre_m=(*ph.exterior.projection_centre_m[:2], z),
            ),
            film_deformation_ppm=(0.0, 0.0),
        )
        for ph in scenario.photos
    )
    return replace(scenario, terrain=Terrain(scenario.terrain.base_height_m), photos=photos)


def standard_points_at_a(prep: PreparedRun, g: Mapping[str, float]) -> PreparedRun:
    """The prepared run with standard points 1, 3, 5 moved by −a and 2, 4, 6 by +a along the
    base (Fig. 39, x_л ∈ {−a, p + a}, a = c − p) and the C2 tolerance 0, so every trial makes
    the same number of passes (no 'stop when satisfied' selection, which (5.54) does not model)."""

    sc, sheet, scene = prep.scenario, prep.sheet, prep.scene
    origin = np.asarray(sheet.frame_origin_m, float)
    theta = float(sheet.frame_rotation)
    frame = instrument_frame_m(scene.standard_points_m, origin, theta)
    a_m = g["a"] * g["flying_height_m"] / g["f"]
    frame[:, 0] += np.array([-a_m, a_m] * 3)
    local = instrument_frame_m(frame, origin, theta, inverse=True)
    local[:, 2] = sc.terrain.height_m(local[:, 0], local[:, 1])
    tol = {**sheet.tolerances, "residual_y_parallax_mm": 0.0}
    return replace(
        prep,
        scene=replace(scene, standard_points_m=local),
        sheet=replace(sheet, tolerances=tol),
    )


def control_frame_points(
    scenario: Scenario, sheet: SetupSheet, g: Mapping[str, float]
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The four levelling control points of (5.54), x_п ∈ {−c, a}, y = ±c, on the ground; with
    their (x_п, y) [mm]."""

    c, p, a = g["c"], g["p"], g["a"]
    xr = np.array([-c, a, -c, a])
    y = np.array([c, c, -c, -c])
    scale = g["flying_height_m"] / g["f"]
    origin = np.asarray(sheet.frame_origin_m, float)
    theta = float(sheet.frame_rotation)
    local = instrument_frame_m(
        np.column_stack([(xr + p) * scale, y * scale, np.zeros(4)]), origin, theta, inverse=True
    )
    local[:, 2] = scenario.terrain.height_m(local[:, 0], local[:, 1])
    return instrument_frame_m(local, origin, theta), xr, y
