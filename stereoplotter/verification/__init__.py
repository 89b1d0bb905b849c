"""Verification of the accuracy formulas (6.19)–(6.61): linear Monte Carlo and covariance
propagation of the linear models (:mod:`.linear_mc`), the Monte Carlo through the simulated
procedure (:mod:`.procedure_mc`) and the verdict table (:mod:`.table`).

Layer: orchestration. May import the pure layers (``accuracy`` formulas, ``geometry``,
``scenario``, ``setup``), ``instrument`` and ``procedure``; never ``io``, ``report`` or
``plotting``.
"""

from stereoplotter.verification.table import (
    BOOK,
    ROW_KEYS,
    VERDICTS,
    closing_comparison,
    run_verification,
)

__all__ = [
    "BOOK",
    "ROW_KEYS",
    "VERDICTS",
    "closing_comparison",
    "run_verification",
]
