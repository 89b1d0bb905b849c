"""The published JSON Schemas (docs/schemas) are the ones the models generate, and every shipped
input file of a kind with a schema validates against it."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest
import yaml

from stereoplotter.io.paths import data_dir
from stereoplotter.io.schemas import MODELS, schema_text, write_schemas

DOCS = Path(__file__).resolve().parents[2] / "docs" / "schemas"
SHIPPED = {"scenario": sorted(data_dir("scenarios").glob("*.yaml"))}


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
    assert len(SHIPPED[kind]) == 4
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
