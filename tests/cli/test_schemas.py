"""The published JSON Schemas (docs/schemas) are the ones the models generate, and every shipped
input file of a kind with a schema validates against it."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest
import yaml

from stereoplotter.io.geometry_file import GeometryFile
from stereoplotter.io.paths import data_dir
from stereoplotter.io.schemas import MODELS, schema_text, write_schemas
from stereoplotter.verification.table import BOOK

DOCS = Path(__file__).resolve().parents[2] / "docs" / "schemas"
SHIPPED = {
    "scenario": sorted(data_dir("scenarios").glob("*.yaml")),
    "instrument": sorted(data_dir("instruments").glob("*.yaml")),
    "block": sorted((data_dir("scenarios") / "blocks").glob("*.yaml")),
    "exercise": sorted(data_dir("exercises").glob("*.yaml")),
}
COUNTS = {"scenario": 4, "instrument": 3, "block": 1, "exercise": 26}


@pytest.mark.parametrize("kind", list(MODELS))
def test_published_schema_is_generated(kind, tmp_path):
    published = DOCS / f"{kind}.schema.json"
    assert published.read_text(encoding="utf-8") == schema_text(kind), (
        "regenerate with: python -m stereoplotter.io.schemas"
    )
    (written,) = [p for p in write_schemas(tmp_path) if p.name == published.name]
    assert written.read_text(encoding="utf-8") == published.read_text(encoding="utf-8")


@pytest.mark.parametrize("kind", list(SHIPPED))
def test_shipped_files_validate_against_their_schema(kind):
    validator = jsonschema.Draft202012Validator(
        json.loads((DOCS / f"{kind}.schema.json").read_text(encoding="utf-8"))
    )
    assert len(SHIPPED[kind]) == COUNTS[kind]
    for path in SHIPPED[kind]:
        doc = yaml.safe_load(path.read_text(encoding="utf-8"))
        assert [e.message for e in validator.iter_errors(doc)] == [], path.name


def test_schema_refuses_what_the_loader_refuses():
    validator = jsonschema.Draft202012Validator(json.loads(schema_text("scenario")))
    doc = yaml.safe_load((data_dir("scenarios") / "pair60.yaml").read_text(encoding="utf-8"))
    doc["camera"]["focal_lenght_mm"] = doc["camera"].pop("focal_length_mm")
    messages = [e.message for e in validator.iter_errors(doc)]
    assert any("focal_lenght_mm" in m for m in messages)  # additionalProperties: false
    doc["camera"]["focal_length_mm"] = doc["camera"].pop("focal_lenght_mm")
    doc["photos"][0]["exterior"]["alpha_deg"] = 25.0  # |tilt| ≤ 15°
    assert [e.validator for e in validator.iter_errors(doc)] == ["maximum"]


def _validator(kind):
    return jsonschema.Draft202012Validator(json.loads(schema_text(kind)))


def _leaf_errors(errors):
    """The innermost errors (an optional section is ``anyOf: [{$ref}, {type: null}]``), without
    the "is not null" branch."""
    for e in errors:
        if e.context:
            yield from _leaf_errors(e.context)
        elif e.validator_value != "null":
            yield e


def _sc1():
    return yaml.safe_load((data_dir("instruments") / "sc1.yaml").read_text(encoding="utf-8"))


def test_instrument_schema_refuses_what_the_loader_refuses():
    validator = _validator("instrument")
    doc = _sc1()
    doc["base"]["z_mm"].pop("basis")  # assumed needs a basis
    doc["mark"]["diameter_mm"]["value"] = 7.0  # (0, 5] mm
    doc["counters"]["present"]["value"] = "yes"
    doc["tolerances"]["corner4_mm"]["basis"] = "why"  # documented: src, no basis
    errors = sorted(
        (list(e.absolute_path), e.validator) for e in _leaf_errors(validator.iter_errors(doc))
    )
    assert errors == [
        (["base", "z_mm"], "required"),
        (["counters", "present", "value"], "type"),
        (["mark", "diameter_mm", "value"], "maximum"),
        (["tolerances", "corner4_mm"], "not"),
    ]


def test_instrument_schema_lets_a_file_with_inherits_omit_leaves():
    validator = _validator("instrument")
    doc = _sc1()
    thin = {"inherits": "family.yaml", "name": doc["name"], "mark": doc["mark"]}
    assert list(validator.iter_errors(thin)) == []
    family = {k: v for k, v in doc.items() if k not in ("name", "principle")}
    assert list(validator.iter_errors(family)) == []  # no name: a family file
    del doc["mark"]  # a whole instrument (a name, no inherits) must have every required leaf
    assert [e.message for e in validator.iter_errors(doc)] == ["'mark' is a required property"]


def test_block_schema_refuses_what_the_loader_refuses():
    validator = _validator("block")
    doc = yaml.safe_load(SHIPPED["block"][0].read_text(encoding="utf-8"))
    doc["models"][0]["left"]["alpha_deg"] = 22.0  # |tilt| ≤ 15°
    doc["models"][1]["name"] = "../evil"  # usable as a folder name
    doc["models_csv"] = "m.csv"  # exactly one of models, models_csv
    errors = sorted(
        (list(e.absolute_path), e.validator) for e in _leaf_errors(validator.iter_errors(doc))
    )
    assert errors == [
        ([], "oneOf"),
        (["models", 0, "left", "alpha_deg"], "maximum"),
        (["models", 1, "name"], "pattern"),
    ]


def test_errors_and_geometry_schemas():
    errors = _validator("errors")
    good = {"backlash": 0.02, "setting.bx": {"distribution": "uniform", "scale": 0.1}}
    assert list(errors.iter_errors(good)) == []
    bad = {"backlash": -1, "setting.bx": {"sigma": 0.1, "scale": 0.1}}
    found = sorted((*e.absolute_path, e.validator) for e in _leaf_errors(errors.iter_errors(bad)))
    assert found == [  # each value fails both branches: a scale, {distribution, scale}
        ("backlash", "minimum"),
        ("backlash", "type"),
        ("setting.bx", "additionalProperties"),
        ("setting.bx", "type"),
    ]
    geometry = _validator("geometry")
    assert list(GeometryFile.model_fields) == list(BOOK)  # the keys of the table's setting
    assert list(geometry.iter_errors({"f": 70.0, "p60": 90.0})) == []
    assert [e.validator for e in _leaf_errors(geometry.iter_errors({"f": 0.5, "q": 1}))] == [
        "additionalProperties",
        "minimum",
    ]
