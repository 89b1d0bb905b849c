"""Run a whole procedure on a virtual instrument (one procedure, or T trials at once).

:func:`simulate` builds the setup sheet, the instrument (with injected errors drawn from the
seed), the operator and the scene, runs the setup-data method (stages 1–5) or the conventional
method, vectorised over ``trials`` on the closed-form back-end, and evaluates the model.
:func:`simulate_per_trial` is the test oracle: the same procedure one trial at a time.
:mod:`stereoplotter.report.simulation` writes the files; :mod:`stereoplotter.procedure.trials`
runs long runs in chunks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any, cast

import numpy as np

from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.error_model import ErrorModel, error_model_from_spec
from stereoplotter.instrument.sc1_complex import (
    ErrorCorrectionUnit,
    SC1Options,
)
from stereoplotter.instrument.virtual import Instrument
from stereoplotter.procedure.conventional import run_conventional_method
from stereoplotter.procedure.evaluation import ModelEvaluation, ModelTruth, evaluate_against
from stereoplotter.procedure.fidelity import Fidelity
from stereoplotter.procedure.operator import Noise, OperatorModel, Scene
from stereoplotter.procedure.records import Check, Remedy, SheetPose, StageRecord
from stereoplotter.procedure.run import (
    GRID_SHAPE,
    PRACTICES,
    PreparedRun,
    Run,
    build_run,
    prepare_pair,
    residual_grid_m,
)
from stereoplotter.procedure.setup_method import run_setup_method
from stereoplotter.procedure.transcript import Transcript
from stereoplotter.scenario.model import Scenario
from stereoplotter.setup.sheet import SetupSheet
from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = [
    "GRID_SHAPE",
    "METHODS",
    "PreparedRun",
    "SimulationResult",
    "prepare_pair",
    "prepare_run",
    "residual_grid_m",
    "run_trials_chunk",
    "simulate",
    "simulate_per_trial",
]

METHODS = ("setup", "conventional")


@dataclass
class SimulationResult:
    """What a simulated run returns.

    Attributes
    ----------
    method, backend : str
    seed : int
    trials : int or None
    sheet : SetupSheet
    transcript : Transcript
        Trial 0 of the run.
    checks : dict
        Check name → :class:`~stereoplotter.procedure.records.Check` (arrays over trials).
    stages : dict
        Stage → :class:`~stereoplotter.procedure.records.StageRecord` (iterations used);
        :attr:`iterations` gives the arrays by stage.
    zero_readings : dict
        The zero readings the operator determined.
    q_standard_mm, q_grid_mm : ndarray
        True residual y-parallax at the six standard points and over the working-area grid
        of the final model, shape (T, 6) / (T, g) or (6,) / (g,). [mm]
    evaluation : ModelEvaluation or None
        The built model against the ground truth (:func:`evaluate_model`), None if not asked.
    instrument : Instrument
    scene : Scene
    operator_model : OperatorModel
    sheet_pose : SheetPose or None
        Stages 4–5: the sheet's placement on the coordinatograph.
    first_trial : int
        Index of the first trial of this result in the whole run (chunked runs).
    practice : {"operator", "book"}
        Remedies after a failed check ("operator") or none (§27 task 1, "book").
    remedies : dict
        Remedy name → :class:`~stereoplotter.procedure.records.Remedy` (operator practice).
    fidelity : Fidelity
        The mechanism switches the run used (:mod:`~stereoplotter.procedure.fidelity`).
    """

    method: str
    backend: str
    seed: int
    trials: int | None
    sheet: SetupSheet
    transcript: Transcript
    checks: dict[str, Check]
    stages: dict[str, StageRecord]
    zero_readings: dict[str, Any]
    q_standard_mm: np.ndarray
    q_grid_mm: np.ndarray
    evaluation: ModelEvaluation | None
    instrument: Instrument
    scene: Scene
    operator_model: OperatorModel
    sheet_pose: SheetPose | None = None
    first_trial: int = 0
    practice: str = "book"
    remedies: dict[str, Remedy] = field(default_factory=dict)
    fidelity: Fidelity = field(default_factory=Fidelity)

    @property
    def iterations(self) -> dict[str, np.ndarray]:
        """Stage → iterations used (arrays over the trials)."""
        return {name: s.iterations for name, s in self.stages.items()}


def _errors(spec: InstrumentSpec, errors: ErrorModel | str | None) -> ErrorModel:
    if errors is None:
        return error_model_from_spec(spec)
    if isinstance(errors, ErrorModel):
        return errors
    if errors == "zero":
        return error_model_from_spec(spec).zero()
    raise StereoplotterError(
        f"errors: expected an ErrorModel, 'zero' or None, found {errors!r} (an errors file is "
        "read by stereoplotter.io.errors_file.load_error_model)"
    )


def apply_correction_unit(
    scenario: Scenario,
    spec: InstrumentSpec,
    operator: OperatorModel,
    unit: ErrorCorrectionUnit | None = None,
) -> tuple[Scenario, OperatorModel]:
    """The SC complex's off-line error-correction unit on a scenario's photos (SC-1 option).

    The unit takes out the systematic image errors — here the scenario's film deformation, the
    only systematic image error a scenario carries — after checking them against its documented
    ±100 µm at the format corner (|s|·10⁻⁶·format/2 per axis; a larger error is refused like a
    stop), and leaves a residual of 3 µm vector RMS (documented) per image point. The residual is
    taken as independent from point to point and from pointing to pointing (ASSUMED: no data on
    its spatial correlation), i.e. added in quadrature to the operator's σ: σ_c per coordinate
    on a monocular pointing, √2·σ_c on an x- or y-parallax (two images).

    ``unit``: the unit as read from ``spec`` (:meth:`ErrorCorrectionUnit.from_spec`), if the
    caller has it already.

    Returns
    -------
    (Scenario, OperatorModel)
        The scenario with the film deformation corrected; the operator with the residual added.
    """
    unit = ErrorCorrectionUnit.from_spec(spec) if unit is None else unit
    operator = operator.for_instrument(spec)  # the eye's σ_p, σ_q where not given
    half_format_um = 0.5 * float(scenario.camera.format_mm) * 1000.0
    for photo in scenario.photos:
        unit.check_input_um(np.asarray(photo.film_deformation_ppm, float) * 1e-6 * half_format_um)
    photos = tuple(replace(p, film_deformation_ppm=(0.0, 0.0)) for p in scenario.photos)
    sc_mm = unit.residual_sigma_um / 1000.0

    def plus(sigma_mm: float | None, k: float) -> float:  # σ resolved for the instrument
        return float(np.hypot(cast(float, sigma_mm), np.sqrt(k) * sc_mm))

    model = replace(
        operator,
        monocular_sigma_mm=plus(operator.monocular_sigma_mm, 1.0),
        stereo_sigma_mm=plus(operator.stereo_sigma_mm, 2.0),
        y_parallax_sigma_mm=plus(operator.y_parallax_sigma_mm, 2.0),
    )
    return replace(scenario, photos=photos), model


def prepare_run(
    scenario: Scenario,
    spec: InstrumentSpec,
    method: str = "setup",
    errors: ErrorModel | str | None = None,
    seed: int = 0,
    backend: str = "closed-form",
    *,
    operator: OperatorModel | None = None,
    ideal_mechanics: bool = False,
    variant: str = "L",
    relative: str = "elements",
    practice: str = "operator",
    options: SC1Options | None = None,
    fidelity: Fidelity | None = None,
) -> PreparedRun:
    """The fixed part of a run (arguments as :func:`simulate`).

    Everything a run's trials share is computed here, once: the SC complex's options checked
    against the instrument file, the setup sheet with its range checks, the scene (true
    fiducials, standard points), the floor of the mechanism and the residual grid
    (:func:`prepare_pair`). The trials see the :class:`PreparedRun`, never recompute it.
    """
    options = SC1Options() if options is None else options.fitted_to(spec)
    # the eye's σ_p, σ_q for this instrument's observation system (procedure.eye)
    operator = (OperatorModel() if operator is None else operator).for_instrument(spec)
    unit = ErrorCorrectionUnit.from_spec(spec) if options.error_correction_unit else None
    if unit is not None:
        scenario, operator = apply_correction_unit(scenario, spec, operator, unit)
    if method not in METHODS:
        raise StereoplotterError(f"method: expected one of {', '.join(METHODS)}, found {method!r}")
    if practice not in PRACTICES:
        raise StereoplotterError(
            f"practice: expected one of {', '.join(PRACTICES)}, found {practice!r}"
        )
    fidelity = Fidelity() if fidelity is None else fidelity
    variant = fidelity.variant(variant)
    pair = prepare_pair(scenario, spec, method, variant)
    sheet, operator = _with_passes(pair.sheet, operator, fidelity.passes)
    if fidelity.bottom_stop == "free":  # the sheet as computed, the carriage without its stop
        low, high = spec.projection_distance_range_mm
        spec = replace(spec, projection_distance_range_mm=(low, high + FREE_STOP_MM))
    return PreparedRun(
        scenario,
        spec,
        method,
        sheet,
        _errors(spec, errors),
        operator,
        pair.scene,
        int(seed),
        backend,
        ideal_mechanics,
        variant,
        relative,
        practice,
        options,
        pair.grid_m,
        unit,
        pair.grid_images_mm,
        pair.truth,
        pair.heights,
        pair.level,
        fidelity,
    )


#: ``bottom_stop="free"``: the carriage's bottom stop moved this far below D_max (the sheet
#: keeps D_max): far beyond any correction of the stage-1 L-check (≈ 0.1 mm). [mm]
FREE_STOP_MM = 20.0


def _with_passes(
    sheet: SetupSheet, operator: OperatorModel, passes: int | None
) -> tuple[SetupSheet, OperatorModel]:
    """Switch ``passes`` (:mod:`~stereoplotter.procedure.fidelity`): every tolerance loop makes
    ``passes`` passes — no check ever passes (its tolerance −∞, so the checks report failed)
    and ``max_iterations`` = ``passes``; None: the sheet and operator as they are."""
    if passes is None:
        return sheet, operator
    never = dict.fromkeys(sheet.tolerances, -math.inf)
    return replace(sheet, tolerances=never), replace(operator, max_iterations=int(passes))


def _run_one(
    prep: PreparedRun,
    injected: dict[str, Any] | None,
    trials: int | None,
    noise: Noise | None,
    transcript: bool = True,
    first: int = 0,
) -> tuple[Run, Any, Any]:
    """Trials ``first … first + trials − 1`` of ``prep`` (the keyed draws where ``injected``,
    ``noise`` are None: :func:`~stereoplotter.procedure.run.build_run`), with the true residual
    y-parallax at the standard points and over the grid."""
    run = build_run(prep, first, trials, injected=injected, noise=noise, transcript=transcript)
    op = run.op
    if prep.method == "setup":
        run_setup_method(run)
    else:
        run_conventional_method(run, prep.relative)
    scene = prep.scene
    q_std = op.y_parallax(scene.standard_points_m, cast(Any, scene.standard))
    q_grid = op.y_parallax(cast(Any, prep.grid_m), cast(Any, prep.grid_images_mm))
    return run, q_std, q_grid


def run_trials_chunk(
    prep: PreparedRun,
    first_trial: int = 0,
    trials: int | None = None,
    *,
    evaluate: bool = True,
    transcript: bool = True,
    injected: dict[str, Any] | None = None,
    noise: Noise | None = None,
) -> SimulationResult:
    """Trials ``first_trial … first_trial + trials − 1`` of the run (one trial for None).

    Every random draw is keyed by the trial index (:mod:`stereoplotter.random_streams`), so
    trial t gives the same result in whichever chunk it runs. ``injected`` (arrays (T,) per
    error term) and ``noise`` (a :class:`Noise`) replace the keyed draws of the instrument and
    the operator: designed runs such as the error budget (``verification.budget``).
    """
    if prep.backend == "pymunk" and trials is not None:
        raise StereoplotterError(
            "the pymunk back-end runs single procedures; use --backend closed-form for --trials"
        )
    run, q_std, q_grid = _run_one(prep, injected, trials, noise, transcript, first_trial)
    evaluation = _evaluate(prep, run) if evaluate else None
    return SimulationResult(
        prep.method,
        prep.backend,
        prep.seed,
        trials,
        prep.sheet,
        run.op.log,
        run.results,
        run.stages,
        run.zero,
        q_std,
        q_grid,
        evaluation,
        run.op.inst,
        prep.scene,
        prep.operator,
        run.sheet_pose,
        first_trial,
        run.practice,
        run.remedies,
        prep.fidelity,
    )


def simulate(
    scenario: Scenario,
    spec: InstrumentSpec,
    method: str = "setup",
    errors: ErrorModel | str | None = None,
    seed: int = 0,
    trials: int | None = None,
    backend: str = "closed-form",
    *,
    operator: OperatorModel | None = None,
    ideal_mechanics: bool = False,
    variant: str = "L",
    evaluate: bool = True,
    relative: str = "elements",
    first_trial: int = 0,
    practice: str = "operator",
    options: SC1Options | None = None,
    fidelity: Fidelity | None = None,
) -> SimulationResult:
    """Run the setup-data or the conventional method on a virtual instrument.

    Parameters
    ----------
    scenario : Scenario
    spec : InstrumentSpec
    method : {"setup", "conventional"}
    errors : ErrorModel, "zero" or None
        Injected instrument errors; None: the instrument's defaults; "zero": none (an errors
        file: :func:`stereoplotter.io.errors_file.load_error_model`).
    seed : int
        Seeds the injected errors and every judgment of the operator.
    trials : int, optional
        T independent instruments and operators at once (closed-form back-end), all in memory:
        for long runs use :func:`stereoplotter.procedure.trials.iter_trial_chunks`.
    backend : {"closed-form", "pymunk"}
    operator : OperatorModel, optional
        Default: :class:`OperatorModel` defaults (assumed).
    ideal_mechanics : bool
        Rigid screws without backlash.
    variant : str
        Decentration linkage variant of the instrument ("L" canonical).
    evaluate : bool
        Evaluate the built model against the ground truth (:func:`evaluate_model`).
    relative : {"elements", "equations"}
        Conventional method only: relative orientation element by element with over-correction,
        or by the six measured q and (5.11).
    first_trial : int
        Index of the first trial in a longer run (a chunk of it); a single run is that trial.
    practice : {"operator", "book"}
        "operator" (default): after a failed check the operator applies the book's remedies
        (repeat the stage-1 setting, refine the relative orientation, refine the scaling on the
        control heights), bounded and logged; "book": §27's task 1, no remedy. Both methods
        (the conventional method's remedies CR1, CR2: ``docs/procedure.md``).
    options : SC1Options, optional
        The SC complex's options on the SC-1 (off by default): the error-correction unit
        (:func:`apply_correction_unit`) and the automatic coordinatograph (stages 4–5).
    fidelity : Fidelity, optional
        The mechanism switches (:mod:`~stereoplotter.procedure.fidelity`); default: the
        competent operator's.

    Returns
    -------
    SimulationResult
    """
    prep = prepare_run(
        scenario,
        spec,
        method,
        errors,
        seed,
        backend,
        operator=operator,
        ideal_mechanics=ideal_mechanics,
        variant=variant,
        relative=relative,
        practice=practice,
        options=options,
        fidelity=fidelity,
    )
    return run_trials_chunk(prep, first_trial, trials, evaluate=evaluate)


def simulate_per_trial(
    scenario: Scenario,
    spec: InstrumentSpec,
    method: str = "setup",
    errors: ErrorModel | str | None = None,
    seed: int = 0,
    trials: int = 2,
    *,
    operator: OperatorModel | None = None,
    ideal_mechanics: bool = False,
    variant: str = "L",
    relative: str = "elements",
    practice: str = "operator",
) -> dict[str, Any]:
    """The test oracle: trial t of ``simulate(..., trials=T)`` run alone, for t = 0 … T−1.

    Returns the checks (:class:`Check` with fields stacked over the trials), iterations, zero
    readings and q arrays stacked over the trials (no evaluation, no transcript).
    """
    prep = prepare_run(
        scenario,
        spec,
        method,
        errors,
        seed,
        operator=operator,
        ideal_mechanics=ideal_mechanics,
        variant=variant,
        relative=relative,
        practice=practice,
    )
    rows = []
    for t in range(trials):
        injected = prep.model.draw_keyed(seed, t)
        noise = Noise(seed, trials, t)
        rows.append(_run_one(prep, injected, None, noise, transcript=False))
    out: dict[str, Any] = {"checks": {}, "iterations": {}, "zero_readings": {}}
    first = rows[0][0]
    for name, c in first.results.items():

        def stacked(attr: str, name: str = name, c: Check = c) -> Any:
            if getattr(c, attr) is None:
                return None
            return np.array([getattr(r[0].results[name], attr) for r in rows])

        out["checks"][name] = Check(
            name,
            stacked("residual"),
            stacked("tolerance"),
            stacked("passed"),
            stacked("iterations"),
            c.unit,
        )
    for name in first.stages:
        out["iterations"][name] = np.array([r[0].stage_iterations(name) for r in rows])
    for name in first.zero:
        out["zero_readings"][name] = np.array([r[0].zero[name] for r in rows])
    out["q_standard_mm"] = np.array([r[1] for r in rows])
    out["q_grid_mm"] = np.array([r[2] for r in rows])
    return out


def _evaluate(prep: PreparedRun, run: Run) -> ModelEvaluation:
    """The built model of ``run`` against the ground truth, on the prepared run's grid."""
    sheet = prep.sheet
    inst = run.op.inst
    state = inst.state()
    units = state["units"]
    # the metre height scale as the operator slipped it, at D = 0 [m]
    zero = (
        np.asarray(inst.read("H", exact=True))
        + np.asarray(state["carriages_mm"]["Z"]) * sheet.vertical_scale_denominator / 1000.0
    )
    corner = run.results.get("stage 5: corner 4")
    return evaluate_against(
        cast(ModelTruth, prep.truth),  # prepared for an evaluated run
        inst.setting,
        units["left"],
        units["right"],
        height_zero=zero,
        corner4_misclosure_mm=None if corner is None else corner.residual,
    )
