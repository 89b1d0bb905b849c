"""Bad input never crashes: the cases of the release floor's item 6, one test each.

Every refusal is one line ``error: FILE: FIELD: expected …, found …`` with exit code 1 (a usage
error of the command line: one ``error:`` line naming the option, exit code 2); nothing reaches
the "internal error" handler of :func:`stereoplotter.cli.main`.
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest
import yaml

from stereoplotter.cli import build_parser, main
from stereoplotter.commands.arguments import (
    MAX_SEED,
    bounded_float,
    non_negative_int,
    positive_int,
    seed_int,
)
from stereoplotter.errors import ConfigError
from stereoplotter.instrument.error_model import error_model_from_spec
from stereoplotter.io.geometry_file import geometry_from_file
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.paths import data_dir
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.io.yaml_input import load_yaml_mapping

ROOT = Path(__file__).resolve().parents[2]


def _shipped(kind: str, name: str) -> Path:
    try:
        folder = data_dir(kind)
        if folder is not None and (Path(folder) / name).is_file():
            return Path(folder) / name
    except Exception:
        pass
    return ROOT / kind / name


PAIR60 = _shipped("scenarios", "pair60.yaml")
MOUNTAIN60 = _shipped("scenarios", "mountain60.yaml")
SINGLE = _shipped("scenarios", "book_resection_table7.yaml")
STRIP60 = _shipped("scenarios", "blocks/strip60.yaml")


def _doc(path: Path) -> dict:
    return yaml.safe_load(path.read_text(encoding="utf-8"))


def _write(tmp_path: Path, doc: dict | str, name: str = "input.yaml") -> Path:
    path = tmp_path / name
    text = doc if isinstance(doc, str) else yaml.safe_dump(doc, sort_keys=False)
    path.write_text(text, encoding="utf-8")
    return path


def _one_error_line(capsys) -> str:
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("error: "), err
    assert "internal error" not in err and "Traceback" not in err
    return lines[0]


# --- optional sections ----------------------------------------------------------------------


def test_scenario_without_errors_section_takes_the_documented_defaults(tmp_path, capsys):
    doc = _doc(PAIR60)
    del doc["errors"]
    path = _write(tmp_path, doc)
    scenario = load_scenario(path)
    # ErrorSettings defaults (scenario/model.py): 3 µm per photo point, 2 µm per fiducial
    assert (scenario.errors.photo_point_sigma_um, scenario.errors.fiducial_sigma_um) == (3.0, 2.0)
    doc["errors"] = {"fiducial_sigma_um": 4.5}  # one of the two given: the other is the default
    scenario = load_scenario(_write(tmp_path, doc))
    assert (scenario.errors.photo_point_sigma_um, scenario.errors.fiducial_sigma_um) == (3.0, 4.5)
    assert main(["scenario", "check", str(path)]) == 0
    assert "valid" in capsys.readouterr().out


@pytest.mark.parametrize("section", ["frame", "terrain", "map_sheet", "errors", "seed"])
def test_every_optional_scenario_section_may_be_left_out(tmp_path, section):
    doc = _doc(PAIR60)
    if section == "frame":  # the frame carries the SK-42 tie the map sheet needs
        del doc["map_sheet"]
    del doc[section]
    scenario = load_scenario(_write(tmp_path, doc))
    assert len(scenario.photos) == 2 and len(scenario.points) == 12


# --- numbers on the command line --------------------------------------------------------------

_PAIR = str(PAIR60)
BAD_OPTIONS = [
    (["verify", "--trials", "0"], "--trials", "found 0"),
    (["verify", "--trials", "1"], "--trials", "found 1"),  # a spread needs two trials
    (["verify", "--trials", "ten"], "--trials", "found 'ten'"),
    (["verify", "--seed", "-1"], "--seed", "found -1"),
    (["verify", "--procedure-trials", "-1"], "--procedure-trials", "found -1"),
    (["simulate", _PAIR, "--instrument", "sc1", "--trials", "0"], "--trials", "found 0"),
    (["simulate", _PAIR, "--instrument", "sc1", "--trials", "-3"], "--trials", "found -3"),
    (["simulate", _PAIR, "--instrument", "sc1", "--seed", "-1"], "--seed", "found -1"),
    (["setup", _PAIR, "--instrument", "sc1", "--seed", "-5"], "--seed", "found -5"),
    (["setup", _PAIR, "--instrument", "sc1", "--seed", str(2**64)], "--seed", "found 1844"),
    (["setup", _PAIR, "--instrument", "sc1", "--horizontal-scale", "0"], "--horizontal-scale", ""),
    (["setup", _PAIR, "--instrument", "sc1", "--vertical-scale", "-3"], "--vertical-scale", ""),
    (["demo", "--seed", "-1"], "--seed", "found -1"),
    (["instrument", "test", "sc1", "--tilts", "nan"], "--tilts", "found nan"),
    (["instrument", "test", "sc1", "--tilts", "1", "inf"], "--tilts", "found inf"),
    (["instrument", "test", "sc1", "--tilts", "60"], "--tilts", "found 60"),
]


@pytest.mark.parametrize(("argv", "option", "found"), BAD_OPTIONS)
def test_out_of_range_numbers_are_one_usage_line(argv, option, found, capsys):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    line = _one_error_line(capsys)
    assert f"argument {option}: expected " in line and found in line


def _numeric_actions(parser: argparse.ArgumentParser, prefix: str = "") -> list:
    found = []
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, child in action.choices.items():
                found += _numeric_actions(child, f"{prefix}{name} ")
        elif action.type is not None:
            found.append((prefix + "/".join(action.option_strings), action))
    return found


def test_every_numeric_option_is_range_checked():
    actions = _numeric_actions(build_parser())
    assert len(actions) >= 11  # 4 seeds, 3 trial counts, 2 scales, b_z sense, tilts, …
    for name, action in actions:
        # a bare int/float accepts -1, 0 and nan; choices are a range of their own
        assert action.type not in (int, float) or action.choices, name


def test_the_range_types_accept_their_ends():
    assert positive_int("1") == 1 and non_negative_int("0") == 0
    assert seed_int(str(MAX_SEED)) == MAX_SEED
    assert bounded_float(-15.0, 15.0)("-15") == -15.0
    with pytest.raises(argparse.ArgumentTypeError, match=r"expected an integer ≥ 1, found 0"):
        positive_int("0")
    with pytest.raises(argparse.ArgumentTypeError, match=r"expected an integer ≥ 0, found '1.5'"):
        non_negative_int("1.5")


# --- did you mean -----------------------------------------------------------------------------


def test_unknown_instrument_name_suggests_the_closest(capsys):
    assert main(["instrument", "show", "sc2"]) == 1
    line = _one_error_line(capsys)
    assert "sc2: expected the name of an instrument" in line and "did you mean sc1?" in line
    assert main(["instrument", "show", "SD3"]) == 1
    assert "did you mean sd3?" in _one_error_line(capsys)
    assert main(["instrument", "show", "theodolite"]) == 1
    assert "did you mean" not in _one_error_line(capsys)  # nothing close: no guess


def test_unknown_scenario_key_suggests_the_closest(tmp_path, capsys):
    doc = _doc(PAIR60)
    doc["camera"]["focal_lenght_mm"] = doc["camera"].pop("focal_length_mm")
    path = _write(tmp_path, doc)
    assert main(["scenario", "check", str(path)]) == 1
    line = _one_error_line(capsys)
    assert line.startswith(f"error: {path}: camera.focal_lenght_mm: expected no such field")
    assert line.endswith("did you mean focal_length_mm?)")


def test_geometry_file_with_a_typo_names_file_and_field(tmp_path, capsys):
    path = _write(tmp_path, "f: 70\nll: 85\n", "geometry.yaml")
    argv = ["verify", "--trials", "2", "--procedure-trials", "0", "--geometry", str(path)]
    assert main(argv) == 1
    line = _one_error_line(capsys)
    assert line.startswith(f"error: {path}: ll: expected no such field, found ll")
    assert "did you mean l?" in line


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("f: seventy\n", r"f: expected a number in \[1, 1000\] mm, found the text 'seventy'"),
        ("n: .nan\n", r"n: expected a number in \[0\.01, 100\], found nan"),
        ("p60: -70\n", r"p60: expected a number in \[1, 500\] mm, found -70"),
        ("c: 5.0e-324\n", r"c: expected a number in \[1, 500\] mm, found 5e-324"),
        ("a60: -80\n", r"a60: expected a60 > −c and a60 > −p60/2 .*found a60 = -80, c = 70"),
        ("p60: 500\na60: 100\n", r"a60: expected a geometry where the root of \(5\.54\) is "
         r"real"),
        ("c: [70]\n", r"c: expected a number .*, found a list of 1"),
    ],
)
def test_geometry_file_values_are_checked(tmp_path, text, message):
    with pytest.raises(ConfigError, match=r"geometry\.yaml: " + message):
        geometry_from_file(_write(tmp_path, text, "geometry.yaml"))


def test_geometry_from_a_single_photo_scenario_is_refused(capsys):
    with pytest.raises(ConfigError, match=r"photos: expected a stereopair .*found 1 photo"):
        geometry_from_file(SINGLE)


def test_errors_file_unknown_term_and_bad_values(tmp_path):
    model = error_model_from_spec(load_instrument("sc1"))
    with pytest.raises(ConfigError, match=r"e\.yaml: backlash\.x: expected an error term .*"
                       r"did you mean backlash\.X\?"):
        model.with_overrides({"backlash.x": 0.01}, "e.yaml")
    with pytest.raises(ConfigError, match=r"e\.yaml: backlash\.X\.distribution: expected constant"):
        model.with_overrides({"backlash.X": {"distribution": "normal", "scale": 0.01}}, "e.yaml")
    with pytest.raises(ConfigError, match=r"e\.yaml: setting\.bx\.sigma: expected no such field"):
        model.with_overrides({"setting.bx": {"sigma": 0.01}}, "e.yaml")
    with pytest.raises(ConfigError, match=r"e\.yaml: setting\.bx\.scale: expected a finite number"):
        model.with_overrides({"setting.bx": {"distribution": "normal"}}, "e.yaml")
    # at most the largest the instrument files allow: 100 mm, 600′, 10⁴ ppm
    with pytest.raises(ConfigError, match=r"zero_reading: expected a finite number ≥ 0 and ≤ 100"):
        model.with_overrides({"zero_reading": 1e300}, "e.yaml")
    with pytest.raises(ConfigError, match=r"counter_scale: expected .* ≤ 0\.01 \(relative\)"):
        model.with_overrides({"counter_scale": 10**400}, "e.yaml")
    at_limit = model.with_overrides({"zero_reading": 100, "counter_scale": 0.01}, "e.yaml")
    assert at_limit.term("zero_reading.X").scale == 100.0


# --- zone mismatch, block files, single photos --------------------------------------------------


def test_zone_mismatch_names_the_file_and_the_point(tmp_path):
    doc = _doc(MOUNTAIN60)
    point = doc["points"][0]
    assert "sk42" in point and point["id"] == "1"
    point["sk42"]["east_m"] -= 1_000_000.0  # the same plain ordinate, one zone to the west
    path = _write(tmp_path, doc)
    with pytest.raises(ConfigError) as info:
        load_scenario(path)
    message = str(info.value)
    assert message.startswith(f"{path}: points[0].sk42.east_m: expected a point in the zone of ")
    assert "(point 1)" in message and "zone 7" in message and "zone 8" in message


def test_block_file_given_to_simulate_says_it_is_a_block_file(tmp_path, capsys):
    assert main(["simulate", str(STRIP60), "--instrument", "sc1", "-o", str(tmp_path)]) == 1
    line = _one_error_line(capsys)
    assert line.startswith(f"error: {STRIP60}: models: expected a scenario")
    assert "found a block file" in line and "stereoplotter setup" in line
    assert main(["scenario", "check", str(STRIP60)]) == 1
    assert "found a block file" in _one_error_line(capsys)


def test_setup_refusals_name_the_scenario_file(tmp_path, capsys):
    assert main(["setup", str(SINGLE), "--instrument", "sc1", "--json"]) == 1
    line = _one_error_line(capsys)
    assert line.startswith(f"error: {SINGLE}: photos: expected two photos named left and right")
    doc = _doc(PAIR60)
    del doc["map_sheet"]
    path = _write(tmp_path, doc)
    assert main(["setup", str(path), "--instrument", "sc1", "--json"]) == 1
    assert _one_error_line(capsys).startswith(f"error: {path}: map_sheet: expected a map sheet")
    assert main(["setup", str(path), "--instrument", "sc1", "--json", "--horizontal-scale",
                 "12500"]) == 0


# --- YAML itself ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("name: a\nname: b\n", r"name: expected each key once in a mapping, found it twice "
         r"\(line 1 and line 2\)"),
        ("camera:\n  f: 1\n  f: 2\n", r"camera\.f: expected each key once"),
        ("a: &c [*c]\n", r"a\[0\]: expected no alias to an enclosing node"),
        ("a: " + "[" * 100 + "]" * 100 + "\n", r"\(file\): expected YAML nested at most 64 "
         r"levels deep, found deeper nesting \(line 1, column 68\)"),
        ("a: " + "[" * 20000 + "]" * 20000 + "\n", r"\(file\): expected YAML nested at most 64 "
         r"levels deep"),
        ("a:\n" + "".join(" " * i + f"k{i}:\n" for i in range(1, 100)), r"\(file\): expected "
         r"YAML nested at most 64 levels deep, found deeper nesting \(line 65, column 65\)"),
        ("a: 2001-02-30\n", r"\(file\): expected valid YAML values, found a value YAML cannot "
         r"construct \(ValueError: day is out of range for month\)"),
        ("a: !!timestamp x\n", r"\(file\): expected valid YAML values"),
        ("a: " + "9" * 5000 + "\n", r"\(file\): expected valid YAML values"),
        ('a: "\\ud800"\n', r"a: expected text without lone surrogates"),
        ("a: 1\x00\n", r"\(file\): expected valid YAML, found unacceptable character #x0000: "
         r"special characters are not allowed at character 5"),
        ("", r"\(top level\): expected a mapping of fields, found an empty document"),
        ("# nothing\n", r"\(top level\): expected a mapping of fields, found an empty document"),
    ],
)
def test_yaml_problems_are_config_errors(tmp_path, text, message):
    path = _write(tmp_path, text, "doc.yaml")
    with pytest.raises(ConfigError, match=r"doc\.yaml: " + message):
        load_yaml_mapping(path)


def test_non_utf8_empty_and_directory_inputs(tmp_path, capsys):
    bad = tmp_path / "latin.yaml"
    bad.write_bytes(_doc_bytes(PAIR60).replace(b"name: pair60", b"name: pa\xefr60"))
    assert main(["scenario", "check", str(bad)]) == 1
    assert f"{bad}: (file): expected a readable UTF-8 text file" in _one_error_line(capsys)
    folder = tmp_path / "folder.yaml"
    folder.mkdir()
    assert main(["scenario", "check", str(folder)]) == 1
    assert f"{folder}: (file): expected a readable UTF-8 text file" in _one_error_line(capsys)
    empty = _write(tmp_path, "", "empty.yaml")
    assert main(["instrument", "show", str(empty)]) == 1
    assert "found an empty document" in _one_error_line(capsys)


def _doc_bytes(path: Path) -> bytes:
    return path.read_bytes()


# --- instrument files and overrides that would give no working axis ----------------------------


@pytest.mark.parametrize(
    ("section", "key", "value", "message"),
    [
        ("mechanics", "friction_coefficient", 1.2, r"mechanics\.friction_coefficient\.value: "
         r"expected a value that gives a working screw axis .*friction μ < 1 on a vertical axis"),
        ("mechanics", "carriage_mass_kg", 1000.0, r"mechanics\.carriage_mass_kg\.value: expected "
         r"a value that gives a working screw axis .*dead band 2h, found \(0\.5, 3\.93"),
        ("errors", "backlash_xy_mm", 0.5, r"errors\.backlash_xy_mm\.value: expected a number in "
         r"\[0, 0\.2\] mm, found 0\.5"),
        ("base", "y_mm", [0, 0], r"base\.y_mm\.value: expected a range \[lo, hi\] with lo < hi"),
    ],
)
def test_instrument_mechanics_that_cannot_run_are_refused(tmp_path, section, key, value, message):
    doc = _doc(_shipped("instruments", "sc1.yaml"))
    doc[section][key]["value"] = value
    path = _write(tmp_path, doc, "sc1.yaml")
    with pytest.raises(ConfigError, match=re.escape(str(path)) + ": " + message):
        load_instrument(path)


def test_errors_file_backlash_beyond_the_overtravel_is_refused(tmp_path, capsys):
    path = _write(tmp_path, "backlash: 1\n", "errors.yaml")
    argv = ["simulate", str(PAIR60), "--instrument", "sc1", "--errors", str(path), "--json"]
    assert main(argv) == 1
    line = _one_error_line(capsys)
    assert line.startswith(f"error: {path}: backlash: expected a finite number ≥ 0 and ≤ 0.2 mm")
