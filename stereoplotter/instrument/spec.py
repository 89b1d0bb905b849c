"""Instrument specifications: ``instruments/*.yaml`` loaded into a frozen :class:`InstrumentSpec`.

Every value in an instrument file is a *leaf* ``{value, status, src | basis, note?}``
(``docs/instruments.md``). ``status: documented`` needs ``src`` (the source keys, e.g. ``SEED6``
for Kushtin & Lyskov 1984, ch. 6); ``status: assumed`` needs ``basis`` (why the value was chosen)
and may name the ``src`` of a relative it was taken from. No factory data sheet of SC-1, SPR-3
or SD-3 was found, so most ranges, least counts and gear sets are assumed;
:meth:`InstrumentSpec.is_assumed` lets every caller flag what rests on them.

Units: the YAML carries the unit in the key (``_mm``, ``_deg``, ``_m``); the typed attributes of
:class:`InstrumentSpec` are in mm, m (height scale only) and radians. Ranges are ``(lo, hi)``
tuples. A setting outside a range is refused with :class:`RangeRefusal` by
:func:`check_in_range`, like a mechanical stop; nothing is ever clipped.

An instrument file may start with ``inherits: family.yaml`` (a file in the same folder): its
sections are merged key by key, the instrument's own leaves win.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, ClassVar

import yaml

from stereoplotter.errors import ConfigError, StereoplotterError
from stereoplotter.io.paths import data_dir, find_data_file, list_data_files
from stereoplotter.io.yaml_files import Fields, describe_value, did_you_mean, load_yaml_mapping

__all__ = [
    "STATUSES",
    "InstrumentSpec",
    "Parameter",
    "RangeRefusal",
    "check_in_range",
    "format_instrument",
    "instrument_from_mapping",
    "instrument_to_dict",
    "list_instruments",
    "load_instrument",
]

#: The two status labels of a leaf (``docs/instruments.md``).
STATUSES = ("documented", "assumed")

_LEAF_KEYS = ("value", "status", "src", "basis", "note")
_MAX_INHERITANCE_DEPTH = 4


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


# --- schema -----------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class _Leaf:
    key: str
    kind: str  # text, bool, int, number, range, pair, triple, int_list, number_list
    unit: str = ""
    low: float = -math.inf
    high: float = math.inf
    low_open: bool = False
    required: bool = True
    contains_zero: bool = False


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
    _Leaf("counters.present", "bool"),
    _Leaf("counters.direction_switches", "bool"),
    _Leaf("counters.xy_least_count_mm", "number", "mm", high=1.0, **_POS),
    _Leaf("counters.z_abs_least_count_mm", "number", "mm", high=1.0, **_POS),
    _Leaf("counters.height_scale_least_count_m", "number", "m", high=100.0, **_POS),
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
_TOP = ("inherits", *_TOP_LEAVES, *_SECTIONS)

_RAD = math.pi / 180.0


def _same(v: Any) -> Any:
    return v


def _deg_range(v: tuple[float, float]) -> tuple[float, float]:
    return (v[0] * _RAD, v[1] * _RAD)


#: attribute → (dotted key, converter from the YAML value to the attribute's unit).
_ATTRIBUTES: dict[str, tuple[str, Callable[[Any], Any]]] = {
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

    Load with :func:`load_instrument`. Ranges are ``(lo, hi)`` tuples; lengths in mm, angles in
    radians. :attr:`KEYS` maps each typed attribute to the dotted YAML key it comes from, and
    :meth:`is_assumed` / :meth:`status` accept either an attribute name or a dotted key.

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
        {name: key for name, (key, _) in _ATTRIBUTES.items()}
    )

    def key_of(self, attribute_name: str) -> str:
        """The dotted YAML key a typed attribute comes from.

        Examples
        --------
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
    fields = Fields(source)
    merged, origins = _merge_inherited(fields, data, source, chain=(_norm(source),))
    params: dict[str, Parameter] = {}
    for leaf in _SCHEMA:
        section, _, name = leaf.key.rpartition(".")
        node = merged.get(section, {}) if section else merged
        if name not in node:
            if leaf.required:
                raise fields.error(
                    leaf.key,
                    "a value {value, status, src | basis} (the field is required)",
                    "nothing",
                    _inherit_hint(data),
                )
            continue
        origin = origins.get(leaf.key, source)
        params[leaf.key] = _parameter(Fields(origin), node[name], leaf, origin)
    _cross_check(fields, params, origins, source)
    values: dict[str, Any] = {}
    for attribute, (dotted, convert) in _ATTRIBUTES.items():
        values[attribute] = convert(params[dotted].value) if dotted in params else None
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
    if "inherits" in data:
        return f"not in this file nor in {data['inherits']}"
    return ""


def _check_structure(fields: Fields, data: Mapping[str, Any]) -> None:
    fields.mapping(data, "", _TOP)
    for section, names in _SECTIONS.items():
        if section in data:
            fields.mapping(data[section], section, names)


def _merge_inherited(
    fields: Fields, data: dict[str, Any], source: str, chain: tuple[str, ...]
) -> tuple[dict[str, Any], dict[str, str]]:
    """The document with its ``inherits`` file merged in, and the file each leaf came from."""
    _check_structure(fields, data)
    merged: dict[str, Any] = {}
    origins: dict[str, str] = {}
    if "inherits" in data:
        name = fields.text(data, "inherits", "")
        parent_path = Path(source).parent / name
        if not parent_path.is_file():
            raise fields.error("inherits", "the name of an existing file in the same folder", name)
        if _norm(str(parent_path)) in chain or len(chain) > _MAX_INHERITANCE_DEPTH:
            raise fields.error(
                "inherits",
                f"a chain of at most {_MAX_INHERITANCE_DEPTH} files without a loop",
                name,
                "files: " + " → ".join(Path(c).name for c in chain),
            )
        parent, parent_source = load_yaml_mapping(parent_path)
        merged, origins = _merge_inherited(
            Fields(parent_source), parent, parent_source, (*chain, _norm(parent_source))
        )
    for top, value in data.items():
        if top == "inherits":
            continue
        if top in _SECTIONS and isinstance(merged.get(top), dict):
            merged[top] = {**merged[top], **value}
            for name in value:
                origins[f"{top}.{name}"] = source
        else:
            merged[top] = value
            if top in _SECTIONS:
                origins.update({f"{top}.{name}": source for name in value})
            else:
                origins[top] = source
    return merged, origins


def _parameter(fields: Fields, node: Any, leaf: _Leaf, origin: str) -> Parameter:
    path = leaf.key
    if not isinstance(node, dict) or "value" not in node:
        raise fields.error(
            path,
            "a leaf {value, status, src | basis, note?}",
            describe_value(node),
            "every value says whether a source documents it (see docs/instruments.md)",
        )
    fields.mapping(node, path, _LEAF_KEYS)
    status = node.get("status")
    if status not in STATUSES:
        raise fields.error(
            fields.join(path, "status"),
            "documented or assumed",
            describe_value(status),
            "every value says whether a source documents it; an inferred value is assumed, "
            "with a basis",
        )
    sources = _sources(fields, node, path)
    basis = _optional_text(fields, node, "basis", path)
    note = _optional_text(fields, node, "note", path)
    if status == "documented" and not sources:
        raise fields.error(
            fields.join(path, "src"),
            "the source key(s) of a documented value (e.g. SEED6)",
            "nothing",
            "a value without a source must be status: assumed with a basis",
        )
    if status == "documented" and basis:
        raise fields.error(
            fields.join(path, "basis"),
            "no basis for a documented value (basis is for assumed ones; use note)",
            basis,
        )
    if status == "assumed" and not basis:
        raise fields.error(
            fields.join(path, "basis"),
            "a basis for an assumed value (why this value was chosen)",
            "nothing",
        )
    value = _value(fields, node, leaf)
    return Parameter(value, leaf.unit, status, sources, basis, note, origin)


def _sources(fields: Fields, node: Mapping[str, Any], path: str) -> tuple[str, ...]:
    raw = node.get("src")
    if raw is None:
        return ()
    items = raw if isinstance(raw, list) else [raw]
    if not items or any(not isinstance(s, str) or not s.strip() for s in items):
        raise fields.error(
            fields.join(path, "src"), "a source key or a list of source keys", describe_value(raw)
        )
    return tuple(s.strip() for s in items)


def _optional_text(fields: Fields, node: Mapping[str, Any], key: str, path: str) -> str:
    raw = node.get(key)
    if raw is None:
        return ""
    if not isinstance(raw, str) or not raw.strip():
        raise fields.error(fields.join(path, key), "a non-empty text", describe_value(raw))
    return raw.strip()


def _value(fields: Fields, node: Mapping[str, Any], leaf: _Leaf) -> Any:
    path = leaf.key
    vpath = fields.join(path, "value")
    limits = {"unit": leaf.unit, "low": leaf.low, "high": leaf.high, "low_open": leaf.low_open}
    kind = leaf.kind
    raw = node["value"]
    if kind == "text":
        return fields.text(node, "value", path)
    if kind == "bool":
        if not isinstance(raw, bool):
            raise fields.error(vpath, "true or false", describe_value(raw))
        return raw
    if kind == "int":
        return fields.integer(node, "value", path, low=int(leaf.low), high=int(leaf.high))
    if kind == "number":
        return _number(fields, raw, vpath, limits)
    if kind in ("range", "pair", "triple"):
        length = 3 if kind == "triple" else 2
        if not isinstance(raw, list) or len(raw) != length:
            what = "[lo, hi]" if kind == "range" else f"{length} numbers"
            raise fields.error(vpath, f"a list of {what} [{leaf.unit}]", describe_value(raw))
        numbers = tuple(
            _number(fields, v, fields.join(vpath, i), limits) for i, v in enumerate(raw)
        )
        if kind == "range" and numbers[0] > numbers[1]:
            raise fields.error(
                vpath, "a range [lo, hi] with lo ≤ hi", list(numbers), "the ends are reversed"
            )
        if leaf.contains_zero and not numbers[0] <= 0.0 <= numbers[1]:
            raise fields.error(
                vpath,
                "a range that contains 0",
                list(numbers),
                "the zero position (scales near their zeros, mark on the left plumb point) "
                "must be reachable",
            )
        return numbers
    # int_list, number_list: gear sets, strictly increasing
    items = fields.sequence(node, "value", path, min_length=1)
    out: list[Any] = []
    for i, v in enumerate(items):
        ipath = fields.join(vpath, i)
        if kind == "int_list":
            if isinstance(v, bool) or not isinstance(v, int) or not leaf.low <= v <= leaf.high:
                raise fields.error(
                    ipath, f"an integer in [{leaf.low:g}, {leaf.high:g}]", describe_value(v)
                )
            out.append(v)
        else:
            out.append(_number(fields, v, ipath, limits))
        if i and out[-1] <= out[-2]:
            raise fields.error(ipath, f"a value above the previous one ({out[-2]:g})", v)
    return tuple(out)


def _number(fields: Fields, value: Any, path: str, limits: Mapping[str, Any]) -> float:
    """:meth:`Fields.check_number` with the limits of a parameter."""
    return fields.check_number(value, path, **limits)


def _cross_check(
    fields: Fields, params: Mapping[str, Parameter], origins: Mapping[str, str], source: str
) -> None:
    d_max = params.get("projection.distance_max_mm")
    if d_max is not None:
        hi = params["projection.distance_mm"].value[1]
        if not math.isclose(d_max.value, hi, rel_tol=0.0, abs_tol=1e-9):
            raise Fields(origins.get("projection.distance_max_mm", source)).error(
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
    >>> spec = load_instrument("sc1")
    >>> check_in_range(spec, "base_z_range_mm", 12.5, "b_z′")  # inside: nothing happens
    >>> check_in_range(spec, "base_z_range_mm", 55.0, "b_z′")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    stereoplotter.instrument.spec.RangeRefusal: b_z′ = 55.000 mm is outside the assumed range [-40, 40] mm of ...sc1.yaml: base.z_mm (the stop refuses it; widen the range in the YAML if your instrument allows it)
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
        entries = tuple(limit)
        if any(math.isclose(value, e, rel_tol=1e-9, abs_tol=0.0) for e in entries):
            return
        listed = ", ".join(f"{e:g}" for e in entries)
        advice = (
            "add the gear to the YAML if your instrument has it" if status == "assumed" else advice
        )
        raise RangeRefusal(
            f"{what} = {shown:g} is not in the {status} gear set [{listed}] of {file}: {key} "
            f"(no such gear; {advice})",
            what=what,
            value=shown,
            low=min(entries),
            high=max(entries),
            status=status,
            file=file,
            key=key,
        )
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
        end = spec.parameters[end_key]
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


# --- presentation -----------------------------------------------------------------------------


def _json_value(value: Any) -> Any:
    if isinstance(value, tuple):
        return [_json_value(v) for v in value]
    return value


def instrument_to_dict(spec: InstrumentSpec) -> dict[str, Any]:
    """A JSON-ready description: every parameter with value, unit, status and provenance.

    Examples
    --------
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
    >>> text = format_instrument(load_instrument("sc1"))
    >>> print(text.splitlines()[2])  # doctest: +ELLIPSIS
    values: 20 documented, 41 assumed (ASSUMED: no source states it for this instrument; edit ...
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
