"""Range checks of an instrument specification: a setting outside a range is refused like a
mechanical stop (:class:`RangeRefusal`), naming the value, the range, its status (documented or
assumed) and the file and key where it is set. Nothing is ever clipped.

Pure data checks on :class:`~stereoplotter.spec.instrument_spec.InstrumentSpec`; the stateful
instrument (:mod:`stereoplotter.instrument`) and the setup computer (:mod:`stereoplotter.setup`)
both call them.
"""

from __future__ import annotations

import math

from stereoplotter.errors import StereoplotterError
from stereoplotter.spec.instrument_spec import InstrumentSpec, Parameter

__all__ = ["RangeRefusal", "check_in_range"]

_RAD = math.pi / 180.0


class RangeRefusal(StereoplotterError):
    """A setting lies outside the instrument's range: the stop refuses it.

    Attributes
    ----------
    what : str
        The quantity as named by the caller (``"b_z′"``).
    value : float
        The refused value, in the YAML unit of the range.
    low, high : float
        The range, in the same unit (for a gear set, its smallest and largest entries).
    status : str
        ``"documented"`` or ``"assumed"``: the status of the limit that refused the value.
    file, key : str
        Where the limit is set, so the user can change it.
    """

    def __init__(
        self,
        message: str,
        *,
        what: str,
        value: float,
        low: float,
        high: float,
        status: str,
        file: str,
        key: str,
    ):
        super().__init__(message)
        self.what = what
        self.value = value
        self.low = low
        self.high = high
        self.status = status
        self.file = file
        self.key = key


# --- range checks ----------------------------------------------------------------------------

_SETS = ("vertical_scale_denominators", "coordinatograph_ratios")
_MAXIMA = ("tilt_max",)
_UPPER_END = {"projection_distance_range_mm": "projection.distance_max_mm"}


def check_in_range(spec: InstrumentSpec, attribute_name: str, value: float, what: str) -> None:
    """Refuse a setting outside the instrument's range, as a mechanical stop would.

    Parameters
    ----------
    spec : InstrumentSpec
        The instrument.
    attribute_name : str
        A range attribute (``"base_z_range_mm"``, ``"kappa_range"``, …), ``"tilt_max"``
        (|value| ≤ tilt_max) or a gear set (``"vertical_scale_denominators"``,
        ``"coordinatograph_ratios"``: the value must be one of its entries).
    value : float
        The setting in the attribute's unit (mm; rad for angles; — for gear ratios).
    what : str
        The quantity's symbol for the message (``"b_z′"``).

    Raises
    ------
    RangeRefusal
        With the value, the range, whether that range is documented or assumed, and the file
        and key where it is set. Nothing is clipped.

    Examples
    --------
    >>> from stereoplotter.io.instrument_file import load_instrument
    >>> spec = load_instrument("sc1")
    >>> check_in_range(spec, "base_z_range_mm", 12.5, "b_z′")  # inside: nothing happens
    >>> check_in_range(spec, "base_z_range_mm", 55.0, "b_z′")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    stereoplotter.spec.range_checks.RangeRefusal: b_z′ = 55.000 mm is outside the assumed range [-40, 40] mm of ...sc1.yaml: base.z_mm (the stop refuses it; widen the range in the YAML if your instrument allows it)
    """  # noqa: E501
    key = spec.key_of(attribute_name)
    parameter = spec.parameters[key]
    limit = getattr(spec, attribute_name)
    to_yaml = 1.0 / _RAD if parameter.unit == "deg" else 1.0
    shown = float(value) * to_yaml
    unit = f" {parameter.unit}" if parameter.unit not in ("", "—") else ""
    status, file = parameter.status, parameter.file
    advice = (
        "widen the range in the YAML if your instrument allows it"
        if status == "assumed"
        else f"the limit is documented ({', '.join(parameter.source)})"
    )
    if attribute_name in _SETS:
        _check_in_gear_set(parameter, key, tuple(limit), value, what, advice)
        return
    if attribute_name in _MAXIMA:
        lo, hi = -limit, limit
    elif (
        isinstance(limit, tuple)
        and len(limit) == 2
        and attribute_name.endswith(("_range_mm", "_range"))
    ):
        lo, hi = limit
    else:
        raise TypeError(f"{attribute_name!r} is not a range, a maximum or a gear set")
    lo_y, hi_y = lo * to_yaml, hi * to_yaml
    eps = 1e-9 * max(1.0, abs(lo_y), abs(hi_y))
    if math.isfinite(shown) and lo_y - eps <= shown <= hi_y + eps:
        return
    end_key = _UPPER_END.get(attribute_name)
    if end_key in spec.parameters and shown > hi_y:
        _refuse_above_end(spec.parameters[end_key], end_key, shown, (lo_y, hi_y), what, unit)
    raise RangeRefusal(
        f"{what} = {shown:.3f}{unit} is outside the {status} range [{lo_y:g}, {hi_y:g}]{unit} "
        f"of {file}: {key} (the stop refuses it; {advice})",
        what=what,
        value=shown,
        low=lo_y,
        high=hi_y,
        status=status,
        file=file,
        key=key,
    )


def _refuse_above_end(
    end: Parameter, end_key: str, shown: float, limits: tuple[float, float], what: str, unit: str
) -> None:
    """The refusal of a value above a range whose upper end is its own documented leaf
    (``projection.distance_max_mm``): the message names that leaf."""
    lo_y, hi_y = limits
    end_advice = (
        f"the limit is documented ({', '.join(end.source)})"
        if not end.is_assumed
        else "raise it in the YAML if your instrument allows it"
    )
    raise RangeRefusal(
        f"{what} = {shown:.3f}{unit} is above the {end.status} maximum {hi_y:g}{unit} of "
        f"{end.file}: {end_key} (the stop refuses it; {end_advice})",
        what=what,
        value=shown,
        low=lo_y,
        high=hi_y,
        status=end.status,
        file=end.file,
        key=end_key,
    )


def _check_in_gear_set(
    parameter: Parameter,
    key: str,
    entries: tuple[float, ...],
    value: float,
    what: str,
    advice: str,
) -> None:
    """The gear-set case of :func:`check_in_range`: the value must be one of the entries."""
    if any(math.isclose(value, e, rel_tol=1e-9, abs_tol=0.0) for e in entries):
        return
    status, file = parameter.status, parameter.file
    listed = ", ".join(f"{e:g}" for e in entries)
    if status == "assumed":
        advice = "add the gear to the YAML if your instrument has it"
    raise RangeRefusal(
        f"{what} = {float(value):g} is not in the {status} gear set [{listed}] of {file}: {key} "
        f"(no such gear; {advice})",
        what=what,
        value=float(value),
        low=min(entries),
        high=max(entries),
        status=status,
        file=file,
        key=key,
    )
