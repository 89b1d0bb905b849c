"""The simulated operator's file (``simulate --operator FILE``): OperatorModel fields in YAML."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from stereoplotter.errors import ConfigError, did_you_mean
from stereoplotter.io.yaml_input import load_yaml_mapping
from stereoplotter.procedure.eye import EYE_MODES
from stereoplotter.procedure.operator import OperatorModel

__all__ = ["load_operator_model"]

_OPERATOR_FIELDS: dict[str, tuple[str, Any]] = {
    "monocular_sigma_mm": ("a number ≥ 0 [mm]", float),
    "stereo_sigma_mm": ("a number ≥ 0 [mm]", float),
    "y_parallax_sigma_mm": ("a number ≥ 0 [mm]", float),
    "reading_sigma_lc": ("a number ≥ 0 [least counts]", float),
    "setting_sigma_lc": ("a number ≥ 0 [least counts]", float),
    "quantise": ("true or false", bool),
    "finish_side": ("below, above or null", str),
    "max_iterations": ("an integer 1 … 100", int),
    "eye": ("physiological or sigma", "eye"),
    "remeasure": ("true or false", bool),
}


def load_operator_model(value: str | Path | OperatorModel | None) -> OperatorModel | None:
    """The operator an ``--operator`` value names: None (the defaults), "zero" (no judgment,
    reading or setting error, no quantisation: ``OperatorModel().zero()``), "sigma" (the free
    σ_p = σ_q = 0.010 mm judged in a single look, the operator before the eye model) or a YAML
    file of :class:`OperatorModel` fields (the others keep their defaults: σ_p, σ_q from the
    operator's eye, or ``eye: sigma`` for the free σ of 0.010 mm); a bad entry is one
    :class:`ConfigError` naming the file and the field."""
    if value is None or isinstance(value, OperatorModel):
        return value
    if str(value) == "zero":
        return OperatorModel().zero()
    if str(value) == "sigma":  # the free σ of one look, no eye model
        return OperatorModel(eye="sigma", remeasure=False)

    data, source = load_yaml_mapping(value)
    fields: dict[str, Any] = {}
    for key, v in data.items():
        if key not in _OPERATOR_FIELDS:
            raise ConfigError(
                source,
                str(key),
                "a field of OperatorModel",
                key,
                did_you_mean(str(key), sorted(_OPERATOR_FIELDS)),
            )
        expected, kind = _OPERATOR_FIELDS[key]
        ok = {
            float: isinstance(v, int | float) and not isinstance(v, bool) and 0 <= v < float("inf"),
            bool: isinstance(v, bool),
            int: isinstance(v, int) and not isinstance(v, bool) and 1 <= v <= 100,
            str: v is None or v in ("below", "above"),
            "eye": v in EYE_MODES,
        }[kind]
        if not ok:
            raise ConfigError(source, str(key), expected, v)
        fields[key] = float(v) if kind is float else v
    return OperatorModel(**fields)
