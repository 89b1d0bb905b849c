"""The validation layer of the input files: pydantic v2 models and one-line errors.

Every input file kind has a pydantic model (``extra="forbid"``: an unknown key is an error). Its
fields use the annotated types below, whose own checks raise a
:class:`pydantic_core.PydanticCustomError` whose message is what was *expected* ("a number in
[0, 1000] µm") and whose context may say what was *found*; :func:`validate` turns the first error
of a :class:`pydantic.ValidationError` into the one-line
:class:`~stereoplotter.errors.ConfigError` ``FILE: FIELD: expected …, found …`` (dotted field path,
"did you mean" for a mistyped key). The same models give the JSON Schema of every file kind
(:mod:`stereoplotter.io.schemas`).

Defaults live in the model fields (``Field(default=…)``), never in class attributes of the domain
dataclasses (on a dataclass with slots those are descriptors).
"""

from __future__ import annotations

import datetime as _dt
import math
import re
import typing
from collections.abc import Callable, Mapping
from typing import Annotated, Any, TypeVar

from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    ValidationError,
    model_validator,
)
from pydantic_core import PydanticCustomError

from stereoplotter.errors import ConfigError, describe_value, did_you_mean

__all__ = [
    "FileModel",
    "check_date",
    "check_number",
    "field_path",
    "integer",
    "invalid",
    "number",
    "number_at",
    "one_of",
    "schema_bounds",
    "sequence",
    "text",
    "validate",
    "vector",
]

M = TypeVar("M", bound=BaseModel)


class FileModel(BaseModel):
    """Base of every input-file model: unknown keys are refused, instances are frozen, and a key
    written without a value (``key:`` or ``key: null``) counts as absent: the default applies,
    or a required field is reported missing."""

    model_config = ConfigDict(extra="forbid", frozen=True, hide_input_in_errors=False)

    @model_validator(mode="before")
    @classmethod
    def _absent_if_null(cls, v: Any) -> Any:
        if isinstance(v, dict):
            return {k: x for k, x in v.items() if x is not None}
        return v


def invalid(
    expected: str, found: object, hint: str = "", at: tuple[str | int, ...] = ()
) -> PydanticCustomError:
    """The error a check raises: ``expected``, ``found`` and a ``hint``; ``at`` is the place of
    the bad value below the field being checked (a list index, or a key of a model whose
    cross-field check failed)."""
    # the expected text goes through the context: its braces are not read as a template
    return PydanticCustomError(
        "stereoplotter",
        "{expected}",
        {"expected": expected, "found": found, "hint": hint, "at": at},
    )


def number_at(source: str, path: str, value: Any, **limits: Any) -> float:
    """:func:`check_number` for a value already validated once (a cross-field limit, such as a
    fiducial mark inside the format), its failure as the :class:`ConfigError` of ``path``."""
    try:
        return check_number(value, **limits)
    except PydanticCustomError as exc:
        ctx = exc.context or {}
        raise ConfigError(
            source, path, ctx["expected"], ctx.get("found"), ctx.get("hint", "")
        ) from None


def range_text(unit: str, low: float, high: float, low_open: bool, high_open: bool) -> str:
    """``in [0, 1000] µm``, ``in (0, 5] mm``, … (empty when unbounded and unitless)."""
    unit_text = f" {unit}" if unit and unit != "—" else ""
    if math.isinf(low) and math.isinf(high):
        return f"[{unit}]" if unit_text else ""
    left = "(" if low_open or math.isinf(low) else "["
    right = ")" if high_open or math.isinf(high) else "]"
    lo = "-inf" if math.isinf(low) else f"{low:g}"
    hi = "inf" if math.isinf(high) else f"{high:g}"
    return f"in {left}{lo}, {hi}{right}{unit_text}"


def check_number(
    value: Any,
    *,
    unit: str = "",
    low: float = -math.inf,
    high: float = math.inf,
    low_open: bool = False,
    high_open: bool = False,
    basis: str = "",
) -> float:
    """A finite real number inside the range, or a :class:`PydanticCustomError`."""
    expected = f"a number {range_text(unit, low, high, low_open, high_open)}".rstrip()
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise invalid(expected, describe_value(value))
    try:
        value = float(value)
    except OverflowError:  # an integer beyond the float range
        raise invalid(expected, "an integer too large for a float", basis) from None
    too_low = value < low or (low_open and value == low)
    too_high = value > high or (high_open and value == high)
    if not math.isfinite(value) or too_low or too_high:
        raise invalid(expected, value, basis)
    return value


def check_date(v: Any) -> str:
    """A date as text ``YYYY-MM-DD`` (an unquoted YAML date is taken as its ISO text)."""
    if isinstance(v, _dt.date) and not isinstance(v, _dt.datetime):  # an unquoted YAML date
        v = v.isoformat()
    if not isinstance(v, str) or not re.fullmatch(r"\d{4}-\d{2}-\d{2}", v):
        raise invalid("a date YYYY-MM-DD (printed on the forms; the clock is never read)", repr(v))
    return v


def schema_bounds(low: float, high: float, low_open: bool, high_open: bool) -> dict[str, float]:
    """JSON Schema keywords of a range (the check itself is :func:`check_number`)."""
    out: dict[str, float] = {}
    if math.isfinite(low):
        out["exclusiveMinimum" if low_open else "minimum"] = low
    if math.isfinite(high):
        out["exclusiveMaximum" if high_open else "maximum"] = high
    return out


def number(
    unit: str = "",
    low: float = -math.inf,
    high: float = math.inf,
    *,
    low_open: bool = False,
    high_open: bool = False,
    basis: str = "",
    description: str = "",
) -> Any:
    """The type of a finite number in a range (JSON Schema: ``minimum``/``maximum``)."""

    def check(v: Any) -> float:
        return check_number(
            v, unit=unit, low=low, high=high, low_open=low_open, high_open=high_open, basis=basis
        )

    unit_note = f"[{unit}]" if unit and unit != "—" else ""
    text = " ".join(t for t in (description, unit_note, basis) if t)
    return Annotated[
        float,
        BeforeValidator(check),
        Field(
            description=text or None,
            json_schema_extra=schema_bounds(low, high, low_open, high_open),
        ),
    ]


def integer(low: int, high: int, description: str = "") -> Any:
    """The type of an integer in [low, high] (no bool, no float)."""

    def check(v: Any) -> int:
        if isinstance(v, bool) or not isinstance(v, int) or not low <= v <= high:
            raise invalid(f"an integer in [{low}, {high}]", describe_value(v))
        return v

    return Annotated[
        int,
        BeforeValidator(check),
        Field(description=description or None, json_schema_extra={"minimum": low, "maximum": high}),
    ]


def _check_text(v: Any) -> str:
    if isinstance(v, bool) or not isinstance(v, str | int) or str(v) == "":
        raise invalid("a non-empty text", describe_value(v))
    return str(v)


#: A non-empty text (a number is accepted and turned into text, as for point ids).
text = Annotated[str, BeforeValidator(_check_text), Field(min_length=1)]


def one_of(*words: str, expected: str = "") -> Any:
    """The type of one word of a fixed set (JSON Schema: ``enum``)."""

    def check(v: Any) -> str:
        if not isinstance(v, str) or v not in words:
            raise invalid(expected or "one of " + ", ".join(words), describe_value(v))
        return v

    return Annotated[typing.Literal[words], BeforeValidator(check)]  # type: ignore[valid-type]


def vector(
    length: int, unit: str, low: float = -math.inf, high: float = math.inf, what: str = ""
) -> Any:
    """The type of a list of ``length`` numbers in a range (a tuple in Python)."""
    item = number(unit, low, high)
    expected = f"a list of {what or f'{length} numbers'} [{unit}]"

    def check(v: Any) -> Any:
        if not isinstance(v, list | tuple) or len(v) != length:
            raise invalid(expected, describe_value(v))
        return v

    return Annotated[
        tuple[(item,) * length],  # type: ignore[misc]
        BeforeValidator(check),
    ]


def sequence(item: Any, min_length: int = 0, max_length: int | None = None) -> Any:
    """The type of a list of ``item`` with at least ``min_length`` entries."""

    def check(v: Any) -> Any:
        if not isinstance(v, list):
            raise invalid("a list", describe_value(v))
        if len(v) < min_length:
            raise invalid(f"a list of at least {min_length} entries", f"{len(v)} entries")
        if max_length is not None and len(v) > max_length:
            raise invalid(f"a list of at most {max_length} entries", f"{len(v)} entries")
        return v

    return Annotated[
        list[item], BeforeValidator(check), Field(min_length=min_length, max_length=max_length)
    ]


# --- turning a ValidationError into one ConfigError -----------------------------------------


def field_path(loc: tuple[Any, ...]) -> str:
    """``("photos", 1, "exterior", "alpha_deg")`` → ``photos[1].exterior.alpha_deg``."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += f".{part}" if out else str(part)
    return out


def _models_in(annotation: Any) -> list[type[BaseModel]]:
    """The model classes an annotation can hold (through Optional, list, tuple, Annotated)."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    args = typing.get_args(annotation)
    if typing.get_origin(annotation) is Annotated:
        args = args[:1]
    found: list[type[BaseModel]] = []
    for a in args:
        found += _models_in(a)
    return found


def _model_at(model: type[BaseModel], loc: tuple[Any, ...]) -> type[BaseModel] | None:
    """The model class whose field holds ``loc`` (the model of the mapping at ``loc[:-1]``)."""
    current: type[BaseModel] | None = model
    for part in loc[:-1]:
        if current is None:
            return None
        if isinstance(part, int):
            continue
        info = current.model_fields.get(str(part))
        if info is None:
            return None
        candidates = _models_in(info.annotation)
        current = candidates[0] if candidates else None
    return current


_GENERIC = {
    "missing": ("a value (the field is required)", "nothing"),
    "dict_type": ("a mapping", None),
    "model_type": ("a mapping", None),
    "model_attributes_type": ("a mapping", None),
    "list_type": ("a list", None),
    "tuple_type": ("a list", None),
    "bool_type": ("true or false", None),
    "bool_parsing": ("true or false", None),
    "string_type": ("a text", None),
    "int_type": ("an integer", None),
    "float_type": ("a number", None),
}


def _found(value: Any) -> str:
    return describe_value(value)


def config_error(
    exc: ValidationError,
    source: str,
    model: type[BaseModel],
    source_of: Callable[[tuple[Any, ...]], str] | None = None,
    prefix: tuple[Any, ...] = (),
) -> ConfigError:
    """The first error of ``exc`` as one :class:`ConfigError` naming the file and the field
    (an unknown key before any other error)."""
    errors = exc.errors(include_url=False)
    # an unknown key first: a mistyped key also makes its intended field "missing"
    err = next((e for e in errors if e["type"] == "extra_forbidden"), errors[0])
    loc = tuple(err["loc"])
    where = source_of(loc) if source_of else source
    owner_loc, loc = loc, (*prefix, *loc)
    kind = err["type"]
    ctx = err.get("ctx") or {}
    if kind == "stereoplotter":
        loc = (*loc, *ctx.get("at", ()))
        return ConfigError(
            where, field_path(loc) or "(top level)", ctx["expected"], ctx["found"],
            ctx.get("hint", ""),
        )
    if kind == "extra_forbidden":
        key = str(loc[-1])
        owner = _model_at(model, owner_loc)
        allowed = list(owner.model_fields) if owner is not None else []
        hint = "allowed here: " + ", ".join(allowed) if allowed else ""
        suggestion = did_you_mean(key, allowed)
        hint = f"{hint}; {suggestion}" if hint and suggestion else hint or suggestion
        return ConfigError(where, field_path(loc), "no such field", key, hint)
    expected, found = _GENERIC.get(kind, (err["msg"], None))
    if kind in ("dict_type", "model_type", "model_attributes_type") and isinstance(
        err["input"], Mapping
    ):  # a mapping with non-text keys
        expected = "text keys"
    return ConfigError(
        where,
        field_path(loc) or "(top level)",
        expected,
        found if found is not None else _found(err["input"]),
    )


def validate(
    model: type[M],
    data: Any,
    source: str,
    source_of: Callable[[tuple[Any, ...]], str] | None = None,
    context: dict[str, Any] | None = None,
    prefix: tuple[Any, ...] = (),
) -> M:
    """``model.model_validate(data)``, its first error as a :class:`ConfigError` (field paths
    start with ``prefix``: the place of ``data`` in its file)."""
    if isinstance(data, dict):
        bad = [k for k in data if not isinstance(k, str)]
        if bad:
            raise ConfigError(source, field_path(prefix) or "(top level)", "text keys", bad[0])
    try:
        return model.model_validate(data, context=context)
    except ValidationError as exc:
        raise config_error(exc, source, model, source_of, prefix) from None
