"""The leaves of an instrument file as plain data: key, kind, unit and bounds of each.

:mod:`stereoplotter.io.instrument_file` builds its validator from these (pydantic stays in
``io``); a correction principle declares the leaves it adds with the same class
(:attr:`stereoplotter.instrument.principles.Principle.schema_fields`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["SchemaField"]


@dataclass(frozen=True, slots=True)
class SchemaField:
    """One instrument-file leaf a principle adds, as plain data (the io layer validates it).

    ``kind`` is one of the io schema's kinds (``number``, ``range``, …); ``low``/``high`` bound
    the value (``low_open``: excluded); ``required`` False: an optional leaf.
    """

    key: str
    kind: str
    unit: str = ""
    low: float = -math.inf
    high: float = math.inf
    low_open: bool = False
    required: bool = True
    contains_zero: bool = False
