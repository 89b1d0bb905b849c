"""Block mode (stereoplotter.setup.block): vectorised setup data of many stereopairs.

The references here are independent computations: the per-pair Python loop of
tests/oracles/setup_pair_oracle.py (scalars through the same equation functions, scales chosen by
a loop over the candidates) and the single-pair sheet (compute_setup_sheet) of an equivalent
scenario.
"""

from __future__ import annotations

import csv
import math
import re
from pathlib import Path

import numpy as np
import pytest
import yaml
from oracles.setup_pair_oracle import per_pair_loop

from stereoplotter.commands.setup_block import run_block, write_block
from stereoplotter.errors import ConfigError
from stereoplotter.geometry.rotation import rotation_matrix
from stereoplotter.io.block_file import CSV_COLUMNS, load_block
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.paths import data_dir
from stereoplotter.io.scenario_file import scenario_from_mapping
from stereoplotter.scenario.synthetic import working_area_grid_m
from stereoplotter.setup.block import BlockResult, Refusal, compute_block
from stereoplotter.setup.scale_choice import candidate_scales
from stereoplotter.setup.sheet import SetupOptions, compute_setup_sheet
from stereoplotter.setup.table24 import compute_table24

STRIP = data_dir("scenarios") / "blocks" / "strip60.yaml"
MARKS = np.array([[-85.0, 0.0], [85.0, 0.0], [0.0, 85.0], [0.0, -85.0]])
FLOAT_FIELDS = (
    "frame_rotation", "base_ground_m", "depth_ground_m", "angles",
    "horizontal_scale_denominator", "vertical_scale_denominator", "f_instrument_mm",
    "transformation_coefficient", "n_left", "n_right", "base_mm", "fiducials_transformed_mm",
    "fiducials_rigorous_mm", "mark_span_mm", "decentration_mm", "depth_range_mm",
    "control_heights_model_mm",
)  # fmt: skip


@pytest.fixture(scope="module")
def sc1():
    return load_instrument("sc1")


def random_block(rng: np.random.Generator, n: int) -> dict:
    """n pairs along random strip azimuths: photo scale 1:15 000–1:25 000, 55–65 % overlap, tilts
    up to 3.5° (some beyond the 3° stop), crab ±10°, relief up to 45 % of the flying height (some
    beyond the depth ratio D_max/D_min)."""
    azimuth = rng.uniform(-np.pi, np.pi, n)
    height = rng.uniform(15_000, 25_000, n) * 70.0 / 1000.0  # H = M_photo·f [m]
    base = (1 - rng.uniform(0.55, 0.65, n)) * 0.18 * height * 1000 / 70.0
    left = np.column_stack([rng.uniform(-5e4, 5e4, (n, 2)), 150 + height])
    step = np.column_stack([base * np.cos(azimuth), base * np.sin(azimuth), rng.normal(0, 8, n)])
    right = left + step + np.column_stack([rng.normal(0, 10, (n, 2)), np.zeros(n)])
    tilts = np.radians(rng.uniform(-3.5, 3.5, (2, n, 2)))
    kappa = azimuth[None, :, None] + np.radians(rng.uniform(-10, 10, (2, n, 1)))
    angles = np.concatenate([tilts, kappa], axis=2)
    relief = rng.uniform(0.02, 0.45, n) * height
    low = 150 - rng.uniform(0, 1, n) * relief
    heights = low[:, None] + rng.uniform(0, 1, (n, 3)) * relief[:, None]
    heights[rng.uniform(size=(n, 3)) < 0.3] = np.nan
    return {
        "centre_left_m": left, "angles_left": angles[0], "centre_right_m": right,
        "angles_right": angles[1], "terrain_m": np.column_stack([low, low + relief]),
        "height_points_m": heights,
    }  # fmt: skip


def assert_same(a: BlockResult, b: BlockResult, rtol: float = 1e-12) -> None:
    np.testing.assert_array_equal(a.reason_code, b.reason_code)
    np.testing.assert_array_equal(a.candidate_index, b.candidate_index)
    np.testing.assert_array_equal(a.feasible_candidates, b.feasible_candidates)
    for name in FLOAT_FIELDS:
        np.testing.assert_allclose(
            getattr(a, name), getattr(b, name), rtol=rtol, atol=1e-12, err_msg=name
        )


@pytest.mark.parametrize("book_sign", [False, True])
def test_vectorised_equals_per_pair_loop(sc1, book_sign):
    arrays = random_block(np.random.default_rng(20260501), 200)
    vec = compute_block(
        70.0, MARKS, spec=sc1, map_scale_denominator=10000, book_sign=book_sign, **arrays
    )
    loop = per_pair_loop(
        70.0, MARKS, spec=sc1, map_scale_denominator=10000, book_sign=book_sign, **arrays
    )
    assert_same(vec, loop)
    # the random block exercises both outcomes and several reasons
    assert 0.3 < vec.accepted.mean() < 0.95
    seen = Refusal(int(np.bitwise_or.reduce(vec.reason_code)))
    assert Refusal.TILT in seen and Refusal.PROJECTION_DISTANCE in seen
    assert np.isnan(vec.n_left[~vec.accepted]).all()
    assert np.isfinite(vec.n_left[vec.accepted]).all()


def test_forced_scales_match_loop(sc1):
    arrays = random_block(np.random.default_rng(7), 40)
    kw = {"horizontal_scale_denominator": 12500, "vertical_scale_denominator": 8000}
    vec = compute_block(70.0, MARKS, spec=sc1, map_scale_denominator=None, **kw, **arrays)
    assert vec.candidate_scales.tolist() == [[12500.0, 8000.0]]
    assert_same(
        vec, per_pair_loop(70.0, MARKS, spec=sc1, map_scale_denominator=None, **kw, **arrays)
    )


def test_refused_pair_gets_nan_and_reason_without_disturbing_others(sc1):
    block = load_block(STRIP)
    args = dict(
        centre_left_m=block.centre_left_m.copy(), angles_left=block.angles_left.copy(),
        centre_right_m=block.centre_right_m, angles_right=block.angles_right,
        terrain_m=block.terrain_m.copy(), height_points_m=block.height_points_m,
    )  # fmt: skip
    good = compute_block(70.0, MARKS, spec=sc1, map_scale_denominator=10000, **args)
    args["terrain_m"][2] = [-400.0, 1400.0]  # relief of 1800 m under a 1550 m station
    args["angles_left"][5, 2] = math.radians(40.0)  # κ far beyond the ±15° stop
    args["centre_left_m"][6, 0] = np.nan
    bad = compute_block(70.0, MARKS, spec=sc1, map_scale_denominator=10000, **args)
    assert Refusal(int(bad.reason_code[2])) == Refusal.PROJECTION_DISTANCE
    assert Refusal.KAPPA in Refusal(int(bad.reason_code[5]))
    assert bad.reason_code[6] == Refusal.INVALID_INPUT
    for i in (2, 5, 6):
        assert np.isnan(bad.n_left[i]) and np.isnan(bad.mark_span_mm[i]).all()
        assert np.isnan(bad.fiducials_transformed_mm[i]).all()
    assert re.search(
        r"none of the 180 scale pairs fits \(way out: .*\); closest M_г = 1:\d+", bad.reason(2)
    )
    assert re.search(
        r"D(_п)? of the (highest|lowest) ground = [-\d.]+ mm is outside the "
        r"assumed range \[110, 185\] mm",
        bad.reason(2),
    )
    assert re.search(r"κ_left = 39\.\d+ deg is outside", bad.reason(5))
    others = [i for i in range(len(block)) if i not in (2, 5, 6)]
    for name in FLOAT_FIELDS:
        np.testing.assert_array_equal(getattr(bad, name)[others], getattr(good, name)[others])


@pytest.mark.parametrize("instrument", ["sc1", "spr3", "sd3"])
def test_strip_gives_a_sheet_per_model(tmp_path, instrument):
    spec = load_instrument(instrument)
    result = run_block(STRIP, spec, output_dir=tmp_path)
    assert len(result) == 8
    rows = list(csv.DictReader((tmp_path / "block.csv").read_text(encoding="utf-8").splitlines()))
    assert [r["model"] for r in rows] == list(result.model_names)
    for i, model in enumerate(result.model_names):
        sheet = yaml.safe_load((tmp_path / model / "sheet.yaml").read_text(encoding="utf-8"))
        assert sheet["status"] in ("ok", "refused")
        if sheet["status"] == "ok":
            assert sheet["reason"] == ""
            assert sheet["n_left"] == pytest.approx(result.n_left[i], abs=1e-6)
            assert set(sheet["fiducials_transformed_mm"]["left"]) == {"x2", "y3", "y4"}
            assert set(sheet["fiducials_transformed_mm"]["right"]) == {"x1", "y3", "y4"}
            assert set(sheet["base_mm"]) == {"bx", "by", "bz"}
            assert len(sheet["control_heights_model_mm"]) == len(result.height_point_ids[i])
        else:
            assert sheet["reason"] and sheet["n_left"] is None
    if instrument == "sc1":  # every model of the plain-terrain strip fits the SC-1
        assert result.accepted.all()
    assert_same(result, per_pair_loop(
        70.0, MARKS, spec=spec, map_scale_denominator=10000,
        **{k: getattr(load_block(STRIP), k) for k in (
            "centre_left_m", "angles_left", "centre_right_m", "angles_right", "terrain_m",
            "height_points_m")}))  # fmt: skip


def test_models_csv_gives_the_same_block(tmp_path, sc1):
    data = yaml.safe_load(STRIP.read_text(encoding="utf-8"))
    lines = [",".join((*CSV_COLUMNS, "height_points"))]
    for m in data.pop("models"):
        eo = [
            m[s][k]
            for s in ("left", "right")
            for k in ("X_m", "Y_m", "Z_m", "alpha_deg", "omega_deg", "kappa_deg")
        ]
        points = ";".join(f"{p['id']}={p['Z_m']}" for p in m.get("height_points", []))
        lines.append(",".join(map(str, (m["name"], *eo, *m["terrain_m"], points))))
    (tmp_path / "models.csv").write_text("# strip60 as CSV\n" + "\n".join(lines) + "\n")
    data["models_csv"] = "models.csv"
    (tmp_path / "strip.yaml").write_text(yaml.safe_dump(data, allow_unicode=True))
    assert_same(run_block(tmp_path / "strip.yaml", sc1), run_block(STRIP, sc1), rtol=0)


def pair_scenario(model: dict, terrain_base_m: float) -> dict:
    return {
        "name": "one-model",
        "seed": 1,
        "camera": {"focal_length_mm": 70.0,
                   "fiducials": {"coordinates_mm": {str(i + 1): m for i, m in
                                                    enumerate(MARKS.tolist())}}},
        "frame": {"kind": "sk42",
                  "origin": {"north_m": 6167100.0, "east_m": 5352300.0, "height_m": 0.0}},
        "terrain": {"base_height_m": terrain_base_m, "slope": [0.004, -0.002]},
        "photos": [{"name": s, "exterior": model[s]} for s in ("left", "right")],
        "points": [
            {"id": "1", "kind": "full", "local": {"X_m": -950.0, "Y_m": 1550.0}},
            {"id": "2", "kind": "full", "local": {"X_m": 950.0, "Y_m": 1550.0}},
            {"id": "3", "kind": "full", "local": {"X_m": 950.0, "Y_m": -1550.0}},
            {"id": "4", "kind": "full", "local": {"X_m": -950.0, "Y_m": -1550.0}},
            {"id": "5", "kind": "height", "local": {"X_m": -700.0, "Y_m": 0.0}},
        ],
        "map_sheet": {"scale": 10000, "nomenclature": "N-35-14-А-б-3"},
        "errors": {"photo_point_sigma_um": 0.0, "fiducial_sigma_um": 0.0},
    }  # fmt: skip


def test_one_model_agrees_with_the_single_pair_sheet(sc1):
    # A 60 % pair with tilts, crab and a base turned 4° off the X axis (the frame rotation acts).
    model = {
        "left": {"X_m": -720.0, "Y_m": 50.0, "Z_m": 1550.0, "alpha_deg": 0.6, "omega_deg": -0.4,
                 "kappa_deg": 4.8},
        "right": {"X_m": 716.5, "Y_m": 150.4, "Z_m": 1560.0, "alpha_deg": -0.5,
                  "omega_deg": 0.7, "kappa_deg": 2.9},
    }  # fmt: skip
    scenario = scenario_from_mapping(pair_scenario(model, 150.0), "<test>")
    sheet = compute_setup_sheet(scenario, sc1, SetupOptions())
    ground = np.vstack(
        [working_area_grid_m(scenario, (15, 15)), [p.local_m for p in scenario.points]]
    )
    eo = {s: np.array([[model[s][k] for k in ("X_m", "Y_m", "Z_m")]]) for s in model}
    ang = {
        s: np.radians([[model[s][k] for k in ("alpha_deg", "omega_deg", "kappa_deg")]])
        for s in model
    }
    r = compute_block(
        70.0,
        MARKS,
        eo["left"],
        ang["left"],
        eo["right"],
        ang["right"],
        [[ground[:, 2].min(), ground[:, 2].max()]],
        sc1,
        10000,
        height_points_m=[[scenario.points[4].local_m[2]]],
    )
    assert (r.horizontal_scale_denominator[0], r.vertical_scale_denominator[0]) == (
        sheet.horizontal_scale_denominator,
        sheet.vertical_scale_denominator,
    )
    tol = {"rtol": 0, "atol": 1e-9}
    np.testing.assert_allclose(r.frame_rotation[0], sheet.frame_rotation, **tol)
    np.testing.assert_allclose(r.n_left[0], sheet.n_left, **tol)
    np.testing.assert_allclose(r.n_right[0], sheet.n_right, **tol)
    np.testing.assert_allclose(r.f_instrument_mm[0], sheet.f_instrument_mm, **tol)
    np.testing.assert_allclose(r.base_mm[0], sheet.base_mm, **tol)
    np.testing.assert_allclose(r.mark_span_mm[0], [p.mark_span_mm for p in sheet.photos], **tol)
    np.testing.assert_allclose(r.depth_range_mm[0], sheet.depth_range_used_mm, **tol)
    for j, photo in enumerate(sheet.photos):
        np.testing.assert_allclose(
            r.fiducials_transformed_mm[0, j], list(photo.transformed_book_mm.values()), **tol
        )
        np.testing.assert_allclose(
            r.fiducials_rigorous_mm[0, j], list(photo.transformed_rigorous_mm.values()), **tol
        )
        np.testing.assert_allclose(r.decentration_mm[0, j], photo.decentration_mm, **tol)
    np.testing.assert_allclose(
        r.control_heights_model_mm[0, 0],
        next(h["model_height_mm"] for h in sheet.control_heights if h["id"] == "5"),
        **tol,
    )


# --- bad block files ------------------------------------------------------------------------

GOOD = yaml.safe_load(STRIP.read_text(encoding="utf-8"))


def write(tmp_path: Path, data: dict, name: str = "block.yaml") -> Path:
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data, allow_unicode=True), encoding="utf-8")
    return path


def edited(**changes) -> dict:
    data = yaml.safe_load(yaml.safe_dump(GOOD))
    for dotted, value in changes.items():
        node, *keys = dotted.split("__")
        target = data
        for key in [node, *keys][:-1]:
            target = target[int(key)] if key.isdigit() else target[key]
        last = [node, *keys][-1]
        if value is ...:
            del target[last]
        elif last.isdigit():
            target[int(last)] = value
        else:
            target[last] = value
    return data


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"camera": ...}, r"block\.yaml: camera: expected a value \(the field is required\)"),
        (
            {"map_scale": 10000.5},
            r"map_scale: expected an integer in \[100, 1000000\], found "
            r"10000\.5",
        ),
        (
            {"models__0__left__alpha_deg": 22.0},
            r"models\[0\]\.left\.alpha_deg: expected a number in \[-15, 15\] °, found 22\.0 "
            r"\(near-vertical",
        ),
        (
            {"models__1__right__kappa_deg": "north"},
            r"models\[1\]\.right\.kappa_deg: expected a number .*found the text 'north'",
        ),
        (
            {"models__2__terrain_m": [200.0]},
            r"models\[2\]\.terrain_m: expected a list of 2 numbers \[m\], found a list of 1",
        ),
        (
            {"models__2__terrain_m": [230.0, 120.0]},
            r"models\[2\]\.terrain_m: expected lowest ≤ highest ground height, found \[230\.0, "
            r"120\.0\]",
        ),
        (
            {"models__3__left__Z_m": 200.0},
            r"models\[3\]\.left\.Z_m: expected a projection centre above the model's highest "
            r"ground \(216 m\), found 200\.0",
        ),
        ({"models__4__name": "102-103"}, r"models\[4\]\.name: expected a unique model name"),
        (
            {"models__4__name": "../evil"},
            r"models\[4\]\.name: expected a model name usable as "
            r"a folder name",
        ),
        ({"models__0__colour": "red"}, r"models\[0\]\.colour: expected no such field"),
        (
            {"models_csv": "x.csv"},
            r"models: expected exactly one of models, models_csv, "
            r"found both",
        ),
        ({"models": []}, r"models: expected a list of at least 1 entries, found 0 entries"),
        ({"scales": {"vertical": "big"}}, r"scales\.vertical: expected an integer"),
    ],
)
def test_bad_block_file_messages(tmp_path, changes, message):
    with pytest.raises(ConfigError, match=message):
        load_block(write(tmp_path, edited(**changes)))


def test_bad_csv_messages(tmp_path):
    data = edited(models=...)
    data["models_csv"] = "m.csv"
    path = write(tmp_path, data)
    with pytest.raises(ConfigError, match=r"m\.csv: \(file\): expected an existing CSV file"):
        load_block(path)
    header = ",".join(CSV_COLUMNS)
    row = "a,0,0,1550,0,0,0,1440,0,1550,0,0,0,120,200"
    (tmp_path / "m.csv").write_text(
        f"{header}\n{row}\n{row.replace('a,', 'b,').replace('1440,0,1550', '1440,0,x')}\n"
    )
    with pytest.raises(
        ConfigError,
        match=r"m\.csv: line 3: right_Z_m: expected a number in "
        r"\[-500, 50000\] m, found the text 'x'",
    ):
        load_block(path)
    (tmp_path / "m.csv").write_text(f"{header.replace(',terrain_highest_m', '')}\n")
    with pytest.raises(
        ConfigError,
        match=r"header: expected the columns name, .* found no "
        r"column terrain_highest_m",
    ):
        load_block(path)


def test_compute_block_rejects_bad_shapes(sc1):
    with pytest.raises(ValueError, match=r"fiducials_mm: expected shape \(4, 2\)"):
        compute_block(
            70.0,
            MARKS[:3],
            [[0, 0, 1500.0]],
            [[0, 0, 0.0]],
            [[1400, 0, 1500.0]],
            [[0, 0, 0.0]],
            [[100.0, 200.0]],
            sc1,
            10000,
        )
    with pytest.raises(ValueError, match=r"terrain_m: expected shape \(1, 2\)"):
        compute_block(
            70.0,
            MARKS,
            [[0, 0, 1500.0]],
            [[0, 0, 0.0]],
            [[1400, 0, 1500.0]],
            [[0, 0, 0.0]],
            [100.0, 200.0],
            sc1,
            10000,
        )


def test_write_block_refused_sheet(tmp_path, sc1):
    block = load_block(STRIP)
    terrain = block.terrain_m.copy()
    terrain[0] = [-400.0, 1400.0]
    r = compute_block(
        70.0,
        MARKS,
        block.centre_left_m,
        block.angles_left,
        block.centre_right_m,
        block.angles_right,
        terrain,
        sc1,
        10000,
        model_names=block.model_names,
    )
    write_block(r, tmp_path)
    sheet = yaml.safe_load((tmp_path / "101-102" / "sheet.yaml").read_text(encoding="utf-8"))
    assert sheet["status"] == "refused" and sheet["n_left"] is None
    assert sheet["reason_code"] == int(Refusal.PROJECTION_DISTANCE)
    assert "instruments/sc1.yaml" in sheet["reason"]
    rows = list(csv.DictReader((tmp_path / "block.csv").read_text(encoding="utf-8").splitlines()))
    assert [r["status"] for r in rows] == ["refused"] + ["ok"] * 7


def _table24_inputs(b: dict) -> dict:
    """compute_table24's arrays from the compute_block arguments of random_block."""
    centres = np.stack([b["centre_left_m"], b["centre_right_m"]], axis=1)
    angles = np.stack([b["angles_left"], b["angles_right"]], axis=1)
    return {
        "centres_m": centres,
        "rotations": rotation_matrix(angles[..., 0], angles[..., 1], angles[..., 2]),
        "depth_m": centres[:, 0, 2:3] - b["terrain_m"][:, ::-1],
        "heights_m": b["height_points_m"],
    }


def test_per_pair_focal_length_equals_each_pair_alone(sc1):
    """compute_table24 with f′ and marks per pair (each pair its own film) gives every pair,
    to the bit, what a call with that pair's scalar f′ alone gives, refusals and their text
    included; a scalar f′ and the array of that value give the same block."""
    rng = np.random.default_rng(12)
    n = 60
    arrays = _table24_inputs(random_block(rng, n))
    f = rng.uniform(69.95, 70.05, n)  # film shrinkage of ±700 ppm, each pair its own
    marks = MARKS + rng.normal(0.0, 0.02, (n, 2, 4, 2))
    grid = candidate_scales(sc1, 10000)
    labels = {"model_names": tuple(map(str, range(n))),
              "height_point_ids": (("1", "2", "3"),) * n}  # fmt: skip
    whole = compute_table24(f, marks, grid=grid, spec=sc1, **arrays, **labels)
    assert 0 < int(whole.accepted.sum()) < n  # both paths exercised
    for i in range(n):
        alone = compute_table24(
            float(f[i]), marks[i : i + 1], grid=grid, spec=sc1,
            **{k: v[i : i + 1] for k, v in arrays.items()},
            model_names=(str(i),), height_point_ids=(("1", "2", "3"),),
        )  # fmt: skip
        one = whole.take(i)
        assert one.focal_length_of(0) == f[i]
        for name in (*FLOAT_FIELDS, "reason_code", "candidate_flags", "correction_inclination"):
            np.testing.assert_array_equal(getattr(one, name), getattr(alone, name), err_msg=name)
        assert one.reason(0) == alone.reason(0) == whole.reason(i)
    shared = compute_table24(70.0, MARKS, grid=grid, spec=sc1, **arrays, **labels)
    same = compute_table24(np.full(n, 70.0), MARKS, grid=grid, spec=sc1, **arrays, **labels)
    for name in (*FLOAT_FIELDS, "reason_code"):
        np.testing.assert_array_equal(getattr(shared, name), getattr(same, name), err_msg=name)
