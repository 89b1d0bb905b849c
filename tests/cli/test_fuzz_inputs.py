"""Seeded mutation fuzzing of every input file: bad input never crashes.

The shipped files (scenarios, block files, instruments, the job ``jobs/strip8/job.yaml`` and its
two CSV files) and two built ones (an errors YAML of
overrides as :meth:`ErrorModel.with_overrides` accepts it, a ``verify --geometry`` mapping, a block
file with its models in CSV) are mutated: keys deleted or misspelt, values of the wrong type,
NaN/inf, huge and negative numbers, YAML alias bombs, cycles and deep nesting, tags PyYAML cannot
construct, non-UTF-8 bytes, control characters, empty files, a directory in place of the file,
truncated files and duplicated keys. Each case is loaded in-process through the library loader
and, for a sample, through :func:`stereoplotter.cli.main` (``scenario check``, ``instrument
show``, ``setup``, ``simulate --trials 1``, ``verify --geometry``, ``job to-scenario``) with stdout
and stderr captured.

Every case must end one of two ways:

* the mutated file is still valid: it loads fully (and what is derived from it: the summary, the
  instrument's listing, the error model's draw) and a command on it exits 0 or refuses with one
  line naming a file and a field (e.g. the instrument's stop);
* it is invalid: the loader raises a :class:`~stereoplotter.errors.StereoplotterError` whose
  message is one line ``FILE: FIELD: expected …, found …`` naming the mutated file, and the
  command prints exactly that line as ``error: …`` on stderr and returns 1.

Never a traceback, another exception, "internal error", output that cannot be encoded as UTF-8,
or a case that takes long. Cases are seeded (numpy Generator, one stream per case): a failure
report names the case number, and ``STEREOPLOTTER_FUZZ_ONLY=N`` reruns that case alone.

Size: 2 000 cases per run by default; ``STEREOPLOTTER_FUZZ_CASES=10000`` is the nightly size
(recorded in docs/validation.md).
"""

from __future__ import annotations

import contextlib
import copy
import io
import json
import math
import os
import shutil
import time
import warnings
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from conftest import node_paths, value_at

from stereoplotter.cli import main
from stereoplotter.commands.setup_job import compute_job
from stereoplotter.errors import ConfigError, StereoplotterError
from stereoplotter.instrument.error_model import error_model_from_spec
from stereoplotter.io.block_file import CSV_COLUMNS, load_block
from stereoplotter.io.exercise_file import load_exercise
from stereoplotter.io.geometry_file import geometry_from_file
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.job_file import load_job
from stereoplotter.io.paths import data_dir
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.io.yaml_input import MAX_YAML_NODES, load_yaml_mapping
from stereoplotter.report.job import pair_dict
from stereoplotter.scenario import summarize_scenario
from stereoplotter.spec.instrument_spec import format_instrument, instrument_to_dict
from stereoplotter.verification.table import BOOK

ROOT = Path(__file__).resolve().parents[2]
SEED = int(os.environ.get("STEREOPLOTTER_FUZZ_SEED", "20240607"))
CASES = int(os.environ.get("STEREOPLOTTER_FUZZ_CASES", "2000"))
ONLY = os.environ.get("STEREOPLOTTER_FUZZ_ONLY")
#: Share of the cases also run through the command line, per command.
CLI_SHARE = 0.12
SIMULATE_SHARE = 0.012
#: A single case slower than this is a failure (an alias bomb that got through, a hang).
SLOW_CASE_S = 5.0

_DUMPER = getattr(yaml, "CSafeDumper", yaml.SafeDumper)  # test side only: speed
_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


# --- the corpus ---------------------------------------------------------------------------------


def _shipped_dir(kind: str) -> Path:
    """The shipped ``kind`` folder: through :mod:`stereoplotter.io.paths` where it says, else the
    checkout's ``kind/`` folder."""
    try:
        folder = data_dir(kind)
        if folder is not None and Path(folder).is_dir():
            return Path(folder)
    except Exception:  # any problem of the lookup: use the checkout
        pass
    return ROOT / kind


@dataclass
class Seed:
    """One file to mutate: its kind, name, text and parsed document."""

    kind: str  # scenario, block, block_csv, csv, instrument, errors, geometry, job, job_csv
    name: str  # the file name written into the case folder
    text: str
    doc: Any
    paths: list = field(default_factory=list)


def _seed(kind: str, name: str, text: str) -> Seed:
    doc = yaml.load(text, Loader=_LOADER)
    return Seed(kind, name, text, doc, node_paths(doc))


def _dump(doc: Any) -> str:
    return yaml.dump(doc, Dumper=_DUMPER, allow_unicode=True, sort_keys=False, width=100)


_CORPUS: dict[str, list[Seed]] | None = None
JOB_DIR = ROOT / "jobs" / "strip8"
JOB_CSV = ("control.csv", "fiducials.csv")
_EO = ("X_m", "Y_m", "Z_m", "alpha_deg", "omega_deg", "kappa_deg")


def corpus() -> dict[str, list[Seed]]:
    """The files to mutate, by kind (built once)."""
    global _CORPUS
    if _CORPUS is not None:
        return _CORPUS
    scenarios, instruments = _shipped_dir("scenarios"), _shipped_dir("instruments")
    out: dict[str, list[Seed]] = {k: [] for k in ("scenario", "block", "instrument")}
    for path in sorted(scenarios.glob("*.yaml")):
        out["scenario"].append(_seed("scenario", path.name, path.read_text(encoding="utf-8")))
    for path in sorted((scenarios / "blocks").glob("*.yaml")):
        out["block"].append(_seed("block", path.name, path.read_text(encoding="utf-8")))
    for path in sorted(instruments.glob("*.yaml")):
        out["instrument"].append(_seed("instrument", path.name, path.read_text(encoding="utf-8")))
    assert len(out["scenario"]) >= 4 and out["block"] and len(out["instrument"]) >= 3

    # errors YAML: every group, some terms by name, some as {distribution, scale}
    model = error_model_from_spec(load_instrument(instruments / "sc1.yaml"))
    errors: dict[str, Any] = {}
    for i, term in enumerate(model.terms):
        group = term.name.split(".")[0]
        if group not in errors:
            errors[group] = term.scale
        elif i % 3 == 0:
            errors[term.name] = {"distribution": term.distribution, "scale": term.scale}
        elif i % 3 == 1:
            errors[term.name] = term.scale * 0.5
    out["errors"] = [_seed("errors", "errors.yaml", _dump(errors))]
    out["exercise"] = [
        _seed("exercise", path.name, path.read_text(encoding="utf-8"))
        for path in sorted(_shipped_dir("exercises").glob("*.yaml"))
    ]
    out["geometry"] = [_seed("geometry", "geometry.yaml", _dump(dict(BOOK)))]

    # the block file again with its models in a CSV file
    block = out["block"][0].doc
    header = [*CSV_COLUMNS, "height_points"]
    rows = [",".join(header)]
    for m in block["models"]:
        cells = [m["name"]]
        for side in ("left", "right"):
            cells += [repr(float(m[side][k])) for k in _EO]
        cells += [repr(float(z)) for z in m["terrain_m"]]
        cells.append(";".join(f"{p['id']}={p['Z_m']}" for p in m.get("height_points", [])))
        rows.append(",".join(cells))
    csv_text = "\n".join(rows) + "\n"
    yaml_doc = {k: v for k, v in block.items() if k != "models"}
    yaml_doc["models_csv"] = "models.csv"
    out["block_csv"] = [_seed("block_csv", "block_csv.yaml", _dump(yaml_doc))]
    out["csv"] = [Seed("csv", "models.csv", csv_text, None)]

    # the shipped production job and its CSV files (control points, fiducial distances)
    out["job"] = [_seed("job", "job.yaml", (JOB_DIR / "job.yaml").read_text(encoding="utf-8"))]
    out["job_csv"] = [Seed("job_csv", name, (JOB_DIR / name).read_text(encoding="utf-8"), None)
                      for name in JOB_CSV]  # fmt: skip
    _CORPUS = out
    return out


# --- mutations ----------------------------------------------------------------------------------

_SENTINEL = "__FUZZ_VALUE__"

_WRONG_TYPES: list[Any] = [
    None,
    True,
    False,
    "text",
    "",
    "  ",
    [],
    {},
    [1, 2, 3],
    ["a"],
    {"x": 1},
    {"value": None},
    0,
    1,
    "1e3",
    "12",
    [[1.0, 2.0]],
    "terrain",
]
_SPECIAL_FLOATS: list[Any] = [math.nan, math.inf, -math.inf, "nan", "inf", "-inf", "NaN", ".nan"]
_HUGE: list[Any] = [
    1e308,
    -1e308,
    1e300,
    10**30,
    -(10**30),
    10**400,
    -(10**400),
    2**63,
    2**64 + 1,
    -1,
    -1.0,
    -0.0,
    0,
    5e-324,
    1e-300,
    -999999,
]
_BOMB_LEVELS = 9


def _bomb_flow(levels: int = _BOMB_LEVELS, width: int = 9) -> str:
    """One flow-style value that stands for width**levels leaves: anchors are defined in the
    first element of each level and aliased by its siblings."""
    text = "[" + ", ".join(["lol"] * width) + "]"
    for level in range(levels):
        text = f"&b{level} {text}"
        text = "[" + ", ".join([text] + [f"*b{level}"] * (width - 1)) + "]"
    return text


_CLASSIC_BOMB = "\n".join(
    ['a0: &a0 ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    + [f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 9) + "]" for i in range(1, 10)]
)

#: Raw YAML put in place of a value: aliases, cycles, nesting, tags PyYAML cannot construct,
#: surrogates, numbers beyond int/float conversion.
_RAW_VALUES: list[str] = [
    _bomb_flow(),
    _bomb_flow(4, 4),
    "&c [*c]",
    "&m {self: *m}",
    "[" * 300 + "]" * 300,
    "{a: " * 200 + "1" + "}" * 200,
    "!!python/object/apply:os.system ['true']",
    "!!python/name:os.system",
    "2001-02-30",
    "2024-01-01",
    "2024-01-01 12:00:00",
    "!!timestamp x",
    "!!int x",
    "!!float x",
    "!!binary zz",
    "!!set {a, b}",
    "!!omap [a: 1, a: 2]",
    '"\\ud800"',
    '"text\\nwith\\nnewlines"',
    "9" * 5000,
    "0x7fffffffffffffffffffffff",
    "1e999",
    "-.inf",
    ".NaN",
    "0o17",
    "1_000",
    "~",
    "''",
    "!!str 5",
    "? [1, 2]\n",
]
_BAD_BYTES: list[bytes] = [b"\xff", b"\xfe\xff", b"\xc3\x28", b"\x80", b"\xed\xa0\x80", b"\xf8\x88"]
_CONTROL: list[str] = ["\x00", "\x07", "\x1b", "\ufffe", "\x7f"]
_EMPTY: list[bytes] = [
    b"",
    b"\n",
    b"   \n\n",
    b"# only a comment\n",
    b"---\n",
    b"~\n",
    b"[]\n",
    b"'text'\n",
    b"42\n",
    b"- a\n- b\n",
    b"---\na: 1\n---\nb: 2\n",
    b"\xef\xbb\xbf",
]

#: Structural mutations (on the parsed document) and raw ones (on the text), with weights.
MUTATIONS = {
    "delete_key": 14,
    "wrong_type": 12,
    "nan_inf": 9,
    "huge_negative": 12,
    "misspell_key": 6,
    "add_key": 3,
    "raw_value": 10,
    "alias_bomb": 4,
    "non_utf8": 5,
    "control_char": 2,
    "empty": 3,
    "directory": 2,
    "truncate": 7,
    "duplicate_key": 5,
    "inherits": 2,  # instruments only (else: wrong_type)
    "valid_edit": 4,  # a small change that keeps most files valid: numbers scaled a little
}
#: Kinds, with their weights (the job's share taken from scenarios and instruments, so the
#: default run keeps its 2 000 cases and about its time).
KINDS = {
    "scenario": 26,
    "block": 10,
    "block_csv": 3,
    "csv": 5,
    "instrument": 24,
    "exercise": 4,
    "errors": 12,
    "geometry": 8,
    "job": 5,
    "job_csv": 3,
}


def _pick(rng: np.random.Generator, weights: dict[str, int]) -> str:
    names = list(weights)
    p = np.array([weights[n] for n in names], float)
    return names[int(rng.choice(len(names), p=p / p.sum()))]


def _choice(rng: np.random.Generator, items: list) -> Any:
    return items[int(rng.integers(len(items)))]


def _set_at(doc: Any, path: tuple, value: Any) -> None:
    parent = value_at(doc, path[:-1])
    parent[path[-1]] = value


def _misspell(rng: np.random.Generator, key: str) -> str:
    if len(key) < 2:
        return key + "x"
    i = int(rng.integers(len(key) - 1))
    how = int(rng.integers(4))
    if how == 0:
        return key[:i] + key[i + 1] + key[i] + key[i + 2 :]  # swap two letters
    if how == 1:
        return key[:i] + key[i + 1 :]  # drop one
    if how == 2:
        return key.upper()
    return key + "s"


def _numeric_paths(seed: Seed) -> list[tuple]:
    return [
        p
        for p in seed.paths
        if isinstance(value_at(seed.doc, p), int | float)
        and not isinstance(value_at(seed.doc, p), bool)
    ]


def _mutate_csv(rng: np.random.Generator, mutation: str, text: str) -> tuple[str, bytes | None]:
    """A mutation of the models CSV: cells, columns and lines."""
    lines = text.splitlines()
    rows = [line.split(",") for line in lines]
    r = int(rng.integers(1, len(rows)))
    c = int(rng.integers(len(rows[0])))
    if mutation in ("delete_key", "misspell_key"):
        col = int(rng.integers(len(rows[0])))
        if mutation == "delete_key":
            rows = [row[:col] + row[col + 1 :] for row in rows]
        else:
            rows[0][col] = _misspell(rng, rows[0][col])
    elif mutation == "wrong_type":
        rows[r][c] = _choice(rng, ["text", "", "[1, 2]", "1,2", '"quoted"', "x=1", "--"])
    elif mutation == "nan_inf":
        rows[r][c] = _choice(rng, ["nan", "inf", "-inf", "NaN", "infinity"])
    elif mutation in ("huge_negative", "valid_edit"):
        rows[r][c] = _choice(rng, ["1e308", "-1e308", "1e400", "-1", "0", "9" * 400, "-0"])
    elif mutation == "add_key":
        rows[0].append("colour")
        for row in rows[1:]:
            row.append("red")
    elif mutation == "duplicate_key":
        rows.insert(r, list(rows[r]))  # a duplicated model
    elif mutation == "raw_value":
        rows[r][-1] = _choice(rng, ["10", "10=", "=5", "10=x;11=nan", "a=1;a=2", "a=1e999"])
    else:
        return text, None
    return "\n".join(",".join(row) for row in rows) + "\n", None


def mutate(rng: np.random.Generator, seed: Seed, mutation: str) -> tuple[str, bytes | None]:
    """The mutated file as text (and bytes, where the mutation is on bytes)."""
    if seed.kind in ("csv", "job_csv"):
        return _mutate_csv(rng, mutation, seed.text)
    doc = copy.deepcopy(seed.doc)
    paths = seed.paths
    if mutation == "inherits" and seed.kind != "instrument":
        mutation = "wrong_type"
    if mutation == "delete_key":
        path = _choice(rng, paths)
        parent = value_at(doc, path[:-1])
        del parent[path[-1]]
        return _dump(doc), None
    if mutation == "wrong_type":
        _set_at(doc, _choice(rng, paths), copy.deepcopy(_choice(rng, _WRONG_TYPES)))
        return _dump(doc), None
    if mutation == "nan_inf":
        numeric = _numeric_paths(seed) or paths
        _set_at(doc, _choice(rng, numeric), _choice(rng, _SPECIAL_FLOATS))
        return _dump(doc), None
    if mutation == "huge_negative":
        numeric = _numeric_paths(seed) or paths
        _set_at(doc, _choice(rng, numeric), _choice(rng, _HUGE))
        return _dump(doc), None
    if mutation == "valid_edit":
        numeric = _numeric_paths(seed) or paths
        path = _choice(rng, numeric)
        value = value_at(doc, path)
        if isinstance(value, int | float) and not isinstance(value, bool):
            factor = float(rng.choice([0.5, 0.9, 0.99, 1.01, 1.1, 2.0]))
            _set_at(doc, path, value * factor if isinstance(value, float) else value + 1)
        return _dump(doc), None
    if mutation in ("misspell_key", "add_key"):
        dict_paths = [p for p in paths if isinstance(p[-1], str)]
        path = _choice(rng, dict_paths)
        parent = value_at(doc, path[:-1])
        if mutation == "misspell_key":
            new = _misspell(rng, path[-1])
            items = [(new if k == path[-1] else k, v) for k, v in parent.items()]
            parent.clear()
            parent.update(items)
        else:
            parent["colour"] = "red"
        return _dump(doc), None
    if mutation in ("raw_value", "alias_bomb"):
        raw = _choice(rng, _RAW_VALUES) if mutation == "raw_value" else _choice(
            rng, [_bomb_flow(), _bomb_flow(12, 6), "&c [*c]"]
        )
        if mutation == "alias_bomb" and rng.random() < 0.3:
            return _CLASSIC_BOMB + "\n" + seed.text, None
        _set_at(doc, _choice(rng, paths), _SENTINEL)
        return _dump(doc).replace(_SENTINEL, raw, 1), None
    if mutation == "inherits":
        doc = {"inherits": _choice(rng, ["sd3.yaml", "spr3.yaml", seed.name, "missing.yaml",
                                         "../sc1.yaml", 5, None, ["sd3.yaml"]]), **doc}
        if rng.random() < 0.5:  # a thin child: only a few of its own leaves
            keep = [k for k in doc if k in ("inherits", "name", "principle") or rng.random() < 0.2]
            doc = {k: doc[k] for k in keep}
        return _dump(doc), None
    data = seed.text.encode("utf-8")
    if mutation == "non_utf8":
        if rng.random() < 0.25:
            return "", seed.text.encode("utf-16") if rng.random() < 0.5 else seed.text.encode(
                "cp1251", errors="replace"
            )
        at = int(rng.integers(len(data) + 1))
        return "", data[:at] + _choice(rng, _BAD_BYTES) + data[at:]
    if mutation == "control_char":
        at = int(rng.integers(len(seed.text) + 1))
        return seed.text[:at] + _choice(rng, _CONTROL) + seed.text[at:], None
    if mutation == "empty":
        return "", _choice(rng, _EMPTY)
    if mutation == "truncate":
        return "", data[: int(rng.integers(len(data)))]
    if mutation == "duplicate_key":
        lines = seed.text.splitlines()
        keyed = [
            i
            for i, line in enumerate(lines)
            if line.strip() and not line.lstrip().startswith(("#", "-")) and ":" in line
        ]
        i = _choice(rng, keyed)
        lines.insert(i + 1, lines[i] if not lines[i].rstrip().endswith(":") else lines[i] + " 1")
        return "\n".join(lines) + "\n", None
    if mutation == "directory":
        return "", None
    raise AssertionError(mutation)


# --- running one case ---------------------------------------------------------------------------


@dataclass
class Outcome:
    case: int
    kind: str
    seed: str
    mutation: str
    library: str = ""  # "ok" or the error message
    commands: list = field(default_factory=list)  # (argv, rc, stderr)
    problems: list = field(default_factory=list)
    seconds: float = 0.0


def _load(kind: str, path: Path) -> Any:
    """The library loader of a kind, and everything derived from what it loaded."""
    if kind == "scenario":
        scenario = load_scenario(path)
        json.dumps(summarize_scenario(scenario), default=float)
        return scenario
    if kind in ("block", "block_csv", "csv"):
        return load_block(path)
    if kind == "instrument":
        spec = load_instrument(path)
        format_instrument(spec).encode("utf-8")
        json.dumps(instrument_to_dict(spec), ensure_ascii=False).encode("utf-8")
        return spec
    if kind == "errors":
        data, source = load_yaml_mapping(path)
        base = error_model_from_spec(load_instrument(_shipped_dir("instruments") / "sc1.yaml"))
        model = base.with_overrides(data, source)
        draws = model.draw(np.random.default_rng(0), 3)
        assert all(np.all(np.isfinite(v)) for v in draws.values()), "non-finite draw"
        return model
    if kind == "exercise":
        exercise = load_exercise(path)
        assert exercise.stages and exercise.preset_stages == exercise.preset_stages
        return exercise
    if kind == "geometry":
        return geometry_from_file(path)
    if kind in ("job", "job_csv"):
        job = load_job(path)
        result = compute_job(job)
        json.dumps([pair_dict(job, p) for p in result.pairs], ensure_ascii=False).encode("utf-8")
        return result
    raise AssertionError(kind)


def _run_cli(argv: list[str]) -> tuple[int | str, str, str, list[str]]:
    out, err = io.StringIO(), io.StringIO()
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                rc: int | str = main(argv)
            except SystemExit as exc:
                rc = f"SystemExit({exc.code})"
            except BaseException as exc:  # the point of the test
                rc = f"raised {type(exc).__name__}: {exc}"
    return rc, out.getvalue(), err.getvalue(), [str(w.message) for w in seen]


def _commands(rng: np.random.Generator, kind: str, path: str, shipped: dict[str, str]) -> list:
    """The CLI commands of a case (a sample of the cases runs them)."""
    s = str(path)
    if kind == "scenario":
        cmds = [["scenario", "check", s], ["setup", s, "--instrument", "sc1", "--json"]]
        if rng.random() < SIMULATE_SHARE / CLI_SHARE:
            cmds.append(["simulate", s, "--instrument", "sc1", "--trials", "1", "--json"])
        if rng.random() < SIMULATE_SHARE / CLI_SHARE:  # a scenario as the verify geometry
            cmds.append(["verify", "--trials", "2", "--procedure-trials", "0", "--geometry", s])
        return cmds
    if kind in ("block", "block_csv", "csv"):
        return [
            ["setup", s, "--instrument", "sc1", "--json"],
            ["simulate", s, "--instrument", "sc1"],
        ]
    if kind == "instrument":
        cmds = [
            ["instrument", "show", s],
            ["setup", shipped["pair60"], "--instrument", s, "--json"],
        ]
        if rng.random() < SIMULATE_SHARE / CLI_SHARE:
            cmds.append(
                ["simulate", shipped["pair60"], "--instrument", s, "--trials", "1", "--json"]
            )
        return cmds
    if kind == "errors":
        return [
            [
                "simulate",
                shipped["pair60"],
                "--instrument",
                "sc1",
                "--errors",
                s,
                "--trials",
                "1",
                "--json",
            ]
        ]
    if kind == "exercise":
        return [["exercise", "show", s, "--json"]]
    if kind == "geometry":
        return [["verify", "--trials", "2", "--procedure-trials", "0", "--json", "--geometry", s]]
    if kind in ("job", "job_csv"):
        cmds = [["setup", s, "--json"]]
        if rng.random() < 0.5:
            scenario = str(Path(s).parent / "pair.yaml")
            cmds.append(["job", "to-scenario", s, "102-103", "-o", scenario])
        return cmds
    raise AssertionError(kind)


def _names_file_and_field(message: str, files: list[str], folder: str) -> bool:
    """``FILE: FIELD: expected …`` for one of ``files`` or a file of the case's ``folder`` (a
    models CSV named by the block file), or a refusal that names a file and its key (``… of
    FILE: key …``)."""
    if message.startswith(folder + os.sep) and ": " in message:
        files = [*files, message[: message.index(": ")]]
    for f in files:
        if message.startswith(f + ": "):
            rest = message[len(f) + 2 :]
            return ": expected " in rest and not rest.startswith(": ")
        if f"of {f}: " in message:
            return True
    return False


def _scenario_problem(path: str) -> str:
    """Why the scenario that ``job to-scenario`` wrote does not load ('' when it does)."""
    try:
        load_scenario(path)
    except BaseException as exc:  # the point of the check
        return f"{type(exc).__name__}: {str(exc)[:300]}"
    return ""


def run_case(case: int, folder: Path) -> Outcome:
    rng = np.random.default_rng([SEED, case])
    kind = _pick(rng, KINDS)
    seed = _choice(rng, corpus()[kind])
    mutation = _pick(rng, MUTATIONS)
    outcome = Outcome(case, kind, seed.name, mutation)
    t0 = time.perf_counter()
    here = folder / f"case{case:05d}"
    here.mkdir(parents=True)
    text, data = mutate(rng, seed, mutation)
    target = here / seed.name
    if mutation == "directory":
        target.mkdir()
    else:
        target.write_bytes(data if data is not None else text.encode("utf-8", "surrogatepass"))
    shipped = {"pair60": str(_shipped_dir("scenarios") / "pair60.yaml")}
    if seed.kind == "instrument":  # for inherits: the family in the same folder
        for other in corpus()["instrument"]:
            if other.name != seed.name:
                (here / other.name).write_text(other.text, encoding="utf-8")
    load_path = target
    if kind == "block_csv":
        (here / "models.csv").write_text(corpus()["csv"][0].text, encoding="utf-8")
    if kind == "csv":  # the mutated CSV under the block YAML that names it
        load_path = here / "block_csv.yaml"
        load_path.write_text(corpus()["block_csv"][0].text, encoding="utf-8")
    if kind in ("job", "job_csv"):  # the job with its CSV files, one of them mutated
        for other in corpus()["job_csv"]:
            if other.name != seed.name:
                (here / other.name).write_text(other.text, encoding="utf-8")
    if kind == "job_csv":
        load_path = here / "job.yaml"
        load_path.write_text(corpus()["job"][0].text, encoding="utf-8")
    files = [str(target), str(load_path)]
    shipped_files = [str(p) for p in _shipped_dir("instruments").glob("*.yaml")]

    # the library
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        try:
            _load(kind, load_path)
            outcome.library = "ok"
        except StereoplotterError as exc:
            outcome.library = str(exc)
            if "\n" in outcome.library:
                outcome.problems.append(f"library message is not one line: {outcome.library!r}")
            if not _names_file_and_field(outcome.library, files, str(here)):
                outcome.problems.append(f"library message names no file/field: {outcome.library}")
        except BaseException as exc:  # the point of the test
            outcome.library = f"{type(exc).__name__}: {exc}"
            outcome.problems.append(f"library raised {type(exc).__name__}: {str(exc)[:300]}")
    if seen:
        outcome.problems.append(f"library warned: {[str(w.message) for w in seen][:2]}")

    # the command line, for a sample
    if ONLY is not None or rng.random() < CLI_SHARE:
        for argv in _commands(rng, kind, str(load_path), shipped):
            rc, out, err, warned = _run_cli(argv)
            outcome.commands.append((argv[:2], rc, err.strip()))
            where = f"`{' '.join(argv[:2])}`"
            try:
                (out + err).encode("utf-8")
            except UnicodeEncodeError as exc:
                outcome.problems.append(f"{where}: output not encodable: {exc}")
            if "Traceback" in err or "internal error" in err:
                outcome.problems.append(f"{where}: {err.strip()[:300]}")
            if warned:
                outcome.problems.append(f"{where}: warned: {warned[:2]}")
            if rc == 0 and argv[0] == "job":  # one pair only (another pair may be refused):
                problem = _scenario_problem(argv[-1])  # what it wrote must be a valid scenario
                if problem:
                    outcome.problems.append(f"{where}: wrote an invalid scenario: {problem}")
            elif rc == 0:
                if outcome.library != "ok":
                    outcome.problems.append(f"{where}: exit 0 but the loader refused the file")
                if kind in ("block", "block_csv", "csv") and argv[0] == "simulate":
                    outcome.problems.append(f"{where}: a block file simulated")
            elif rc == 1:
                lines = err.strip().splitlines()
                if len(lines) != 1 or not lines[0].startswith("error: "):
                    outcome.problems.append(f"{where}: not one error line: {err[:300]!r}")
                elif not _names_file_and_field(lines[0][7:], files + shipped_files, str(here)):
                    outcome.problems.append(f"{where}: names no file/field: {lines[0][:300]}")
                if (
                    kind in ("block", "block_csv")
                    and argv[0] == "simulate"
                    and outcome.library == "ok"
                    and "block file" not in err
                ):
                    outcome.problems.append(f"{where}: does not say block file: {err[:200]}")
            else:
                outcome.problems.append(f"{where}: exit {rc}: {err.strip()[:300]}")
    outcome.seconds = time.perf_counter() - t0
    if outcome.seconds > SLOW_CASE_S:
        outcome.problems.append(f"slow: {outcome.seconds:.1f} s")
    shutil.rmtree(here, ignore_errors=True)
    return outcome


def run_cases(folder: Path, cases: int = CASES) -> tuple[list[Outcome], float]:
    t0 = time.perf_counter()
    which = [int(ONLY)] if ONLY is not None else range(cases)
    outcomes = [run_case(i, folder) for i in which]
    return outcomes, time.perf_counter() - t0


def report(outcomes: list[Outcome], seconds: float) -> str:
    bad = [o for o in outcomes if o.problems]
    kinds = Counter(o.kind for o in outcomes)
    mutations = Counter(o.mutation for o in outcomes)
    valid = sum(o.library == "ok" for o in outcomes)
    commands = sum(len(o.commands) for o in outcomes)
    exits = Counter(rc for o in outcomes for _, rc, _ in o.commands)
    lines = [
        f"{len(outcomes)} cases in {seconds:.1f} s (seed {SEED}); {valid} still valid, "
        f"{len(outcomes) - valid} refused by the loader; {commands} CLI runs, exit codes "
        f"{dict(sorted(exits.items(), key=str))}; {len(bad)} with problems",
        "kinds: " + ", ".join(f"{k} {v}" for k, v in sorted(kinds.items())),
        "mutations: " + ", ".join(f"{k} {v}" for k, v in sorted(mutations.items())),
    ]
    for o in bad[:15]:
        lines.append(f"case {o.case} ({o.kind} {o.seed}, {o.mutation}): {o.problems[:3]}")
    return "\n".join(lines)


# --- the tests ----------------------------------------------------------------------------------


def test_mutated_inputs_never_crash(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # any default output folder lands here
    monkeypatch.delenv("STEREOPLOTTER_DEBUG", raising=False)
    outcomes, seconds = run_cases(tmp_path / "cases")
    text = report(outcomes, seconds)
    print(text)
    assert ONLY is not None or len(outcomes) >= 2000 or CASES < 2000
    assert not [o for o in outcomes if o.problems], text
    # the fuzzer reaches both ends: files still valid and files refused, through the CLI too
    if ONLY is None:
        assert sum(o.library == "ok" for o in outcomes) >= 0.02 * len(outcomes), text
        exits = Counter(rc for o in outcomes for _, rc, _ in o.commands)
        assert exits[0] > 0 and exits[1] > 0, text


@pytest.mark.parametrize("raw", [_bomb_flow(), _bomb_flow(12, 6), _CLASSIC_BOMB])
def test_alias_bombs_are_refused_by_their_node_count(tmp_path, raw):
    """Refused by counting the nodes the aliases would expand to, before any expansion (the
    time it takes is the benchmarks', not asserted here)."""
    path = tmp_path / "bomb.yaml"
    path.write_text(raw if raw.startswith("a0:") else f"name: x\nvalue: {raw}\n", encoding="utf-8")
    with pytest.raises(ConfigError, match=r"bomb\.yaml: .*: expected at most 1,000,000 YAML nodes"):
        load_yaml_mapping(path)
    assert MAX_YAML_NODES == 1_000_000
