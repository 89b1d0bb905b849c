"""Accuracy of model building, Kushtin & Lyskov 1984, ch. 5 §22-§24 and ch. 6 §27.

Formulas (:mod:`.chapter5`, :mod:`.setup_accuracy`), their linear Monte Carlo and covariance
propagation (:mod:`.montecarlo`) and the verification table (:mod:`.verification`).
Figures are in :mod:`stereoplotter.accuracy_plot` (matplotlib is imported only there).
"""

from stereoplotter.accuracy.verification import (
    BOOK,
    ROW_KEYS,
    VERDICTS,
    closing_comparison,
    run_verification,
    verify,
    write_verification,
)

__all__ = [
    "BOOK",
    "ROW_KEYS",
    "VERDICTS",
    "closing_comparison",
    "run_verification",
    "verify",
    "write_verification",
]
