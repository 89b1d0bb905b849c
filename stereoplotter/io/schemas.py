"""JSON Schemas of the input files (and of ``budget --json``), generated from pydantic models.

``python -m stereoplotter.io.schemas [FOLDER]`` writes ``FOLDER/KIND.schema.json`` (default
``docs/schemas``); editors that read JSON Schema (VS Code's YAML extension, JetBrains) can then
check a file as it is typed. ``tests/cli/test_schemas.py`` keeps the published files equal to
the generated ones. ``docs/input-files.md`` says how to point an editor at them.
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path
from typing import Any

from pydantic import BaseModel

from stereoplotter.io.atomic_write import atomic_write_text
from stereoplotter.io.block_file import BlockFile
from stereoplotter.io.block_measurements_file import BlockMeasurementsFile
from stereoplotter.io.budget_output import BudgetOutput
from stereoplotter.io.errors_file import ErrorsFile
from stereoplotter.io.exercise_file import ExerciseFile
from stereoplotter.io.geometry_file import GeometryFile
from stereoplotter.io.instrument_file import InstrumentFile
from stereoplotter.io.job_file import JobFile
from stereoplotter.io.scenario_file import ScenarioFile
from stereoplotter.io.trainee_sheet import TraineeSheet

__all__ = ["MODELS", "schema", "schema_text", "write_schemas"]

#: File kind → its model.
MODELS: dict[str, type[BaseModel]] = {
    "scenario": ScenarioFile,
    "instrument": InstrumentFile,
    "block": BlockFile,
    "errors": ErrorsFile,
    "geometry": GeometryFile,
    "job": JobFile,
    "budget": BudgetOutput,  # an output: the JSON of `stereoplotter budget --json`
    "trainee-sheet": TraineeSheet,
    "exercise": ExerciseFile,
    "block-measurements": BlockMeasurementsFile,
}


def schema(kind: str) -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of one file kind."""
    out = MODELS[kind].model_json_schema(mode="validation")
    return {"$schema": "https://json-schema.org/draft/2020-12/schema", **out}


def schema_text(kind: str) -> str:
    """:func:`schema` as the text of the published file."""
    return json.dumps(schema(kind), indent=2, ensure_ascii=False, sort_keys=True) + "\n"


def write_schemas(folder: str | os.PathLike[str]) -> list[Path]:
    """Write ``KIND.schema.json`` for every kind of :data:`MODELS` into ``folder``."""
    paths = []
    for kind in MODELS:
        path = Path(folder) / f"{kind}.schema.json"
        atomic_write_text(path, schema_text(kind))
        paths.append(path)
    return paths


if __name__ == "__main__":  # pragma: no cover
    for p in write_schemas(sys.argv[1] if len(sys.argv) > 1 else "docs/schemas"):
        print(p)
