"""``stereoplotter info``: versions, the data folders, the instruments and scenarios found."""

from __future__ import annotations

import argparse
import sys
from importlib.metadata import version
from typing import Any

from stereoplotter import __version__

__all__ = ["add_arguments", "format_info", "info", "run"]

#: Distribution of each library whose version ``info`` prints (read from its metadata, without
#: importing the library: ``info`` stays quick).
_LIBRARIES = {
    "numpy": "numpy",
    "scipy": "scipy",
    "pymunk": "pymunk",
    "matplotlib": "matplotlib",
    "pyyaml": "PyYAML",
    "pyproj": "pyproj",
}


def add_arguments(sub: Any) -> None:
    p = sub.add_parser("info", help="versions, instruments and scenarios found")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    # imported here: the CLI loads no report or file reader until a command runs
    from stereoplotter.report.plain_data import json_text

    result = info()
    sys.stdout.write(json_text(result) if args.json else format_info(result))
    return 0


def _versions() -> dict[str, str]:
    # the interpreter's version as platform.python_version() reads it (the first word of
    # sys.version), without importing platform
    found = {"stereoplotter": __version__, "python": sys.version.split()[0]}
    found.update({key: version(dist) for key, dist in _LIBRARIES.items()})
    found["proj"] = _proj_version()
    return found


def _proj_version() -> str:
    """The PROJ library's version (not in pyproj's package metadata).

    Read from pyproj's own version module (``pyproj._version``, a small extension linked to
    PROJ) loaded alone: ``import pyproj`` sets up its coordinate systems, transformers and
    network code first, a third of ``info``'s time. Where pyproj is loaded already, or that
    module moves, pyproj's own attribute is read.
    """
    # imported here: only `info` reads the PROJ version, and only this way
    import importlib.machinery
    import importlib.util

    if "pyproj" not in sys.modules:
        try:
            package = importlib.util.find_spec("pyproj")
            folders = package.submodule_search_locations if package else None
            spec = importlib.machinery.PathFinder.find_spec("pyproj._version", folders)
            if spec is not None and spec.loader is not None:
                module = importlib.util.module_from_spec(spec)
                spec.loader.exec_module(module)
                # the extension registers itself; a later `import pyproj` loads it as its own
                sys.modules.pop(spec.name, None)
                return str(module.PROJ_VERSION_STR)
        except (ImportError, AttributeError, OSError):
            pass
    # imported here: the fallback when pyproj's version module cannot be loaded alone
    import pyproj

    return str(pyproj.proj_version_str)


def _count_status(node: Any, counts: dict[str, int]) -> None:
    if isinstance(node, dict):
        status = node.get("status")
        if status in ("documented", "assumed"):
            counts[status] += 1
        for value in node.values():
            _count_status(value, counts)
    elif isinstance(node, list):
        for value in node:
            _count_status(value, counts)


def _data_entry(found: Any) -> dict[str, Any]:
    """The name, file and origin of a data file (:class:`~stereoplotter.io.paths.DataFile`)."""
    entry: dict[str, Any] = {"key": found.name, "file": str(found.path), "from": found.origin}
    if found.hides:
        entry["hides"] = [str(p) for p in found.hides]
    return entry


def info() -> dict[str, Any]:
    """Versions, data folders (in look-up order), instruments and scenarios with their counts."""
    # imported here: `--help` reads no file. A scenario is listed from its outline (name,
    # photos, points), not validated whole: that loads numpy, pydantic and pyproj
    # (`stereoplotter scenario check NAME` validates it)
    from stereoplotter.errors import StereoplotterError
    from stereoplotter.io.paths import data_files, shipped_root, user_folders
    from stereoplotter.io.scenario_outline import scenario_outline
    from stereoplotter.io.yaml_input import load_yaml_mapping

    instruments = []
    for found in data_files("instruments"):
        counts = {"documented": 0, "assumed": 0}
        entry = _data_entry(found)
        try:
            data, _ = load_yaml_mapping(found.path)
            _count_status(data, counts)
            entry.update(values_documented=counts["documented"], values_assumed=counts["assumed"])
        except StereoplotterError as exc:
            entry["error"] = str(exc)
        instruments.append(entry)
    scenarios = []
    for found in data_files("scenarios"):
        entry = _data_entry(found)
        try:
            s = scenario_outline(found.path)
            entry.update(name=s.name, photos=s.photos, points=s.points)
        except StereoplotterError as exc:
            entry["error"] = str(exc)
        scenarios.append(entry)
    # in the order names are looked up: user folders first, the shipped data last
    folders = [{"folder": str(f.path), "from": f.origin} for f in user_folders()]
    folders.append({"folder": str(shipped_root()), "from": "shipped"})
    return {
        "versions": _versions(),
        "data_folders": folders,
        "instruments": instruments,
        "scenarios": scenarios,
    }


def format_info(info: dict[str, Any]) -> str:
    """The text of ``info``."""
    lines = ["stereoplotter " + info["versions"]["stereoplotter"], "", "versions:"]
    lines += [f"  {k:<14}{v}" for k, v in info["versions"].items()]
    lines += ["", "data folders (a name is looked up in this order):"]
    lines += [f"  {f['from']:<20}{f['folder']}" for f in info["data_folders"]]
    for kind in ("instruments", "scenarios"):
        lines += ["", f"{kind} ({len(info[kind])} found):"]
        if not info[kind]:
            lines.append("  none")
        width = max((len(e["key"]) for e in info[kind]), default=0) + 2
        for entry in info[kind]:
            lines += _info_entry_lines(kind, entry, width)
    return "\n".join(lines) + "\n"


def _info_entry_lines(kind: str, entry: dict[str, Any], width: int) -> list[str]:
    head = f"  {entry['key']:<{width}}[{entry['from']}] {entry['file']}"
    if "error" in entry:
        lines = [f"{head}: INVALID: {entry['error']}"]
    elif kind == "instruments":
        lines = [
            f"{head}: {entry['values_documented']} documented, "
            f"{entry['values_assumed']} assumed values"
        ]
    else:
        lines = [f"{head}: {entry['name']} ({entry['photos']} photo(s), {entry['points']} points)"]
    if "hides" in entry:
        lines.append(f"  {'':<{width}}hides {', '.join(entry['hides'])}")
    return lines
