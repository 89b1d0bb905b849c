"""Instrument specifications: the shipped YAML files, their provenance, and the loader's messages.

Documented values are checked against the book (Kushtin & Lyskov 1984, ch. 6 = SEED6, OCR file
``000_37245f13991756af.txt``) and the other sources of ``docs/instruments.md``.
"""

from __future__ import annotations

import copy
import functools
import json
import math
import re
from pathlib import Path

import pytest
import yaml
from conftest import deg, node_paths
from hypothesis import given, settings
from hypothesis import strategies as st

from stereoplotter.errors import ConfigError, StereoplotterError
from stereoplotter.io.instrument_file import (
    instrument_from_mapping,
    list_instruments,
    load_instrument,
)
from stereoplotter.io.paths import data_dir
from stereoplotter.spec import (
    InstrumentSpec,
    RangeRefusal,
    check_in_range,
    format_instrument,
    instrument_to_dict,
)

NAMES = ("sc1", "spr3", "sd3")
_Loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
FOLDER = data_dir("instruments")


@functools.cache
def _raw(name: str) -> dict:
    return yaml.load((FOLDER / f"{name}.yaml").read_text(encoding="utf-8"), Loader=_Loader)


def raw(name: str) -> dict:
    """A fresh copy of the parsed file (tests mutate it)."""
    return copy.deepcopy(_raw(name))


@functools.cache
def shipped(name: str) -> InstrumentSpec:
    """The shipped spec, loaded once (it is immutable)."""
    return load_instrument(name)


def write(tmp_path: Path, data: dict, name: str = "sc1.yaml") -> Path:
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data, allow_unicode=True, sort_keys=False), encoding="utf-8")
    return path


def leaves(node, path=()):
    """Every leaf {value, status, ...} of a raw document, with its key path."""
    if isinstance(node, dict) and "value" in node:
        yield path, node
    elif isinstance(node, dict):
        for k, v in node.items():
            yield from leaves(v, (*path, k))


# --- the shipped files -----------------------------------------------------------------------


@pytest.mark.parametrize("name", NAMES)
def test_shipped_instruments_load(name):
    spec = load_instrument(name)
    assert isinstance(spec, InstrumentSpec)
    assert spec.key == name
    assert Path(spec.source).name == f"{name}.yaml"
    lo, hi = spec.projection_distance_range_mm
    assert 0 < lo < hi == spec.projection_distance_max_mm


def test_list_instruments_finds_the_three():
    assert set(NAMES) <= set(list_instruments())


@pytest.mark.parametrize("name", NAMES)
def test_every_leaf_has_status_and_provenance(name):
    found = list(leaves(raw(name)))
    assert len(found) > 30
    for path, leaf in found:
        assert leaf["status"] in ("documented", "assumed"), path
        if leaf["status"] == "documented":
            assert leaf.get("src"), path
        else:
            assert leaf.get("basis"), path


@pytest.mark.parametrize("name", NAMES)
def test_parameters_mirror_the_file(name):
    spec = shipped(name)
    keys = {".".join(p) for p, _ in leaves(raw(name))}
    assert set(spec.parameters) == keys
    counts = spec.counts()
    assert counts["documented"] + counts["assumed"] == len(keys)


@pytest.mark.parametrize("name", NAMES)
def test_every_typed_attribute_is_traceable(name):
    spec = shipped(name)
    for attribute in InstrumentSpec.KEYS:
        if getattr(spec, attribute) is None:  # optional leaf absent from this file
            continue
        key = spec.key_of(attribute)
        assert key in spec.parameters, (attribute, key)
        assert spec.status(attribute) == spec.parameters[key].status


def test_sc1_documented_values_from_the_book():
    spec = shipped("sc1")
    # SEED6 L3715: "для СЦ-1 D_max = 185 мм"
    assert spec.projection_distance_max_mm == 185.0
    assert spec.status("projection_distance_max_mm") == "documented"
    assert spec.parameter("projection.distance_max_mm").source == ("SEED6",)
    # D_min was not found: the range as a whole is assumed
    assert spec.is_assumed("projection_distance_range_mm")
    # SEED6 L3956: accuracy example on SC-1 with l = 85 mm, n = 1.42
    assert spec.parameters["facts.n_example"].value == 1.42
    assert spec.parameters["facts.fiducial_distance_l_mm"].value == 85.0
    # SCX: automatic coordinatograph up to 10× the photo scale; error unit ±100 µm, RMS 3 µm
    assert spec.status("gears.max_photo_to_map_enlargement_automatic") == "documented"
    assert spec.parameters["facts.error_correction_unit_range_um"].value == 100.0
    # instruments.md §5: tilt range for SC-1 is inferred from the family, hence assumed
    assert spec.is_assumed("tilt_max")


@pytest.mark.parametrize("name", NAMES)
def test_tolerances_are_the_books(name):
    spec = shipped(name)
    assert spec.tolerance_L_numerator_mm == 0.03  # SEED6 L3777: ±0.03/n_л mm
    assert spec.tolerance_mark_fit_per_n_mm == 0.02  # SEED6 L3783: ±0.02·n_л
    assert spec.residual_q_fraction_of_mark == 0.25  # SEED6 L3795: 1/4 of the mark
    assert spec.control_height_fraction_of_H == pytest.approx(1 / 3000, rel=1e-15)  # L3803
    assert spec.corner_tolerance_mm == 0.3  # SEED6 L3823
    assert spec.pointing_error_typical_mm == 0.015  # SEED5 L3080
    assert spec.standard_points_c_mm == 80.0  # SEED5 L3080
    for attribute in (
        "tolerance_L_numerator_mm",
        "tolerance_mark_fit_per_n_mm",
        "residual_q_fraction_of_mark",
        "control_height_fraction_of_H",
        "corner_tolerance_mm",
    ):
        assert spec.status(attribute) == "documented"
        assert "SEED6" in spec.parameter(attribute).source


@pytest.mark.parametrize("name", NAMES)
def test_undocumented_instrument_data_are_assumed(name):
    # instruments.md §1: no data sheet; ranges, least counts, gears, marks are assumptions
    spec = shipped(name)
    for attribute in (
        "projection_distance_range_mm",
        "f_instrument_range_mm",
        "model_x_offset_range_mm",
        "model_y_offset_range_mm",
        "base_x_range_mm",
        "base_y_range_mm",
        "base_z_range_mm",
        "kappa_range",
        "decentration_range_mm",
        "xy_least_count_mm",
        "z_least_count_mm",
        "height_scale_least_count_m",
        "vertical_scale_denominators",
        "coordinatograph_ratios",
        "coordinatograph_table_mm",
        "coordinatograph_sigma_mm",
        "mark_diameter_mm",
        "backlash_xy_mm",
        "zero_reading_scatter_mm",
        "known_zero_error_mm",
    ):
        assert spec.is_assumed(attribute), attribute
    assert spec.counters_present and spec.direction_switches  # SEED6 L3693, stage 2
    assert spec.status("counters_present") == "documented"
    assert spec.status("coordinatograph_present") == "documented"


def test_sd3_documented_values_from_geograce():
    spec = shipped("sd3")
    assert spec.photo_format_mm == (180.0, 180.0)
    assert spec.camera_f_range_mm == (55.0, 210.0)
    assert spec.status("photo_format_mm") == spec.status("camera_f_range_mm") == "documented"
    assert spec.height_error_fraction_of_H == 1 / 8000
    assert spec.status("height_error_fraction_of_H") == "documented"
    assert spec.parameters["facts.max_relief_fraction_of_H"].value == 0.35
    assert spec.parameters["facts.mass_kg"].value == 400.0
    # GSE-SD: tilts up to 3°
    assert spec.tilt_max == pytest.approx(3.0 * deg)
    assert spec.status("tilt_max") == "documented"


def test_spr3_relatives_are_assumed():
    spec = shipped("spr3")
    # SPR-2 figures (DRO60, AFFIN) carried over to SPR-3 are assumed, naming the relative
    for key in ("gears.model_to_photo_scale", "facts.phi_omega_dependent_settings"):
        p = spec.parameters[key]
        assert p.is_assumed and p.source and "SPR-2" in p.basis
    assert spec.status("tilt_max") == "documented"  # GSE-SPR: up to 3°
    assert spec.status("photo_format_mm") == "assumed"


def test_units_are_converted_on_load():
    spec = shipped("sc1")
    assert spec.kappa_range == pytest.approx((-15 * deg, 15 * deg))
    assert spec.parameter("kappa_range").value == (-15.0, 15.0)  # display keeps degrees
    assert spec.parameter("kappa_range").unit == "deg"
    assert spec.vertical_scale_denominators[0] == 1000
    assert all(isinstance(m, int) for m in spec.vertical_scale_denominators)
    assert spec.n_range == pytest.approx((110 / 185, 185 / 100))


def test_spec_is_frozen():
    spec = shipped("sc1")
    with pytest.raises(AttributeError, match="cannot assign"):
        spec.mark_diameter_mm = 0.1  # type: ignore[misc]
    with pytest.raises(TypeError, match="does not support item assignment"):
        spec.parameters["mark.diameter_mm"] = None  # type: ignore[index]


def test_unknown_names_are_key_errors():
    spec = shipped("sc1")
    with pytest.raises(KeyError, match="not a typed attribute"):
        spec.key_of("base_w_range_mm")
    with pytest.raises(KeyError, match="neither a key"):
        spec.status("base.w_mm")


# --- display ---------------------------------------------------------------------------------


def test_instrument_to_dict_is_json_ready():
    d = instrument_to_dict(shipped("sc1"))
    text = json.dumps(d, ensure_ascii=False)
    back = json.loads(text)
    p = back["parameters"]["base.z_mm"]
    assert p == {
        "value": [-40.0, 40.0],
        "unit": "mm",
        "status": "assumed",
        "src": [],
        "basis": p["basis"],
        "note": p["note"],
        "file": d["file"],
    }
    assert Path(p["file"]).resolve() == (FOLDER / "sc1.yaml").resolve()  # the shipped file
    assert "Planimat" in p["basis"]
    assert back["counts"] == shipped("sc1").counts()
    assert back["derived"]["n_range_status"] == "assumed"


def test_format_instrument_labels_every_value():
    spec = shipped("sc1")
    text = format_instrument(spec)
    counts = spec.counts()
    assert f"{counts['documented']} documented, {counts['assumed']} assumed" in text
    listing = text.split("\nderived:\n")[0]
    value_lines = [ln for ln in listing.splitlines() if re.match(r"  \w+ = ", ln)]
    assert len(value_lines) == len(spec.parameters)
    for line in value_lines:
        assert "[documented: " in line or "[ASSUMED: " in line, line
    assert "  distance_max_mm = 185 mm  [documented: SEED6]" in text
    assert "  corner4_mm = 0.3 mm  [documented: SEED6]" in text
    assert re.search(r"  z_mm = \[-40, 40\] mm  \[ASSUMED: .*Planimat", text)


# --- range refusals --------------------------------------------------------------------------


def test_check_in_range_accepts_inside_and_at_the_ends():
    spec = shipped("sc1")
    for value in (-40.0, 0.0, 40.0):
        check_in_range(spec, "base_z_range_mm", value, "b_z′")
    check_in_range(spec, "kappa_range", 15 * deg, "κ")
    check_in_range(spec, "tilt_max", -3 * deg, "α")
    check_in_range(spec, "vertical_scale_denominators", 5000, "M_в")
    check_in_range(spec, "coordinatograph_ratios", 2.5, "r")


def test_check_in_range_refuses_with_file_key_and_status():
    spec = shipped("sc1")
    with pytest.raises(
        RangeRefusal,
        match=re.escape(
            "b_z′ = 55.000 mm is outside the assumed range [-40, 40] mm of "
            f"{spec.source}: base.z_mm (the stop refuses it; widen the range in the YAML if "
            "your instrument allows it)"
        ),
    ) as info:
        check_in_range(spec, "base_z_range_mm", 55.0, "b_z′")
    err = info.value
    assert (err.value, err.low, err.high, err.status, err.key) == (
        55.0,
        -40.0,
        40.0,
        "assumed",
        "base.z_mm",
    )
    assert isinstance(err, StereoplotterError)


def test_check_in_range_angles_are_shown_in_degrees():
    spec = shipped("sc1")
    with pytest.raises(
        RangeRefusal,
        match=r"κ_л = 20\.000 deg is outside the assumed range \[-15, 15\] deg .*"
        r"orientation\.kappa_deg",
    ):
        check_in_range(spec, "kappa_range", 20 * deg, "κ_л")
    with pytest.raises(
        RangeRefusal, match=r"α_л = -3\.500 deg is outside the assumed range \[-3, 3\] deg"
    ):
        check_in_range(spec, "tilt_max", -3.5 * deg, "α_л")


def test_check_in_range_documented_upper_end_of_D():
    spec = shipped("sc1")
    with pytest.raises(
        RangeRefusal,
        match=r"D = 190\.000 mm is above the documented maximum 185 mm of .*sc1\.yaml: "
        r"projection\.distance_max_mm \(the stop refuses it; the limit is documented \(SEED6\)\)",
    ) as info:
        check_in_range(spec, "projection_distance_range_mm", 190.0, "D")
    assert info.value.status == "documented"
    with pytest.raises(RangeRefusal, match=r"D = 100\.000 mm is outside the assumed range"):
        check_in_range(spec, "projection_distance_range_mm", 100.0, "D")


def test_check_in_range_gear_sets_and_nan():
    spec = shipped("sc1")
    with pytest.raises(
        RangeRefusal,
        match=r"M_в = 7000 is not in the assumed gear set \[1000, 1250, .*, 25000\] of .*: "
        r"gears\.vertical_scale_denominators \(no such gear; add the gear",
    ):
        check_in_range(spec, "vertical_scale_denominators", 7000, "M_в")
    with pytest.raises(RangeRefusal, match=r"b_x = nan mm is outside"):
        check_in_range(spec, "base_x_range_mm", math.nan, "b_x")


def test_check_in_range_needs_a_range_attribute():
    spec = shipped("sc1")
    with pytest.raises(TypeError, match="not a range, a maximum or a gear set"):
        check_in_range(spec, "mark_diameter_mm", 1.0, "mark")


# --- bad files -------------------------------------------------------------------------------


def _mutated(tmp_path, mutate):
    data = raw("sc1")
    mutate(data)
    return write(tmp_path, data)


BAD = [
    (
        lambda d: d["base"].__setitem__("w_mm", d["base"]["x_mm"]),
        r"sc1\.yaml: base\.w_mm: expected no such field, found w_mm \(allowed here: x_mm, y_mm, "
        r"z_mm\)",
    ),
    (
        lambda d: d.__setitem__("lens", {}),
        r"sc1\.yaml: lens: expected no such field",
    ),
    (
        lambda d: d["base"]["z_mm"].__setitem__("value", [40, -40]),
        r"base\.z_mm\.value: expected a range \[lo, hi\] with lo ≤ hi, found \[40\.0, -40\.0\] "
        r"\(the ends are reversed\)",
    ),
    (
        lambda d: d["base"]["z_mm"].__setitem__("value", "±40"),
        r"base\.z_mm\.value: expected a list of \[lo, hi\] \[mm\], found the text '±40'",
    ),
    (
        lambda d: d["base"]["y_mm"].__setitem__("value", [5, 20]),
        r"base\.y_mm\.value: expected a range that contains 0, found \[5\.0, 20\.0\]",
    ),
    (
        lambda d: d["counters"]["xy_least_count_mm"].__setitem__("value", -0.01),
        r"counters\.xy_least_count_mm\.value: expected a number in \(0, 1\] mm, found -0\.01",
    ),
    (
        lambda d: d["counters"]["present"].__setitem__("value", "yes"),
        r"counters\.present\.value: expected true or false, found the text 'yes'",
    ),
    (
        lambda d: d["base"]["z_mm"].pop("status"),
        r"base\.z_mm\.status: expected documented or assumed, found nothing",
    ),
    (
        lambda d: d["base"]["z_mm"].__setitem__("status", "inferred"),
        r"base\.z_mm\.status: expected documented or assumed, found the text 'inferred' \(.*"
        r"an inferred value is assumed, with a basis\)",
    ),
    (
        lambda d: d["projection"]["distance_max_mm"].pop("src"),
        r"projection\.distance_max_mm\.src: expected the source key\(s\) of a documented value",
    ),
    (
        lambda d: d["base"]["z_mm"].pop("basis"),
        r"base\.z_mm\.basis: expected a basis for an assumed value",
    ),
    (
        lambda d: d["tolerances"]["corner4_mm"].__setitem__("basis", "why"),
        r"tolerances\.corner4_mm\.basis: expected no basis for a documented value",
    ),
    (
        lambda d: d["base"]["z_mm"].__setitem__("src", [""]),
        r"base\.z_mm\.src: expected a source key or a list of source keys",
    ),
    (
        lambda d: d["mark"].__setitem__("diameter_mm", 0.05),
        r"mark\.diameter_mm: expected a leaf \{value, status, src \| basis, note\?\}, found 0\.05",
    ),
    (
        lambda d: d.pop("mark"),
        r"mark\.diameter_mm: expected a value \{value, status, src \| basis\} \(the field is "
        r"required\), found nothing",
    ),
    (
        lambda d: d["gears"]["vertical_scale_denominators"]["value"].__setitem__(3, 1000),
        r"gears\.vertical_scale_denominators\.value\[3\]: expected a value above the previous "
        r"one \(1600\), found 1000",
    ),
    (
        lambda d: d["gears"]["vertical_scale_denominators"]["value"].__setitem__(0, 1000.5),
        r"vertical_scale_denominators\.value\[0\]: expected an integer in \[1, 1e\+07\], "
        r"found 1000\.5",
    ),
    (
        lambda d: d["projection"]["distance_max_mm"].__setitem__("value", 200),
        r"projection\.distance_max_mm\.value: expected the upper end of projection\.distance_mm "
        r"\(185 mm\), found 200\.0",
    ),
    (
        lambda d: d["tolerances"]["control_height_denominator"].__setitem__("value", 0),
        r"tolerances\.control_height_denominator\.value: expected a number in \[1, 1e\+07\]",
    ),
    (
        lambda d: d["correction"]["tilt_max_deg"].__setitem__("value", float("nan")),
        r"correction\.tilt_max_deg\.value: expected a number in \(0, 45\] deg, found nan",
    ),
    (
        lambda d: d["mark"]["diameter_mm"].__setitem__("value", 10**400),
        r"mark\.diameter_mm\.value: expected a number in \(0, 5\] mm, found an integer too large "
        r"for a float",
    ),
]


@pytest.mark.parametrize(("mutate", "message"), BAD)
def test_bad_files_are_refused_with_a_clear_message(tmp_path, mutate, message):
    path = _mutated(tmp_path, mutate)
    with pytest.raises(ConfigError, match=message) as info:
        load_instrument(path)
    assert str(info.value).startswith(f"{path}: ")


def test_unknown_instrument_name():
    with pytest.raises(
        ConfigError, match=r"sc9: expected the name of an instrument \(.*sc1.*\) or a path"
    ):
        load_instrument("sc9")


def test_missing_file_and_bad_yaml(tmp_path):
    with pytest.raises(ConfigError, match=r"nope\.yaml: \(file\): expected an existing file"):
        load_instrument(tmp_path / "nope.yaml")
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: [unclosed\n", encoding="utf-8")
    with pytest.raises(ConfigError, match=r"bad\.yaml: \(file\): expected valid YAML"):
        load_instrument(bad)


# --- inheritance from a family file ----------------------------------------------------------


def _split_family(tmp_path):
    """sc1.yaml split into family.yaml (everything but the name) and a thin sc1.yaml."""
    data = raw("sc1")
    family = {k: v for k, v in data.items() if k not in ("name", "principle")}
    child = {
        "inherits": "family.yaml",
        "name": data["name"],
        "principle": data["principle"],
        "base": {"z_mm": {"value": [-50, 50], "status": "assumed", "basis": "cf. Topocart ±50"}},
    }
    write(tmp_path, family, "family.yaml")
    return family, child


def test_inherits_merges_and_overrides(tmp_path):
    _, child = _split_family(tmp_path)
    spec = load_instrument(write(tmp_path, child))
    reference = shipped("sc1")
    assert spec.base_z_range_mm == (-50.0, 50.0)
    assert spec.base_x_range_mm == reference.base_x_range_mm
    assert spec.projection_distance_max_mm == 185.0
    assert spec.parameters["base.z_mm"].file == str(tmp_path / "sc1.yaml")
    assert spec.parameters["base.x_mm"].file == str(tmp_path / "family.yaml")
    with pytest.raises(RangeRefusal, match=r"of .*family\.yaml: base\.x_mm"):
        check_in_range(spec, "base_x_range_mm", 250.0, "b_x")
    assert "from: " in format_instrument(spec)


def test_inherits_errors_name_the_right_file(tmp_path):
    family, child = _split_family(tmp_path)
    family["mark"]["diameter_mm"]["value"] = -1
    write(tmp_path, family, "family.yaml")
    with pytest.raises(ConfigError, match=r"family\.yaml: mark\.diameter_mm\.value: expected"):
        load_instrument(write(tmp_path, child))
    child["inherits"] = "missing.yaml"
    with pytest.raises(ConfigError, match=r"sc1\.yaml: inherits: expected the name of an exist"):
        load_instrument(write(tmp_path, child))
    loop = {"inherits": "sc1.yaml"}
    write(tmp_path, loop, "family.yaml")
    child["inherits"] = "family.yaml"
    with pytest.raises(ConfigError, match=r"inherits: expected a chain of at most 4 files"):
        load_instrument(write(tmp_path, child))


# --- fuzzing: a mutated file never produces anything but a StereoplotterError -----------------

_SC1 = raw("sc1")
_PATHS = node_paths(_SC1)
_JUNK = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(10**7), 10**7),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
    st.lists(st.floats(-1e3, 1e3), max_size=4),
    st.lists(st.integers(-5, 5000), max_size=3),
    st.dictionaries(st.sampled_from(["value", "status", "src", "basis", "x"]), st.integers()),
)


@settings(max_examples=150)
@given(st.sampled_from(_PATHS), _JUNK)
def test_fuzzed_instruments_fail_cleanly(path, junk):
    d = copy.deepcopy(_SC1)
    node = d
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = junk
    try:
        spec = instrument_from_mapping(d, "fuzz.yaml")
    except StereoplotterError as exc:
        assert str(exc).startswith("fuzz.yaml: ")
    else:
        format_instrument(spec)
        json.dumps(instrument_to_dict(spec))
