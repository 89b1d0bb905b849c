"""Procedure Monte Carlo: the formulas of §27 against the simulated operator (``accuracy.md`` 4).

:func:`procedure_mc` runs the real stages on the virtual SC-1 (``procedure.simulate``, closed-form
back-end, vectorised over trials) twice with the same seed — once with the operator's pointing
errors of the formula switched on, once with every error zero — and takes the x-parallax error
field δp of the built model (photo mm, at the ideal model position,
:mod:`stereoplotter.procedure.evaluation`)
on the formula's own integration domain. The difference of the two runs is the error the
pointing caused (the zero run carries the deterministic residue of the sheet's approximations,
reported as ``bias``). The statistic is the protocol's: sqrt(mean over trials and a uniform
midpoint grid of δp²), with a CI half-width of ``CI_Z`` standard errors from the per-trial mean
squares.

Configurations (chosen to match the formulas' assumptions as far as the model allows):

* ``method="setup"`` — (6.39)/(6.40) → (6.43)/(6.44): only the monocular pointing error σ of the
  operator (photo scale; the fiducial settings of stages 1–2); no injected instrument errors,
  ideal mechanics, exact counter reading and setting, no stereo / y-parallax judgment error.
  Coefficient = RMS / m_xy with m_xy = n_л·σ (the book's m_x is a counter error, (6.31)
  m_Δx = m_x/n). Domain of (6.27): x_л ∈ [0, c], y ∈ [−c, c]; no plane removal.
* ``method="conventional"`` — (6.45)/(6.46) = (6.60)/(6.61): y-parallax judgment σ_q = σ and
  stereo (x-parallax) judgment σ_p = σ (m_q = m_p), relative orientation by the six measured q and
  (5.11) (``relative="equations"``, least squares as (5.54) assumes), levelling on the scenario's
  four control points by the procedure itself; coefficient = RMS / σ. Domain of chapter 5:
  x_п ∈ [−c, 0], y ∈ [−c, c] (x_л = x_п + p). By default the measured quantity is the height
  as read on the slipped height scale (converted to parallax units), the standard points stand
  at a = c − p as in the formula, and the height datum is the mean of the four levelling heights
  re-observed with σ_p (the formula's plane); ``quantity``, ``standard_points`` and ``datum``
  select the other readings (δp at the ideal model position, the nadirs, the procedure's
  one-point slip) — ``docs/accuracy.md`` gives the numbers of each. ``levelling="book"``
  re-levels the built model at Fig. 39's control points and ``sources`` switches σ_q or σ_p
  off; :func:`levelling_formula` is the rigorous formula with the plane at any four points (the
  procedure levels on the scenario's control points, which moves the formula by +5 %).

* ``method="setup_control"`` — §27 task 2, setup data refined on control: the setup run above,
  then the built model levelled on Fig. 39's four control points by the least-squares plane
  through its δp there ((6.47)–(6.50) exact control heights, per m_xy; (6.58)/(6.59) control
  parallaxes observed with m_p = m_xy/√2, per m_p); domain of chapter 5. One setup run gives all
  three readings (``fields`` of the result).

Every run can carry the instrument's error terms at their σ (``instrument=True``, real
mechanics), and is estimated with the linear control variate of
:mod:`~stereoplotter.verification.control_variate` (unbiased; ``plain`` keeps the plain mean).

:func:`relative_orientation_mc` runs the conventional relative orientation alone (σ_q only, fixed
passes) against (5.54).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.accuracy import setup_accuracy as sa
from stereoplotter.accuracy.chapter5 import (
    control_points,
    geodetic_orientation_parallax_rms,
    levelling_design,
    relative_orientation_design,
    relative_orientation_parallax_rms,
    standard_points,
)
from stereoplotter.instrument.kinematics import counters_from_homologous_points
from stereoplotter.instrument.virtual import HEIGHT_SCALE
from stereoplotter.procedure import conventional as cv
from stereoplotter.procedure import evaluation as ev
from stereoplotter.procedure.evaluation import instrument_frame_m
from stereoplotter.procedure.fidelity import LINKAGE_VARIANTS, Fidelity
from stereoplotter.procedure.operator import Noise, OperatorModel
from stereoplotter.procedure.simulate import SimulationResult, prepare_run, run_trials_chunk
from stereoplotter.procedure.trials import (
    DEFAULT_MEMORY_BUDGET_MB,
    chunk_trials_for,
)
from stereoplotter.scenario.model import Terrain
from stereoplotter.scenario.synthetic import working_area_grid_m
from stereoplotter.setup.sheet import compute_setup_sheet
from stereoplotter.verification import control_variate as cvar
from stereoplotter.verification import decomposition as dc
from stereoplotter.verification.as_formula import RunResult
from stereoplotter.verification.linear_mc import (
    CI_Z,
    FloatArray,
    LinearModel,
    covariance_rms,
    grid_chapter5,
    relative_field_basis,
)

if TYPE_CHECKING:
    from stereoplotter.instrument.kinematics import CorrectionUnit, InstrumentSetting
    from stereoplotter.instrument.virtual import Instrument
    from stereoplotter.procedure.run import PreparedRun
    from stereoplotter.scenario.model import Scenario
    from stereoplotter.setup.records import SetupSheet
    from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = [
    "LINKAGE_VARIANTS",
    "SOURCES",
    "ProcedureOptions",
    "conventional_sources_mc",
    "idealised_geometry",
    "levelling_formula",
    "levelling_points_photo",
    "procedure_mc",
    "scenario_geometry",
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
    return _dp_of(scenario, sheet, frame_pts)(inst.setting, units["left"], units["right"])


def _dp_of(scenario: Scenario, sheet: SetupSheet, frame_pts: FloatArray) -> dc.DpOf:
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
    dp, _ = ev.parallax_errors_at_ideal(model, gl, gr, setting, left, right)
    return np.asarray(dp, float)


#: ``procedure_mc(sources=…)`` of the conventional method: which judgment errors are on.
SOURCES = ("both", "y_parallax", "stereo")

#: The procedure methods: §27 task 1 with unadjusted setup data ("setup"), task 2 with setup data
#: refined on control ("setup_control"), and the conventional method.
METHODS = ("setup", "setup_control", "conventional")


@dataclass(frozen=True)
class MethodOperator:
    """The operator and the statistic's domain of a method's runs (the module docstring).

    Attributes
    ----------
    error_free : OperatorModel
        Every operator error zero: the run whose δp is the deterministic residue (``bias``).
    noisy : OperatorModel
        The formula's operator errors on (monocular σ; or σ_q, σ_p of the conventional method).
    x_left_range_mm : tuple of float
        The statistic's domain in x_л [mm]: (6.27)'s [0, c], or chapter 5's x_п ∈ [−c, 0].
    unit_mm : float
        The statistic's unit [photo mm]: m_xy = n_л·σ (setup) or σ (conventional).
    relative : {"elements", "equations"}
        The relative orientation of the run (``prepare_run``): by the elements (setup data) or
        by the six measured q and (5.11) (conventional, least squares as (5.54) assumes).
    stereo_sigma_mm : float
        σ_p of the noisy operator's stereo judgments (conventional; 0 for the setup methods),
        also the σ of each observed levelling height.
    """

    error_free: OperatorModel
    noisy: OperatorModel
    x_left_range_mm: tuple[float, float]
    unit_mm: float
    relative: str
    stereo_sigma_mm: float = 0.0


def _configuration(
    method: str, sigma_mm: float, c: float, p: float, n: float, sources: str = "both"
) -> MethodOperator:
    """The operator, domain and unit of ``method`` (module docstring).

    ``sources`` (conventional only): "both" (σ_q = σ_p = σ, the formula's m_q = m_p), or only
    the y-parallax σ_q ("y_parallax", the relative-orientation part (5.54)) or only the stereo σ_p
    ("stereo", the levelling part (5.55))."""

    zero = OperatorModel().zero()
    if method in ("setup", "setup_control"):
        op = replace(zero, monocular_sigma_mm=sigma_mm)
        return MethodOperator(zero, op, (0.0, c), n * sigma_mm, "elements")  # domain of (6.27)
    if method == "conventional":
        sq = 0.0 if sources == "stereo" else sigma_mm
        sp = 0.0 if sources == "y_parallax" else sigma_mm
        op = replace(zero, stereo_sigma_mm=sp, y_parallax_sigma_mm=sq)
        return MethodOperator(zero, op, (p - c, p), sigma_mm, "equations", sp)  # x_п ∈ [−c, 0]
    raise ValueError(f"method: expected one of {METHODS}, found {method!r}")


def _height_errors_parallax(
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
    depth = counters_from_homologous_points(gl, gr, setting, left, right).depth_mm
    dh: FloatArray = slip - depth * gear / 1000.0 - local[:, 2]
    return dh


@dataclass(frozen=True)
class _SceneOf:
    """What ``conventional.levelling_points`` reads of a run: its scene and sheet."""

    scene: Any
    sheet: SetupSheet


def _levelling_frame_points(prep: PreparedRun) -> tuple[list[str], FloatArray]:
    """The procedure's four levelling points (``conventional.levelling_points``) in the frame."""

    ids = list(cv.levelling_points(_SceneOf(prep.scene, prep.sheet)))
    local = np.array(
        [next(p for p in prep.scenario.points if p.id == i).local_m for i in ids], float
    )
    origin = np.asarray(prep.sheet.frame_origin_m, float)
    return ids, instrument_frame_m(local, origin, float(prep.sheet.frame_rotation))


#: The key of a per-trial mean square: a field's name, or (reading, level) of a decomposition
#: (:mod:`.decomposition`) and ("element", element) of the setup elements' errors.
FieldKey = str | tuple[str, str]
#: A run's fields: (result, noise) → field name → per-trial values over the domain, (T, n).
Fields = Callable[[SimulationResult, Noise], dict[str, FloatArray]]
#: The decomposition's mean squares: (result, the run's fields) → (reading, level) → (T,).
Decompose = Callable[[SimulationResult, dict[str, FloatArray]], dict[FieldKey, FloatArray]]


@dataclass(frozen=True)
class FieldMaker:
    """What a method's procedure MC measures on a run: its ``fields`` and, for the setup-data
    method, the per-trial mean squares of their first-order ``decompose`` (None: none)."""

    fields: Fields
    decompose: Decompose | None = None


@dataclass(frozen=True)
class ProcedureRun:
    """One configuration's run of the procedure MC: what :func:`mean_squares` runs.

    Attributes
    ----------
    scenario : Scenario
        The simulated pair (loaded by the caller).
    spec : InstrumentSpec
        The instrument, its standard points at the geometry's c (``standard_points_c_mm``).
    method : {"setup", "setup_control", "conventional"}
        :data:`METHODS`.
    seed : int
        The seed of every keyed draw of the run.
    trials : int
        Trials 0 … trials − 1.
    operator : MethodOperator
        The error-free and the noisy operator, the domain and the unit (:func:`_configuration`).
    geometry : dict
        :func:`scenario_geometry` of the scenario.
    grid : tuple of int
        Midpoint grid of the statistic (nx, ny).
    variant : str
        The instrument's decentration variant (:data:`LINKAGE_VARIANTS` of the linkage).
    fidelity : Fidelity
        The mechanism switches, resolved (:meth:`ProcedureOptions.switches`).
    instrument_errors : bool
        Every injected instrument error term at its configured σ, with the real mechanics.
    control_variate : bool
        Also the estimate with the linear control variate
        (:mod:`~stereoplotter.verification.control_variate`).
    standard_points_at_a : bool
        The standard points moved to Fig. 39 at a = c − p (:func:`standard_points_at_a`; the
        conventional method's "book" layout).
    sigma_control_mm : float
        Setup methods: σ of each observed control parallax (the "observed" reading).
    sources_off : mapping or None
        Key prefix → (trials,) mask of the trials whose acts of that prefix draw 0
        (:func:`conventional_sources_mc`); None: every act drawn on every trial.
    """

    scenario: Scenario
    spec: InstrumentSpec
    method: str
    seed: int
    trials: int
    operator: MethodOperator
    geometry: dict[str, float]
    grid: tuple[int, int]
    variant: str
    fidelity: Fidelity
    instrument_errors: bool = False
    control_variate: bool = True
    standard_points_at_a: bool = False
    sigma_control_mm: float = 0.0
    sources_off: Mapping[str, NDArray[np.bool_]] | None = None

    @property
    def procedure(self) -> str:
        """The procedure that runs: the conventional method or the setup-data method."""
        return "conventional" if self.method == "conventional" else "setup"

    def prepared(self, operator: OperatorModel, errors: str | None) -> PreparedRun:
        """The prepared run with ``operator``; ``errors`` "zero" (none injected, ideal
        mechanics) or None (the instrument's error model, real mechanics if
        :attr:`instrument_errors`). The formulas of §27 describe the book's procedure, task 1:
        each element set once, no remedies (``practice="book"``) — for both methods (the
        operator's remedies would lower the setup-data value)."""
        real_mechanics = self.instrument_errors and errors != "zero"
        prep = prepare_run(
            self.scenario,
            self.spec,
            self.procedure,
            errors,
            self.seed,
            operator=operator,
            ideal_mechanics=not real_mechanics,
            variant=self.variant,
            relative=self.operator.relative,
            practice="book",
            fidelity=self.fidelity,
        )
        if self.standard_points_at_a:
            tol = prep.sheet.tolerances  # keep the operator's tolerances (stopping rule as built)
            prep = standard_points_at_a(prep, self.geometry)
            prep = replace(prep, sheet=replace(prep.sheet, tolerances=tol))
        return prep


@dataclass(frozen=True)
class MeanSquares:
    """Per-trial mean squares of each field of a run, (trials,) each: ``plain`` (and the
    decomposition's, :data:`FieldKey`), ``controlled`` (with the linear control variate; empty
    without it), and ``error_free_dp`` (δp of the error-free run on the statistic's domain)."""

    plain: dict[FieldKey, FloatArray]
    controlled: dict[FieldKey, FloatArray]
    error_free_dp: FloatArray


def _setup_fields(run: ProcedureRun, zero_run: SimulationResult) -> tuple[FieldMaker, FloatArray]:
    """Field makers of the setup-data method: δp on the (6.27) domain ("parallax", task 1), and
    on the chapter-5 domain after levelling on Fig. 39's four control points (task 2,
    :data:`METHODS` "setup_control"): "levelled" with exact control heights, "observed" with
    each control height's parallax observed with σ_c = ``run.sigma_control_mm`` (keyed draws
    ``mc/control/i``). With the error-free run's δp on the (6.27) domain."""

    sc, g, grid = run.scenario, run.geometry, run.grid
    f, p, c, h = g["f"], g["p"], g["c"], g["flying_height_m"]
    sheet = zero_run.sheet
    pts = domain_points(sc, sheet, run.operator.x_left_range_mm, c, p, f, h, grid)
    lev = domain_points(sc, sheet, (p - c, p), c, p, f, h, grid)
    book, _, _ = control_frame_points(sc, sheet, g)
    n, nl = len(pts), len(lev)
    # below 70 % overlap c = p: the two domains are one (60 %: x_л ∈ [0, p]), δp computed once
    same = pts.shape == lev.shape and np.array_equal(pts, lev)
    allp = np.vstack([pts, book] if same else [pts, lev, book])
    first_lev, first_ctl = (0, n) if same else (n, n + nl)
    zero = dp_at(sc, sheet, zero_run.instrument, allp)
    refit = levelling_design(lev[:, 0], lev[:, 1]) @ np.linalg.pinv(
        levelling_design(book[:, 0], book[:, 1])
    )
    sigma_control = run.sigma_control_mm

    def readings(d: FloatArray) -> dict[str, FloatArray]:
        dom, ctl = d[:, first_lev : first_lev + nl], d[:, first_ctl:]
        return {"parallax": d[:, :n], "levelled": dom - ctl @ refit.T}

    def fields(result: SimulationResult, noise: Noise) -> dict[str, FloatArray]:
        d = dp_at(sc, result.sheet, result.instrument, allp) - zero
        out = readings(d)
        obs = np.stack(
            [noise.normal(f"mc/control/{i}", sigma_control) for i in range(len(book))], -1
        )
        return {**out, "observed": out["levelled"] - obs @ refit.T}

    units0 = zero_run.instrument.state()["units"]
    state0 = (zero_run.instrument.setting, {s: units0[s] for s in ("left", "right")})
    jac = dc.state_jacobian(*state0, _dp_of(sc, sheet, allp))

    def decompose(
        result: SimulationResult, main: dict[str, FloatArray]
    ) -> dict[FieldKey, FloatArray]:
        """Per-trial mean squares of the first-order fields of the decomposition
        (:mod:`.decomposition`) of each reading, (reading, level) → (T,) [photo mm²]."""
        units = result.instrument.state()["units"]
        trials = len(next(iter(main.values())))
        deltas = dc.state_deltas(
            result.instrument.setting, {s: units[s] for s in ("left", "right")}, *state0, trials
        )
        noise = main["observed"] - main["levelled"]  # the observed control parallaxes' part
        # each (6.22) element's error (instrument units: mm, tangent, rad), squared per trial
        out: dict[FieldKey, FloatArray] = {
            ("element", f"{o}.{f}"): deltas[i] ** 2 for i, (o, f) in enumerate(dc.ELEMENTS)
        }
        for step, d in dc.linear_fields(jac, deltas):
            r = readings(d)
            r["observed"] = r["levelled"] + noise
            out.update({(key, step): np.mean(v**2, axis=-1) for key, v in r.items()})
        return out

    return FieldMaker(fields, decompose), zero[:n]


def _conventional_fields(
    run: ProcedureRun, zero_prep: PreparedRun, zero_run: SimulationResult
) -> tuple[FieldMaker, FloatArray]:
    """Field makers of the conventional method (``procedure_mc`` options): δp at the ideal model
    position ("parallax") and the heights read on the slipped height scale in parallax units
    (dp/dH = B·f/(Z_S − Z)², frame origin S_л) with three datums: the procedure's slip ("slip"),
    the levelling plane's offset from the four levelling heights each observed with σ_p ("plane",
    the formula's), and the built model re-levelled by the least-squares plane through its
    height errors at x_п ∈ {−c, a}, y = ±c, each observed with σ_p ("book"). With the
    error-free run's δp on the statistic's domain."""

    sc, g, grid = run.scenario, run.geometry, run.grid
    sigma_p = run.operator.stereo_sigma_mm
    f, p, c, h = g["f"], g["p"], g["c"], g["flying_height_m"]
    sheet = zero_run.sheet
    pts = domain_points(sc, sheet, run.operator.x_left_range_mm, c, p, f, h, grid)
    d_zero = dp_at(sc, sheet, zero_run.instrument, pts)
    _, lev = _levelling_frame_points(zero_prep)
    book, _, _ = control_frame_points(sc, sheet, g)
    allp = np.vstack([pts, lev, book])
    k = (p * h / f) * f / allp[:, 2] ** 2  # photo mm of x-parallax per m of height
    h_zero = _height_errors_parallax(sc, sheet, zero_run.instrument, allp)
    n, nl = len(pts), len(lev)
    refit = levelling_design(pts[:, 0], pts[:, 1]) @ np.linalg.pinv(
        levelling_design(book[:, 0], book[:, 1])
    )

    def fields(result: SimulationResult, noise: Noise) -> dict[str, FloatArray]:
        d = dp_at(sc, result.sheet, result.instrument, pts) - d_zero
        e = (_height_errors_parallax(sc, result.sheet, result.instrument, allp) - h_zero) * k
        obs = e[:, n : n + nl] + np.stack(
            [noise.normal(f"mc/datum/{i}", sigma_p) for i in range(nl)], -1
        )
        ctl = e[:, n + nl :] + np.stack(
            [noise.normal(f"mc/book/{i}", sigma_p) for i in range(len(book))], -1
        )
        return {
            "parallax": d,
            "slip": e[:, :n],
            "plane": e[:, :n] - np.mean(obs, axis=-1, keepdims=True),
            "book": e[:, :n] - ctl @ refit.T,
        }

    return FieldMaker(fields), d_zero


def mean_squares(run: ProcedureRun) -> MeanSquares:
    """Per-trial mean squares of each field of ``run`` (:func:`_setup_fields`,
    :func:`_conventional_fields`), plain and with the linear control variate
    (:mod:`~stereoplotter.verification.control_variate`), and the error-free run's δp.

    The error-free run once; the linearisation once; the noisy trials in chunks under the memory
    budget (the random draws are keyed by trial, so the chunk size changes no result).
    """

    zero_prep = run.prepared(run.operator.error_free, "zero")
    zero_run = run_trials_chunk(zero_prep, 0, None, evaluate=False, transcript=False)
    if run.procedure == "setup":
        maker, d_zero = _setup_fields(run, zero_run)
    else:
        maker, d_zero = _conventional_fields(run, zero_prep, zero_run)
    prep = run.prepared(run.operator.noisy, None if run.instrument_errors else "zero")
    lin = _linearisation(prep, maker) if run.control_variate else None
    chunk = chunk_trials_for(DEFAULT_MEMORY_BUDGET_MB, run.procedure)
    plain: dict[FieldKey, FloatArray] = {}
    controlled: dict[FieldKey, FloatArray] = {}
    for first in range(0, run.trials, chunk):
        m = min(chunk, run.trials - first)
        part_plain, part_controlled = _chunk_mean_squares(run, prep, maker, lin, first, m)
        for name, v in part_plain.items():
            plain.setdefault(name, np.empty(run.trials))[first : first + m] = v
            if name in part_controlled:
                controlled.setdefault(name, np.empty(run.trials))[first : first + m] = (
                    part_controlled[name]
                )
    return MeanSquares(plain, controlled, d_zero)


def _linearisation(prep: PreparedRun, maker: FieldMaker) -> cvar.LinearControl:
    """The linear control variate of ``maker``'s fields about the run with every random input 0
    (:func:`~stereoplotter.verification.control_variate.linear_control`)."""

    def fields_of(injected: dict[str, Any], noise: Noise, trials: int) -> dict[str, FloatArray]:
        result = run_trials_chunk(
            prep, 0, trials, evaluate=False, transcript=False, injected=injected, noise=noise
        )
        return maker.fields(result, noise)

    return cvar.linear_control(fields_of, prep.model)


def _chunk_mean_squares(
    run: ProcedureRun,
    prep: PreparedRun,
    maker: FieldMaker,
    lin: cvar.LinearControl | None,
    first: int,
    trials: int,
) -> tuple[dict[FieldKey, FloatArray], dict[str, FloatArray]]:
    """Per-trial mean squares of trials ``first … first + trials − 1``: plain (with the
    decomposition's) and controlled (empty without ``lin``)."""
    model = prep.model
    injected = model.draw_keyed(prep.seed, first, first + trials)
    off = run.sources_off
    noise: cvar.RecordingNoise
    part: dict[str, NDArray[np.bool_]] = {}
    if off:
        part = {k: v[first : first + trials] for k, v in off.items()}
        noise = cvar.SourceNoise(prep.seed, trials, first, part)
    else:
        noise = cvar.RecordingNoise(prep.seed, trials, first)
    result = run_trials_chunk(
        prep, first, trials, evaluate=False, transcript=False, injected=injected, noise=noise
    )
    fs = maker.fields(result, noise)
    controlled: dict[str, FloatArray] = {}
    if lin:
        on = _inputs_on(lin, part, trials) if off else None
        controlled = cvar.per_trial_controlled(fs, lin, noise, dict(injected), model, on)
    plain: dict[FieldKey, FloatArray] = {
        name: np.mean(np.asarray(v) ** 2, axis=-1) for name, v in fs.items()
    }
    if maker.decompose is not None:  # already mean squares
        plain.update(maker.decompose(result, fs))
    return plain, controlled


def _inputs_on(
    lin: cvar.LinearControl, off: Mapping[str, NDArray[np.bool_]], trials: int
) -> FloatArray:
    """(K, T): 1 where input k of ``lin`` is drawn on a trial, 0 where its source is off."""
    on = np.ones((len(lin.inputs), trials))
    for j, name in enumerate(lin.inputs):
        kind, _, key = name.partition(":")
        mask = next((m for p, m in off.items() if key.startswith(p)), None)
        if kind == "noise" and mask is not None:
            on[j] = ~mask
    return on


def levelling_formula(
    g: Mapping[str, float],
    x_right_mm: ArrayLike,
    y_mm: ArrayLike,
    grid: tuple[int, int] = (16, 32),
) -> dict[str, float]:
    """The rigorous M_p of the conventional method, (5.54) ⊕ (5.55), with the levelling plane
    fitted at the given control points instead of Fig. 39's x_п ∈ {−c, a}, y = ±c.

    The linear model of (6.60)/(6.61) (relative orientation by least squares on the six standard
    points, the plane's error from control heights with the parallax error m_p) on the chapter-5
    domain, propagated exactly (:func:`~stereoplotter.verification.linear_mc.covariance_rms`).
    ``g``: :func:`scenario_geometry` (a, c, p, f). Returns the coefficients per m_q = m_p:
    "y_parallax" (the (5.54) part), "stereo" (the (5.55) part) and "both" (their quadrature).

    Examples
    --------
    At Fig. 39's own points it is the rigorous (6.60), 0.6862:

    >>> from stereoplotter.accuracy.chapter5 import control_points
    >>> g = {"a": 0.0, "c": 70.0, "p": 70.0, "f": 70.0}
    >>> round(levelling_formula(g, *control_points(0.0, 70.0))["both"], 3)
    0.686
    """

    a, c, p, f = g["a"], g["c"], g["p"], g["f"]
    _, xs, ys = standard_points(a, p, c)
    lsq = np.linalg.pinv(relative_orientation_design(xs, ys, p, f))
    xg, yg = grid_chapter5(c, *grid)
    xc, yc = np.asarray(x_right_mm, float), np.asarray(y_mm, float)
    fit = levelling_design(xg, yg) @ np.linalg.pinv(levelling_design(xc, yc))
    out: dict[str, float] = {}
    for name, sq, sp in (("y_parallax", 1.0, 0.0), ("stereo", 0.0, 1.0), ("both", 1.0, 1.0)):
        model = LinearModel(
            relative_field_basis(xg, yg, p, f),
            lsq * sq,
            relative_field_basis(xc, yc, p, f),
            fit,
            sp,
            0.0,
        )
        out[name] = covariance_rms(model)
    return out


def levelling_points_photo(
    scenario: Scenario, spec: InstrumentSpec, g: Mapping[str, float]
) -> tuple[FloatArray, FloatArray]:
    """(x_п, y) [mm] of the procedure's four levelling points (the scenario's control points
    nearest standard points 3–6, ``conventional.levelling_points``) at the mean photo scale."""

    spec = replace(spec, standard_points_c_mm=g["c"])
    prep = prepare_run(scenario, spec, "conventional", "zero", 0, operator=OperatorModel().zero())
    _, lev = _levelling_frame_points(prep)
    s = g["f"] / g["flying_height_m"]
    return lev[:, 0] * s - g["p"], lev[:, 1] * s


def rms_ci(ms: FloatArray, unit: float) -> tuple[float, float]:
    """(RMS, CI half-width) per ``unit`` from per-trial mean squares (``CI_Z`` s.e.)."""
    mean_ms = float(np.mean(ms))
    rms = math.sqrt(max(mean_ms, 0.0))
    se = float(np.std(ms, ddof=1)) / math.sqrt(len(ms))
    # a mean square at or below zero (a control-variate estimate can be): RMS 0, CI unbounded
    half = CI_Z * se / (2.0 * rms) if rms > 0.0 else math.inf
    return rms / unit, half / unit


def _check_options(method: str, **options: str) -> None:
    if method not in METHODS:
        raise ValueError(f"method: expected one of {METHODS}, found {method!r}")
    allowed = {
        "quantity": ("heights", "parallax"),
        "standard_points": ("book", "nadirs"),
        "datum": ("plane", "slip"),
        "levelling": ("procedure", "book"),
        "sources": SOURCES,
        "control": ("exact", "observed"),
    }
    for name, value in options.items():
        if value not in allowed[name]:
            raise ValueError(f"{name}: expected one of {allowed[name]}, found {value!r}")


def _field_name(method: str, quantity: str, levelling: str, datum: str, control: str) -> str:
    """The field whose mean square is the procedure's statistic."""
    if method == "setup":
        return "parallax"
    if method == "setup_control":
        return "levelled" if control == "exact" else "observed"
    if quantity == "parallax":
        return "parallax"
    return "book" if levelling == "book" else datum


def _formulas(
    method: str,
    scenario: Scenario,
    spec: InstrumentSpec,
    g: Mapping[str, float],
    sources: str,
    control: str,
    levelled: tuple[Mapping[str, float], Mapping[str, float]] | None = None,
) -> dict[str, float]:
    """The rigorous formula at the simulated geometry for the statistic (per its unit).
    ``levelled``: the two :func:`levelling_formula` results (procedure's points, Fig. 39's) if
    already computed."""
    f, p, c, a, n, ll = g["f"], g["p"], g["c"], g["a"], g["n"], g["l"]
    if method == "setup":
        return {
            "rigorous": float(
                sa.setup_parallax_rms_from_pointing(f, p, c, ll, n, 1.0, mode="rigorous")
            )
        }
    if method == "setup_control":
        if control == "exact":  # (6.47)–(6.50) per m_xy
            return {
                "rigorous": float(sa.setup_relative_residual_rms(a, c, f, ll, n, 1.0, "rigorous"))
            }
        # (6.58)/(6.59) per m_p with m_xy = √2 m_p and control parallaxes with m_p
        residual = sa.setup_relative_residual_rms(a, c, f, ll, n, math.sqrt(2.0), "rigorous")
        geodetic = geodetic_orientation_parallax_rms(a, c, p, f, 1.0, "rigorous")
        return {"rigorous": float(math.hypot(residual, geodetic))}
    part = {"both": None, "y_parallax": 0, "stereo": 1}[sources]
    terms = (
        relative_orientation_parallax_rms(a, c, p, 1.0, "rigorous"),
        geodetic_orientation_parallax_rms(a, c, p, f, 1.0, "rigorous"),
    )
    rig = math.hypot(*terms) if part is None else terms[part]
    if levelled is None:
        levelled = (
            levelling_formula(g, *levelling_points_photo(scenario, spec, g)),
            levelling_formula(g, *control_points(a, c)),
        )
    return {
        "rigorous": float(rig),
        "procedure": levelled[0][sources],
        "book": levelled[1][sources],
    }


@dataclass(frozen=True)
class ProcedureOptions:
    """The options of :func:`procedure_mc` (keyword arguments there; defaults as here).

    Attributes
    ----------
    sigma_mm : float
        The operator's σ (photo scale): monocular pointing (setup) or σ_q = σ_p (conventional).
    grid : tuple of int
        Midpoint grid of the statistic (nx, ny).
    quantity : {"heights", "parallax"}
        Conventional only (``docs/accuracy.md``, "The conventional method: levelling, height
        datum and error-free floor"): the
        height read on the slipped height scale in parallax units (what M_p measures) or δp at
        the ideal model position (counts the b_x scale error and the model's datum).
    standard_points : {"book", "nadirs"}
        Conventional only: Fig. 39 at a = c − p (the formula's layout) or a = 0.
    datum : {"plane", "slip"}
        Conventional only: the formula's levelling offset (the four levelling heights, each
        with σ_p) or the procedure's (the height scale slipped at one levelling point).
    levelling : {"procedure", "book"}
        Conventional only: the model as the procedure levelled it (the scenario's four control
        points nearest standard points 3–6) or re-levelled by the least-squares plane through
        its height errors at Fig. 39's x_п ∈ {−c, a}, y = ±c, each observed with σ_p.
    sources : {"both", "y_parallax", "stereo"}
        Conventional only: σ_q = σ_p = σ, σ_q only or σ_p only.
    control : {"exact", "observed"}
        "setup_control" only: exact control heights (per m_xy, (6.47)–(6.50)) or each control
        parallax observed with m_p = m_xy/√2 (per m_p, (6.58)/(6.59)).
    instrument : bool
        Every injected instrument error term of ``spec`` at its configured σ and the real
        mechanics (backlash), besides the operator's σ; the unit stays the operator's.
    control_variate : bool
        The estimator with the linear control variate
        (:mod:`~stereoplotter.verification.control_variate`; unbiased, its CI ≈ 10–40×
        narrower); False: the plain mean.
    passes : int or None
        Every loop makes this many passes (no check ever passes); None: as ``fidelity`` says.
    linkage : {"drag", "independent"} or None
        The knob–decentration linkage (:data:`LINKAGE_VARIANTS`); None: as ``fidelity`` says
        (its None: the instrument's ``correction.decentration_linkage``).
    fidelity : Fidelity or None
        The mechanism switches of the setup-data procedure
        (:mod:`~stereoplotter.procedure.fidelity`); None: the defaults. ``passes`` and
        ``linkage``, where given, override its own.
    """

    sigma_mm: float = 0.01
    grid: tuple[int, int] = (16, 32)
    quantity: str = "heights"
    standard_points: str = "book"
    datum: str = "plane"
    levelling: str = "procedure"
    sources: str = "both"
    control: str = "exact"
    instrument: bool = False
    control_variate: bool = True
    passes: int | None = None
    linkage: str | None = None
    fidelity: Fidelity | None = None

    def switches(self, spec: InstrumentSpec) -> Fidelity:
        """The run's :class:`Fidelity`, ``passes`` and ``linkage`` applied, the linkage
        resolved (:meth:`linkage_of`)."""
        f = self.fidelity or Fidelity()
        passes = f.passes if self.passes is None else self.passes
        return replace(f, passes=passes, linkage=self.linkage_of(spec))

    def linkage_of(self, spec: InstrumentSpec) -> str:
        """The run's knob–decentration linkage: ``linkage``, else the fidelity's, else the
        instrument's ``correction.decentration_linkage``."""
        f = self.fidelity or Fidelity()
        linkage: str = self.linkage or f.linkage or spec.decentration_linkage
        return linkage


def procedure_mc(
    scenario: Scenario,
    method: str = "setup",
    *,
    spec: InstrumentSpec,
    trials: int = 600,
    seed: int = 20240601,
    **options: Any,
) -> RunResult:
    """Run the procedure MC for one scenario and method (see the module docstring).

    ``method`` (:data:`METHODS`): "setup" (§27 task 1: stages 1–5 with the operator's monocular
    pointing σ; δp on the (6.27) domain per m_xy = n_л·σ, (6.39)–(6.44)); "setup_control" (§27
    task 2: the same run levelled on Fig. 39's four control points by the least-squares plane
    through the δp there; the chapter-5 domain); "conventional". ``options``: the fields of
    :class:`ProcedureOptions`. ``scenario`` and ``spec`` (the book's SC-1) are loaded by the
    caller; this layer reads no files.

    Returns
    -------
    dict
        ``coefficient`` (per m_xy, m_p or m_q as above), ``ci`` (half-width), ``plain``
        (coefficient, ci of the plain mean), ``formula`` (``rigorous`` at the simulated
        geometry; conventional also :func:`levelling_formula` at the procedure's levelling
        points, ``procedure``, and at Fig. 39's, ``book``), ``rms_mm``, ``bias_mm`` (RMS δp of
        the error-free run), ``per_trial``, the geometry (f, l, n, f_instrument, p, c, a,
        overlap), ``seconds``; setup methods also ``fields`` (the three readings, each with its
        ``decomposition``, :mod:`.decomposition`), conventional ``by_datum`` and the options.

    Examples
    --------
    >>> from stereoplotter.io.paths import data_dir
    >>> from stereoplotter.io.scenario_file import load_scenario
    >>> from stereoplotter.io.instrument_file import load_instrument
    >>> sc = load_scenario(data_dir("scenarios") / "pair60.yaml")
    >>> r = procedure_mc(sc, "setup", spec=load_instrument("sc1"), trials=20, seed=1)
    >>> 0.3 < r["coefficient"] < 3.0
    True
    """
    t0 = time.perf_counter()
    o = ProcedureOptions(**options)
    _check_options(
        method,
        **{k: getattr(o, k) for k in ("quantity", "standard_points", "datum", "levelling")},
        **{k: getattr(o, k) for k in ("sources", "control")},
    )
    g = scenario_geometry(scenario, spec)
    linkage = o.linkage_of(spec)
    runs = run_configuration(scenario, spec, method, trials, seed, o, g, linkage)
    out = _result(scenario, spec, method, o, g, linkage, runs)
    return {**out, "trials": int(trials), "seed": int(seed), "seconds": time.perf_counter() - t0}


def _result(
    scenario: Scenario,
    spec: InstrumentSpec,
    method: str,
    o: ProcedureOptions,
    g: dict[str, float],
    linkage: str,
    runs: ConfigurationRun,
    formulas: dict[str, float] | None = None,
) -> RunResult:
    """The result of :func:`procedure_mc` from the per-trial mean squares of its run(s)."""
    plain, controlled, d_zero, units = runs
    name = _field_name(method, o.quantity, o.levelling, o.datum, o.control)
    best = controlled or plain
    unit = units[name]
    coefficient, ci = rms_ci(best[name], unit)
    if formulas is None:
        formulas = _formulas(method, scenario, spec, g, o.sources, o.control)
    out = {
        **_extras(scenario, spec, method, o, g, plain, best, units),
        "method": method,
        "scenario": scenario.name,
        "sigma_mm": o.sigma_mm,
        "instrument": bool(o.instrument),
        "instrument_key": spec.key,
        "linkage": linkage,
        "fidelity": o.switches(spec),
        "control_variate": bool(controlled),
        "coefficient": coefficient,
        "ci": ci,
        "plain": rms_ci(plain[name], unit),
        "formula": formulas,
        "rms_mm": coefficient * unit,
        "bias_mm": float(np.sqrt(np.mean(d_zero**2))),
        "per_trial": np.sqrt(plain[name]) / unit,
    }
    return {**out, **g}


#: Key prefixes of the acts of each judgment source of the conventional method (σ_q: the
#: y-parallax judgments ``q/…``; σ_p: the stereo judgments ``stereo/…`` and the observed
#: levelling heights ``mc/datum/…``, ``mc/book/…`` of :func:`_conventional_fields`).
SOURCE_PREFIXES = {"y_parallax": ("q/",), "stereo": ("stereo/", "mc/datum/", "mc/book/")}


def conventional_sources_mc(
    scenario: Scenario,
    *,
    spec: InstrumentSpec,
    trials: dict[str, int],
    seed: int = 20240601,
    **options: Any,
) -> dict[str, RunResult]:
    """:func:`procedure_mc` of the conventional method for several ``sources`` at once, as one
    run: ``trials`` maps a source (:data:`SOURCES`) to its trials, laid out in blocks of one run
    with σ_q = σ_p = σ whose acts of the sources a block leaves out draw 0 on its trials
    (:class:`~stereoplotter.verification.control_variate.SourceNoise`). A block's trials are those
    of a run with only its sources on (the draws keyed by trial: block b holds trials
    first_b … first_b + T_b − 1 of ``seed``), so each result is that of ``procedure_mc`` on those
    trials; the error-free run, the linearisation and the procedure's per-act overhead are shared.
    Returns source → result (as :func:`procedure_mc`; ``first_trial`` its block's start).
    """
    t0 = time.perf_counter()
    if "sources" in options:
        raise ValueError("sources: given by the keys of trials")
    unknown = set(trials) - set(SOURCES)
    if unknown:
        raise ValueError(f"trials: expected sources among {SOURCES}, found {sorted(unknown)}")
    o = ProcedureOptions(**options)
    _check_options("conventional", **{k: getattr(o, k) for k in ("quantity", "standard_points")})
    g = scenario_geometry(scenario, spec)
    linkage = o.linkage_of(spec)
    names = list(trials)
    bounds = np.cumsum([0] + [int(trials[k]) for k in names])
    off_of = {
        prefix: np.concatenate([np.full(int(trials[k]), k not in ("both", src)) for k in names])
        for src, prefixes in SOURCE_PREFIXES.items()
        for prefix in prefixes
    }
    plain, controlled, d_zero, units = run_configuration(
        scenario, spec, "conventional", int(bounds[-1]), seed, o, g, linkage, off_of
    )
    lev = levelling_formula(g, *levelling_points_photo(scenario, spec, g))
    book = levelling_formula(g, *control_points(g["a"], g["c"]))
    out: dict[str, RunResult] = {}
    for k, first, last in zip(names, bounds[:-1], bounds[1:], strict=True):
        ok = replace(o, sources=k)
        plain_k, controlled_k = (
            {n: v[first:last] for n, v in d.items()} for d in (plain, controlled)
        )
        formulas = _formulas("conventional", scenario, spec, g, k, o.control, (lev, book))
        runs = ConfigurationRun(plain_k, controlled_k, d_zero, units)
        res = _result(scenario, spec, "conventional", ok, g, linkage, runs, formulas)
        out[k] = {**res, "trials": int(last - first), "seed": int(seed), "first_trial": int(first)}
    seconds = time.perf_counter() - t0
    return {k: {**v, "seconds": seconds} for k, v in out.items()}


class ConfigurationRun(NamedTuple):
    """The runs of one configuration (:func:`run_configuration`): per-trial mean squares
    (``plain``, ``controlled``; :class:`MeanSquares`), the error-free δp and the unit of each
    field [photo mm]."""

    plain: dict[FieldKey, FloatArray]
    controlled: dict[FieldKey, FloatArray]
    error_free_dp: FloatArray
    units: dict[str, float]


def run_configuration(
    scenario: Scenario,
    spec: InstrumentSpec,
    method: str,
    trials: int,
    seed: int,
    options: ProcedureOptions,
    geometry: dict[str, float],
    linkage: str,
    sources_off: Mapping[str, NDArray[np.bool_]] | None = None,
) -> ConfigurationRun:
    """The runs of :func:`procedure_mc` with ``options`` at ``geometry``
    (:func:`scenario_geometry`) and ``linkage`` (resolved: "drag" or "independent").
    ``sources_off``: key prefix → (trials,) mask of the trials whose acts of that prefix draw 0
    (:func:`conventional_sources_mc`; the run then has every source on)."""
    sources = "both" if sources_off else options.sources
    c, p, n = geometry["c"], geometry["p"], geometry["n"]
    operator = _configuration(method, options.sigma_mm, c, p, n, sources)
    unit = operator.unit_mm
    if method == "conventional":
        units = dict.fromkeys(("parallax", "slip", "plane", "book"), unit)
        sigma_control = 0.0
    else:  # m_p = m_xy/√2 of the observed control parallaxes
        units = {"parallax": unit, "levelled": unit, "observed": unit / math.sqrt(2.0)}
        sigma_control = units["observed"]
    run = ProcedureRun(
        scenario=scenario,
        spec=replace(spec, standard_points_c_mm=c),
        method=method,
        seed=seed,
        trials=int(trials),
        operator=operator,
        geometry=geometry,
        grid=options.grid,
        variant=LINKAGE_VARIANTS[linkage],
        fidelity=options.switches(spec),
        instrument_errors=bool(options.instrument),
        control_variate=options.control_variate,
        standard_points_at_a=method == "conventional" and options.standard_points == "book",
        sigma_control_mm=sigma_control,
        sources_off=sources_off,
    )
    ms = mean_squares(run)
    return ConfigurationRun(ms.plain, ms.controlled, ms.error_free_dp, units)


def _keyed(ms: Mapping[FieldKey, FloatArray], kind: str) -> list[tuple[str, FloatArray]]:
    """(name, values) of the items of ``ms`` whose key is a tuple (``kind``, name)."""
    return [(k[1], v) for k, v in ms.items() if isinstance(k, tuple) and k[0] == kind]


def _extras(
    scenario: Scenario,
    spec: InstrumentSpec,
    method: str,
    o: ProcedureOptions,
    g: dict[str, float],
    plain: Mapping[FieldKey, FloatArray],
    best: Mapping[FieldKey, FloatArray],
    units: Mapping[str, float],
) -> dict[str, Any]:
    """The method's own parts of the result: the three readings of a setup run with their
    decompositions, or the conventional run's readings by datum and its options."""
    if method == "conventional":
        unit = units["plane"]
        return {
            "by_datum": {k: rms_ci(best[k], unit) for k in ("parallax", "slip", "plane", "book")},
            **{k: getattr(o, k) for k in ("quantity", "standard_points", "datum", "levelling")},
            "sources": o.sources,
        }
    fields: dict[str, dict[str, Any]] = {}
    for key, m, c in (
        ("parallax", "setup", "exact"),
        ("levelled", "setup_control", "exact"),
        ("observed", "setup_control", "observed"),
    ):
        cf, h = rms_ci(best[key], units[key])
        ref = _formulas(m, scenario, spec, g, o.sources, c)["rigorous"]
        ms = {s: plain[(key, s)] for s, _ in dc.LEVELS}
        fields[key] = {
            "coefficient": cf,
            "ci": h,
            "plain": rms_ci(plain[key], units[key]),
            "formula": ref,
            "decomposition": dc.rms_steps(ref, {**ms, "procedure": plain[key]}, units[key]),
            "mean_squares": plain[key],  # per trial, photo mm² (paired switch steps)
            "unit": units[key],
        }
    extra: dict[str, Any] = {"fields": fields}
    extra["element_rms"] = {
        name: float(np.sqrt(np.mean(v))) for name, v in _keyed(plain, "element")
    }
    if method == "setup_control":
        extra["control"] = o.control
    return extra


# --------------------------------------------------------------------------------------------
# The conventional relative orientation alone against (5.54)
# --------------------------------------------------------------------------------------------


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
