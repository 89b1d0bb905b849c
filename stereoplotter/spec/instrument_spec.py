"""Instrument specifications: the frozen :class:`InstrumentSpec` of one instrument file.

Every value in an instrument file is a *leaf* ``{value, status, src | basis, note?}``
(``docs/instruments.md``). ``status: documented`` needs ``src`` (the source keys, e.g. ``SEED6``
for Kushtin & Lyskov 1984, ch. 6); ``status: assumed`` needs ``basis`` (why the value was chosen)
and may name the ``src`` of a relative it was taken from. No factory data sheet of SC-1, SPR-3
or SD-3 was found, so most ranges, least counts and gear sets are assumed;
:meth:`InstrumentSpec.is_assumed` lets every caller flag what rests on them.

Units: the YAML carries the unit in the key (``_mm``, ``_deg``, ``_m``); the typed attributes of
:class:`InstrumentSpec` are in mm, m (height scale only) and radians. Ranges are ``(lo, hi)``
tuples. A setting outside a range is refused with
:class:`~stereoplotter.spec.range_checks.RangeRefusal` by
:func:`~stereoplotter.spec.range_checks.check_in_range`, like a mechanical stop; nothing is ever
clipped.

This module is pure data: reading and validating the files is
:mod:`stereoplotter.io.instrument_file` (``load_instrument``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, ClassVar

__all__ = [
    "ATTRIBUTE_KEYS",
    "DECENTRATION_LINKAGES",
    "STATUSES",
    "InstrumentSpec",
    "Parameter",
    "format_instrument",
    "instrument_to_dict",
]

#: The two status labels of a leaf (``docs/instruments.md``).
STATUSES = ("documented", "assumed")
#: ``correction.decentration_linkage``: turning a k_α, k_ω knob drags the photo and plane
#: decentrations ("drag", decision D1, the default of a file without the leaf) or leaves them
#: ("independent").
DECENTRATION_LINKAGES = ("drag", "independent")


@dataclass(frozen=True, slots=True)
class Parameter:
    """One leaf of an instrument file, for display and provenance.

    Attributes
    ----------
    value : object
        As in the YAML (lists become tuples; angles stay in degrees).
    unit : str
        ``"mm"``, ``"deg"``, ``"m"``, ``"—"`` (dimensionless) or ``""`` (text, yes/no).
    status : str
        ``"documented"`` or ``"assumed"``.
    source : tuple of str
        Source keys (``src``), e.g. ``("SEED6",)``; may be empty for an assumed value.
    basis : str
        Why an assumed value was chosen ("" for documented values).
    note : str
        Free remark ("" when absent).
    file : str
        The file the leaf was read from (an instrument file or the file it inherits from).
    """

    value: Any
    unit: str
    status: str
    source: tuple[str, ...]
    basis: str
    note: str
    file: str

    @property
    def is_assumed(self) -> bool:
        """True unless a source documents the value."""
        return self.status == "assumed"

    def label(self) -> str:
        """``[documented: SEED6]`` or ``[ASSUMED: basis]``."""
        if self.is_assumed:
            return f"[ASSUMED: {self.basis}]"
        return f"[documented: {', '.join(self.source)}]"


_RAD = math.pi / 180.0


def _same(v: Any) -> Any:
    return v


def _deg_range(v: tuple[float, float]) -> tuple[float, float]:
    return (v[0] * _RAD, v[1] * _RAD)


#: attribute → (dotted key, converter from the YAML value to the attribute's unit).
ATTRIBUTE_KEYS: dict[str, tuple[str, Callable[[Any], Any]]] = {
    "title": ("name", _same),
    "principle": ("principle", _same),
    "photo_format_mm": ("photo.format_mm", _same),
    "camera_f_range_mm": ("photo.camera_f_mm", _same),
    "projection_distance_range_mm": ("projection.distance_mm", _same),
    "projection_distance_max_mm": ("projection.distance_max_mm", _same),
    "f_instrument_range_mm": ("projection.f_instrument_mm", _same),
    "model_x_offset_range_mm": ("model.x_offset_mm", _same),
    "model_y_offset_range_mm": ("model.y_offset_mm", _same),
    "base_x_range_mm": ("base.x_mm", _same),
    "base_y_range_mm": ("base.y_mm", _same),
    "base_z_range_mm": ("base.z_mm", _same),
    "kappa_range": ("orientation.kappa_deg", _deg_range),
    "tilt_max": ("correction.tilt_max_deg", lambda v: v * _RAD),
    "decentration_range_mm": ("correction.decentration_mm", _same),
    "decentration_linkage": ("correction.decentration_linkage", _same),
    "counters_present": ("counters.present", _same),
    "direction_switches": ("counters.direction_switches", _same),
    "xy_least_count_mm": ("counters.xy_least_count_mm", _same),
    "z_least_count_mm": ("counters.z_abs_least_count_mm", _same),
    "height_scale_least_count_m": ("counters.height_scale_least_count_m", _same),
    "vertical_scale_denominators": ("gears.vertical_scale_denominators", _same),
    "coordinatograph_ratios": ("gears.coordinatograph_ratios", _same),
    "max_photo_to_map_enlargement": ("gears.max_photo_to_map_enlargement", _same),
    "coordinatograph_present": ("coordinatograph.present", _same),
    "coordinatograph_table_mm": ("coordinatograph.table_mm", _same),
    "coordinatograph_sigma_mm": ("coordinatograph.plotting_sigma_mm", _same),
    "corner_tolerance_mm": ("tolerances.corner4_mm", _same),
    "mark_diameter_mm": ("mark.diameter_mm", _same),
    "tolerance_L_numerator_mm": ("tolerances.L_check_times_n_mm", _same),
    "tolerance_mark_fit_per_n_mm": ("tolerances.mark_fit_per_n_mm", _same),
    "residual_q_fraction_of_mark": ("tolerances.residual_q_fraction_of_mark", _same),
    "control_height_fraction_of_H": ("tolerances.control_height_denominator", lambda v: 1.0 / v),
    "pointing_error_typical_mm": ("tolerances.m_q_typical_mm", _same),
    "standard_points_c_mm": ("tolerances.standard_points_c_mm", _same),
    "backlash_xy_mm": ("errors.backlash_xy_mm", _same),
    "backlash_z_mm": ("errors.backlash_z_mm", _same),
    "zero_reading_scatter_mm": ("errors.zero_reading_scatter_mm", _same),
    "known_zero_error_mm": ("errors.known_zero_error_mm", _same),
    "counter_scale_error_ppm": ("errors.counter_scale_error_ppm", _same),
    "f_instrument_setting_sigma_mm": ("errors.f_instrument_setting_mm", _same),
    "base_setting_sigma_mm": ("errors.base_setting_mm", _same),
    "kappa_setting_sigma": ("errors.kappa_setting_arcmin", lambda v: v * _RAD / 60.0),
    "decentration_setting_sigma_mm": ("errors.decentration_setting_mm", _same),
    "correction_setting_sigma": ("errors.correction_setting_arcmin", lambda v: v * _RAD / 60.0),
    "coordinatograph_nonorthogonality_sigma": (
        "errors.coordinatograph_nonorthogonality_arcsec",
        lambda v: v * _RAD / 3600.0,
    ),
    "pen_play_mm": ("errors.pen_play_mm", _same),
    "sheet_placement_sigma_mm": ("errors.sheet_placement_mm", _same),
    "carriage_mass_kg": ("mechanics.carriage_mass_kg", _same),
    "z_carriage_mass_kg": ("mechanics.z_carriage_mass_kg", _same),
    "friction_coefficient": ("mechanics.friction_coefficient", _same),
    "screw_stiffness_N_per_um": ("mechanics.screw_stiffness_N_per_um", _same),
    "bridge_mass_kg": ("mechanics.bridge_mass_kg", _same),
    "pen_carriage_mass_kg": ("mechanics.pen_carriage_mass_kg", _same),
    "sheet_friction_torque_Nm": ("mechanics.sheet_friction_torque_Nm", _same),
    "height_error_fraction_of_H": ("accuracy.height_error_fraction_of_H", _same),
}


# --- the spec ---------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class InstrumentSpec:
    """The parameters of one instrument, typed and traceable to their YAML leaves.

    Load with :func:`stereoplotter.io.instrument_file.load_instrument`. Ranges are ``(lo, hi)``
    tuples; lengths in mm, angles in radians. :attr:`KEYS` maps each typed attribute to the
    dotted YAML key it comes from, and :meth:`is_assumed` / :meth:`status` accept either an
    attribute name or a dotted key.

    Attributes
    ----------
    key : str
        Short name, the file stem (``"sc1"``).
    title : str
        Full name (``name`` in the YAML).
    source : str
        The file the spec was loaded from.
    projection_distance_range_mm : tuple of float
        [D_min, D_max], depth of a model point below the left projection centre S_л. [mm]
    projection_distance_max_mm : float
        D_max of (6.3); ``projection.distance_max_mm`` if given, else the upper end of the range.
    f_instrument_range_mm : tuple of float
        Range of the instrument principal distance f_пр. [mm]
    model_x_offset_range_mm, model_y_offset_range_mm : tuple of float
        Carriage travel as counter offsets from the left plumb point (X − MO_X, Y − MO_Y). [mm]
    base_x_range_mm, base_y_range_mm, base_z_range_mm : tuple of float
        b_x, b_y and b_z′ = k·b_z as set on the base carriage. [mm]
    kappa_range : tuple of float
        Cassette rotation κ. [rad]
    tilt_max : float
        Largest |α|, |ω| the correction mechanisms handle. [rad]
    decentration_range_mm : tuple of float
        Decentration scales (photo and correction mechanism). [mm]
    decentration_linkage : str
        "drag" or "independent" (:data:`DECENTRATION_LINKAGES`): whether turning a k_α, k_ω
        knob moves the decentrations; "drag" when the file does not say.
    xy_least_count_mm, z_least_count_mm : float
        Least counts of the X/Y counters and of the absolute height counter. [mm]
    height_scale_least_count_m : float
        Least count of the metre slip scale of the height counter. [m]
    vertical_scale_denominators : tuple of int
        Height-counter gear set: the M_в the counter can be geared for.
    coordinatograph_ratios : tuple of float
        Coordinatograph gear set: r = M_г / M_map. [—]
    coordinatograph_table_mm : tuple of float
        Drawing table (width, height). [mm]
    coordinatograph_sigma_mm : float
        Plotting error (one σ per coordinate) injected by the simulator. [mm]
    corner_tolerance_mm : float
        Stage-5 check: misfit of the needle at corner 4. [mm]
    mark_diameter_mm : float
        Diameter of the measuring mark. [mm]
    tolerance_L_numerator_mm : float
        Stage 1: |L − L′| ≤ tolerance_L_numerator_mm / n_л. [mm]
    tolerance_mark_fit_per_n_mm : float
        Stage 2: mark-4 misfit ≤ tolerance_mark_fit_per_n_mm · n_л. [mm]
    residual_q_fraction_of_mark : float
        Residual y-parallax ≤ this fraction of the mark diameter. [—]
    control_height_fraction_of_H : float
        Control-height discrepancy ≤ this fraction of the mean flying height H (1/3000). [—]
    camera_f_range_mm : tuple of float
        Camera focal lengths the instrument accepts. [mm]
    photo_format_mm : tuple of float
        Photo format (width, height). [mm]
    parameters : Mapping[str, Parameter]
        Every leaf by dotted key, for display and provenance.
    """

    key: str
    title: str
    source: str
    principle: str
    photo_format_mm: tuple[float, float]
    camera_f_range_mm: tuple[float, float]
    projection_distance_range_mm: tuple[float, float]
    projection_distance_max_mm: float
    f_instrument_range_mm: tuple[float, float]
    model_x_offset_range_mm: tuple[float, float]
    model_y_offset_range_mm: tuple[float, float]
    base_x_range_mm: tuple[float, float]
    base_y_range_mm: tuple[float, float]
    base_z_range_mm: tuple[float, float]
    kappa_range: tuple[float, float]
    tilt_max: float
    decentration_range_mm: tuple[float, float]
    decentration_linkage: str
    counters_present: bool
    direction_switches: bool
    xy_least_count_mm: float
    z_least_count_mm: float
    height_scale_least_count_m: float
    vertical_scale_denominators: tuple[int, ...]
    coordinatograph_ratios: tuple[float, ...]
    max_photo_to_map_enlargement: float | None
    coordinatograph_present: bool
    coordinatograph_table_mm: tuple[float, float]
    coordinatograph_sigma_mm: float
    corner_tolerance_mm: float
    mark_diameter_mm: float
    tolerance_L_numerator_mm: float
    tolerance_mark_fit_per_n_mm: float
    residual_q_fraction_of_mark: float
    control_height_fraction_of_H: float
    pointing_error_typical_mm: float
    standard_points_c_mm: float
    backlash_xy_mm: float
    backlash_z_mm: float
    zero_reading_scatter_mm: float
    known_zero_error_mm: float
    counter_scale_error_ppm: float
    f_instrument_setting_sigma_mm: float
    base_setting_sigma_mm: float
    kappa_setting_sigma: float
    decentration_setting_sigma_mm: float
    correction_setting_sigma: float
    coordinatograph_nonorthogonality_sigma: float
    pen_play_mm: float
    sheet_placement_sigma_mm: float
    carriage_mass_kg: float
    z_carriage_mass_kg: float
    friction_coefficient: float
    screw_stiffness_N_per_um: float
    bridge_mass_kg: float
    pen_carriage_mass_kg: float
    sheet_friction_torque_Nm: float
    height_error_fraction_of_H: float | None
    parameters: Mapping[str, Parameter] = field(repr=False)

    #: Typed attribute → dotted YAML key. ``projection_distance_max_mm`` falls back to
    #: ``projection.distance_mm`` when the file has no separate D_max (see :meth:`key_of`).
    KEYS: ClassVar[Mapping[str, str]] = MappingProxyType(
        {name: key for name, (key, _) in ATTRIBUTE_KEYS.items()}
    )

    def key_of(self, attribute_name: str) -> str:
        """The dotted YAML key a typed attribute comes from.

        Examples
        --------
        >>> from stereoplotter.io.instrument_file import load_instrument
        >>> spec = load_instrument("sc1")
        >>> spec.key_of("base_z_range_mm")
        'base.z_mm'
        >>> load_instrument("sd3").key_of("projection_distance_max_mm")
        'projection.distance_mm'
        """
        try:
            key = self.KEYS[attribute_name]
        except KeyError:
            raise KeyError(
                f"{attribute_name!r} is not a typed attribute of InstrumentSpec; "
                f"known: {', '.join(self.KEYS)}"
            ) from None
        if key not in self.parameters and attribute_name == "projection_distance_max_mm":
            return "projection.distance_mm"
        return key

    def parameter(self, name: str) -> Parameter:
        """The leaf behind a dotted key or a typed attribute name."""
        key = name if name in self.parameters else None
        if key is None and name in self.KEYS:
            key = self.key_of(name)
        if key is None or key not in self.parameters:
            raise KeyError(
                f"{name!r} is neither a key of {self.source} nor a typed attribute of "
                "InstrumentSpec"
            )
        return self.parameters[key]

    def status(self, name: str) -> str:
        """``"documented"`` or ``"assumed"`` for a dotted key or a typed attribute name.

        Examples
        --------
        >>> from stereoplotter.io.instrument_file import load_instrument
        >>> spec = load_instrument("sc1")
        >>> spec.status("projection_distance_max_mm"), spec.status("base.z_mm")
        ('documented', 'assumed')
        """
        return self.parameter(name).status

    def is_assumed(self, name: str) -> bool:
        """True if the value behind a dotted key or typed attribute rests on an assumption."""
        return self.parameter(name).is_assumed

    def counts(self) -> dict[str, int]:
        """How many leaves are documented and how many assumed."""
        out = dict.fromkeys(STATUSES, 0)
        for p in self.parameters.values():
            out[p.status] += 1
        return out

    @property
    def n_range(self) -> tuple[float, float]:
        """Derived range of the counter scale coefficient n = D / f_пр, (6.3). [—]

        It rests on ``projection.distance_mm`` and ``projection.f_instrument_mm``; it is assumed
        whenever either is.
        """
        d_lo, d_hi = self.projection_distance_range_mm
        f_lo, f_hi = self.f_instrument_range_mm
        return (d_lo / f_hi, d_hi / f_lo)


# --- presentation -----------------------------------------------------------------------------


def _json_value(value: Any) -> Any:
    if isinstance(value, tuple):
        return [_json_value(v) for v in value]
    return value


def instrument_to_dict(spec: InstrumentSpec) -> dict[str, Any]:
    """A JSON-ready description: every parameter with value, unit, status and provenance.

    Examples
    --------
    >>> from stereoplotter.io.instrument_file import load_instrument
    >>> d = instrument_to_dict(load_instrument("sc1"))
    >>> d_max = d["parameters"]["projection.distance_max_mm"]
    >>> d_max["value"], d_max["unit"], d_max["status"], d_max["src"]
    (185.0, 'mm', 'documented', ['SEED6'])
    """
    return {
        "key": spec.key,
        "title": spec.title,
        "file": spec.source,
        "counts": spec.counts(),
        "parameters": {
            key: {
                "value": _json_value(p.value),
                "unit": p.unit,
                "status": p.status,
                "src": list(p.source),
                "basis": p.basis or None,
                "note": p.note or None,
                "file": p.file,
            }
            for key, p in spec.parameters.items()
        },
        "derived": {
            "n_range": list(spec.n_range),
            "n_range_status": (
                "assumed"
                if spec.is_assumed("projection.distance_mm")
                or spec.is_assumed("projection.f_instrument_mm")
                else "documented"
            ),
        },
    }


def _format_value(p: Parameter) -> str:
    unit = f" {p.unit}" if p.unit not in ("", "—") else ""
    v = p.value
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, tuple):
        return "[" + ", ".join(f"{x:g}" for x in v) + "]" + unit
    if isinstance(v, int | float):
        return f"{v:g}{unit}"
    return str(v)


def format_instrument(spec: InstrumentSpec, *, notes: bool = True) -> str:
    """Human-readable listing, grouped by section, each value labelled documented or ASSUMED.

    Parameters
    ----------
    spec : InstrumentSpec
    notes : bool
        Print each leaf's note on an indented line below it.

    Examples
    --------
    >>> from stereoplotter.io.instrument_file import load_instrument
    >>> text = format_instrument(load_instrument("sc1"))
    >>> print(text.splitlines()[2])  # doctest: +ELLIPSIS
    values: 20 documented, 47 assumed (ASSUMED: no source states it for this instrument; edit ...
    >>> [line.strip() for line in text.splitlines() if line.startswith("  distance_max_mm")]
    ['distance_max_mm = 185 mm  [documented: SEED6]']
    """
    counts = spec.counts()
    lines = [
        f"{spec.title}  [{spec.key}]",
        f"file: {spec.source}",
        f"values: {counts['documented']} documented, {counts['assumed']} assumed "
        "(ASSUMED: no source states it for this instrument; edit the YAML to change it)",
    ]
    current = None
    for key, p in spec.parameters.items():
        section, _, name = key.rpartition(".")
        if section != current:
            lines.append("")
            lines.append(f"{section or 'instrument'}:")
            current = section
        lines.append(f"  {name} = {_format_value(p)}  {p.label()}")
        if p.is_assumed and p.source:
            lines.append(f"      taken from: {', '.join(p.source)}")
        if notes and p.note:
            lines.append(f"      note: {p.note}")
        if p.file != spec.source:
            lines.append(f"      from: {p.file}")
    lo, hi = spec.n_range
    n_status = (
        "ASSUMED: rests on projection.distance_mm and projection.f_instrument_mm"
        if spec.is_assumed("projection.distance_mm")
        or spec.is_assumed("projection.f_instrument_mm")
        else "documented"
    )
    lines += ["", "derived:", f"  n = D / f_пр (6.3) in [{lo:.3g}, {hi:.3g}]  [{n_status}]"]
    return "\n".join(lines) + "\n"
