"""The study file: the shipped studies, one-line errors, the published JSON Schema."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest
import yaml

from stereoplotter.cli import main
from stereoplotter.errors import ConfigError
from stereoplotter.io.study_file import load_study, study_from_mapping, study_schema_text

ROOT = Path(__file__).parents[2]
VALID = {
    "format": "stereoplotter-study/1",
    "name": "t",
    "base": {"scenario": "pair60"},
    "axes": {"overlap": {"from": 0.6, "to": 0.8, "steps": 3}, "method": ["setup"]},
    "trials": 10,
    "seed": 1,
}


def test_shipped_studies_have_their_grid_sizes():
    fv, _ = load_study("formula-validity")
    assert len(fv.cells()) == 4 * 5 * 4 * 4 * 4 * 3 * 2  # 7 680 configurations
    assert fv.procedures() == 76_800_000
    assert set(fv.instruments) == {"sc1", "spr3", "sd3"}
    skill, _ = load_study(ROOT / "studies" / "operator-skill.yaml")
    assert len(skill.cells()) == 9 * 5 * 2
    assert "budget" in skill.measures and skill.budget_trials > 0


def test_a_normal_case_base_gives_defaults_for_the_cells():
    data = {**VALID, "base": {"normal_case": {"f_mm": 100, "overlap": 0.7}}}
    d = study_from_mapping(data)
    assert d.defaults == {"f_mm": 100.0, "overlap": 0.7, "relief": 0.0}
    assert d.config(d.cells()[0])["overlap"] == 0.6  # the axis overrides the default


@pytest.mark.parametrize(
    ("path", "value", "message"),
    [
        (("axes", "tilt"), [1.0], "axes.tilt: expected no such field.*allowed here"),
        (
            ("axes", "overlap"),
            {"from": 0.8, "to": 0.6, "steps": 3},
            r"axes\.overlap\.to: expected a value above from = 0\.8",
        ),
        (("axes", "overlap"), [0.3], r"axes\.overlap\[0\]: expected a number in \(0\.5, 0\.99\]"),
        (
            ("axes", "method"),
            ["levelled"],
            r"axes\.method\[0\]: expected one of setup, conventional",
        ),
        (("sample",), {"method": "sobol", "points": 100}, r"sample\.points: expected a power of 2"),
        (("measures",), ["heights", "speed"], r"measures\[1\]: expected one of"),
        (("base",), {"scenario": "pair60", "normal_case": {}}, "base: expected exactly one of"),
        (
            ("axes", "overlap"),
            {"from": 0.6, "to": 0.8},
            r"axes\.overlap\.steps: expected a number of steps",
        ),
    ],
)
def test_bad_study_gives_one_line_naming_the_field(path, value, message):
    data = copy.deepcopy(VALID)
    node = data
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    with pytest.raises(ConfigError, match=message) as err:
        study_from_mapping(data, "s.yaml")
    assert str(err.value).startswith("s.yaml: ") and "\n" not in str(err.value)


def test_the_shipped_files_are_valid_yaml_with_the_format_line():
    for name in ("formula-validity", "operator-skill"):
        data = yaml.safe_load((ROOT / "studies" / f"{name}.yaml").read_text(encoding="utf-8"))
        assert data["format"] == "stereoplotter-study/1" and data["name"] == name


def test_published_schema_is_the_generated_one():
    published = (ROOT / "docs" / "schemas" / "study.schema.json").read_text(encoding="utf-8")
    assert published == study_schema_text()
    jsonschema = pytest.importorskip("jsonschema")
    jsonschema.validate(VALID, json.loads(published))


def test_shipped_studies_validate_against_the_schema():
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads((ROOT / "docs" / "schemas" / "study.schema.json").read_text("utf-8"))
    for path in sorted((ROOT / "studies").glob("*.yaml")):
        doc = yaml.safe_load(path.read_text(encoding="utf-8"))
        assert list(jsonschema.Draft202012Validator(schema).iter_errors(doc)) == [], path.name


def test_cli_answers_a_bad_study_with_one_error_line(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump({**VALID, "trials": 1}), encoding="utf-8")
    code = main(["study", "run", str(bad), "-o", str(tmp_path / "r.zarr"), "--workers", "0"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 1
    assert err == [f"error: {bad}: trials: expected an integer in [2, 1000000000], found 1"]
    assert not (tmp_path / "r.zarr").exists()
