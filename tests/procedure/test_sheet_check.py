"""check-sheet: five planted mistakes, each of another kind, are found
and named; the program's own sheet passes; a missing value is reported in one line.

The planted values are computed independently of the checker: the sign of (6.4) by the
program's ``--book-sign`` sheet (the printed sign, Z_Sл − Z_Sп), the others by the mistaken
formula written out here from the sheet's inputs.
"""

from __future__ import annotations

import copy
import math

import pytest
import yaml

from stereoplotter.cli import main
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.report.sheet import sheet_to_dict
from stereoplotter.setup.sheet import SetupOptions, compute_setup_sheet


@pytest.fixture(scope="module")
def program():
    spec = load_instrument("sc1")
    scenario = load_scenario("pair60")
    sheet = compute_setup_sheet(scenario, spec)
    book = compute_setup_sheet(scenario, spec, SetupOptions(book_sign_n_right=True))
    return sheet, book, sheet_to_dict(sheet)


def _reading(data, name):
    return next(r for r in data["readings"] if r["reading"] == name)


def _run(tmp_path, data, capsys, *extra):
    path = tmp_path / "mine.yaml"
    path.write_text(yaml.safe_dump(data, allow_unicode=True), encoding="utf-8")
    code = main(["check-sheet", str(path), "--scenario", "pair60", "--instrument", "sc1", *extra])
    captured = capsys.readouterr()
    return code, captured.out + captured.err


def test_program_sheet_passes(tmp_path, capsys, program):
    code, out = _run(tmp_path, program[2], capsys)
    assert code == 0
    assert "0 wrong, 0 missing" in out and "PASSED" in out


def test_five_planted_mistakes_found_and_named(tmp_path, capsys, program):
    sheet, book, data = program
    mine = copy.deepcopy(data)
    left = sheet.photos[0]
    # 1. sign of (6.4): the printed Z_Sл − Z_Sп (the program's --book-sign sheet)
    assert abs(book.n_right - sheet.n_right) > 1e-3
    mine["n_right"] = book.n_right
    # 2. n applied twice in (6.5): n·n·(y⁰₃ − y⁰₄)
    y3, y4 = left.transformed_book_mm["y3"], left.transformed_book_mm["y4"]
    mine["L_mm"]["left"] = sheet.n_left**2 * (y3 - y4)
    # 3. mm versus m: the model height of point 1 written in metres, H·1/M_в
    h1 = next(h for h in sheet.control_heights if h["id"] == "1")
    mine["control_heights_model_mm"]["1"] = h1["model_height_mm"] / 1000.0
    # 4. magnitude for the signed reading of mark 4 in (6.12): n·|y⁰₄|
    _reading(mine, "O_Y4,л")["value"] = sheet.n_left * abs(y4)
    # 5. f_пр in place of f′ in the decentration f′·tan α
    mine["decentrations_mm"]["left"]["x"] = sheet.f_instrument_mm * math.tan(left.alpha)
    code, out = _run(tmp_path, mine, capsys, "--json")
    assert code == 1
    result = yaml.safe_load(out)
    wrong = {i["key"]: i["likely_mistake"] for i in result["items"] if i["status"] == "wrong"}
    assert wrong == {
        "n_right": "sign of (6.4): Z_Sл − Z_Sп in place of Z_Sп − Z_Sл",
        "L_mm.left": "n applied twice in (6.5)",
        "control_heights_model_mm.1": "mm versus m: written in metres",
        "readings.O_Y4,л": "magnitude in place of the signed reading in (6.12)",
        "decentrations_mm.left.x": "f_пр in place of f′",
    }
    assert result["counts"]["wrong"] == 5


def test_unrecognised_error_is_wrong_without_a_name(tmp_path, capsys, program):
    mine = copy.deepcopy(program[2])
    mine["L_mm"]["right"] += 0.5  # an arithmetic slip no hypothesis reproduces
    _, out = _run(tmp_path, mine, capsys)
    line = next(x for x in out.splitlines() if "L_mm.right" in x)
    assert line.startswith("WRONG") and "no known mistake fits" in line
    assert "tolerance ±0.018 mm (the book's mark-span tolerance" in line


def test_missing_value_is_one_line(tmp_path, capsys, program):
    mine = copy.deepcopy(program[2])
    del mine["n_left"]
    mine["base_mm"]["bx"] = None
    code, out = _run(tmp_path, mine, capsys)
    assert code == 1
    missing = [x for x in out.splitlines() if x.startswith("MISSING")]
    assert [x.split(":")[0] for x in missing] == ["MISSING n_left", "MISSING base_mm.bx"]
    assert "0 wrong, 2 missing" in out


def test_unknown_key_refused_in_one_line(tmp_path, capsys, program):
    mine = copy.deepcopy(program[2])
    mine["n_rigth"] = 1.7
    code, out = _run(tmp_path, mine, capsys)
    assert code == 1
    errors = [x for x in out.splitlines() if x.startswith("error:")]
    assert len(errors) == 1 and "n_rigth" in errors[0] and "n_right" in errors[0]
