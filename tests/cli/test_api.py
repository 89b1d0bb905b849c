"""The public API at the package top (docs/api.md) is the code the command line runs."""

from __future__ import annotations

import json

import pytest

import stereoplotter
from stereoplotter.cli import main
from stereoplotter.commands.verification import verify
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.procedure.simulate import simulate
from stereoplotter.setup.sheet import compute_setup_sheet


def test_public_names_resolve_to_their_modules():
    assert stereoplotter.load_scenario is load_scenario
    assert stereoplotter.compute_setup_sheet is compute_setup_sheet
    assert stereoplotter.simulate is simulate
    assert stereoplotter.verify is verify
    assert set(stereoplotter.__all__) <= set(dir(stereoplotter))
    with pytest.raises(AttributeError):
        stereoplotter.no_such_name  # noqa: B018


def test_api_sheet_equals_the_cli_sheet(capsys):
    """The sheet computed through the API is the one `setup --json` prints (same f_пр, n_л, n_п)."""
    # imported here: the package's lazy public names, resolved as a user's import resolves them
    from stereoplotter import compute_setup_sheet, load_instrument, load_scenario

    sheet = compute_setup_sheet(load_scenario("pair60"), load_instrument("sc1"))
    assert main(["setup", "pair60", "--instrument", "sc1", "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["f_instrument_mm"] == pytest.approx(sheet.f_instrument_mm, rel=1e-6)
    assert printed["n_left"] == pytest.approx(sheet.n_left, rel=1e-5)
    assert printed["n_right"] == pytest.approx(sheet.n_right, rel=1e-5)
