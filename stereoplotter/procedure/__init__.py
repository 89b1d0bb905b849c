"""The simulated operator and the procedures of chapter 6 (``procedure.md``).

* :mod:`~stereoplotter.procedure.operator` — the operator model with its judgment errors;
* :mod:`~stereoplotter.procedure.setup_method` — the setup-data method, stages 1–5 (§26);
* :mod:`~stereoplotter.procedure.conventional` — relative orientation by the six standard points
  and absolute orientation by control points (§22, ch. 6);
* :mod:`~stereoplotter.procedure.simulate` — whole runs, vectorised;
* :mod:`~stereoplotter.procedure.trials` — long runs in chunks under a memory budget, summarised.
"""

from __future__ import annotations

from stereoplotter.procedure.operator import Noise, Operator, OperatorModel, Scene
from stereoplotter.procedure.simulate import (
    METHODS,
    SimulationResult,
    simulate,
    simulate_per_trial,
)
from stereoplotter.procedure.transcript import Record, Transcript

__all__ = [
    "METHODS",
    "Noise",
    "Operator",
    "OperatorModel",
    "Record",
    "Scene",
    "SimulationResult",
    "Transcript",
    "simulate",
    "simulate_per_trial",
]
