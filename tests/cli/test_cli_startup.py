"""A command line that starts at once: the CLI and the quick commands import only
what they use. Checked on ``sys.modules`` of a fresh interpreter (nothing about time here: speed
is measured in ``benchmarks/``)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

#: The trainer's modules but its exercise vocabulary (``trainer.exercise``: the choices of
#: ``exercise new``, imports no numpy) and the package itself.
_TRAINER = tuple(
    f"stereoplotter.trainer.{p.stem}"
    for p in sorted((Path(__file__).parents[2] / "stereoplotter" / "trainer").glob("*.py"))
    if p.stem not in ("__init__", "exercise")
)

#: Loaded by no command's parser, nor by ``--version``/``--help``: the heavy libraries, the
#: pydantic models of the input files (each command's own) and the web server.
NOT_AT_START = (
    "numpy",
    "scipy",
    "matplotlib",
    "pydantic",
    "yaml",
    "pyproj",
    "starlette",
    "uvicorn",
    "stereoplotter.web",
    "stereoplotter.io.scenario_file",
    "stereoplotter.io.instrument_file",
    "stereoplotter.io.job_file",
    "stereoplotter.io.study_file",
    "stereoplotter.procedure",
    "stereoplotter.verification",
    *_TRAINER,
)

#: What ``info`` (versions, data files) has no use for: pyproj is asked for its PROJ version
#: through its version module alone, and no progress bar is drawn.
NOT_IN_INFO = (
    "numpy",
    "pydantic",
    "pyproj",
    "tqdm",
    "scipy",
    "matplotlib",
    "starlette",
    "stereoplotter.web",
    "stereoplotter.procedure",
    "stereoplotter.instrument",
    "stereoplotter.verification",
    "stereoplotter.io.job_file",
    "stereoplotter.io.study_file",
)


def _loaded(code: str) -> list[str]:
    """The modules of :data:`NOT_AT_START` and :data:`NOT_IN_INFO` a fresh interpreter has
    after running ``code``."""
    watch = sorted(set(NOT_AT_START) | set(NOT_IN_INFO))
    probe = (
        f"import sys, json\n{code}\n"
        f"print(json.dumps([m for m in {watch!r} if any(k == m or k.startswith(m + '.') "
        "for k in sys.modules)]))"
    )
    done = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, check=True, timeout=120
    )
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_importing_the_cli_and_building_its_parser_loads_none_of_it():
    code = "import stereoplotter.cli as c\nc.full_parser()"
    assert _loaded(code) == []


@pytest.mark.parametrize("argv", [["--version"], ["--help"], ["info", "--help"]])
def test_version_and_help_load_none_of_it(argv):
    code = (
        "import contextlib, io\nfrom stereoplotter.cli import main\n"
        "with contextlib.suppress(SystemExit), contextlib.redirect_stdout(io.StringIO()):\n"
        f"    main({argv!r})"
    )
    assert _loaded(code) == []


def test_info_loads_only_the_file_readers():
    code = (
        "import contextlib, io\nfrom stereoplotter.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n    main(['info'])"
    )
    assert set(_loaded(code)).isdisjoint(NOT_IN_INFO)


def test_info_prints_the_proj_version_pyproj_reports_and_leaves_pyproj_whole():
    code = (
        "import contextlib, io, json\nfrom stereoplotter.cli import main\n"
        "out = io.StringIO()\n"
        "with contextlib.redirect_stdout(out):\n    main(['info', '--json'])\n"
        "import pyproj\nfrom pyproj import Transformer\n"
        "t = Transformer.from_crs(4326, 28404, always_xy=True)\n"
        "print(json.dumps([json.loads(out.getvalue())['versions']['proj'],"
        " pyproj.proj_version_str, pyproj._version.PROJ_VERSION_STR,"
        " [round(v, 3) for v in t.transform(37.0, 55.0)]]))"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120
    )
    printed, reported, module, moved = json.loads(done.stdout.strip().splitlines()[-1])
    assert printed == reported == module
    # pyproj loaded after info transforms as it does alone
    alone = subprocess.run(
        [sys.executable, "-c", "import json\nfrom pyproj import Transformer\n"
         "t = Transformer.from_crs(4326, 28404, always_xy=True)\n"
         "print(json.dumps([round(v, 3) for v in t.transform(37.0, 55.0)]))"],
        capture_output=True, text=True, check=True, timeout=120,
    )  # fmt: skip
    assert moved == json.loads(alone.stdout.strip().splitlines()[-1])
