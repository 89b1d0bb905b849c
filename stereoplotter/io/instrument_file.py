"""Reading instrument files (``instruments/*.yaml``) into a frozen
:class:`~stereoplotter.spec.instrument_spec.InstrumentSpec`: name resolution, ``inherits``, the leaf
schema, validation and the mechanics feasibility check.

Every value in an instrument file is a *leaf* ``{value, status, src | basis, note?}``
(``docs/instruments.md``). ``status: documented`` needs ``src``; ``status: assumed`` needs
``basis``. An instrument file may start with ``inherits: family.yaml`` (a file in the same
folder): its sections are merged key by key, the instrument's own leaves win.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from functools import partial
from pathlib import Path
from types import MappingProxyType
from typing import Annotated, Any

import yaml
from pydantic import BeforeValidator, ConfigDict, Field, WithJsonSchema, create_model
from pydantic import model_validator as _model_validator
from pydantic_core import PydanticCustomError

from stereoplotter.errors import ConfigError, StereoplotterError, describe_value, did_you_mean
from stereoplotter.instrument.principles import PRINCIPLES
from stereoplotter.io.paths import data_dir, find_data_file, list_data_files
from stereoplotter.io.validation import (
    FileModel,
    check_number,
    invalid,
    schema_bounds,
    text,
    validate,
)
from stereoplotter.io.yaml_input import load_yaml_mapping
from stereoplotter.spec.instrument_spec import (
    ATTRIBUTE_KEYS,
    DECENTRATION_LINKAGES,
    STATUSES,
    InstrumentSpec,
    Parameter,
)
from stereoplotter.spec.schema_fields import SchemaField as _Leaf

__all__ = ["InstrumentFile", "instrument_from_mapping", "list_instruments", "load_instrument"]

_LEAF_KEYS = ("value", "status", "src", "basis", "note")
_MAX_INHERITANCE_DEPTH = 4

# --- schema -----------------------------------------------------------------------------------


_POS = {"low": 0.0, "low_open": True}

_SCHEMA: tuple[_Leaf, ...] = (
    _Leaf("name", "text"),
    _Leaf("principle", "text"),
    _Leaf("photo.format_mm", "pair", "mm", high=500.0, **_POS),
    _Leaf("photo.camera_f_mm", "range", "mm", high=1000.0, **_POS),
    _Leaf("projection.distance_mm", "range", "mm", high=2000.0, **_POS),
    _Leaf("projection.distance_max_mm", "number", "mm", high=2000.0, required=False, **_POS),
    _Leaf("projection.f_instrument_mm", "range", "mm", high=1000.0, **_POS),
    _Leaf("model.x_offset_mm", "range", "mm", -5000.0, 5000.0, contains_zero=True),
    _Leaf("model.y_offset_mm", "range", "mm", -5000.0, 5000.0, contains_zero=True),
    _Leaf("base.x_mm", "range", "mm", -1000.0, 1000.0),
    _Leaf("base.y_mm", "range", "mm", -1000.0, 1000.0, contains_zero=True),
    _Leaf("base.z_mm", "range", "mm", -1000.0, 1000.0, contains_zero=True),
    _Leaf("orientation.kappa_deg", "range", "deg", -180.0, 180.0, contains_zero=True),
    _Leaf("correction.tilt_max_deg", "number", "deg", high=45.0, **_POS),
    _Leaf("correction.decentration_mm", "range", "mm", -200.0, 200.0, contains_zero=True),
    _Leaf("correction.decentration_linkage", "text", required=False),
    # each correction principle's own leaves, declared as plain data in its module
    *(f for p in PRINCIPLES.values() for f in p.schema_fields),
    _Leaf("counters.present", "bool"),
    _Leaf("counters.direction_switches", "bool"),
    _Leaf("counters.xy_least_count_mm", "number", "mm", high=1.0, **_POS),
    _Leaf("counters.z_abs_least_count_mm", "number", "mm", high=1.0, **_POS),
    _Leaf("counters.height_scale_least_count_m", "number", "m", high=100.0, **_POS),
    _Leaf("counters.scale_least_count_mm", "number", "mm", high=1.0, required=False, **_POS),
    _Leaf("gears.vertical_scale_denominators", "int_list", "—", 1, 10_000_000),
    _Leaf("gears.coordinatograph_ratios", "number_list", "—", high=100.0, **_POS),
    _Leaf("gears.max_photo_to_map_enlargement", "number", "—", high=100.0, required=False, **_POS),
    _Leaf(
        "gears.max_photo_to_map_enlargement_automatic",
        "number",
        "—",
        high=100.0,
        required=False,
        **_POS,
    ),
    _Leaf("gears.photo_to_map_scale_ratio", "range", "—", high=100.0, required=False, **_POS),
    _Leaf("gears.model_to_photo_scale", "range", "—", high=100.0, required=False, **_POS),
    _Leaf("coordinatograph.present", "bool"),
    _Leaf("coordinatograph.automatic_variant", "bool", required=False),
    _Leaf("coordinatograph.table_mm", "pair", "mm", high=5000.0, **_POS),
    _Leaf("coordinatograph.plotting_sigma_mm", "number", "mm", 0.0, 10.0),
    _Leaf("mark.diameter_mm", "number", "mm", high=5.0, **_POS),
    # the operator's eye (procedure.eye): the binocular's magnification and viewing distance
    _Leaf("observation.magnification", "number", "×", 0.5, 100.0, required=False),
    _Leaf("observation.viewing_distance_mm", "number", "mm", 50.0, 1000.0, required=False),
    _Leaf("tolerances.L_check_times_n_mm", "number", "mm", high=10.0, **_POS),
    _Leaf("tolerances.mark_fit_per_n_mm", "number", "mm", high=10.0, **_POS),
    _Leaf("tolerances.residual_q_fraction_of_mark", "number", "—", high=10.0, **_POS),
    _Leaf("tolerances.control_height_denominator", "number", "—", 1.0, 1.0e7),
    _Leaf("tolerances.corner4_mm", "number", "mm", high=100.0, **_POS),
    _Leaf("tolerances.m_q_typical_mm", "number", "mm", high=1.0, **_POS),
    _Leaf("tolerances.standard_points_c_mm", "number", "mm", high=500.0, **_POS),
    # at most 0.2 mm: the unidirectional approach overtravels by 0.5 mm > the dead band 2h
    _Leaf("errors.backlash_xy_mm", "number", "mm", 0.0, 0.2),
    _Leaf("errors.backlash_z_mm", "number", "mm", 0.0, 0.2),
    _Leaf("errors.zero_reading_scatter_mm", "number", "mm", 0.0, 100.0),
    _Leaf("errors.known_zero_error_mm", "number", "mm", 0.0, 100.0),
    _Leaf("errors.counter_scale_error_ppm", "number", "ppm", 0.0, 1.0e4),
    _Leaf("errors.f_instrument_setting_mm", "number", "mm", 0.0, 10.0),
    _Leaf("errors.base_setting_mm", "number", "mm", 0.0, 10.0),
    _Leaf("errors.kappa_setting_arcmin", "number", "′", 0.0, 600.0),
    _Leaf("errors.decentration_setting_mm", "number", "mm", 0.0, 10.0),
    _Leaf("errors.correction_setting_arcmin", "number", "′", 0.0, 600.0),
    _Leaf("errors.coordinatograph_nonorthogonality_arcsec", "number", "″", 0.0, 3600.0),
    _Leaf("errors.pen_play_mm", "number", "mm", 0.0, 10.0),
    _Leaf("errors.sheet_placement_mm", "number", "mm", 0.0, 100.0),
    _Leaf("mechanics.carriage_mass_kg", "number", "kg", 0.001, 1000.0),
    _Leaf("mechanics.z_carriage_mass_kg", "number", "kg", 0.001, 1000.0),
    _Leaf("mechanics.friction_coefficient", "number", "—", 0.0, 2.0),
    # no smaller masses and stiffness: F/k stays finite, the dead band measurable
    _Leaf("mechanics.screw_stiffness_N_per_um", "number", "N/µm", 0.001, 1.0e4),
    _Leaf("mechanics.bridge_mass_kg", "number", "kg", 0.001, 1000.0),
    _Leaf("mechanics.pen_carriage_mass_kg", "number", "kg", 0.001, 1000.0),
    _Leaf("mechanics.sheet_friction_torque_Nm", "number", "N·m", 0.0, 1000.0),
    _Leaf("accuracy.height_error_fraction_of_H", "number", "—", high=1.0, required=False, **_POS),
    _Leaf("facts.n_formula", "text", required=False),
    _Leaf("facts.n_example", "number", "—", high=100.0, required=False, **_POS),
    _Leaf("facts.fiducial_distance_l_mm", "number", "mm", high=500.0, required=False, **_POS),
    _Leaf("facts.error_correction_unit_range_um", "number", "µm", 0.0, 1.0e4, required=False),
    _Leaf("facts.error_correction_unit_rms_um", "number", "µm", 0.0, 1.0e4, required=False),
    _Leaf("facts.photos_move_under_fixed_marks", "bool", required=False),
    _Leaf("facts.base_on_z_carriage", "text", required=False),
    _Leaf("facts.phi_omega_dependent_settings", "int", "—", 0, 100, required=False),
    _Leaf("facts.max_relief_fraction_of_H", "number", "—", high=1.0, required=False, **_POS),
    _Leaf("facts.correction_plane_tilt", "text", required=False),
    _Leaf("facts.mass_kg", "number", "kg", high=1.0e5, required=False, **_POS),
    _Leaf("facts.footprint_cm", "triple", "cm", high=1.0e4, required=False, **_POS),
)
_BY_KEY = {leaf.key: leaf for leaf in _SCHEMA}
_SECTIONS: dict[str, tuple[str, ...]] = {}
for _leaf in _SCHEMA:
    if "." in _leaf.key:
        _section, _name = _leaf.key.split(".", 1)
        _SECTIONS.setdefault(_section, ())
        _SECTIONS[_section] += (_name,)
_TOP_LEAVES = tuple(leaf.key for leaf in _SCHEMA if "." not in leaf.key)

# --- the pydantic models: one leaf model per parameter, one model per section ---------------
#
# They validate ONE file as written: every leaf is optional here (a file with ``inherits`` omits
# the inherited ones, a family file has no name); which leaves an instrument must have is
# checked after the merge (:func:`instrument_from_mapping`). The JSON Schema says the same with
# ``if name and no inherits then required``.

_LEAF_SHAPE = "a leaf {value, status, src | basis, note?}"
_STATUS_HINT = (
    "every value says whether a source documents it; an inferred value is assumed, with a basis"
)


def _at(exc: PydanticCustomError, at: tuple[str | int, ...]) -> PydanticCustomError:
    """The same error one level down (``value[3]``)."""
    ctx = exc.context or {}
    return invalid(ctx["expected"], ctx["found"], ctx.get("hint", ""), at)


def _number(value: Any, leaf: _Leaf, at: tuple[str | int, ...] = ()) -> float:
    try:
        return check_number(
            value, unit=leaf.unit, low=leaf.low, high=leaf.high, low_open=leaf.low_open
        )
    except PydanticCustomError as exc:
        raise _at(exc, at) from None


def _check_value(leaf: _Leaf, raw: Any) -> Any:
    """The ``value`` of one leaf, by its kind (raises the error of :mod:`.validation`)."""
    kind = leaf.kind
    if kind == "text":
        if isinstance(raw, bool) or not isinstance(raw, str | int) or str(raw) == "":
            raise invalid("a non-empty text", describe_value(raw))
        return str(raw)
    if kind == "bool":
        if not isinstance(raw, bool):
            raise invalid("true or false", describe_value(raw))
        return raw
    if kind == "int":
        lo, hi = int(leaf.low), int(leaf.high)
        if isinstance(raw, bool) or not isinstance(raw, int) or not lo <= raw <= hi:
            raise invalid(f"an integer in [{lo}, {hi}]", describe_value(raw))
        return raw
    if kind == "number":
        return _number(raw, leaf)
    if kind in ("range", "pair", "triple"):
        return _check_tuple(leaf, raw)
    return _check_gear_set(leaf, raw)


def _check_tuple(leaf: _Leaf, raw: Any) -> tuple[float, ...]:
    kind = leaf.kind
    length = 3 if kind == "triple" else 2
    if not isinstance(raw, list) or len(raw) != length:
        what = "[lo, hi]" if kind == "range" else f"{length} numbers"
        raise invalid(f"a list of {what} [{leaf.unit}]", describe_value(raw))
    numbers = tuple(_number(v, leaf, (i,)) for i, v in enumerate(raw))
    if kind == "range" and numbers[0] > numbers[1]:
        raise invalid("a range [lo, hi] with lo ≤ hi", list(numbers), "the ends are reversed")
    if leaf.contains_zero and not numbers[0] <= 0.0 <= numbers[1]:
        raise invalid(
            "a range that contains 0",
            list(numbers),
            "the zero position (scales near their zeros, mark on the left plumb point) "
            "must be reachable",
        )
    return numbers


def _check_gear_set(leaf: _Leaf, raw: Any) -> tuple[Any, ...]:
    """int_list, number_list: gear sets, at least one entry, strictly increasing."""
    if not isinstance(raw, list):
        raise invalid("a list", describe_value(raw))
    if not raw:
        raise invalid("a list of at least 1 entries", "0 entries")
    out: list[Any] = []
    for i, v in enumerate(raw):
        if leaf.kind == "int_list":
            if isinstance(v, bool) or not isinstance(v, int) or not leaf.low <= v <= leaf.high:
                raise invalid(
                    f"an integer in [{leaf.low:g}, {leaf.high:g}]", describe_value(v), at=(i,)
                )
            out.append(v)
        else:
            out.append(_number(v, leaf, (i,)))
        if i and out[-1] <= out[-2]:
            raise invalid(f"a value above the previous one ({out[-2]:g})", v, at=(i,))
    return tuple(out)


def _value_schema(leaf: _Leaf) -> dict[str, Any]:
    """The JSON Schema of the ``value`` of one leaf (the check is :func:`_check_value`)."""
    unit = f"[{leaf.unit}]" if leaf.unit and leaf.unit != "—" else None
    bounds = schema_bounds(leaf.low, leaf.high, leaf.low_open, False)
    number: dict[str, Any] = {"type": "number", **bounds}
    kind = leaf.kind
    if kind == "text":
        out: dict[str, Any] = {"type": ["string", "integer"], "minLength": 1}
    elif kind == "bool":
        out = {"type": "boolean"}
    elif kind == "int":
        out = {"type": "integer", "minimum": int(leaf.low), "maximum": int(leaf.high)}
    elif kind == "number":
        out = number
    elif kind in ("range", "pair", "triple"):
        n = 3 if kind == "triple" else 2
        out = {"type": "array", "items": number, "minItems": n, "maxItems": n}
        if kind == "range":
            zero = ", containing 0" if leaf.contains_zero else ""
            out["description"] = f"[lo, hi], lo ≤ hi{zero}"
    else:
        item = number if kind == "number_list" else {
            "type": "integer", "minimum": int(leaf.low), "maximum": int(leaf.high)
        }
        out = {"type": "array", "items": item, "minItems": 1, "description": "increasing"}
    if unit:
        out["description"] = f"{out.get('description', '')} {unit}".strip()
    return out


def _check_status(v: Any) -> str:
    if v not in STATUSES:
        raise invalid("documented or assumed", describe_value(v), _STATUS_HINT)
    return v


def _check_sources(raw: Any) -> tuple[str, ...]:
    items = raw if isinstance(raw, list) else [raw]
    if not items or any(not isinstance(s, str) or not s.strip() for s in items):
        raise invalid("a source key or a list of source keys", describe_value(raw))
    return tuple(s.strip() for s in items)


def _check_note(raw: Any) -> str:
    if not isinstance(raw, str) or not raw.strip():
        raise invalid("a non-empty text", describe_value(raw))
    return raw.strip()


_NOTE = Annotated[
    str, BeforeValidator(_check_note), WithJsonSchema({"type": "string", "pattern": r"\S"})
]
_SOURCE_KEY = {"type": "string", "pattern": r"\S"}


class LeafBase(FileModel):
    """``{value, status, src | basis, note?}``: documented values name their source keys
    (``src``), assumed ones say why (``basis``)."""

    model_config = ConfigDict(
        extra="forbid",
        frozen=True,
        json_schema_extra={
            "if": {"properties": {"status": {"const": "documented"}}},
            "then": {"required": ["src"], "not": {"required": ["basis"]}},
            "else": {"required": ["basis"]},
        },
    )

    status: Annotated[
        str, BeforeValidator(_check_status), WithJsonSchema({"enum": list(STATUSES)})
    ]
    src: Annotated[
        tuple[str, ...],
        BeforeValidator(_check_sources),
        WithJsonSchema(
            {"anyOf": [_SOURCE_KEY, {"type": "array", "items": _SOURCE_KEY, "minItems": 1}]}
        ),
    ] = ()
    basis: _NOTE = ""  # type: ignore[valid-type]
    note: _NOTE = ""  # type: ignore[valid-type]

    @_model_validator(mode="before")
    @classmethod
    def _shape(cls, v: Any) -> Any:
        if not isinstance(v, dict) or v.get("value") is None:
            raise invalid(
                _LEAF_SHAPE,
                describe_value(v),
                "every value says whether a source documents it (see docs/instruments.md)",
            )
        if v.get("status") is None and set(v) <= set(_LEAF_KEYS):
            raise invalid("documented or assumed", "nothing", _STATUS_HINT, at=("status",))
        return v

    @_model_validator(mode="after")
    def _provenance(self) -> LeafBase:
        if self.status == "documented" and not self.src:
            raise invalid(
                "the source key(s) of a documented value (e.g. SEED6)",
                "nothing",
                "a value without a source must be status: assumed with a basis",
                at=("src",),
            )
        if self.status == "documented" and self.basis:
            raise invalid(
                "no basis for a documented value (basis is for assumed ones; use note)",
                self.basis,
                at=("basis",),
            )
        if self.status == "assumed" and not self.basis:
            raise invalid(
                "a basis for an assumed value (why this value was chosen)", "nothing", at=("basis",)
            )
        return self


def _leaf_model(leaf: _Leaf) -> type[LeafBase]:
    value = Annotated[
        Any, BeforeValidator(partial(_check_value, leaf)), WithJsonSchema(_value_schema(leaf))
    ]
    name = "".join(part[:1].upper() + part[1:] for part in leaf.key.replace(".", "_").split("_"))
    return create_model(name, __base__=LeafBase, value=(value, ...))  # type: ignore[call-overload]


_LEAF_MODELS = {leaf.key: _leaf_model(leaf) for leaf in _SCHEMA}


class _SectionBase(FileModel):
    model_config = ConfigDict(extra="forbid", frozen=True, protected_namespaces=())


def _section_model(section: str) -> type[FileModel]:
    leaves = {
        name: (_LEAF_MODELS[f"{section}.{name}"] | None, None) for name in _SECTIONS[section]
    }
    return create_model(  # type: ignore[call-overload]
        section.capitalize() + "Section", __base__=_SectionBase, **leaves
    )


def _required_when_complete() -> dict[str, Any]:
    """JSON Schema: a file with a name and no ``inherits`` is a whole instrument."""
    sections: dict[str, list[str]] = {}
    for leaf in _SCHEMA:
        if leaf.required and "." in leaf.key:
            section, name = leaf.key.split(".", 1)
            sections.setdefault(section, []).append(name)
    top = [leaf.key for leaf in _SCHEMA if leaf.required and "." not in leaf.key]
    return {
        "if": {"required": ["name"], "not": {"required": ["inherits"]}},
        "then": {
            "required": [*top, *sections],
            "properties": {s: {"required": names} for s, names in sections.items()},
        },
    }


class _InstrumentBase(FileModel):
    model_config = ConfigDict(
        extra="forbid",
        frozen=True,
        protected_namespaces=(),
        title="stereoplotter instrument file",
        json_schema_extra=_required_when_complete(),
    )


#: One instrument file as written (``docs/instruments.md``).
InstrumentFile: type[FileModel] = create_model(  # type: ignore[call-overload]
    "InstrumentFile",
    __base__=_InstrumentBase,
    inherits=(text | None, Field(None, description="a file in the same folder to start from")),
    **{name: (_LEAF_MODELS[name] | None, None) for name in _TOP_LEAVES},
    **{section: (_section_model(section) | None, None) for section in _SECTIONS},
)


# --- loading ----------------------------------------------------------------------------------


def load_instrument(name_or_path: str | os.PathLike[str]) -> InstrumentSpec:
    """Load an instrument file by short name (``"sc1"``) or by path.

    Parameters
    ----------
    name_or_path : str or path-like
        A bare name is looked up as ``<name>.yaml`` in the user data folders, then the shipped
        ones (:func:`stereoplotter.io.paths.find_data_file`); anything with a folder part, or an
        existing ``.yaml``/``.yml`` file, is used as a path.

    Returns
    -------
    InstrumentSpec

    Raises
    ------
    ConfigError
        No such instrument, or the file is invalid; the message names the file, the field, what
        was expected and what was found.

    Examples
    --------
    >>> spec = load_instrument("sc1")
    >>> spec.projection_distance_max_mm, spec.status("projection_distance_max_mm")
    (185.0, 'documented')
    >>> spec.base_z_range_mm, spec.is_assumed("base_z_range_mm")
    ((-40.0, 40.0), True)
    """
    path = _resolve(name_or_path)
    data, source = load_yaml_mapping(path)
    return instrument_from_mapping(data, source)


def instrument_from_mapping(
    data: dict[str, Any], source: str = "<instrument>", *, key: str | None = None
) -> InstrumentSpec:
    """Validate a parsed instrument document and build the :class:`InstrumentSpec`.

    Parameters
    ----------
    data : dict
        The parsed YAML.
    source : str
        The file name: used in messages, for the default ``key`` (its stem) and to find an
        ``inherits`` file (in the same folder).
    key : str, optional
        Short name; default the stem of ``source``.
    """
    leaves, origins = _merge_inherited(data, source, chain=(_norm(source),))
    params: dict[str, Parameter] = {}
    for leaf in _SCHEMA:
        node = leaves.get(leaf.key)
        if node is None:
            if leaf.required:
                raise ConfigError(
                    source,
                    leaf.key,
                    "a value {value, status, src | basis} (the field is required)",
                    "nothing",
                    _inherit_hint(data),
                )
            continue
        params[leaf.key] = Parameter(
            node.value,  # type: ignore[attr-defined]
            leaf.unit,
            node.status,
            node.src,
            node.basis,
            node.note,
            origins[leaf.key],
        )
    _cross_check(params, source)
    values: dict[str, Any] = {}
    for attribute, (dotted, convert) in ATTRIBUTE_KEYS.items():
        values[attribute] = convert(params[dotted].value) if dotted in params else None
    if values["decentration_linkage"] is None:  # files without the leaf: decision D1
        values["decentration_linkage"] = DECENTRATION_LINKAGES[0]
    if values["projection_distance_max_mm"] is None:
        values["projection_distance_max_mm"] = values["projection_distance_range_mm"][1]
    spec = InstrumentSpec(
        key=key or Path(source).stem,
        source=source,
        parameters=MappingProxyType(params),
        **values,
    )
    _check_mechanics(spec)
    return spec


def _check_mechanics(spec: InstrumentSpec) -> None:
    """Refuse ``mechanics.*`` and ``errors.backlash_*`` values that give no working screw axis
    (``mechanics.md``): μ ≥ 1 on the vertical Z axis, or a dead band 2h = b + 2μmg/k that the
    0.5 mm overtravel of the unidirectional approach does not clear. The axes are built as the
    virtual instrument builds them, so a file that loads also runs."""
    # imported here: ``info`` lists the instrument files through this module without loading
    # the instrument's mechanics (pymunk)
    from stereoplotter.instrument.mechanics.base import N_PER_UM, AxisParams
    from stereoplotter.instrument.mechanics.coordinatograph import CoordinatographParams

    def refuse(key: str, exc: StereoplotterError, hint: str = "") -> ConfigError:
        return ConfigError(
            spec.parameters[key].file,
            f"{key}.value",
            "a value that gives a working screw axis (mechanics.md: μ < 1 on the vertical "
            "axis, dead band 2h = backlash b + 2μmg/k below the 0.5 mm overtravel)",
            str(exc),
            hint,
        )

    overtravel = AxisParams.__dataclass_fields__["overtravel_mm"].default
    # as Instrument._axis_params builds them: (axis, range, backlash, mass)
    axes = [
        ("X", "model_x_offset_range_mm", "backlash_xy_mm", "carriage_mass_kg"),
        ("Y", "model_y_offset_range_mm", "backlash_xy_mm", "carriage_mass_kg"),
        ("Z", "projection_distance_range_mm", "backlash_z_mm", "z_carriage_mass_kg"),
        ("bx", "base_x_range_mm", "backlash_xy_mm", "carriage_mass_kg"),
        ("by", "base_y_range_mm", "backlash_xy_mm", "carriage_mass_kg"),
        ("bz", "base_z_range_mm", "backlash_z_mm", "carriage_mass_kg"),
    ]
    for name, range_attribute, backlash_attribute, mass_attribute in axes:
        backlash = float(getattr(spec, backlash_attribute))
        vertical = name == "Z"
        backlash_key, mass_key = (spec.key_of(a) for a in (backlash_attribute, mass_attribute))
        lo, hi = getattr(spec, range_attribute)
        try:
            AxisParams(
                name=f"{spec.key} {name}",
                backlash_mm=backlash,
                friction=spec.friction_coefficient,
                mass_kg=getattr(spec, mass_attribute),
                stiffness_kg_s2=spec.screw_stiffness_N_per_um * N_PER_UM,
                range_mm=(float(lo), float(hi)),
                vertical=vertical,
            )
        except StereoplotterError as exc:
            # the key to change: a range without travel; μ on the vertical axis; b where it
            # alone fills half the overtravel; else the 2μmg/k part, named by its mass
            if not lo < hi:
                raise ConfigError(
                    spec.parameters[spec.key_of(range_attribute)].file,
                    f"{spec.key_of(range_attribute)}.value",
                    "a range [lo, hi] with lo < hi (the axis must travel)",
                    [lo, hi],
                ) from None
            if vertical and spec.friction_coefficient >= 1.0:
                key = "mechanics.friction_coefficient"
            elif 2.0 * backlash >= 0.5 * overtravel:
                key = backlash_key
            else:
                key = mass_key
            hint = "or lower μ, or raise the screw stiffness k" if key == mass_key else ""
            raise refuse(key, exc, hint) from None
    try:
        CoordinatographParams.from_instrument(spec)
    except StereoplotterError as exc:
        mass_key = "mechanics.pen_carriage_mass_kg" if " Y:" in str(exc) else (
            "mechanics.bridge_mass_kg"
        )
        raise refuse(mass_key, exc, "or lower mechanics.friction_coefficient") from None


def _resolve(name_or_path: str | os.PathLike[str]) -> Path:
    text = os.fspath(name_or_path)
    if isinstance(name_or_path, os.PathLike) or os.sep in text or "/" in text:
        return Path(text)
    is_file_name = text.endswith((".yaml", ".yml"))
    if is_file_name and Path(text).exists():
        return Path(text)
    # user folders (--data, STEREOPLOTTER_DATA) first, then the shipped data
    candidate = find_data_file("instruments", text)
    if candidate is None and is_file_name:
        return Path(text)  # reading it reports the missing file
    folder = data_dir("instruments")
    if candidate is None:
        names = list_instruments()
        available = ", ".join(names) or "none found"
        raise ConfigError(
            _display(folder) if folder else "instruments/",
            text,
            f"the name of an instrument ({available}) or a path to a YAML file",
            "no such instrument file",
            did_you_mean(text, names),
        )
    return Path(_display(candidate))


def _display(path: Path) -> str:
    """A path relative to the current folder when it lies inside it (shorter messages)."""
    try:
        return str(path.resolve().relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(path)


def _norm(source: str) -> str:
    try:
        return str(Path(source).resolve())
    except (OSError, RuntimeError):
        return source


def _inherit_hint(data: Mapping[str, Any]) -> str:
    if isinstance(data.get("inherits"), str):
        return f"not in this file nor in {data['inherits']}"
    return ""


def _leaves(doc: FileModel) -> dict[str, LeafBase]:
    """The leaves a validated file gives, by dotted key."""
    out: dict[str, LeafBase] = {}
    for name in _TOP_LEAVES:
        if getattr(doc, name) is not None:
            out[name] = getattr(doc, name)
    for section, names in _SECTIONS.items():
        node = getattr(doc, section)
        if node is None:
            continue
        for name in names:
            if getattr(node, name) is not None:
                out[f"{section}.{name}"] = getattr(node, name)
    return out


def _merge_inherited(
    data: dict[str, Any], source: str, chain: tuple[str, ...]
) -> tuple[dict[str, LeafBase], dict[str, str]]:
    """The leaves of the file and of its ``inherits`` chain (its own win), and the file each
    leaf came from. Each file is validated as written before the merge, so an error names the
    file that has it."""
    doc = validate(InstrumentFile, data, source)
    leaves: dict[str, LeafBase] = {}
    origins: dict[str, str] = {}
    name = doc.inherits  # type: ignore[attr-defined]
    if name is not None:
        parent_path = Path(source).parent / name
        if not parent_path.is_file():
            raise ConfigError(
                source, "inherits", "the name of an existing file in the same folder", name
            )
        if _norm(str(parent_path)) in chain or len(chain) > _MAX_INHERITANCE_DEPTH:
            raise ConfigError(
                source,
                "inherits",
                f"a chain of at most {_MAX_INHERITANCE_DEPTH} files without a loop",
                name,
                "files: " + " → ".join(Path(c).name for c in chain),
            )
        parent, parent_source = load_yaml_mapping(parent_path)
        leaves, origins = _merge_inherited(parent, parent_source, (*chain, _norm(parent_source)))
    own = _leaves(doc)
    leaves.update(own)
    origins.update(dict.fromkeys(own, source))
    return leaves, origins


def _cross_check(params: Mapping[str, Parameter], source: str) -> None:
    link = params.get("correction.decentration_linkage")
    if link is not None and link.value not in DECENTRATION_LINKAGES:
        raise ConfigError(
            link.file or source,
            "correction.decentration_linkage.value",
            " or ".join(DECENTRATION_LINKAGES),
            link.value,
            "drag: turning k_α, k_ω moves the decentrations (D1); independent: it does not",
        )
    d_max = params.get("projection.distance_max_mm")
    if d_max is not None:
        hi = params["projection.distance_mm"].value[1]
        if not math.isclose(d_max.value, hi, rel_tol=0.0, abs_tol=1e-9):
            raise ConfigError(
                d_max.file or source,
                "projection.distance_max_mm.value",
                f"the upper end of projection.distance_mm ({hi:g} mm)",
                d_max.value,
                "D_max is the deepest position of the carriage; change both together",
            )

def list_instruments() -> list[str]:
    """Short names of the instrument files in the ``instruments`` data folder.

    Files without a top-level ``name`` (shared family files meant for ``inherits``) are not
    instruments and are left out.

    Examples
    --------
    >>> {"sc1", "spr3", "sd3"} <= set(list_instruments())
    True
    """
    names = []
    for path in list_data_files("instruments"):
        try:
            data = yaml.safe_load(path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, yaml.YAMLError):
            data = {"name": None}  # list it: loading it reports the problem
        if isinstance(data, dict) and "name" in data:
            names.append(path.stem)
    return names
