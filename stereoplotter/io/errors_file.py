"""An injected-errors file (``simulate --errors FILE``): overrides of the error terms."""

from __future__ import annotations

import os

from stereoplotter.instrument.error_model import ErrorModel, error_model_from_spec
from stereoplotter.instrument.spec import InstrumentSpec
from stereoplotter.io.yaml_files import load_yaml_mapping

__all__ = ["load_error_model"]


def load_error_model(
    errors: str | os.PathLike[str] | ErrorModel | None, spec: InstrumentSpec
) -> ErrorModel | str | None:
    """The error model an ``--errors`` value names: a file of overrides becomes an
    :class:`ErrorModel`; ``None`` (the instrument's defaults), ``"zero"`` and a model pass through.

    The file maps a term or group name to a scale or ``{distribution, scale}``
    (:meth:`ErrorModel.with_overrides`); a bad entry names the file and the field.
    """
    if errors is None or isinstance(errors, ErrorModel) or errors == "zero":
        return errors
    data, source = load_yaml_mapping(errors)
    return error_model_from_spec(spec).with_overrides(data, source)
