"""Instruments: the specification of SC-1, SPR-3 and SD-3 (read from ``instruments/*.yaml`` by
:mod:`stereoplotter.io.instrument_file`), their kinematics, mechanics and error model.

Every value carries its status (documented by a source, or assumed with a basis); see
``docs/instruments.md``.
"""

from __future__ import annotations

from stereoplotter.instrument.spec import (
    STATUSES,
    InstrumentSpec,
    Parameter,
    RangeRefusal,
    check_in_range,
    format_instrument,
    instrument_to_dict,
)

__all__ = [
    "STATUSES",
    "InstrumentSpec",
    "Parameter",
    "RangeRefusal",
    "check_in_range",
    "format_instrument",
    "instrument_to_dict",
]
