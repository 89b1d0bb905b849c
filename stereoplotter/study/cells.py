"""What one task of a study computes, and how the parts of a cell combine.

A chunk task runs trials ``first … first + n − 1`` of the simulated procedure of its cell
(``procedure.simulate``, closed-form back-end) and reduces them at once to *moments*: per
measure the count, mean and sum of squared deviations of its finite per-trial values
(:class:`Moments`). Every draw is keyed by the trial index, so a chunk's moments depend only on
the study seed, the cell and the trial range — not on the worker that ran it. A cell's moments
are combined chunk by chunk in trial order (Chan et al.'s pairwise update), so the cell's
figures are the same bit for bit whatever the number of workers and the order the chunks
finished in.

Every cell runs trials 0 … T−1 of the study seed: common random numbers across the cells, so
the difference between two neighbouring cells is not blurred by independent noise.

The procedure task runs :func:`~stereoplotter.verification.procedure_mc.procedure_mc` (its
own configuration: the operator's pointing σ only, the book's practice) for the outcome rows of
the cell's method; the budget task runs :func:`~stereoplotter.verification.budget.run_budget`.
Both are one task per cell (neither takes a trial offset).

A refused setup (an instrument's range, a tilt beyond its correction mechanism) is a result: the
task returns the refusal's one-line message and the cell is marked refused.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from stereoplotter.accuracy import setup_accuracy as sa
from stereoplotter.constants import MM_PER_M
from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.error_model import ErrorModel, error_model_from_spec
from stereoplotter.procedure.operator import OperatorModel
from stereoplotter.procedure.simulate import prepare_run, run_trials_chunk
from stereoplotter.procedure.trials import trial_columns
from stereoplotter.scenario.model import Scenario
from stereoplotter.spec.instrument_spec import InstrumentSpec
from stereoplotter.study.design import StudyDesign, Task
from stereoplotter.study.geometry import cell_scenario
from stereoplotter.verification.budget import MEASURES as BUDGET_MEASURES
from stereoplotter.verification.budget import run_budget
from stereoplotter.verification.linear_mc import CI_Z
from stereoplotter.verification.procedure_mc import procedure_mc

__all__ = [
    "OUTCOME_ROWS",
    "CellRun",
    "Moments",
    "cell_operator",
    "cell_run",
    "combine_chunks",
    "prepared_run",
    "run_task",
]

#: Outcome rows of §27 the procedure task measures: row → (method, procedure_mc field, equations).
OUTCOME_ROWS = {
    "setup": ("setup", "parallax", "(6.39)–(6.44)"),
    "setup_levelled": ("setup", "levelled", "(6.47)–(6.50)"),
    "setup_observed": ("setup", "observed", "(6.58)/(6.59)"),
    "conventional": ("conventional", None, "(6.45)/(6.46) = (6.60)/(6.61)"),
}

#: Operator pointing σ of the procedure MC at judgement scale 1 (the module default of
#: ``procedure_mc``: 10 µm, the operator's default pointing σ). [mm]
PROCEDURE_SIGMA_MM = 0.01


@dataclass(frozen=True)
class CellRun:
    """Everything a task of one cell runs with."""

    scenario: Scenario
    spec: InstrumentSpec
    method: str
    practice: str
    operator: OperatorModel
    errors: ErrorModel
    judgement_scale: float


def cell_operator(name: str, spec: InstrumentSpec, judgement: float) -> OperatorModel:
    """The operator of a cell: ``name`` a value of the ``operator`` axis
    (:data:`~stereoplotter.study.design.OPERATORS`), resolved for the instrument, its σ of
    pointing, x- and y-parallax judgement multiplied by ``judgement``.

    "eye" is :class:`OperatorModel`'s default — the operator of ``simulate``, ``verify``'s checks,
    ``budget`` and the trainer.

    Examples
    --------
    >>> from stereoplotter.io.instrument_file import load_instrument
    >>> sc1 = load_instrument("sc1")
    >>> cell_operator("eye", sc1, 1.0) == OperatorModel().for_instrument(sc1)
    True
    >>> round(cell_operator("sigma", sc1, 2.0).y_parallax_sigma_mm, 3)
    0.02
    """
    if name == "eye":
        base = OperatorModel().for_instrument(spec)
    elif name == "sigma":
        base = OperatorModel(eye="sigma", remeasure=False).for_instrument(spec)
    elif name == "zero":
        return OperatorModel().for_instrument(spec).zero()
    else:
        raise StereoplotterError(f"operator: expected one of eye, sigma, zero, found {name!r}")
    if judgement == 1.0:
        return base
    assert base.stereo_sigma_mm is not None and base.y_parallax_sigma_mm is not None
    return replace(
        base,
        monocular_sigma_mm=base.monocular_sigma_mm * judgement,
        stereo_sigma_mm=base.stereo_sigma_mm * judgement,
        y_parallax_sigma_mm=base.y_parallax_sigma_mm * judgement,
    )


def cell_run(design: StudyDesign, cell: int, config: dict[str, Any]) -> CellRun:
    """The scenario, instrument, method, operator and error model of a cell's configuration."""
    config = design.config(config)
    spec = design.instruments[str(config.get("instrument", next(iter(design.instruments))))]
    judgement = float(config.get("judgement_scale", 1.0))
    operator = cell_operator(str(config.get("operator", "eye")), spec, judgement)
    errors = error_model_from_spec(spec).scaled(float(config.get("instrument_error_scale", 1.0)))
    return CellRun(
        cell_scenario(design.base, config, f"{design.base.name} cell {cell}"),
        spec,
        str(config.get("method", "setup")),
        str(config.get("practice", "operator")),
        operator,
        errors,
        judgement,
    )


@dataclass(frozen=True)
class Moments:
    """Count, mean and sum of squared deviations of each measure's finite values."""

    n: NDArray[np.float64]
    mean: NDArray[np.float64]
    m2: NDArray[np.float64]

    @classmethod
    def of(cls, values: NDArray[np.float64]) -> Moments:
        """The moments of each row of ``values`` (measures × trials), NaN left out."""
        finite = np.isfinite(values)
        n = finite.sum(axis=1).astype(float)
        x = np.where(finite, values, 0.0)
        with np.errstate(invalid="ignore", divide="ignore"):
            mean = np.where(n > 0, x.sum(axis=1) / n, np.nan)
            dev = np.where(finite, values - mean[:, None], 0.0)
        return cls(n, mean, (dev**2).sum(axis=1))

    def __add__(self, other: Moments) -> Moments:
        """Chan et al.'s pairwise update (exact in real arithmetic; a fixed order makes it
        reproducible in floating point)."""
        n = self.n + other.n
        with np.errstate(invalid="ignore", divide="ignore"):
            delta = other.mean - self.mean
            mean = np.where(
                other.n == 0,
                self.mean,
                np.where(self.n == 0, other.mean, self.mean + delta * other.n / n),
            )
            m2 = np.where(
                (self.n == 0) | (other.n == 0),
                self.m2 + other.m2,
                self.m2 + other.m2 + delta**2 * self.n * other.n / n,
            )
        return Moments(n, mean, m2)

    def standard_error(self) -> NDArray[np.float64]:
        """s/√n of each mean (NaN below two values)."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(self.n > 1, np.sqrt(self.m2 / (self.n - 1) / self.n), np.nan)


def chunk_measures(
    run: CellRun, checks: tuple[str, ...], columns: dict[str, NDArray], height_m: float
):
    """Rows (measures × trials) of a chunk: each check's pass flag (NaN where the method has no
    such check), the residual y-parallax, height and plan RMS on the working-area grid."""
    t = len(columns["residual_y_parallax/grid_rms_um"])
    rows = []
    for name in checks:
        flag = columns.get(f"check/{name}/passed")
        rows.append(np.full(t, np.nan) if flag is None else flag.astype(float))
    rows.append(columns["residual_y_parallax/grid_rms_um"])
    rows.append(columns["evaluation/grid/height_error_rms_m"] * MM_PER_M / height_m)
    rows.append(columns["evaluation/grid/plan_error_rms_map_mm"])
    return np.vstack(rows)


#: The value measures after the check flags in a chunk's rows, and their names in the Dataset.
VALUE_MEASURES = ("y_parallax_rms_um", "height_rms_permille", "plan_rms_map_mm")


def prepared_run(design: StudyDesign, run: CellRun):
    """A cell's procedure prepared once (the sheet, the instrument, the keyed streams of the
    study's seed), for any number of its chunks."""
    return prepare_run(
        run.scenario,
        run.spec,
        run.method,
        run.errors,
        design.seed,
        operator=run.operator,
        practice=run.practice,
    )


def _chunk(design: StudyDesign, run: CellRun, task: Task, checks: tuple[str, ...]) -> Moments:
    prep = prepared_run(design, run)
    result = run_trials_chunk(prep, task.first, task.trials, evaluate=True, transcript=False)
    assert result.evaluation is not None
    cols = trial_columns(result)
    return Moments.of(chunk_measures(run, checks, cols, float(result.evaluation.flying_height_m)))


def _procedure(design: StudyDesign, run: CellRun, task: Task) -> dict[str, tuple[float, ...]]:
    """Row → (procedure value, CI half-width / CI_Z, rigorous formula, book formula)."""
    method = "conventional" if run.method == "conventional" else "setup"
    r = procedure_mc(
        run.scenario,
        method,
        spec=run.spec,
        trials=task.trials,
        seed=design.seed,
        sigma_mm=PROCEDURE_SIGMA_MM * run.judgement_scale,
    )
    out = {}
    if method == "conventional":
        out["conventional"] = (
            r["coefficient"],
            r["ci"] / CI_Z,
            r["formula"]["rigorous"],
            r["formula"]["book"],
        )
        return out
    g = r
    book = {
        "parallax": sa.setup_parallax_rms_from_pointing(
            g["f"], g["p"], g["c"], g["l"], g["n"], 1.0
        ),
        "levelled": sa.setup_relative_residual_rms(g["a"], g["c"], g["f"], g["l"], g["n"], 1.0),
        "observed": math.nan,
    }
    for row, (_, field, _) in OUTCOME_ROWS.items():
        if field is None:
            continue
        entry = r["fields"][field]
        out[row] = (entry["coefficient"], entry["ci"] / CI_Z, entry["formula"], float(book[field]))
    return out


def _budget(design: StudyDesign, run: CellRun, task: Task) -> dict[str, dict[str, tuple]]:
    """Term → measure → (one-at-a-time Δ mean square, its SE)."""
    b = run_budget(
        run.scenario,
        run.spec,
        run.method,
        trials=task.trials,
        seed=design.seed,
        errors=run.errors,
        operator=run.operator,
    )
    out = {}
    for term in b["terms"]:
        one = term["one_at_a_time"]
        out[term["name"]] = {
            m: (float(one[m]["delta_ms"]), float(one[m]["delta_ms_se"])) for m in BUDGET_MEASURES
        }
    return out


def run_task(
    design: StudyDesign, config: dict[str, Any], task: Task, checks: tuple[str, ...]
) -> tuple[Task, Any]:
    """Run one task; its result, or ``("refused", message)`` when the setup is refused."""
    try:
        run = cell_run(design, task.cell, config)
        if task.kind == "chunk":
            return task, _chunk(design, run, task, checks)
        if task.kind == "procedure":
            return task, _procedure(design, run, task)
        return task, _budget(design, run, task)
    except StereoplotterError as exc:
        return task, ("refused", str(exc).splitlines()[0])


def combine_chunks(parts: list[tuple[Task, Moments]]) -> Moments:
    """The cell's moments from its chunks, combined in trial order."""
    ordered = sorted(parts, key=lambda p: p[0].first)
    total = ordered[0][1]
    for _, m in ordered[1:]:
        total = total + m
    return total
