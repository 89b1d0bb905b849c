"""The JSON of ``stereoplotter budget --json`` as a pydantic model (its published JSON Schema).

Not read back by the package: the model exists so that ``docs/schemas/budget.schema.json`` is
generated like the input files' schemas (:mod:`stereoplotter.io.schemas`) and the command's
output can be checked against it (``tests/cli/test_budget_command.py``). Numbers are floats or
null (a measure a scenario cannot give, e.g. the plan error without a map scale).
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict

__all__ = ["BudgetOutput"]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Contribution(_Strict):
    """A contribution: signed RMS sign(Δ)·√|Δ| with its SE, and Δ of the mean square with SE."""

    rms: float | None
    se: float | None
    delta_ms: float | None
    delta_ms_se: float | None


class Linear(_Strict):
    """The predicted Δ of the mean square (smooth σ² expansion) and its √, null where there is
    no smooth model or the prediction was dropped; its validation against the simulated Δ."""

    rms: float | None
    delta_ms: float | None
    predicted_ms: float | None
    status: Literal["validated", "negligible", "dropped", "none"]
    z: float | None
    reason: str


class Rms(_Strict):
    """RMS of a configuration with its SE, and the mean square with its SE."""

    rms: float | None
    se: float | None
    ms: float | None
    ms_se: float | None


class Interaction(_Strict):
    """A term's Δ(all but one) − Δ(one at a time), paired, with its SE."""

    term: str
    delta_ms: float | None
    delta_ms_se: float | None


class Additivity(_Strict):
    """Σ one-at-a-time Δᵢ, its paired gap to Δ(all on − all off) with SE, whether it is within
    2 SE, and the terms that interact beyond 2 SE."""

    sum_one_at_a_time_ms: float | None
    gap_ms: float | None
    gap_ms_se: float | None
    adds_up: bool
    interactions: list[Interaction]


class Totals(_Strict):
    all_on: Rms
    all_off: Rms
    total_delta: Contribution
    additivity: Additivity
    linear_all_on_rms: float | None


class _ByMeasure(_Strict):
    """One entry per measure (keys end in their unit)."""


class ContributionByMeasure(_ByMeasure):
    residual_y_parallax_rms_um: Contribution
    height_error_rms_permille: Contribution
    plan_error_rms_map_mm: Contribution


class LinearByMeasure(_ByMeasure):
    residual_y_parallax_rms_um: Linear
    height_error_rms_permille: Linear
    plan_error_rms_map_mm: Linear


class TotalsByMeasure(_ByMeasure):
    residual_y_parallax_rms_um: Totals
    height_error_rms_permille: Totals
    plan_error_rms_map_mm: Totals


class Measure(_Strict):
    unit: str
    meaning: str


class MeasureDescriptions(_ByMeasure):
    residual_y_parallax_rms_um: Measure
    height_error_rms_permille: Measure
    plan_error_rms_map_mm: Measure


class Term(_Strict):
    """One error term: what it is, its three contributions per measure."""

    name: str
    kind: Literal["instrument", "operator"]
    distribution: Literal["normal", "uniform", "constant", "rounding"]
    scale: float
    unit: str
    source: str
    assumed: bool
    meaning: str
    linear_model: Literal["numerical linearisation", "no linear model", "zero (σ = 0)"]
    decisions_changed: float
    one_at_a_time: ContributionByMeasure
    all_but_one: ContributionByMeasure
    linear: LinearByMeasure


class BudgetOutput(_Strict):
    """``stereoplotter budget --json``: the per-part error budget of a simulated procedure."""

    model_config = ConfigDict(
        extra="forbid", frozen=True, title="stereoplotter error budget (budget --json)"
    )

    scenario: str
    instrument: str
    method: Literal["setup", "conventional"]
    trials: int
    seed: int
    configurations: int
    linearisation_step_sigma: float
    check_step_sigma: float
    agreement_z: float
    seconds: float | None = None
    measures: MeasureDescriptions
    operator: dict[str, object]
    terms: list[Term]
    totals: TotalsByMeasure
