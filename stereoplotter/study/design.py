"""The design of a study: its axes, its cells (configurations) and its tasks.

Plain data, no files: ``io.study_file`` validates a study file and builds a :class:`StudyDesign`.

An axis is either a list of values or a range. Without a ``sample`` every ranged axis is
``steps`` evenly spaced values and the cells are the Cartesian product of all axes, in the order
of :data:`AXES` (the last axis varies fastest; ``io.study_file`` sorts them so). With a
``sample`` the ranged axes are sampled jointly by a scrambled Sobol sequence or a Latin
hypercube (``scipy.stats.qmc``, seeded) and the sample is crossed with the listed axes.

A cell's trials are cut into chunks of ``chunk_trials`` (a property of the study, so the same
study partitions its work the same way on any cluster); the tasks are (cell, chunk) for the
simulated procedure and (cell) for the procedure Monte Carlo and the budget.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.stats import qmc

from stereoplotter.scenario.model import Scenario
from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = [
    "AXES",
    "GEOMETRY_AXES",
    "MEASURES",
    "OPERATORS",
    "Axis",
    "Sample",
    "StudyDesign",
    "Task",
]


@dataclass(frozen=True)
class AxisInfo:
    """What an axis varies: its unit and meaning (shown in the report and the schema)."""

    unit: str
    meaning: str
    categorical: bool = False


#: Axis name → what it varies. Geometry axes build a normal-case scenario
#: (:mod:`stereoplotter.study.geometry`); the others choose the run.
AXES: dict[str, AxisInfo] = {
    "f_mm": AxisInfo("mm", "camera focal length f"),
    "overlap": AxisInfo("—", "forward overlap, fraction of the format (0.6 = 60 %)"),
    "flying_height_m": AxisInfo(
        "m", "flying height H above the mean terrain (default: f × the base's photo-scale number)"
    ),
    "alpha_deg": AxisInfo("°", "longitudinal tilt α: left photo +α, right photo −α"),
    "omega_deg": AxisInfo("°", "transverse tilt ω: left photo −ω, right photo +ω"),
    "relief": AxisInfo("H", "relief: height of one Gaussian hill in the model, fraction of H"),
    "base_direction_deg": AxisInfo("°", "direction of the air base from the X axis"),
    "instrument": AxisInfo("", "instrument (shipped key or user instrument)", True),
    "method": AxisInfo("", "setup (setup data) or conventional", True),
    "practice": AxisInfo("", "operator (remedies after a failed check) or book (none)", True),
    "operator": AxisInfo(
        "",
        "the operator model: eye (default, as simulate), sigma (free 10 µm σ, one look) or zero",
        True,
    ),
    "judgement_scale": AxisInfo(
        "×", "factor on the operator's σ of pointing, x- and y-parallax judgement"
    ),
    "instrument_error_scale": AxisInfo("×", "factor on every instrument error term's σ"),
}

#: Values of the ``operator`` axis: "eye" the default operator of ``simulate``, ``verify``'s
#: checks, ``budget`` and the trainer (σ_p, σ_q from the eye, a remeasure before a failure);
#: "sigma" the free σ = 10 µm of pointing, x- and y-parallax judgement in one look; "zero" no
#: judgement, reading or setting error.
OPERATORS = ("eye", "sigma", "zero")

#: The axes that change the scenario.
GEOMETRY_AXES = (
    "f_mm",
    "overlap",
    "flying_height_m",
    "alpha_deg",
    "omega_deg",
    "relief",
    "base_direction_deg",
)

#: Measure name → what it keeps per cell (mean and Monte Carlo standard error).
MEASURES = {
    "checks": "pass rate of each of the book's checks",
    "y_parallax": "true residual y-parallax RMS over the working-area grid [µm]",
    "heights": "height error RMS over the working-area grid [‰ H]",
    "plan": "plan error RMS over the working-area grid [mm at map scale]",
    "procedure": "each outcome row's procedure value, its formula at the same geometry, ratio",
    "budget": "one-at-a-time contribution of each error term (the budget's runs)",
}

#: Measures computed from the chunked simulated procedure.
CHUNKED_MEASURES = ("checks", "y_parallax", "heights", "plan")


@dataclass(frozen=True)
class Axis:
    """One axis: a list of ``values``, or a range ``low``–``high`` (``steps`` values on a grid;
    sampled when the study has a :class:`Sample`)."""

    name: str
    values: tuple[Any, ...] | None = None
    low: float | None = None
    high: float | None = None
    steps: int | None = None

    @property
    def ranged(self) -> bool:
        return self.values is None

    def grid_values(self) -> tuple[Any, ...]:
        """The values of a listed axis, or ``steps`` evenly spaced values of a range."""
        if self.values is not None:
            return self.values
        assert self.low is not None and self.high is not None
        steps = self.steps or 2
        return tuple(float(v) for v in np.linspace(self.low, self.high, steps))


@dataclass(frozen=True)
class Sample:
    """A quasi-random sample of the ranged axes: ``kind`` "sobol" (``points`` a power of 2) or
    "lhs"; ``seed`` of the scrambling."""

    kind: str
    points: int
    seed: int


@dataclass(frozen=True)
class Task:
    """One unit of work: ``kind`` "chunk" (trials ``first`` … ``first + trials − 1`` of the
    simulated procedure), "procedure" or "budget" of cell ``cell``."""

    kind: str
    cell: int
    first: int = 0
    trials: int = 0

    @property
    def key(self) -> str:
        return f"{self.kind}-{self.cell}-{self.first}"


@dataclass(frozen=True)
class StudyDesign:
    """A validated study with its base scenario and instruments loaded (``io.study_file``).

    ``defaults``: values of axes not varied (a generated normal case's geometry, or none: then a
    cell without geometry axes runs the base scenario itself). ``instruments``: key → spec of
    every instrument the study names. ``chunk_trials``: trials per chunk task.
    """

    name: str
    base: Scenario
    instruments: dict[str, InstrumentSpec]
    axes: tuple[Axis, ...]
    trials: int
    chunk_trials: int
    measures: tuple[str, ...]
    seed: int
    procedure_trials: int = 0
    budget_trials: int = 0
    sample: Sample | None = None
    defaults: dict[str, Any] = field(default_factory=dict)
    description: str = ""

    @property
    def axis_names(self) -> tuple[str, ...]:
        return tuple(a.name for a in self.axes)

    def cells(self) -> list[dict[str, Any]]:
        """Every configuration: axis name → value, in the study's fixed order."""
        listed = [a for a in self.axes if not (a.ranged and self.sample)]
        lists = [a.grid_values() for a in listed]
        if self.sample is None:
            return [dict(zip(self.axis_names, combo, strict=True)) for combo in _product(lists)]
        ranged = [a for a in self.axes if a.ranged]
        points = _sample_points(self.sample, ranged)
        cells = []
        for point in points:
            for combo in _product(lists):
                cell = dict(zip([a.name for a in listed], combo, strict=True))
                cell.update(zip([a.name for a in ranged], point, strict=True))
                cells.append({name: cell[name] for name in self.axis_names})
        return cells

    def config(self, cell: dict[str, Any]) -> dict[str, Any]:
        """A cell's values with the defaults of the axes it does not vary."""
        return {**self.defaults, **cell}

    def tasks(self, cell: int) -> list[Task]:
        """The tasks of cell ``cell``: its chunks, then its procedure MC and budget if asked."""
        out = []
        if any(m in self.measures for m in CHUNKED_MEASURES):
            for first in range(0, self.trials, self.chunk_trials):
                n = min(self.chunk_trials, self.trials - first)
                out.append(Task("chunk", cell, first, n))
        if "procedure" in self.measures and self.procedure_trials:
            out.append(Task("procedure", cell, 0, self.procedure_trials))
        if "budget" in self.measures and self.budget_trials:
            out.append(Task("budget", cell, 0, self.budget_trials))
        return out

    def procedures(self) -> int:
        """Simulated procedures of the whole study (chunk trials; the procedure MC's trials
        count twice — a noisy and an error-free run — are left out: a lower bound)."""
        return len(self.cells()) * self.trials


def _product(lists: list[tuple[Any, ...]]) -> list[tuple[Any, ...]]:
    return list(itertools.product(*lists)) if lists else [()]


def _sample_points(sample: Sample, ranged: list[Axis]) -> list[tuple[float, ...]]:
    """``sample.points`` points of the ranged axes (Sobol or Latin hypercube, scrambled)."""
    if not ranged:
        return [()]
    d = len(ranged)
    rng = np.random.default_rng(sample.seed)
    if sample.kind == "sobol":
        unit = qmc.Sobol(d, scramble=True, rng=rng).random_base2(int(math.log2(sample.points)))
    else:
        unit = qmc.LatinHypercube(d, rng=rng).random(sample.points)
    low = [a.low for a in ranged]
    high = [a.high for a in ranged]
    scaled = qmc.scale(unit, low, high) if d else unit
    return [tuple(float(v) for v in row) for row in scaled]
