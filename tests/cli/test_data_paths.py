"""Shipped data as package data, user folders (``--data``, ``STEREOPLOTTER_DATA``) beside them.

The shipped instruments and scenarios are found from any working directory; a user folder adds
names and may hide a shipped file, but never silently.
"""

from __future__ import annotations

import json
import logging
import os
from pathlib import Path

import pytest

from stereoplotter.cli import main
from stereoplotter.io import paths
from stereoplotter.io.instrument_file import load_instrument

SHIPPED = Path(paths.data_dir("instruments"))


@pytest.fixture(autouse=True)
def _clean(monkeypatch, tmp_path):
    """No user folders from the environment or from an earlier main(); run in an empty folder."""
    monkeypatch.delenv(paths.ENVIRONMENT_VARIABLE, raising=False)
    paths.set_user_folders([])
    monkeypatch.chdir(tmp_path)
    yield
    paths.set_user_folders([])


def _user_folder(root: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(text, encoding="utf-8")
    return root


def test_shipped_data_are_package_data_inside_the_package():
    root = paths.shipped_root()
    assert root == Path(paths.__file__).parent.parent / "data"
    assert paths.available_names("instruments") == ["sc1", "sd3", "spr3"]
    assert paths.available_names("scenarios") == [
        "book_resection_table7",
        "mountain60",
        "pair60",
        "pair80",
    ]
    assert (root / "scenarios" / "blocks" / "strip60.yaml").is_file()


def test_empty_instruments_folder_in_cwd_does_not_break_a_shipped_name(tmp_path, capsys):
    (tmp_path / "instruments").mkdir()
    (tmp_path / "scenarios").mkdir()
    assert load_instrument("sc1").source == str(SHIPPED / "sc1.yaml")
    assert main(["setup", "pair60", "--instrument", "sc1", "-o", "sheet", "--json"]) == 0
    sheet = json.loads(capsys.readouterr().out)
    assert sheet["scale_horizontal"] == 12500  # the shipped SC-1 on the shipped pair60
    assert sorted(p.name for p in (tmp_path / "sheet").iterdir()) == [
        "sheet.md",
        "sheet.pdf",
        "sheet.png",
        "sheet.yaml",
    ]


def test_a_scenario_by_name_is_the_shipped_file(capsys):
    assert main(["scenario", "check", "pair60", "--json"]) == 0
    by_name = json.loads(capsys.readouterr().out)
    assert by_name["file"] == str(paths.data_dir("scenarios") / "pair60.yaml")
    assert by_name["base"]["horizontal_m"] == pytest.approx(1440.078, abs=0.001)


def test_user_folder_adds_an_instrument_and_a_scenario(tmp_path, capsys, caplog):
    sd3 = (SHIPPED / "sd3.yaml").read_text(encoding="utf-8")
    pair80 = (paths.data_dir("scenarios") / "pair80.yaml").read_text(encoding="utf-8")
    user = _user_folder(
        tmp_path / "mine",
        {"instruments/my_sd3.yaml": sd3, "scenarios/my_pair80.yaml": pair80},
    )
    with caplog.at_level(logging.WARNING, logger="stereoplotter.io.paths"):
        assert main(["--data", str(user), "instrument", "show", "my_sd3", "--json"]) == 0
        shown = json.loads(capsys.readouterr().out)
        assert Path(shown["file"]).resolve() == user / "instruments" / "my_sd3.yaml"
        assert main(["--data", str(user), "info", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    origins = {e["key"]: e["from"] for e in info["instruments"] + info["scenarios"]}
    assert origins == {
        "my_sd3": "--data",
        "sc1": "shipped",
        "sd3": "shipped",
        "spr3": "shipped",
        "my_pair80": "--data",
        "book_resection_table7": "shipped",
        "mountain60": "shipped",
        "pair60": "shipped",
        "pair80": "shipped",
    }
    assert [f["from"] for f in info["data_folders"]] == ["--data", "shipped"]
    assert caplog.records == []  # adding is not hiding: nothing to warn about


def test_environment_variable_adds_folders_in_order(tmp_path, monkeypatch):
    sd3 = (SHIPPED / "sd3.yaml").read_text(encoding="utf-8")
    first = _user_folder(tmp_path / "a", {"instruments/extra.yaml": sd3})
    second = _user_folder(tmp_path / "b", {"instruments/more.yaml": sd3})
    monkeypatch.setenv(paths.ENVIRONMENT_VARIABLE, os.pathsep.join([str(first), str(second)]))
    assert paths.available_names("instruments") == ["extra", "more", "sc1", "sd3", "spr3"]
    assert Path(load_instrument("more").source).resolve() == second / "instruments" / "more.yaml"


def test_a_user_file_hiding_a_shipped_one_is_used_with_a_warning(tmp_path, capsys, caplog):
    text = (SHIPPED / "sc1.yaml").read_text(encoding="utf-8")
    assert text.count("value: [-40, 40]") == 1  # base.z_mm
    user = _user_folder(
        tmp_path / "mine", {"instruments/sc1.yaml": text.replace("[-40, 40]", "[-30, 30]")}
    )
    with caplog.at_level(logging.WARNING, logger="stereoplotter.io.paths"):
        assert main(["--data", str(user), "instrument", "show", "sc1", "--json"]) == 0
    shown = json.loads(capsys.readouterr().out)
    assert shown["parameters"]["base.z_mm"]["value"] == [-30.0, 30.0]  # the user's file
    (record,) = caplog.records
    assert record.levelno == logging.WARNING
    message = record.getMessage()
    assert str(user / "instruments" / "sc1.yaml") in message
    assert str(SHIPPED / "sc1.yaml") in message


def test_a_checkout_named_as_user_folder_hides_nothing(caplog):
    checkout = Path(paths.__file__).resolve().parents[2]
    if not (checkout / "instruments").is_dir():
        pytest.skip("not a checkout: no instruments link beside the package")
    paths.set_user_folders([checkout])
    with caplog.at_level(logging.WARNING, logger="stereoplotter.io.paths"):
        assert paths.find_data_file("instruments", "sc1") == SHIPPED / "sc1.yaml"
    assert {f.origin for f in paths.data_files("instruments")} == {"shipped"}
    assert caplog.records == []


def test_unknown_name_and_missing_data_folder_are_one_error_line(tmp_path, capsys):
    assert main(["setup", "pair61", "--instrument", "sc1"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("error: scenarios/: pair61: expected the name of a scenario")
    assert "pair60" in err and len(err.strip().splitlines()) == 1
    assert main(["--data", str(tmp_path / "nowhere"), "info"]) == 1
    err = capsys.readouterr().err
    nowhere = tmp_path / "nowhere"
    assert err == f"error: {nowhere}: --data: expected an existing folder, found no such folder\n"


def test_paths_and_existing_yaml_files_are_used_as_given(tmp_path):
    local = tmp_path / "pair60.yaml"
    local.write_text("not used", encoding="utf-8")
    assert paths.resolve_data_file("scenarios", "pair60.yaml") == Path("pair60.yaml")
    assert paths.resolve_data_file("scenarios", "pair60") == (
        paths.data_dir("scenarios") / "pair60.yaml"
    )
    assert paths.resolve_data_file("scenarios", "sub/pair60") == Path("sub/pair60")
    # a .yaml name found nowhere stays as given: reading it reports the missing file
    assert paths.resolve_data_file("scenarios", "gone.yaml") == Path("gone.yaml")
