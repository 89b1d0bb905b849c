"""The outline of a scenario file — its name and how many photos and points it holds — read
without validating the rest (what ``stereoplotter info`` lists; ``stereoplotter scenario check``
and every command that uses a scenario validate it whole, :mod:`stereoplotter.io.scenario_file`).

This module loads no numpy, pydantic or pyproj: listing the data files stays quick. The three
fields it reads are checked as the full validation checks them, with the same messages.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any

from stereoplotter.errors import ConfigError, describe_value
from stereoplotter.io.yaml_input import load_yaml_mapping

__all__ = ["BLOCK_FIELDS", "ScenarioOutline", "refuse_block_file", "scenario_outline"]

#: Top-level fields that only a block file has (``stereoplotter.setup.block``).
BLOCK_FIELDS = ("models", "models_csv")

_PHOTOS_EXPECTED = "a list of 1 photo or 2 photos named left and right"


@dataclass(frozen=True, slots=True)
class ScenarioOutline:
    """A scenario file's name and its numbers of photos and points."""

    name: str
    photos: int
    points: int


def refuse_block_file(data: Any, source: str) -> None:
    """A :class:`ConfigError` when the document is a block file, not a scenario."""
    block_fields = [k for k in BLOCK_FIELDS if isinstance(data, dict) and k in data]
    if block_fields:
        raise ConfigError(
            source,
            block_fields[0],
            "a scenario (one photo or one stereopair: fields photos, points)",
            "a block file (it has " + ", ".join(block_fields) + ")",
            "a block file is set up model by model with: stereoplotter setup FILE --instrument "
            "NAME",
        )


def _present(data: dict[str, Any], key: str, source: str) -> Any:
    value = data.get(key)
    if value is None:  # a key written without a value counts as absent
        raise ConfigError(source, key, "a value (the field is required)", "nothing")
    return value


def scenario_outline(path: str | os.PathLike[str]) -> ScenarioOutline:
    """Read the name and the numbers of photos and points of the scenario file at ``path``.

    Raises
    ------
    ConfigError
        The file cannot be read or parsed, is a block file, or its ``name``, ``photos`` or
        ``points`` are not what a scenario needs (missing, not a text, not a list of 1 or 2
        photos, not a list of at least one point).
    """
    data, source = load_yaml_mapping(path)
    refuse_block_file(data, source)
    name = _present(data, "name", source)
    if isinstance(name, bool) or not isinstance(name, str | int) or str(name) == "":
        raise ConfigError(source, "name", "a non-empty text", describe_value(name))
    photos = _present(data, "photos", source)
    if not isinstance(photos, list) or not 1 <= len(photos) <= 2:
        found = f"a list of {len(photos)}" if isinstance(photos, list) else describe_value(photos)
        raise ConfigError(source, "photos", _PHOTOS_EXPECTED, found)
    points = _present(data, "points", source)
    if not isinstance(points, list):
        raise ConfigError(source, "points", "a list", describe_value(points))
    if not points:
        raise ConfigError(source, "points", "a list of at least 1 entries", "0 entries")
    return ScenarioOutline(str(name), len(photos), len(points))
