"""The instrument specification as its own layer: what an instrument file says, not the instrument.

Layer: pure data, below :mod:`stereoplotter.setup` and :mod:`stereoplotter.instrument` (both import
it; it imports neither). Reading and validating the YAML files is :mod:`stereoplotter.io`.

* :mod:`.instrument_spec` — :class:`InstrumentSpec` (typed ranges, least counts, gear sets, each
  leaf's status and provenance) and its presentation;
* :mod:`.range_checks` — :func:`check_in_range` and :class:`RangeRefusal` (the mechanical stop);
* :mod:`.limits` — the documented limits on the material (relief/H, model-to-photo scale,
  photo-to-map ratio);
* :mod:`.schema_fields` — the leaves of an instrument file as plain data (io validates them).
"""

from __future__ import annotations

from stereoplotter.spec.instrument_spec import (
    STATUSES,
    InstrumentSpec,
    Parameter,
    format_instrument,
    instrument_to_dict,
)
from stereoplotter.spec.range_checks import RangeRefusal, check_in_range

__all__ = [
    "STATUSES",
    "InstrumentSpec",
    "Parameter",
    "RangeRefusal",
    "check_in_range",
    "format_instrument",
    "instrument_to_dict",
]
