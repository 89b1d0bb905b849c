"""Documented limits of an instrument on the material it is given (issue 11, deliverable 3).

A scenario outside a documented limit is refused like a mechanical stop, with one line naming the
file, the key, the limit and its status (:class:`~stereoplotter.instrument.spec.RangeRefusal`).
Pure functions; units: m ground, mm photo.
"""

from __future__ import annotations

from stereoplotter.instrument.spec import InstrumentSpec, RangeRefusal, check_in_range

__all__ = ["RELIEF_KEY", "check_material_limits"]

#: Key of the relief limit (relief range within a pair over the flying height, SD-3: 0.35).
RELIEF_KEY = "facts.max_relief_fraction_of_H"


def check_material_limits(
    spec: InstrumentSpec, *, relief_m: float, flying_height_m: float, camera_f_mm: float, what: str
) -> None:
    """Refuse a pair whose relief or camera lies outside the instrument's documented limits.

    Parameters
    ----------
    spec : InstrumentSpec
    relief_m : float
        Range of the terrain heights within the pair (max − min). [m]
    flying_height_m : float
        Mean flying height above the terrain, H. [m]
    camera_f_mm : float
        Camera principal distance f_k. [mm]
    what : str
        The material, for the message (the scenario file).

    Raises
    ------
    RangeRefusal
        Relief/H above ``facts.max_relief_fraction_of_H`` (SD-3: 0.35, documented) or f_k outside
        ``photo.camera_f_mm``.
    """
    check_in_range(spec, "camera_f_range_mm", camera_f_mm, f"{what}: camera f_k")
    limit = spec.parameters.get(RELIEF_KEY)
    if limit is None:
        return
    ratio = relief_m / flying_height_m
    if ratio > float(limit.value):
        raise RangeRefusal(
            f"{what}: relief {relief_m:.0f} m = {ratio:.2f} H exceeds the {spec.title} limit of "
            f"{float(limit.value):g} H ({limit.status}: {', '.join(limit.source) or limit.basis}; "
            f"{limit.file}: {RELIEF_KEY})",
            what="relief/H",
            value=ratio,
            low=0.0,
            high=float(limit.value),
            status=limit.status,
            file=limit.file,
            key=RELIEF_KEY,
        )
