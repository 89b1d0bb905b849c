"""An exercise file (``stereoplotter-exercise/1``): what a trainee does, and with which help.

:class:`ExerciseFile` is the pydantic model (and the JSON Schema in ``docs/schemas/``);
:func:`load_exercise` reads a file by name or path and returns a
:class:`~stereoplotter.trainer.exercise.Exercise` with its scenario and instrument resolved.
The exercise's ``terrain`` and ``tilt`` act on the scenario's file content before it is built:
``flat`` removes the hills and the slope (the plain at the base height); ``hilly`` and
``mountainous`` must be the scenario's own relief class (relief over flying height, see
:data:`RELIEF_CLASSES`); the tilt class scales the photos' α and ω so that the largest is the
class's :data:`TILT_TARGET_DEG` (κ unchanged). A bad file gives one line naming the file and field.

:func:`exercise_from_mapping` is the reader that callers pass to
:meth:`Session.replay <stereoplotter.trainer.session.Session.replay>` (``read_exercise=``) to
rebuild the exercise of a session log from its header; importing this module registers nothing.
"""

from __future__ import annotations

import copy
import os
from pathlib import Path
from typing import Any

from pydantic import Field, field_validator

from stereoplotter.errors import ConfigError
from stereoplotter.io.atomic_write import atomic_write_text
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.paths import list_data_files, resolve_data_file
from stereoplotter.io.scenario_file import scenario_from_mapping
from stereoplotter.io.validation import FileModel, integer, one_of, sequence, text, validate
from stereoplotter.io.yaml_input import load_yaml_mapping
from stereoplotter.io.yaml_output import yaml_text
from stereoplotter.trainer.exercise import (
    ERROR_MODES,
    EXERCISE_FORMAT,
    MODES,
    STAGES,
    TERRAINS,
    TILTS,
    Exercise,
)

__all__ = [
    "RELIEF_CLASSES",
    "TEXT_LIMITS",
    "TILT_TARGET_DEG",
    "AssistsModel",
    "ExerciseFile",
    "exercise_from_mapping",
    "load_exercise",
    "shipped_exercises",
    "write_exercise",
]

#: Longest name, title and description of an exercise (a page shows them whole; the shipped
#: ones are at most 30, 74 and 220). [characters]
TEXT_LIMITS = {"name": 64, "title": 160, "description": 2_000}
#: The largest |α|, |ω| of the photos in each tilt class (assumed: the book's "small tilts"
#: of a few tenths of a degree up to about 2.5°, inside the ±3° correction range of the
#: instruments after the frame rotation of the sheet). [degrees]
TILT_TARGET_DEG = {"small": 0.7, "medium": 1.0, "large": 2.5}
#: Relief classes by (highest − lowest hill or slope effect) / flying height (assumed, the
#: usual split of plain, hilly and mountain terrain for stereoplotter work). [—]
RELIEF_CLASSES = {"flat": (0.0, 0.01), "hilly": (0.01, 0.15), "mountainous": (0.15, 10.0)}


class AssistsModel(FileModel):
    """What the trainee may use (exam mode: never undo nor hints)."""

    parallax_readout: bool = Field(False, description="numeric y/x-parallax read-out")
    undo: bool = Field(True, description="undo/redo (practice mode only)")
    hints: bool = Field(True, description="hints of levels 1-3 (practice mode only)")


class ExerciseFile(FileModel):
    """An exercise file."""

    format: one_of(EXERCISE_FORMAT)  # type: ignore[valid-type]
    name: text
    title: text
    level: integer(1, 20, "difficulty, 1 easiest")  # type: ignore[valid-type]
    description: str = ""
    instrument: text
    scenario: text
    method: one_of(*STAGES)  # type: ignore[valid-type]
    stages: str = Field("all", description="'all' or one stage of the method (1-5, C1-C4)")
    terrain: one_of(*TERRAINS)  # type: ignore[valid-type]
    model: one_of("complete", "incomplete") = "complete"  # type: ignore[valid-type]
    unusable_points: sequence(integer(1, 6), 0, 6) = Field(  # type: ignore[valid-type]
        default_factory=list, description="standard points (1-6) on water or outside the overlap"
    )
    errors: one_of(*ERROR_MODES) = "hidden"  # type: ignore[valid-type]
    tilt: one_of(*TILTS) = "small"  # type: ignore[valid-type]
    assists: AssistsModel = Field(default_factory=AssistsModel)
    mode: one_of(*MODES) = "practice"  # type: ignore[valid-type]
    seed: int | str = Field("per-trainee", description="an integer, or 'per-trainee'")

    @field_validator("name", "title", "description")
    @classmethod
    def _short(cls, v: str, info: Any) -> str:
        limit = TEXT_LIMITS[info.field_name]
        if len(v) > limit:
            raise ValueError(f"text of at most {limit} characters, found {len(v)}")
        return v

    @field_validator("seed")
    @classmethod
    def _seed(cls, v: Any) -> Any:
        if v == "per-trainee" or (isinstance(v, int) and not isinstance(v, bool) and v >= 0):
            return v
        raise ValueError("a non-negative integer or 'per-trainee'")


def _stages(source: str, doc: ExerciseFile) -> tuple[str, ...]:
    all_stages = STAGES[doc.method]
    if doc.stages == "all":
        return all_stages
    if doc.stages not in all_stages:
        raise ConfigError(
            source,
            "stages",
            f"'all' or one stage of the {doc.method} method ({', '.join(all_stages)})",
            doc.stages,
        )
    return (doc.stages,)


def _relief_ratio(scenario: dict[str, Any]) -> float:
    """(Highest − lowest terrain effect) / flying height of the first photo (the file's own
    hills and slope over the points' extent). [—]"""
    terrain = scenario.get("terrain") or {}
    hills = terrain.get("hills") or []
    heights = [0.0] + [float(h["height_m"]) for h in hills]
    placed = [p["local"] for p in scenario.get("points", []) if isinstance(p.get("local"), dict)]
    xs = [float(p["X_m"]) for p in placed] or [0.0]
    ys = [float(p["Y_m"]) for p in placed] or [0.0]
    sx, sy = (float(v) for v in terrain.get("slope", (0.0, 0.0)))
    slope = abs(sx) * (max(xs) - min(xs)) + abs(sy) * (max(ys) - min(ys))
    relief = max(heights) - min(heights) + slope
    flying = float(scenario["photos"][0]["exterior"]["Z_m"]) - float(
        terrain.get("base_height_m", 0.0)
    )
    return relief / flying


def _scenario_for(source: str, doc: ExerciseFile) -> dict[str, Any]:
    """The scenario file's content with the exercise's terrain and tilt applied."""
    data, _ = load_yaml_mapping(resolve_data_file("scenarios", doc.scenario))
    data = copy.deepcopy(data)
    if "terrain" not in data:
        raise ConfigError(source, "scenario", "a scenario with a terrain", doc.scenario)
    if doc.terrain == "flat":
        data["terrain"] = {"base_height_m": data["terrain"].get("base_height_m", 0.0)}
    else:
        ratio = _relief_ratio(data)
        lo, hi = RELIEF_CLASSES[doc.terrain]
        if not lo <= ratio < hi:
            raise ConfigError(
                source,
                "terrain",
                f"the relief class of scenario {doc.scenario} (relief/H = {ratio:.3f})",
                doc.terrain,
                "flat flattens any scenario; hilly and mountainous name the scenario's own relief",
            )
    largest = max(
        abs(float(p["exterior"].get(k, 0.0)))
        for p in data["photos"]
        for k in ("alpha_deg", "omega_deg")
    )
    if largest > 0:
        factor = TILT_TARGET_DEG[doc.tilt] / largest
        for p in data["photos"]:
            for k in ("alpha_deg", "omega_deg"):
                if k in p["exterior"]:
                    p["exterior"][k] = round(float(p["exterior"][k]) * factor, 6)
    return data


def exercise_from_mapping(data: dict[str, Any], source: str = "<exercise>") -> Exercise:
    """An :class:`Exercise` from an exercise file's content (``source`` names it in errors)."""
    doc = validate(ExerciseFile, data, source)
    stages = _stages(source, doc)
    if doc.model == "incomplete" and not doc.unusable_points:
        raise ConfigError(
            source, "unusable_points", "at least one point for an incomplete model", "none"
        )
    if doc.model == "complete" and doc.unusable_points:
        raise ConfigError(
            source, "unusable_points", "none for a complete model", doc.unusable_points
        )
    try:
        spec = load_instrument(doc.instrument)
    except ConfigError as exc:
        raise ConfigError(
            source, "instrument", "an instrument name or file", f"{doc.instrument!r}: {exc}"
        ) from None
    scenario_data = _scenario_for(source, doc)
    scenario = scenario_from_mapping(scenario_data, f"{source}: scenario {doc.scenario}")
    return Exercise(
        name=doc.name,
        title=doc.title,
        level=doc.level,
        instrument=doc.instrument,
        scenario_name=doc.scenario,
        method=doc.method,
        stages=stages,
        terrain=doc.terrain,
        model=doc.model,
        unusable_points=tuple(doc.unusable_points),
        errors=doc.errors,
        tilt=doc.tilt,
        assists=doc.assists.model_dump(),
        mode=doc.mode,
        seed=None if doc.seed == "per-trainee" else int(doc.seed),
        description=doc.description,
        spec=spec,
        scenario=scenario,
        source=dict(data),
    )


def load_exercise(path: str | os.PathLike[str]) -> Exercise:
    """Read an exercise file by shipped name (``"e01-stage1-sc1"``) or by path."""
    data, source = load_yaml_mapping(resolve_data_file("exercises", path))
    return exercise_from_mapping(data, source)


def shipped_exercises() -> list[Path]:
    """The exercise files found by name (shipped and user folders), sorted by name."""
    return sorted(list_data_files("exercises"))




def write_exercise(
    path: str | os.PathLike[str], data: dict[str, Any], *, overwrite: bool = False
) -> Exercise:
    """Validate an exercise file's content (as :func:`load_exercise` would read it back) and
    write it as YAML, whole or not at all (temporary file and rename, the user's umask).

    Raises
    ------
    ConfigError
        The content is not a valid exercise (one line naming the field), or the file exists
        and ``overwrite`` is false.
    """
    target = Path(path)
    exercise = exercise_from_mapping(data, str(target))
    if target.exists() and not overwrite:
        raise ConfigError(str(target), "path", "a new file (or --force)", "an existing file")
    atomic_write_text(target, yaml_text(data, width=100))
    return exercise
