"""The block file: N stereopairs of one camera for the setup-data computer in block mode.

A YAML file (``docs/scenarios.md``) with ``name``, ``camera``, ``map_scale``, optional ``scales``
and the models, inline (``models``) or in a CSV file (``models_csv``); read and validated into a
:class:`Block` (arrays over the N models) for :func:`stereoplotter.setup.block.compute_block`.
"""

from __future__ import annotations

import csv
import io
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from pydantic import ConfigDict, Field, field_validator, model_validator

from stereoplotter.errors import ConfigError
from stereoplotter.io.scenario_file import MAX_TILT_DEG, CameraModel, camera_from_model
from stereoplotter.io.validation import (
    FileModel,
    integer,
    invalid,
    number,
    sequence,
    text,
    validate,
    vector,
)
from stereoplotter.io.yaml_input import load_yaml_mapping
from stereoplotter.scenario.model import Camera

__all__ = ["CSV_COLUMNS", "Block", "BlockFile", "load_block"]

_EO_KEYS = ("X_m", "Y_m", "Z_m", "alpha_deg", "omega_deg", "kappa_deg")
#: Columns of a ``models_csv`` file; ``height_points`` ("id=Z_m;id=Z_m", may be empty) is optional.
CSV_COLUMNS = (
    "name",
    *(f"left_{k}" for k in _EO_KEYS),
    *(f"right_{k}" for k in _EO_KEYS),
    "terrain_lowest_m",
    "terrain_highest_m",
)
_NAME_RE = re.compile(r"^[\w][\w.+-]*$")

# --- the block file ---------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class Block:
    """A validated block file: N stereopairs of one camera.

    Attributes
    ----------
    name, source : str
        Block name; the file it was read from.
    camera : Camera
        The camera (same schema as a scenario's camera).
    map_scale_denominator : int
        M_map. [—]
    horizontal_scale_denominator, vertical_scale_denominator : int or None
        Forced M_г, M_в (``scales:``), else None (chosen per pair).
    model_names : tuple of str
    centre_left_m, centre_right_m : ndarray, shape (N, 3)
        X_S, Y_S, Z_S of the left and right photo. [m]
    angles_left, angles_right : ndarray, shape (N, 3)
        α, ω, κ of Eq. (2.50). [rad]
    terrain_m : ndarray, shape (N, 2)
        Lowest and highest ground height of each model's working area. [m]
    height_point_ids : tuple of tuple of str
        Ids of the height points of each model.
    height_points_m : ndarray, shape (N, P)
        Their Z, padded with NaN. [m]
    """

    name: str
    source: str
    camera: Camera
    map_scale_denominator: int
    horizontal_scale_denominator: int | None
    vertical_scale_denominator: int | None
    model_names: tuple[str, ...]
    centre_left_m: NDArray[np.float64]
    angles_left: NDArray[np.float64]
    centre_right_m: NDArray[np.float64]
    angles_right: NDArray[np.float64]
    terrain_m: NDArray[np.float64]
    height_point_ids: tuple[tuple[str, ...], ...]
    height_points_m: NDArray[np.float64]

    def __len__(self) -> int:
        return len(self.model_names)



# --- the models -------------------------------------------------------------------------------

_TILT_BASIS = f"near-vertical aerial photos only: |tilt| ≤ {MAX_TILT_DEG:g}°"
_XY = number("m", -1.0e7, 1.0e7)
_TILT = number("°", -MAX_TILT_DEG, MAX_TILT_DEG, basis=_TILT_BASIS)
_GROUND = number("m", -500.0, 9000.0)
_SCALE = integer(100, 1_000_000)


class Station(FileModel):
    """The exterior orientation of one photo of a model (Eq. (2.50) angles)."""

    X_m: _XY  # type: ignore[valid-type]
    Y_m: _XY  # type: ignore[valid-type]
    Z_m: number("m", -500.0, 50000.0)  # type: ignore[valid-type]
    alpha_deg: _TILT  # type: ignore[valid-type]
    omega_deg: _TILT  # type: ignore[valid-type]
    kappa_deg: number("°", -180.0, 180.0)  # type: ignore[valid-type]


class HeightPoint(FileModel):
    id: text  # type: ignore[valid-type]
    Z_m: _GROUND  # type: ignore[valid-type]


class ModelEntry(FileModel):
    """One stereopair of the block (an entry of ``models``, or a row of ``models_csv``)."""

    name: text = Field(  # type: ignore[valid-type]
        description="usable as a folder name: letters, digits, _ . + -",
        json_schema_extra={"pattern": _NAME_RE.pattern},
    )
    left: Station
    right: Station
    terrain_m: vector(2, "m", -500.0, 9000.0) = Field(  # type: ignore[valid-type]
        description="lowest and highest ground of the working area [m]"
    )
    height_points: sequence(HeightPoint) = Field(default_factory=list)  # type: ignore[valid-type]

    @field_validator("name")
    @classmethod
    def _folder_name(cls, name: str) -> str:
        if not _NAME_RE.match(name) or name in (".", ".."):
            raise invalid("a model name usable as a folder name (letters, digits, _ . + -)", name)
        return name

    @model_validator(mode="after")
    def _unique_ids(self) -> ModelEntry:
        seen: set[str] = set()
        for j, p in enumerate(self.height_points):
            if p.id in seen:
                raise invalid("a unique point id", p.id, at=("height_points", j, "id"))
            seen.add(p.id)
        return self


class Scales(FileModel):
    horizontal: _SCALE | None = None  # type: ignore[valid-type]
    vertical: _SCALE | None = None  # type: ignore[valid-type]


class BlockFile(FileModel):
    """A block file (``docs/scenarios.md``): exactly one of ``models``, ``models_csv``."""

    model_config = ConfigDict(
        extra="forbid",
        frozen=True,
        title="stereoplotter block file",
        json_schema_extra={"oneOf": [{"required": ["models"]}, {"required": ["models_csv"]}]},
    )

    name: text  # type: ignore[valid-type]
    description: str | None = None
    camera: CameraModel
    map_scale: _SCALE  # type: ignore[valid-type]
    scales: Scales | None = None
    models: sequence(ModelEntry, min_length=1) | None = None  # type: ignore[valid-type]
    models_csv: text | None = Field(  # type: ignore[valid-type]
        None, description="a CSV file next to this one (columns: docs/scenarios.md)"
    )

    @model_validator(mode="before")
    @classmethod
    def _exactly_one(cls, v: Any) -> Any:
        if isinstance(v, dict) and not set(v) - set(cls.model_fields):
            given = [k for k in ("models", "models_csv") if v.get(k) is not None]
            if len(given) != 1:
                found = "both" if given else "neither"
                raise invalid("exactly one of models, models_csv", found, at=("models",))
        return v

    @model_validator(mode="after")
    def _unique_names(self) -> BlockFile:
        seen: set[str] = set()
        for i, m in enumerate(self.models or ()):
            if m.name in seen:
                raise invalid("a unique model name", m.name, at=("models", i, "name"))
            seen.add(m.name)
        return self


def load_block(path: str | os.PathLike[str]) -> Block:
    """Read and validate a block file.

    Parameters
    ----------
    path : str or path-like
        A YAML file with ``name``, ``camera``, ``map_scale``, optional ``scales: {horizontal,
        vertical}`` and exactly one of ``models`` (a list) or ``models_csv`` (a CSV file relative
        to the YAML, columns :data:`CSV_COLUMNS` plus an optional ``height_points`` column
        ``"id=Z_m;id=Z_m"``).

    Returns
    -------
    Block

    Raises
    ------
    ConfigError
        "FILE: FIELD: expected …, found …" for the first problem found (for a CSV row the field
        is ``line L: column``).

    Examples
    --------
    >>> from stereoplotter.io.paths import data_dir
    >>> block = load_block(data_dir("scenarios") / "blocks" / "strip60.yaml")
    >>> len(block), block.camera.focal_length_mm
    (8, 70.0)
    """
    data, source = load_yaml_mapping(path)
    doc = validate(BlockFile, data, source)
    camera = camera_from_model(source, doc.camera)
    if doc.models is not None:
        models, rows_source = list(doc.models), source
        where = [f"models[{i}]" for i in range(len(models))]
    else:
        assert doc.models_csv is not None  # the model has exactly one of the two
        csv_path = Path(source).parent / doc.models_csv
        rows_source = str(csv_path)
        models, where = _models_csv(csv_path)
        if not models:
            raise ConfigError(source, "models", "a list of at least 1 model", "0 models")
        seen: set[str] = set()
        for m, at in zip(models, where, strict=True):
            if m.name in seen:
                raise ConfigError(rows_source, f"{at}: name", "a unique model name", m.name)
            seen.add(m.name)
    eo = {
        side: np.array([[getattr(getattr(m, side), k) for k in _EO_KEYS] for m in models])
        for side in ("left", "right")
    }
    n_points = max((len(m.height_points) for m in models), default=0)
    heights = np.full((len(models), n_points), np.nan)
    for i, m in enumerate(models):
        heights[i, : len(m.height_points)] = [p.Z_m for p in m.height_points]
    scales = doc.scales or Scales()
    block = Block(
        name=doc.name,
        source=source,
        camera=camera,
        map_scale_denominator=doc.map_scale,
        horizontal_scale_denominator=scales.horizontal,
        vertical_scale_denominator=scales.vertical,
        model_names=tuple(m.name for m in models),
        centre_left_m=eo["left"][:, :3],
        angles_left=np.radians(eo["left"][:, 3:]),
        centre_right_m=eo["right"][:, :3],
        angles_right=np.radians(eo["right"][:, 3:]),
        terrain_m=np.array([m.terrain_m for m in models]),
        height_point_ids=tuple(tuple(p.id for p in m.height_points) for m in models),
        height_points_m=heights,
    )
    _check_block_geometry(rows_source, block, where)
    return block


def _csv_column(field: str, pid: str) -> str:
    """The CSV column of a field of :class:`ModelEntry` (``left.Z_m`` → ``left_Z_m``)."""
    if field.startswith("height_points"):
        return f"height_points.{pid}" if field.endswith("Z_m") else "height_points"
    return {
        "terrain_m[0]": "terrain_lowest_m",
        "terrain_m[1]": "terrain_highest_m",
    }.get(field, field.replace(".", "_"))


def _models_csv(path: Path) -> tuple[list[ModelEntry], list[str]]:
    """The rows of a ``models_csv`` file, each validated by :class:`ModelEntry`; the field of an
    error is ``line L: column``."""
    source = str(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError(
            source, "(file)", "an existing CSV file (models_csv)", "no such file"
        ) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(source, "(file)", "a readable UTF-8 CSV file", str(exc)) from None
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    reader = csv.DictReader(io.StringIO("\n".join(lines)))
    header = reader.fieldnames or []
    missing = [c for c in CSV_COLUMNS if c not in header]
    if missing:
        raise ConfigError(
            source, "header", "the columns " + ", ".join(CSV_COLUMNS), "no column " + missing[0]
        )
    unknown = [c for c in header if c not in (*CSV_COLUMNS, "height_points")]
    if unknown:
        raise ConfigError(
            source,
            "header",
            "no such column",
            unknown[0],
            "allowed: " + ", ".join((*CSV_COLUMNS, "height_points")),
        )
    models: list[ModelEntry] = []
    where: list[str] = []
    for line, row in enumerate(reader, start=2):
        at = f"line {line}"
        entry, pids = _csv_entry(source, at, row)
        try:
            models.append(validate(ModelEntry, entry, source))
        except ConfigError as exc:
            pid = next((p for j, p in enumerate(pids) if f"[{j}]" in exc.field), "")
            raise ConfigError(
                source, f"{at}: {_csv_column(exc.field, pid)}", exc.expected, exc.found, exc.hint
            ) from None
        where.append(at)
    return models, where


def _csv_entry(source: str, at: str, row: dict[str, Any]) -> tuple[dict[str, Any], list[str]]:
    """One CSV row as the mapping :class:`ModelEntry` validates (numbers where they parse)."""

    def cell(column: str) -> Any:
        raw = (row.get(column) or "").strip()
        try:
            return float(raw)
        except ValueError:
            return raw

    points, pids = [], []
    for item in (row.get("height_points") or "").split(";"):
        if not item.strip():
            continue
        pid, sep, z = item.partition("=")
        if not sep or not pid.strip():
            raise ConfigError(source, f"{at}: height_points", "entries id=Z_m separated by ;", item)
        pids.append(pid.strip())
        points.append({"id": pid.strip(), "Z_m": _parse(z)})
    entry = {
        "name": (row.get("name") or "").strip(),
        "left": {k: cell(f"left_{k}") for k in _EO_KEYS},
        "right": {k: cell(f"right_{k}") for k in _EO_KEYS},
        "terrain_m": [cell("terrain_lowest_m"), cell("terrain_highest_m")],
        "height_points": points,
    }
    return entry, pids


def _parse(raw: str) -> Any:
    try:
        return float(raw.strip())
    except ValueError:
        return raw.strip()


def _check_block_geometry(source: str, block: Block, where: list[str]) -> None:
    """Refuse degenerate models at load time: terrain lowest > highest, a station at or below the
    highest ground or a height point, a horizontal base under 1 m."""
    sep = "." if where and where[0].startswith("models") else ": "
    low, high = block.terrain_m[:, 0], block.terrain_m[:, 1]
    bad = np.flatnonzero(low > high)
    if bad.size:
        i = int(bad[0])
        raise ConfigError(
            source,
            f"{where[i]}{sep}terrain" + ("_m" if sep == "." else "_lowest_m"),
            "lowest ≤ highest ground height",
            [float(low[i]), float(high[i])],
        )
    top = np.fmax(high, np.nanmax(block.height_points_m, axis=1, initial=-np.inf))
    for side, centre in (("left", block.centre_left_m), ("right", block.centre_right_m)):
        bad = np.flatnonzero(centre[:, 2] <= top)
        if bad.size:
            i = int(bad[0])
            raise ConfigError(
                source,
                f"{where[i]}{sep}{side}" + (".Z_m" if sep == "." else "_Z_m"),
                f"a projection centre above the model's highest ground ({top[i]:g} m)",
                float(centre[i, 2]),
            )
    base = np.hypot(*(block.centre_right_m - block.centre_left_m)[:, :2].T)
    bad = np.flatnonzero(base < 1.0)
    if bad.size:
        i = int(bad[0])
        raise ConfigError(
            source, f"{where[i]}{sep}right", "a horizontal base of at least 1 m", f"{base[i]:.3g} m"
        )
