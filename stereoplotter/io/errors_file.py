"""An injected-errors file (``simulate --errors FILE``): overrides of the error terms.

The file maps a term (``backlash.X``) or a group (``backlash``) to a scale, or to
``{distribution, scale}``. Which names exist, which distribution a group may have and how large
a scale may be depend on the instrument's :class:`ErrorModel`, so those checks are
:meth:`ErrorModel.with_overrides` — the same checks, and the same one-line messages, for a
Python caller that passes a mapping. :class:`ErrorsFile` checks what does not depend on the
instrument (a mapping with text keys) and gives the file its JSON Schema.
"""

from __future__ import annotations

import os
from typing import Annotated, Any

from pydantic import ConfigDict, RootModel, WithJsonSchema

from stereoplotter.instrument.error_model import DISTRIBUTIONS, ErrorModel, error_model_from_spec
from stereoplotter.io.validation import validate
from stereoplotter.io.yaml_input import load_yaml_mapping
from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = ["ErrorsFile", "load_error_model"]

_SCALE = {
    "type": "number",
    "minimum": 0,
    "description": "internal units: mm, rad or relative (at most the largest the instrument "
    "files allow)",
}
_OVERRIDE = Annotated[
    Any,
    WithJsonSchema(
        {
            "anyOf": [
                _SCALE,
                {
                    "type": "object",
                    "properties": {"distribution": {"enum": list(DISTRIBUTIONS)}, "scale": _SCALE},
                    "required": ["scale"],
                    "additionalProperties": False,
                },
            ]
        }
    ),
]


class ErrorsFile(RootModel[dict[str, _OVERRIDE]]):  # type: ignore[valid-type]
    """An injected-errors file: error term or group → scale or ``{distribution, scale}``."""

    model_config = ConfigDict(
        frozen=True,
        title="stereoplotter injected-errors file (simulate --errors)",
        json_schema_extra={
            "propertyNames": {"pattern": r"^[a-z_]+(\.[A-Za-z_]+)?$"},
            "description": "keys: an error term (backlash.X) or a group (backlash); the names "
            "are listed in docs/instruments.md (injected errors)",
        },
    )


def load_error_model(
    errors: str | os.PathLike[str] | ErrorModel | None, spec: InstrumentSpec
) -> ErrorModel | str | None:
    """The error model an ``--errors`` value names: a file of overrides becomes an
    :class:`ErrorModel`; ``None`` (the instrument's defaults), ``"zero"`` and a model pass through.

    The file is :class:`ErrorsFile`; each entry is checked against the instrument's terms by
    :meth:`ErrorModel.with_overrides`; a bad entry names the file and the field.
    """
    if errors is None or isinstance(errors, ErrorModel) or errors == "zero":
        return errors
    data, source = load_yaml_mapping(errors)
    doc = validate(ErrorsFile, data, source)
    return error_model_from_spec(spec).with_overrides(doc.root, source)
