"""Where the data live: the shipped instruments and scenarios, and the user's own.

*Shipped* data are package data, ``stereoplotter/data/instruments/*.yaml`` and
``stereoplotter/data/scenarios/*.yaml`` (with ``scenarios/blocks/``), found through
:mod:`importlib.resources` wherever the package is installed and whatever the working directory.

*User* folders add to them: the folders given with the command-line option ``--data DIR``
(:func:`set_user_folders`, in the order given), then those of the environment variable
``STEREOPLOTTER_DATA`` (separated by ``os.pathsep``). Each user folder may hold an
``instruments/`` and a ``scenarios/`` sub-folder. The current working directory is not searched
unless it is named.

A *name* (``sc1``, ``pair60``) resolves in the user folders first, then in the shipped data. A
user file with the name of a shipped one is used, with a warning that names both paths; a shipped
file is never hidden silently. Anything with a folder part (``scenarios/pair60.yaml``) or a
``.yaml``/``.yml`` file that exists is a path and is used as given.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Iterable
from dataclasses import dataclass
from importlib.resources import files
from pathlib import Path

from stereoplotter.errors import ConfigError

__all__ = [
    "DEFAULT_SCENARIO",
    "ENVIRONMENT_VARIABLE",
    "KINDS",
    "DataFile",
    "UserFolder",
    "available_names",
    "data_dir",
    "data_files",
    "find_data_file",
    "list_data_files",
    "resolve_data_file",
    "set_user_folders",
    "shipped_root",
    "user_folders",
]

log = logging.getLogger(__name__)

#: The scenario the README's main job runs (a shipped name).
DEFAULT_SCENARIO = "pair60"

#: The environment variable naming user data folders.
ENVIRONMENT_VARIABLE = "STEREOPLOTTER_DATA"

#: The kinds of data: the sub-folder names of a data folder.
KINDS = ("instruments", "scenarios", "exercises")

_SINGULAR = {"instruments": "instrument", "scenarios": "scenario", "exercises": "exercise"}

_option_folders: tuple[Path, ...] = ()
_warned: set[tuple[str, str, str]] = set()


@dataclass(frozen=True)
class UserFolder:
    """A user data folder and where it was named (``"--data"`` or ``"STEREOPLOTTER_DATA"``)."""

    path: Path
    origin: str


@dataclass(frozen=True)
class DataFile:
    """One data file found by name.

    Attributes
    ----------
    name : str
        The name it is found by: the file name without ``.yaml``.
    path : Path
        The file.
    origin : str
        ``"shipped"``, ``"--data"`` or ``"STEREOPLOTTER_DATA"``.
    hides : tuple of Path
        Files of the same name it hides (a shipped file, or one of a later user folder).
    """

    name: str
    path: Path
    origin: str
    hides: tuple[Path, ...] = ()


def _check_kind(kind: str) -> None:
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, not {kind!r}")


def shipped_root() -> Path:
    """The folder of the shipped data (``stereoplotter/data`` of the installed package)."""
    root = files("stereoplotter") / "data"
    if not isinstance(root, Path):  # e.g. a zip import: the loaders need real files
        raise ConfigError(
            str(root), "(package data)", "a folder on the file system", "an archive member"
        )
    return root


def data_dir(kind: str) -> Path:
    """The shipped ``kind`` folder (``"instruments"`` or ``"scenarios"``).

    Examples
    --------
    >>> sorted(p.name for p in data_dir("instruments").glob("*.yaml"))
    ['sc1.yaml', 'sd3.yaml', 'spr3.yaml']
    """
    _check_kind(kind)
    return shipped_root() / kind


def set_user_folders(folders: Iterable[str | os.PathLike[str]]) -> None:
    """Set the user folders of the command-line option ``--data`` (replacing earlier ones).

    Raises
    ------
    ConfigError
        A folder does not exist or is not a folder.
    """
    checked = []
    for folder in folders:
        path = Path(folder)
        if not path.is_dir():
            found = "a file" if path.exists() else "no such folder"
            raise ConfigError(str(folder), "--data", "an existing folder", found)
        checked.append(path)
    global _option_folders
    _option_folders = tuple(checked)
    _warned.clear()


def user_folders() -> list[UserFolder]:
    """The user folders in search order: ``--data`` ones, then ``STEREOPLOTTER_DATA`` ones.

    An entry of the environment variable that is not a folder is left out with a warning.
    """
    found = [UserFolder(p, "--data") for p in _option_folders]
    for text in os.environ.get(ENVIRONMENT_VARIABLE, "").split(os.pathsep):
        if not text:
            continue
        path = Path(text)
        if path.is_dir():
            found.append(UserFolder(path, ENVIRONMENT_VARIABLE))
        else:
            _warn_once(
                ("env", text, ""),
                "%s names %s, which is not a folder; it is left out",
                ENVIRONMENT_VARIABLE,
                text,
            )
    return found


def _warn_once(key: tuple[str, str, str], message: str, *args: object) -> None:
    if key not in _warned:
        _warned.add(key)
        log.warning(message, *args)


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.samefile(b)
    except OSError:
        return False


def data_files(kind: str) -> list[DataFile]:
    """Every ``kind`` file found by name, user ones first, each name once, sorted by name.

    A user file with the name of a shipped one comes with ``hides`` naming the shipped file. A
    user folder that reaches the shipped data themselves (``--data`` on a checkout, whose
    ``instruments`` links to them) adds nothing and hides nothing.

    Examples
    --------
    >>> [f.name for f in data_files("scenarios")][:2]
    ['book_resection_table7', 'mountain60']
    """
    _check_kind(kind)
    sources = [(f.path / kind, f.origin) for f in user_folders()]
    sources.append((data_dir(kind), "shipped"))
    chosen: dict[str, DataFile] = {}
    for folder, origin in sources:
        if not folder.is_dir():
            continue
        for path in sorted(folder.glob("*.yaml")):
            name = path.stem
            first = chosen.get(name)
            if first is None:
                chosen[name] = DataFile(name, path, origin)
            elif not _same_file(first.path, path):
                chosen[name] = DataFile(name, first.path, first.origin, (*first.hides, path))
    # a user entry that is the shipped file itself (through a link) counts as shipped
    shipped = data_dir(kind)
    result = []
    for entry in chosen.values():
        if entry.origin != "shipped" and _same_file(entry.path, shipped / entry.path.name):
            entry = DataFile(entry.name, shipped / entry.path.name, "shipped", entry.hides)
        result.append(entry)
    return sorted(result, key=lambda f: f.name)


def list_data_files(kind: str) -> list[Path]:
    """The ``kind`` files found by name (user and shipped), sorted by name."""
    return [f.path for f in data_files(kind)]


def available_names(kind: str) -> list[str]:
    """The names a ``kind`` can be given by (``["sc1", "sd3", "spr3"]`` and user ones), sorted.

    Examples
    --------
    >>> available_names("instruments")
    ['sc1', 'sd3', 'spr3']
    """
    return [f.name for f in data_files(kind)]


def find_data_file(kind: str, name: str) -> Path | None:
    """The file of a bare ``name`` (``"sc1"`` or ``"sc1.yaml"``), or None.

    User folders come first; a user file that hides a shipped one is used and a warning names
    both.

    Examples
    --------
    >>> find_data_file("scenarios", "pair60").name
    'pair60.yaml'
    >>> find_data_file("scenarios", "pair61") is None
    True
    """
    stem = name[: -len(".yaml")] if name.endswith(".yaml") else name
    for entry in data_files(kind):
        if entry.name == stem:
            if entry.hides:
                _warn_once(
                    (kind, stem, str(entry.path)),
                    "%s %s: using %s (from %s), which hides %s",
                    _SINGULAR[kind],
                    stem,
                    entry.path,
                    entry.origin,
                    ", ".join(str(p) for p in entry.hides),
                )
            return entry.path
    return None


def resolve_data_file(kind: str, name_or_path: str | os.PathLike[str]) -> Path:
    """A name or a path given on the command line, as the file to read.

    Anything with a folder part, and a ``.yaml``/``.yml`` file that exists, is used as given; a
    bare name (with or without ``.yaml``) is looked up by :func:`find_data_file`. A ``.yaml``
    name found nowhere is returned as given, so that reading it reports the missing file.

    Raises
    ------
    ConfigError
        A bare name without ``.yaml`` that names no data file; the message lists the names.
    """
    _check_kind(kind)
    text = os.fspath(name_or_path)
    if isinstance(name_or_path, os.PathLike) or "/" in text or os.sep in text:
        return Path(text)
    is_file_name = text.endswith((".yaml", ".yml"))
    if is_file_name and Path(text).exists():
        return Path(text)
    found = find_data_file(kind, text)
    if found is not None:
        return found
    if is_file_name:
        return Path(text)
    names = ", ".join(available_names(kind)) or "none found"
    raise ConfigError(
        f"{kind}/",
        text,
        f"the name of a {_SINGULAR[kind]} ({names}) or a path to a YAML file",
        f"no such {_SINGULAR[kind]}",
    )
