"""The trainer core: exercises, a trainee's session on the virtual instrument, grading.

Layer: orchestration (beside ``verification``). May import ``procedure``, ``setup``,
``instrument``, ``scenario``, ``imagery`` and the pure layers; never ``io``, ``report``,
``plotting`` or ``web``. Exercise files are read by ``io``.
"""

from __future__ import annotations

from importlib import import_module
from typing import Any

__all__ = ["Exercise", "Session", "grade"]

#: Public name → its module (resolved on first use: ``stereoplotter.trainer.Session``).
_API = {
    "Exercise": "stereoplotter.trainer.exercise",
    "Session": "stereoplotter.trainer.session",
    "grade": "stereoplotter.trainer.grading",
}


def __getattr__(name: str) -> Any:
    # lazy, as the package top: importing trainer.exercise does not load the procedure
    if name in _API:
        value = getattr(import_module(_API[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'stereoplotter.trainer' has no attribute {name!r}")
