"""The correction principles of the instruments, one module each, and their registry.

* :mod:`.plates` — SD-3, correction plates with a follower (:class:`PlaneFollower`);
* :mod:`.lens_shift` — SPR-3, the lens shifted on a swinging arm (:class:`LensShift`);
* :mod:`.gimbal` — SC-1, mechanical projection with a gimbal photo carrier
  (:class:`MechanicalProjection`);
* :mod:`.base` — what a principle declares (:class:`Principle`) and the shared pieces.

Adding a principle: a new module that defines its ``Principle`` (kinematics, settings and control
names, schema field, error terms) and one entry in :data:`PRINCIPLES` below
(``docs/architecture.md``, "Where a new instrument principle goes").
"""

from __future__ import annotations

from stereoplotter.instrument.principles import gimbal, lens_shift, plates
from stereoplotter.instrument.principles.base import (
    CorrectionMechanism,
    Principle,
    SchemaField,
    Setting,
    SettingSequence,
    correction_setting_terms,
    setting_values,
)
from stereoplotter.instrument.principles.gimbal import MechanicalProjection
from stereoplotter.instrument.principles.lens_shift import LensShift
from stereoplotter.instrument.principles.plates import PlaneFollower
from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = [
    "PRINCIPLES",
    "CorrectionMechanism",
    "LensShift",
    "MechanicalProjection",
    "PlaneFollower",
    "Principle",
    "SchemaField",
    "Setting",
    "SettingSequence",
    "error_terms_for",
    "mark_phrase",
    "mechanism_for",
    "sequence_for",
    "setting_values",
]

#: The registry: ``principle:`` of an instrument file → its :class:`Principle`.
PRINCIPLES: dict[str, Principle] = {
    p.name: p for p in (plates.PLATES, lens_shift.LENS_SHIFT, gimbal.GIMBAL)
}


def mechanism_for(spec: InstrumentSpec) -> CorrectionMechanism | None:
    """The instrument's mechanism, its dimension from the YAML leaf when present (assumed)."""
    p = PRINCIPLES.get(spec.principle)
    if p is None:
        return None
    leaf = spec.parameters.get(p.dimension.key)
    return p.mechanism_with(None if leaf is None else leaf.value)


def sequence_for(principle: str) -> SettingSequence | None:
    """The settings of an instrument ``principle`` (None: not one of the registered ones)."""
    p = PRINCIPLES.get(principle)
    return p.settings if p is not None else None


def mark_phrase(principle: str, mark: str) -> str:
    """How the fiducial meets the mark: the SPR-3 moves the photo under a fixed mark."""
    p = PRINCIPLES.get(principle)
    if p is not None and p.mechanism.photo_moves:
        return f"the photo carriage brings mark {mark} under the fixed measuring mark"
    return f"mark {mark} is under the measuring mark"


def error_terms_for(principle: str, side: str) -> tuple[tuple[str, str, str, str], ...]:
    """The correction-setting error terms of the ``side`` unit of an instrument ``principle``
    (:meth:`Principle.error_terms`; the canonical unit's for an unregistered principle)."""
    p = PRINCIPLES.get(principle)
    return p.error_terms(side) if p is not None else correction_setting_terms(side)
