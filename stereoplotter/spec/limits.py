"""Documented limits of an instrument on the material it is given.

A scenario outside a documented limit is refused like a mechanical stop, with one line naming the
file, the key, the limit and its status (:class:`~stereoplotter.spec.range_checks.RangeRefusal`).
Pure functions; units: m ground, mm photo.
"""

from __future__ import annotations

from stereoplotter.spec.instrument_spec import InstrumentSpec
from stereoplotter.spec.range_checks import RangeRefusal, check_in_range

__all__ = [
    "MAP_RATIO_KEY",
    "MODEL_SCALE_KEY",
    "RELIEF_KEY",
    "check_material_limits",
    "check_model_to_photo_scale",
    "check_photo_to_map_ratio",
]

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


#: Key of the SPR-3 model-to-photo scale range (model 0.5–2 × photo scale, SPR-2 family).
MODEL_SCALE_KEY = "gears.model_to_photo_scale"


def check_model_to_photo_scale(
    spec: InstrumentSpec, *, photo_scale_denominator: float, model_scale_denominator: float
) -> None:
    """Refuse a model scale outside ``gears.model_to_photo_scale`` (SPR-3: 0.5–2 × photo scale).

    The ratio is m/M_г (photo scale denominator over the horizontal model scale denominator). [—]
    """
    ratio = photo_scale_denominator / model_scale_denominator
    _refuse_ratio_outside(
        spec,
        MODEL_SCALE_KEY,
        ratio,
        "model/photo scale",
        f"model scale 1:{model_scale_denominator:.0f} = {ratio:.2f} × the photo scale "
        f"1:{photo_scale_denominator:.0f} is outside the {spec.title} range",
    )


def _refuse_ratio_outside(
    spec: InstrumentSpec, key: str, ratio: float, what: str, text: str
) -> None:
    """RangeRefusal when ``ratio`` is outside the [low, high] leaf ``key`` (absent: no limit)."""
    limit = spec.parameters.get(key)
    if limit is None:
        return
    low, high = (float(v) for v in limit.value)
    if not low <= ratio <= high:
        raise RangeRefusal(
            f"{text} [{low:g}, {high:g}] ({limit.status}; {limit.file}: {key})",
            what=what,
            value=ratio,
            low=low,
            high=high,
            status=limit.status,
            file=limit.file,
            key=key,
        )


#: Key of the SD-3 photo-to-map scale ratio (GEOGRACE: 0.5–3.0, read as map/photo scale).
MAP_RATIO_KEY = "gears.photo_to_map_scale_ratio"


def check_photo_to_map_ratio(
    spec: InstrumentSpec, *, photo_scale_denominator: float, map_scale_denominator: float
) -> None:
    """Refuse a map scale outside ``gears.photo_to_map_scale_ratio`` (SD-3: 0.5–3.0 ×).

    The ratio is m/M_map (photo scale denominator over map scale denominator). [—]
    """
    ratio = photo_scale_denominator / map_scale_denominator
    _refuse_ratio_outside(
        spec,
        MAP_RATIO_KEY,
        ratio,
        "photo-to-map ratio",
        f"map scale 1:{map_scale_denominator:.0f} = {ratio:.2f} × the photo scale "
        f"1:{photo_scale_denominator:.0f} is outside the {spec.title} photo-to-map ratio",
    )
