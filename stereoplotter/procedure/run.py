"""The run assembler: one place where a procedure's instrument, operator and :class:`Run` are
put together from a prepared run.

:func:`build_run` is used by every caller that runs the simulated operator —
:mod:`~stereoplotter.procedure.simulate` (and through it ``budget`` and the procedure Monte
Carlo), :mod:`~stereoplotter.verification.procedure_mc`, the trainer's demonstration
(:mod:`~stereoplotter.trainer.operator_steps`) and its grading population
(:mod:`~stereoplotter.trainer.grading`); :func:`build_instrument` is its instrument alone (a
trainee's session drives it by hand). ``tests/procedure/test_run_assembler.py`` checks that no
other module builds a :class:`Run` or an :class:`~stereoplotter.instrument.virtual.Instrument`.

:class:`PreparedRun` is what a run fixes before its trials (built once by
:func:`stereoplotter.procedure.simulate.prepare_run`), its stereopair part the
:class:`PreparedPair` of :func:`prepare_pair`; :class:`Run` is what a procedure works on and what
it found.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.instrument.decentration_variants import decentration_variant
from stereoplotter.instrument.error_model import ErrorModel
from stereoplotter.instrument.principles import mechanism_for
from stereoplotter.instrument.sc1_complex import (
    AutomaticCoordinatograph,
    ErrorCorrectionUnit,
    SC1Options,
)
from stereoplotter.instrument.virtual import Instrument
from stereoplotter.procedure.evaluation import ModelTruth, model_truth
from stereoplotter.procedure.fidelity import Fidelity
from stereoplotter.procedure.floor import (
    ControlHeights,
    control_heights_of,
    refuse_beyond_mechanism,
)
from stereoplotter.procedure.levelling import LevelDesign, level_design
from stereoplotter.procedure.operator import Noise, Operator, OperatorModel, Scene
from stereoplotter.procedure.records import Check, Remedy, SheetPose, SheetReadings, StageRecord
from stereoplotter.procedure.transcript import Transcript
from stereoplotter.scenario.model import Scenario
from stereoplotter.scenario.synthetic import working_area_grid_m
from stereoplotter.setup.sheet import SetupSheet, compute_setup_sheet
from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = [
    "GRID_SHAPE",
    "PRACTICES",
    "PreparedPair",
    "PreparedRun",
    "Run",
    "build_instrument",
    "build_run",
    "log_options",
    "prepare_pair",
    "residual_grid_m",
]

#: ``--practice``: "operator" applies the remedies after a failed check (the operator's
#: practice; §26 intro: the set orientation "most often is not accurate enough and its
#: correction takes additional time"); "book" is §27's task 1 (the elements are set, each once
#: by the stage text, and not refined: a failed check is recorded and the operator goes on).
PRACTICES = ("operator", "book")


@dataclass
class Run:
    """Everything a procedure works on, and what it found.

    Attributes
    ----------
    op : Operator
    sheet : SetupSheet
    scene : Scene
    zero : dict
        Zero readings the operator has determined, by the sheet's names (MO_X, MO_Y, MO_X,п,
        MO_Y,п, MO_by, MO_bz, MO_Z), arrays over the trials. [mm, m for MO_Z]
    results : dict
        Check name → :class:`~stereoplotter.procedure.records.Check`.
    stages : dict
        Stage → :class:`~stereoplotter.procedure.records.StageRecord` (iterations used).
    sheet_pose : SheetPose or None
        Stages 4–5: the sheet on the coordinatograph (None without a map sheet).
    practice : {"book", "operator"}
        :data:`PRACTICES`: remedies after a failed check only with "operator".
    remedies : dict
        Remedy name → :class:`~stereoplotter.procedure.records.Remedy` (operator practice).
    readings : SheetReadings
        The sheet's printed readings: every target reading the operator sets comes from here.
    heights : ControlHeights or None
        The sheet's height control points with their ground points and true images (prepared
        once per run, :func:`prepare_pair`).
    level : LevelDesign or None
        Remedy R3's levelling design at the sheet's own settings (setup-data method; prepared
        once per run).
    fidelity : Fidelity
        The mechanism switches (:mod:`~stereoplotter.procedure.fidelity`).
    calibration : Calibration or None
        The conventional method's calibration of the instrument's response
        (:class:`~stereoplotter.procedure.conventional.Calibration`, found after C1; None
        otherwise).
    """

    op: Operator
    sheet: SetupSheet
    scene: Scene
    zero: dict[str, NDArray[np.float64]] = field(default_factory=dict)
    results: dict[str, Check] = field(default_factory=dict)
    stages: dict[str, StageRecord] = field(default_factory=dict)
    sheet_pose: SheetPose | None = None
    practice: str = "book"
    remedies: dict[str, Remedy] = field(default_factory=dict)
    heights: ControlHeights | None = None
    level: LevelDesign | None = None
    fidelity: Fidelity = field(default_factory=Fidelity)
    calibration: Any = None
    readings: SheetReadings = field(init=False)

    def __post_init__(self) -> None:
        self.readings = SheetReadings.of(self.sheet)

    def check(
        self,
        name: str,
        residual: ArrayLike,
        tolerance: ArrayLike | None,
        unit: str = "mm",
        iterations: ArrayLike | None = None,
    ) -> NDArray[np.bool_]:
        """Record a tolerance check (|residual| ≤ tolerance) and return pass/fail per trial."""
        residual = self.op.v(residual)
        tol = self.op.v(tolerance) if tolerance is not None else None
        passed = np.abs(residual) <= tol if tol is not None else None
        its = None if iterations is None else self.op.v(iterations).astype(int)
        self.results[name] = Check(name, residual, tol, passed, its, unit)
        return cast(NDArray[np.bool_], passed)  # None only for a check without a tolerance

    @property
    def remedial(self) -> bool:
        """The operator's practice: remedies after a failed check."""
        return self.practice == "operator"

    def record_remedy(self, name: str, check: str, applied: ArrayLike, rounds: ArrayLike) -> None:
        """Record a remedy against the final state of ``check``."""
        applied = self.op.v(applied).astype(bool)
        passed = self.results[check].passed
        self.remedies[name] = Remedy(
            name,
            check,
            applied,
            self.op.v(rounds).astype(int),
            self.op.v(cast(ArrayLike, passed)).astype(bool),
        )

    def record_stage(self, stage: str, iterations: ArrayLike) -> None:
        """Record the iterations a stage (or loop) used, per trial."""
        self.stages[stage] = StageRecord(stage, np.asarray(iterations).astype(int))

    def stage_iterations(self, stage: str) -> NDArray[np.int64]:
        """The iterations recorded for ``stage``."""
        return self.stages[stage].iterations

    def target(self, reading: str, zero: ArrayLike | None = None) -> Any:
        """The sheet's reading ``reading`` as set: its zero reading + the printed value.

        ``zero`` defaults to the zero reading the operator has determined (``self.zero``, by
        the sheet's name); the instrument's nominal zero places (MO_bx, MO_dx, MO_dy) are
        passed by the caller.
        """
        r = self.readings[reading]
        if r.zero_reading and zero is None:
            zero = self.zero[r.zero_reading]
        return r.target(zero)


@dataclass(frozen=True)
class PreparedRun:
    """Everything a run fixes before its trials: sheet, error model, operator, scene (with the
    true fiducials and the standard points), options and the evaluation grid.

    Built once by :func:`prepare_run`; :func:`run_trials_chunk` runs any range of trials on it,
    so a long run in chunks computes the sheet and the scene once.
    """

    scenario: Scenario
    spec: InstrumentSpec
    method: str
    sheet: SetupSheet
    model: ErrorModel
    operator: OperatorModel
    scene: Scene
    seed: int
    backend: str = "closed-form"
    ideal_mechanics: bool = False
    variant: str = "L"
    relative: str = "elements"
    practice: str = "operator"
    options: SC1Options = field(default_factory=SC1Options)
    #: The working-area grid where the true residual y-parallax is evaluated (local frame),
    #: computed once per run (:func:`residual_grid_m`). [m]
    grid_m: NDArray[np.float64] | None = None
    #: The SC complex's error-correction unit as the instrument file documents it (read once per
    #: run; None without the option).
    correction_unit: ErrorCorrectionUnit | None = None
    #: The true images of ``grid_m`` on the left and right photo (read-only), once per run. [mm]
    grid_images_mm: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None
    #: The ground truth the built model is evaluated against (points, frame, images), once per
    #: run (:func:`~stereoplotter.procedure.evaluation.model_truth`; None: not prepared).
    truth: ModelTruth | None = None
    #: The sheet's height control points with their ground points and true images, once per
    #: run (None: not prepared).
    heights: ControlHeights | None = None
    #: Remedy R3's levelling design at the sheet's own settings, once per run (setup-data
    #: method; None for the conventional method).
    level: LevelDesign | None = None
    #: The mechanism switches of the procedure (:mod:`~stereoplotter.procedure.fidelity`).
    fidelity: Fidelity = field(default_factory=Fidelity)


@dataclass(frozen=True)
class PreparedPair:
    """The stereopair as a run needs it, built once (:func:`prepare_pair`): the setup sheet (its
    frame S_л, θ; Table 24; every range check of the sheet passed), the scene (the photos, the
    control points, true fiducials, the six standard points and their true images, the
    working-area grid of the residual y-parallax with its true images), the ground truth of
    the evaluation, the sheet's height control points with their true images and, for the
    setup-data method, remedy R3's levelling design at the sheet's own settings. Every step of a
    run reads these, never the scenario. [—, —, m, mm, —, —, —]"""

    sheet: SetupSheet
    scene: Scene
    grid_m: NDArray[np.float64]
    grid_images_mm: tuple[NDArray[np.float64], NDArray[np.float64]]
    truth: ModelTruth
    heights: ControlHeights
    level: LevelDesign | None = None


def log_options(op: Operator, prep: PreparedRun) -> None:
    """Transcript lines (at the start) for the SC complex's options fitted to the instrument."""
    unit = prep.correction_unit  # read from the spec once, by prepare_run
    if unit is not None:
        op.log.add(
            "1",
            "SC complex: the error-correction unit has corrected the image coordinates (film "
            f"deformation within ±{unit.range_um:g} µm; residual {unit.rms_um:g} µm RMS added to "
            "every pointing)",
        )
    if prep.options.automatic_coordinatograph:
        op.log.add(
            "1",
            "SC complex: the automatic coordinatograph's servo will drive the needle in stages "
            f"4–5 (no gear backlash or pen play; settled noise σ_s = "
            f"{op.inst.servo_sigma_mm or AutomaticCoordinatograph().sigma_mm:g} mm per axis)",
        )


# long: the parameters are the overrides the callers need, documented one by one (the code is 25)
def build_instrument(
    prep: PreparedRun,
    first: int = 0,
    trials: int | None = None,
    *,
    injected: dict[str, Any] | None = None,
    backend: str | None = None,
    ideal_mechanics: bool | None = None,
) -> Instrument:
    """The instrument of trials ``first … first + trials − 1`` of ``prep`` (one trial for None).

    Parameters
    ----------
    prep : PreparedRun
        Spec, sheet (its f_пр), error model, variant, back-end, mechanics and the SC complex's
        options, all taken from here unless overridden.
    first, trials : int, int or None
        The trials; the injected errors are the keyed draws of these trials
        (``prep.model.draw_keyed(prep.seed, first, first + trials)``).
    injected : dict, optional
        Replaces the keyed draws (designed runs: the error budget, a trainer population).
    backend : str, optional
        Overrides ``prep.backend`` (a vectorised population needs ``"closed-form"``).
    ideal_mechanics : bool, optional
        Overrides ``prep.ideal_mechanics``.
    """
    if injected is None:
        stop = None if trials is None else first + trials
        injected = prep.model.draw_keyed(prep.seed, first, stop)
    return Instrument(
        prep.spec,
        prep.sheet.focal_length_corrected_mm,
        errors=prep.model,
        injected=injected,
        variant=prep.variant,
        backend=prep.backend if backend is None else backend,
        trials=trials,
        ideal_mechanics=prep.ideal_mechanics if ideal_mechanics is None else ideal_mechanics,
        options=prep.options,
        options_checked=True,  # fitted to prep.spec once, by prepare_run
    )


# long: the parameters are documented one by one (the code is 20 lines)
def build_run(
    prep: PreparedRun,
    first: int = 0,
    trials: int | None = None,
    *,
    injected: dict[str, Any] | None = None,
    noise: Noise | None = None,
    transcript: bool = True,
    backend: str | None = None,
    ideal_mechanics: bool | None = None,
    practice: str | None = None,
) -> Run:
    """Assemble a run: the instrument, the operator at it, and the :class:`Run` on the sheet.

    Parameters
    ----------
    prep : PreparedRun
        The prepared run: scenario, spec, sheet, scene, error model, operator model, seed,
        back-end, SC complex options, practice.
    first, trials : int, int or None
        Trials ``first … first + trials − 1`` (None: one trial); every draw keyed by the trial.
    injected : dict, optional
        Instrument error terms replacing the keyed draws (:func:`build_instrument`).
    noise : Noise, optional
        The operator's judgment noise; default the keyed ``Noise(prep.seed, trials, None,
        first)``.
    transcript : bool
        Write the transcript (off for populations).
    backend, ideal_mechanics : optional
        Override ``prep``'s (:func:`build_instrument`).
    practice : {"operator", "book"}, optional
        Overrides ``prep.practice``.

    Returns
    -------
    Run
        ``run.op`` is the operator, ``run.op.inst`` the instrument. The transcript starts with
        the lines of the SC complex's options fitted (:func:`log_options`).
    """
    inst = build_instrument(
        prep,
        first,
        trials,
        injected=injected,
        backend=backend,
        ideal_mechanics=ideal_mechanics,
    )
    if noise is None:
        noise = Noise(prep.seed, trials, None, first)
    op = Operator(inst, prep.operator, noise, Transcript(enabled=transcript))
    log_options(op, prep)
    run = Run(
        op, prep.sheet, prep.scene, heights=prep.heights, level=prep.level, fidelity=prep.fidelity
    )
    run.practice = prep.practice if practice is None else practice
    return run


#: Rows and columns of the working-area grid where the true residual y-parallax is evaluated.
GRID_SHAPE = (9, 9)


def residual_grid_m(scenario: Scenario) -> np.ndarray:
    """The working-area grid of ``q_grid_mm`` (:data:`GRID_SHAPE`, local frame). [m]"""
    return working_area_grid_m(scenario, GRID_SHAPE)


def prepare_pair(
    scenario: Scenario, spec: InstrumentSpec, method: str = "setup", variant: str = "L"
) -> PreparedPair:
    """The prepared pair of a run, built once: the setup sheet (frame, Table 24, every range
    check of the sheet), the scene (true fiducials, the six standard points and their images,
    the residual grid (:func:`residual_grid_m`, local frame) with its true images), for the setup
    method the floor of the mechanism at the sheet's own settings (D9) and remedy R3's levelling
    design there, and the ground truth of the evaluation on that grid. The scenario goes no
    further than here."""
    sheet = compute_setup_sheet(scenario, spec, rng=np.random.default_rng(scenario.seed))
    grid_m = residual_grid_m(scenario)
    c_mm = spec.standard_points_c_mm
    scene = Scene.build(scenario, sheet.frame_origin_m, sheet.frame_rotation, c_mm, grid_m)
    heights = control_heights_of(sheet, scene)
    level = None
    if method == "setup":  # the mechanism at the sheet's own settings (D9, R3)
        linkage = decentration_variant(variant)
        strict = linkage.strict_per_axis
        refuse_beyond_mechanism(sheet, scene, heights, strict, mechanism_for(spec))
        level = level_design(sheet, scene, heights, linkage.linkage, strict)
    truth = model_truth(
        scenario,
        sheet,
        cast(NDArray[np.float64], scene.grid_m),
        standard_points_c_mm=c_mm,
        grid_images_mm=scene.grid_images_mm,
    )
    grid_m = cast(NDArray[np.float64], scene.grid_m)  # built with the grid above
    images = cast(tuple[NDArray[np.float64], NDArray[np.float64]], scene.grid_images_mm)
    return PreparedPair(sheet, scene, grid_m, images, truth, heights, level)
