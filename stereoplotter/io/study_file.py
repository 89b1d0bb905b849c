"""The study file (``stereoplotter-study/1``): a pydantic schema and the loader.

A study file names the base scenario (a shipped name, a file, or a generated normal case), the
axes (each a list of values or a range ``{from, to, steps}``), an optional quasi-random
``sample`` of the ranged axes (Sobol or Latin hypercube), the trials per cell, the measures and
the seed. ``docs/studies.md`` describes it; the JSON Schema is ``docs/schemas/study.schema.json``
(:func:`study_schema_text`). :func:`load_study` validates a file and loads its base scenario and
instruments into a :class:`~stereoplotter.study.design.StudyDesign`; a bad file gives one line
``FILE: FIELD: expected …, found …``.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from pathlib import Path
from typing import Annotated, Any

from pydantic import Discriminator, Field, Tag, create_model, model_validator

from stereoplotter.errors import ConfigError, StereoplotterError
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.paths import shipped_root
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.io.validation import (
    FileModel,
    integer,
    invalid,
    number,
    one_of,
    sequence,
    text,
    validate,
)
from stereoplotter.io.yaml_input import load_yaml_mapping
from stereoplotter.procedure.trials import DEFAULT_MEMORY_BUDGET_MB, chunk_trials_for
from stereoplotter.study.design import (
    AXES,
    GEOMETRY_AXES,
    MEASURES,
    OPERATORS,
    Axis,
    Sample,
    StudyDesign,
)

__all__ = [
    "STUDY_FORMAT",
    "StudyFile",
    "load_study",
    "shipped_studies",
    "study_fingerprint",
    "study_from_mapping",
    "study_schema_text",
]

STUDY_FORMAT = "stereoplotter-study/1"

#: Numeric axes: name → (low, high, low open) of a value. Limits: beyond them the normal case
#: is meaningless (an overlap ≤ 50 % leaves no stereo model) or outside every instrument.
_LIMITS = {
    "f_mm": (0.0, 1000.0, True),
    "overlap": (0.5, 0.99, True),
    "flying_height_m": (0.0, 30000.0, True),
    "alpha_deg": (-20.0, 20.0, False),
    "omega_deg": (-20.0, 20.0, False),
    "relief": (0.0, 1.0, False),
    "base_direction_deg": (-360.0, 360.0, False),
    "judgement_scale": (0.0, 100.0, False),
    "instrument_error_scale": (0.0, 100.0, False),
}


def _num(name: str) -> Any:
    low, high, low_open = _LIMITS[name]
    return number(AXES[name].unit, low, high, low_open=low_open, description=AXES[name].meaning)


def _ordered(self: Any) -> Any:
    if not self.from_ < self.to:
        raise invalid(f"a value above from = {self.from_:g}", self.to, at=("to",))
    return self


def _range_model(name: str) -> type[FileModel]:
    """The model of a range of axis ``name`` (named ``Range_<axis>`` in the JSON Schema)."""
    value = _num(name)
    steps = integer(2, 100_000, "values on a grid (ignored when sampled)")
    return create_model(
        f"Range_{name}",
        __base__=FileModel,
        __doc__=f"A range of {name}: `steps` values from `from` to `to` (sampled with `sample`).",
        __validators__={"ordered": model_validator(mode="after")(_ordered)},
        from_=(value, Field(alias="from")),
        to=(value, ...),
        steps=(steps | None, None),
    )


def _kind(v: Any) -> str:
    return "list" if isinstance(v, list) else "range"


def _axis_type(name: str) -> Any:
    """A list of values, or (numeric axes) a range."""
    if AXES[name].categorical:
        words = {
            "method": ("setup", "conventional"),
            "practice": ("operator", "book"),
            "operator": OPERATORS,
        }
        item = one_of(*words[name]) if name in words else text
        return sequence(item, 1)
    return Annotated[
        Annotated[sequence(_num(name), 1), Tag("list")]
        | Annotated[_range_model(name), Tag("range")],
        Discriminator(_kind),
    ]


class AxesModel(FileModel):
    """The axes of the study: each a list of values or a range (``docs/studies.md``)."""

    f_mm: _axis_type("f_mm") | None = None  # type: ignore[valid-type]
    overlap: _axis_type("overlap") | None = None  # type: ignore[valid-type]
    flying_height_m: _axis_type("flying_height_m") | None = None  # type: ignore[valid-type]
    alpha_deg: _axis_type("alpha_deg") | None = None  # type: ignore[valid-type]
    omega_deg: _axis_type("omega_deg") | None = None  # type: ignore[valid-type]
    relief: _axis_type("relief") | None = None  # type: ignore[valid-type]
    base_direction_deg: _axis_type("base_direction_deg") | None = None  # type: ignore[valid-type]
    instrument: _axis_type("instrument") | None = None  # type: ignore[valid-type]
    method: _axis_type("method") | None = None  # type: ignore[valid-type]
    practice: _axis_type("practice") | None = None  # type: ignore[valid-type]
    operator: _axis_type("operator") | None = None  # type: ignore[valid-type]
    judgement_scale: _axis_type("judgement_scale") | None = None  # type: ignore[valid-type]
    instrument_error_scale: _axis_type("instrument_error_scale") | None = None  # type: ignore[valid-type]


class NormalCaseModel(FileModel):
    """A generated normal case: geometry values on the base scenario's camera, frame and map
    sheet (``study.geometry``); every value not given is the template's."""

    template: text = Field(
        "pair60", description="the scenario whose camera, frame and map sheet are used"
    )
    f_mm: _num("f_mm") | None = None  # type: ignore[valid-type]
    overlap: _num("overlap") | None = None  # type: ignore[valid-type]
    flying_height_m: _num("flying_height_m") | None = None  # type: ignore[valid-type]
    alpha_deg: _num("alpha_deg") | None = None  # type: ignore[valid-type]
    omega_deg: _num("omega_deg") | None = None  # type: ignore[valid-type]
    relief: _num("relief") | None = None  # type: ignore[valid-type]
    base_direction_deg: _num("base_direction_deg") | None = None  # type: ignore[valid-type]


class BaseModelFile(FileModel):
    """The base scenario: exactly one of ``scenario`` (a shipped name or a file) and
    ``normal_case``."""

    scenario: text | None = None
    normal_case: NormalCaseModel | None = None

    @model_validator(mode="after")
    def _one(self) -> BaseModelFile:
        if (self.scenario is None) == (self.normal_case is None):
            found = "both" if self.scenario is not None else "neither"
            raise invalid("exactly one of scenario, normal_case", found)
        return self


class SampleModel(FileModel):
    """A quasi-random sample of the ranged axes (``scipy.stats.qmc``, scrambled, seeded)."""

    method: one_of("sobol", "lhs")  # type: ignore[valid-type]
    points: integer(1, 1_048_576, "sample points (a power of 2 for sobol)")  # type: ignore[valid-type]
    seed: integer(0, 2**63 - 1, "seed of the scrambling") = 0  # type: ignore[valid-type]

    @model_validator(mode="after")
    def _power_of_two(self) -> SampleModel:
        if self.method == "sobol" and self.points & (self.points - 1):
            raise invalid("a power of 2 for a Sobol sample", self.points, at=("points",))
        return self


class StudyFile(FileModel):
    """A study file (``stereoplotter-study/1``)."""

    format: one_of(STUDY_FORMAT)  # type: ignore[valid-type]
    name: text
    description: str = ""
    base: BaseModelFile
    instrument: text = Field("sc1", description="the instrument when `instrument` is no axis")
    axes: AxesModel
    sample: SampleModel | None = None
    trials: integer(2, 10**9, "trials of the simulated procedure per cell")  # type: ignore[valid-type]
    chunk_trials: (
        integer(1, 10**7, "trials per task (default: the 256 MB memory budget)") | None
    ) = None  # type: ignore[valid-type]
    measures: sequence(one_of(*MEASURES), 1) = Field(  # type: ignore[valid-type]
        default_factory=lambda: ["checks", "y_parallax", "heights", "plan"]
    )
    procedure_trials: integer(0, 10**8, "trials of the procedure Monte Carlo per cell") = 0  # type: ignore[valid-type]
    budget_trials: integer(0, 10**6, "trials of each budget configuration per cell") = 0  # type: ignore[valid-type]
    seed: integer(0, 2**63 - 1, "the study seed (every cell runs trials 0…T−1 of it)")  # type: ignore[valid-type]


def _axes(doc: StudyFile, source: str) -> tuple[Axis, ...]:
    out = []
    ranged = False
    for name in doc.axes.model_fields_set:
        value = getattr(doc.axes, name)
        if value is None:
            continue
        if isinstance(value, list):
            out.append(Axis(name, tuple(value)))
            continue
        ranged = True
        if doc.sample is None and value.steps is None:
            raise ConfigError(
                source, f"axes.{name}.steps", "a number of steps (no sample)", "nothing"
            )
        out.append(Axis(name, None, value.from_, value.to, value.steps))
    if doc.sample is not None and not ranged:
        raise ConfigError(source, "sample", "at least one ranged axis to sample", "only lists")
    order = list(AxesModel.model_fields)
    return tuple(sorted(out, key=lambda a: order.index(a.name)))


def _resolve_study(name_or_path: str | os.PathLike[str]) -> Path:
    """A shipped study by name (``"formula-validity"``) or a path."""
    path = Path(name_or_path)
    if path.suffix or os.sep in str(name_or_path) or path.exists():
        return path
    shipped = shipped_root() / "studies" / f"{name_or_path}.yaml"
    if not shipped.exists():
        raise ConfigError(
            str(name_or_path),
            "(file)",
            "a study file or a shipped study name",
            "neither",
            "shipped: " + ", ".join(p.stem for p in shipped_studies()),
        )
    return shipped


def shipped_studies() -> list[Path]:
    """The shipped study files, sorted by name."""
    return sorted((shipped_root() / "studies").glob("*.yaml"))


def study_from_mapping(data: dict[str, Any], source: str = "<study>") -> StudyDesign:
    """Validate a parsed study document, load its scenario and instruments."""
    try:
        doc = validate(StudyFile, data, source)
    except ConfigError as exc:  # an axis is a tagged union: drop the tag from the field path
        field = exc.field.replace(".list[", "[").replace(".range.", ".")
        raise ConfigError(exc.source, field, exc.expected, exc.found, exc.hint) from None
    axes = _axes(doc, source)
    names = {a.name: a for a in axes}
    keys = list(names["instrument"].values) if "instrument" in names else [doc.instrument]
    instruments = {}
    for key in keys:
        try:
            instruments[key] = load_instrument(key)
        except StereoplotterError as exc:
            raise ConfigError(
                source, "instrument", "an instrument name or file", key, str(exc)
            ) from None
    defaults: dict[str, Any] = {}
    if doc.base.normal_case is not None:
        case = doc.base.normal_case
        base = load_scenario(case.template)
        defaults = {k: getattr(case, k) for k in GEOMETRY_AXES if getattr(case, k) is not None}
        defaults.setdefault("relief", 0.0)  # a normal case: flat unless asked
    else:
        base = load_scenario(str(doc.base.scenario))
    if not base.is_stereopair:
        raise ConfigError(source, "base", "a stereopair scenario", base.name)
    method = (
        "conventional"
        if "conventional" in (names.get("method") or Axis("", ("",))).values
        else "setup"
    )
    chunk = doc.chunk_trials or min(doc.trials, chunk_trials_for(DEFAULT_MEMORY_BUDGET_MB, method))
    sample = (
        None
        if doc.sample is None
        else Sample(doc.sample.method, doc.sample.points, doc.sample.seed)
    )
    return StudyDesign(
        name=doc.name,
        base=base,
        instruments=instruments,
        axes=axes,
        trials=doc.trials,
        chunk_trials=chunk,
        measures=tuple(dict.fromkeys(doc.measures)),
        seed=doc.seed,
        procedure_trials=doc.procedure_trials,
        budget_trials=doc.budget_trials,
        sample=sample,
        defaults=defaults,
        description=doc.description,
    )


def load_study(path: str | os.PathLike[str]) -> tuple[StudyDesign, dict[str, Any]]:
    """Read a study file (a path or a shipped name); the design and the parsed document."""
    data, source = load_yaml_mapping(_resolve_study(path))
    return study_from_mapping(data, source), data


def study_fingerprint(data: dict[str, Any]) -> str:
    """SHA-256 of the study document as canonical JSON (a results store belongs to one study)."""
    canonical = json.dumps(data, sort_keys=True, ensure_ascii=False, default=str)
    return hashlib.sha256(canonical.encode()).hexdigest()


def study_schema_text() -> str:
    """The JSON Schema (draft 2020-12) of the study file, as published in ``docs/schemas``."""
    out = StudyFile.model_json_schema(mode="validation")
    out = {"$schema": "https://json-schema.org/draft/2020-12/schema", **out}
    return json.dumps(out, indent=2, ensure_ascii=False, sort_keys=True, default=_inf) + "\n"


def _inf(value: Any) -> Any:  # pragma: no cover - the limits are finite
    return None if isinstance(value, float) and math.isinf(value) else value


if __name__ == "__main__":  # pragma: no cover
    import sys

    target = Path(sys.argv[1] if len(sys.argv) > 1 else "docs/schemas/study.schema.json")
    target.write_text(study_schema_text(), encoding="utf-8")
