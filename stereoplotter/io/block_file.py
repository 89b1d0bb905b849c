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

from stereoplotter.io.scenario_file import MAX_TILT_DEG, CameraModel, camera_from_model
from stereoplotter.io.validation import validate
from stereoplotter.io.yaml_files import Fields, load_yaml_mapping
from stereoplotter.scenario.model import Camera

__all__ = ["CSV_COLUMNS", "Block", "load_block"]

_EO_KEYS = ("X_m", "Y_m", "Z_m", "alpha_deg", "omega_deg", "kappa_deg")
_TOP = ("name", "description", "camera", "map_scale", "scales", "models", "models_csv")
_MODEL = ("name", "left", "right", "terrain_m", "height_points")
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
    fields = Fields(source)
    fields.mapping(data, "", _TOP, required=("name", "camera", "map_scale"))
    name = fields.text(data, "name", "")
    camera_model = validate(CameraModel, fields.get(data, "camera", ""), source, prefix=("camera",))
    camera = camera_from_model(fields, camera_model)
    map_scale = fields.integer(data, "map_scale", "", low=100, high=1_000_000)
    forced: dict[str, int | None] = {"horizontal": None, "vertical": None}
    if data.get("scales") is not None:
        node = fields.mapping(data["scales"], "scales", ("horizontal", "vertical"))
        for key in forced:
            if node.get(key) is not None:
                forced[key] = fields.integer(node, key, "scales", low=100, high=1_000_000)
    if ("models" in data) == ("models_csv" in data):
        raise fields.error(
            "models", "exactly one of models, models_csv", "both" if "models" in data else "neither"
        )
    if "models" in data:
        rows, where = _models_yaml(fields, data)
        csv_fields = fields
    else:
        csv_name = fields.text(data, "models_csv", "")
        csv_path = Path(source).parent / csv_name
        csv_fields = Fields(str(csv_path))
        rows, where = _models_csv(csv_fields, csv_path)
    names, eo_l, eo_r, terrain, points = zip(*rows, strict=True) if rows else ((),) * 5
    if not names:
        raise fields.error("models", "a list of at least 1 model", "0 models")
    eo_l, eo_r = np.array(eo_l), np.array(eo_r)
    terrain = np.array(terrain)
    n_points = max((len(p) for p in points), default=0)
    heights = np.full((len(names), n_points), np.nan)
    for i, p in enumerate(points):
        heights[i, : len(p)] = [z for _, z in p]
    block = Block(
        name=name,
        source=source,
        camera=camera,
        map_scale_denominator=map_scale,
        horizontal_scale_denominator=forced["horizontal"],
        vertical_scale_denominator=forced["vertical"],
        model_names=tuple(names),
        centre_left_m=eo_l[:, :3],
        angles_left=np.radians(eo_l[:, 3:]),
        centre_right_m=eo_r[:, :3],
        angles_right=np.radians(eo_r[:, 3:]),
        terrain_m=terrain,
        height_point_ids=tuple(tuple(pid for pid, _ in p) for p in points),
        height_points_m=heights,
    )
    _check_block_geometry(csv_fields, block, where)
    return block


def _eo_limits(key: str) -> dict[str, Any]:
    if key in ("X_m", "Y_m"):
        return {"unit": "m", "low": -1.0e7, "high": 1.0e7}
    if key == "Z_m":
        return {"unit": "m", "low": -500.0, "high": 50000.0}
    if key == "kappa_deg":
        return {"unit": "°", "low": -180.0, "high": 180.0}
    return {
        "unit": "°",
        "low": -MAX_TILT_DEG,
        "high": MAX_TILT_DEG,
        "basis": f"near-vertical aerial photos only: |tilt| ≤ {MAX_TILT_DEG:g}°",
    }


def _check_name(fields: Fields, name: str, path: str, seen: set[str]) -> str:
    if not _NAME_RE.match(name) or name in (".", ".."):
        raise fields.error(
            path,
            "a model name usable as a folder name (letters, digits, _ . + -)",
            name,
        )
    if name in seen:
        raise fields.error(path, "a unique model name", name)
    seen.add(name)
    return name


def _models_yaml(fields: Fields, data: dict[str, Any]) -> tuple[list[tuple], list[str]]:
    rows, where, seen = [], [], set()
    for i, item in enumerate(fields.sequence(data, "models", "", min_length=1)):
        mpath = fields.join("models", i)
        fields.mapping(item, mpath, _MODEL, required=("name", "left", "right", "terrain_m"))
        name = _check_name(
            fields, fields.text(item, "name", mpath), fields.join(mpath, "name"), seen
        )
        eos = []
        for side in ("left", "right"):
            epath = fields.join(mpath, side)
            node = fields.mapping(item[side], epath, _EO_KEYS, required=_EO_KEYS)
            eos.append(tuple(fields.number(node, k, epath, **_eo_limits(k)) for k in _EO_KEYS))
        terrain = fields.vector(item, "terrain_m", mpath, 2, unit="m", low=-500.0, high=9000.0)
        points, ids = [], set()
        for j, p in enumerate(fields.sequence(item, "height_points", mpath, default=[])):
            ppath = fields.join(fields.join(mpath, "height_points"), j)
            fields.mapping(p, ppath, ("id", "Z_m"), required=("id", "Z_m"))
            pid = fields.text(p, "id", ppath)
            if pid in ids:
                raise fields.error(fields.join(ppath, "id"), "a unique point id", pid)
            ids.add(pid)
            points.append((pid, fields.number(p, "Z_m", ppath, unit="m", low=-500.0, high=9000.0)))
        rows.append((name, eos[0], eos[1], terrain, tuple(points)))
        where.append(mpath)
    return rows, where


def _models_csv(fields: Fields, path: Path) -> tuple[list[tuple], list[str]]:
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise fields.error("(file)", "an existing CSV file (models_csv)", "no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise fields.error("(file)", "a readable UTF-8 CSV file", str(exc)) from None
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    reader = csv.DictReader(io.StringIO("\n".join(lines)))
    header = reader.fieldnames or []
    missing = [c for c in CSV_COLUMNS if c not in header]
    if missing:
        raise fields.error(
            "header", "the columns " + ", ".join(CSV_COLUMNS), "no column " + missing[0]
        )
    unknown = [c for c in header if c not in (*CSV_COLUMNS, "height_points")]
    if unknown:
        raise fields.error(
            "header",
            "no such column",
            unknown[0],
            "allowed: " + ", ".join((*CSV_COLUMNS, "height_points")),
        )
    rows, where, seen = [], [], set()
    for line, row in enumerate(reader, start=2):
        at = f"line {line}"

        def number(column: str, limits: dict[str, Any], at: str = at, row: dict = row) -> float:
            raw = (row.get(column) or "").strip()
            try:
                value: Any = float(raw)
            except ValueError:
                value = raw
            return fields.check_number(value, f"{at}: {column}", **limits)

        name = _check_name(fields, (row.get("name") or "").strip(), f"{at}: name", seen)
        eos = [
            tuple(number(f"{side}_{k}", _eo_limits(k)) for k in _EO_KEYS)
            for side in ("left", "right")
        ]
        ground = {"unit": "m", "low": -500.0, "high": 9000.0}
        terrain = (number("terrain_lowest_m", ground), number("terrain_highest_m", ground))
        points = []
        for item in (row.get("height_points") or "").split(";"):
            if not item.strip():
                continue
            pid, sep, z = item.partition("=")
            if not sep or not pid.strip():
                raise fields.error(f"{at}: height_points", "entries id=Z_m separated by ;", item)
            points.append(
                (pid.strip(), number("", ground, row={"": z}, at=f"{at}: height_points.{pid}"))
            )
        rows.append((name, eos[0], eos[1], terrain, tuple(points)))
        where.append(at)
    return rows, where


def _check_block_geometry(fields: Fields, block: Block, where: list[str]) -> None:
    """Refuse degenerate models at load time: terrain lowest > highest, a station at or below the
    highest ground or a height point, a horizontal base under 1 m."""
    sep = "." if where and where[0].startswith("models") else ": "
    low, high = block.terrain_m[:, 0], block.terrain_m[:, 1]
    bad = np.flatnonzero(low > high)
    if bad.size:
        i = int(bad[0])
        raise fields.error(
            f"{where[i]}{sep}terrain" + ("_m" if sep == "." else "_lowest_m"),
            "lowest ≤ highest ground height",
            [float(low[i]), float(high[i])],
        )
    top = np.fmax(high, np.nanmax(block.height_points_m, axis=1, initial=-np.inf))
    for side, centre in (("left", block.centre_left_m), ("right", block.centre_right_m)):
        bad = np.flatnonzero(centre[:, 2] <= top)
        if bad.size:
            i = int(bad[0])
            raise fields.error(
                f"{where[i]}{sep}{side}" + (".Z_m" if sep == "." else "_Z_m"),
                f"a projection centre above the model's highest ground ({top[i]:g} m)",
                float(centre[i, 2]),
            )
    base = np.hypot(*(block.centre_right_m - block.centre_left_m)[:, :2].T)
    bad = np.flatnonzero(base < 1.0)
    if bad.size:
        i = int(bad[0])
        raise fields.error(
            f"{where[i]}{sep}right", "a horizontal base of at least 1 m", f"{base[i]:.3g} m"
        )


