"""An output folder a run owns: refused when it holds another run's files, replaced whole on
``--force``, with a manifest of what was written.

:func:`write_outputs` writes a set of rendered files (name → bytes, names may hold one
sub-folder such as ``101-102/sheet.pdf``) into a folder:

* a new or empty folder is written;
* a folder that holds anything is refused (one line) unless ``force``: its files may be another
  job's or an earlier run's, and mixing them with this run's leaves a folder nobody can read;
* with ``force`` the previous outputs are replaced as a whole: every new file is written (each
  whole or not at all, :mod:`stereoplotter.io.atomic_write`), then every file the previous run
  wrote that this one does not (by the previous manifest; without one, the pair folders of an
  earlier version: a folder holding only ``sheet.*`` files) is removed, with the folders that it
  leaves empty, and the manifest is written last. Files no run of ours wrote are left alone and
  counted.

The manifest (:data:`MANIFEST`, JSON) lists every file with its size and SHA-256 and who wrote
it; it holds no clock, so the same job gives the same manifest, byte for byte.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from stereoplotter.errors import StereoplotterError
from stereoplotter.io.atomic_write import atomic_write_bytes, write_files

__all__ = ["MANIFEST", "OutputReport", "manifest_bytes", "write_outputs"]

#: The manifest's file name, in the output folder.
MANIFEST = "manifest.json"
_FORMAT = "stereoplotter-outputs/1"
#: The files of a pair folder of a job written before manifests (removed by ``--force``).
_LEGACY_PAIR_FILES = {"sheet.yaml", "sheet.md", "sheet.pdf"}


@dataclass(frozen=True, slots=True)
class OutputReport:
    """What :func:`write_outputs` did: the names written, the stale names removed, and the
    number of files left in place that no run of ours wrote."""

    written: tuple[str, ...]
    removed: tuple[str, ...]
    kept_foreign: int


def manifest_bytes(files: Mapping[str, bytes], about: Mapping[str, Any]) -> bytes:
    """The manifest of ``files``: ``about`` (job, job file, program) and per file its size and
    SHA-256, sorted by name."""
    listing = {
        name: {"bytes": len(data), "sha256": hashlib.sha256(data).hexdigest()}
        for name, data in sorted(files.items())
    }
    doc = {"format": _FORMAT, **about, "files": listing}
    return (json.dumps(doc, indent=2, ensure_ascii=False) + "\n").encode("utf-8")


def _entries(folder: Path) -> list[Path]:
    return sorted(p for p in folder.rglob("*") if p.is_file() or p.is_symlink())


def _previous(folder: Path) -> tuple[set[str], str]:
    """The names the previous run wrote (by its manifest, or the legacy pair folders) and a
    phrase saying whose the folder's files are."""
    manifest = folder / MANIFEST
    if manifest.is_file():
        try:
            doc = json.loads(manifest.read_text(encoding="utf-8"))
            names = set(doc["files"]) | {MANIFEST}
            who = f"the outputs of {doc.get('job', '?')} ({doc.get('job_file', '?')})"
            return names, who
        except (OSError, ValueError, KeyError, TypeError):
            pass  # a damaged manifest: as if none
    names = set()
    for sub in folder.iterdir():
        inside = {p.name for p in sub.iterdir()} if sub.is_dir() and not sub.is_symlink() else ()
        if inside and set(inside) <= _LEGACY_PAIR_FILES:
            names |= {f"{sub.name}/{n}" for n in inside}
    return names, "files without a manifest (another program, or a run of an older version)"


def write_outputs(
    folder: str | os.PathLike[str],
    files: Mapping[str, bytes],
    about: Mapping[str, Any],
    *,
    force: bool = False,
) -> OutputReport:
    """Write ``files`` and their manifest into ``folder`` (the rules in the module docstring).

    Raises
    ------
    StereoplotterError
        ``folder`` is a file, or holds files and ``force`` is not given (one line; nothing is
        written).
    """
    out = Path(folder)
    if out.exists() and not out.is_dir():
        raise StereoplotterError(f"{out}: -o: expected a folder, found a file")
    present = _entries(out) if out.exists() else []
    previous, who = _previous(out) if present else (set(), "")
    if present and not force:
        raise StereoplotterError(
            f"{out}: -o: expected a new or empty output folder, found {len(present)} files "
            f"({who}): give --force to replace them, or another folder"
        )
    write_files(out, files)
    removed = []
    for name in sorted(previous - set(files) - {MANIFEST}):
        path = out / name
        if path.is_file() or path.is_symlink():
            path.unlink()
            removed.append(name)
            _remove_empty_parents(path.parent, out)
    atomic_write_bytes(out / MANIFEST, manifest_bytes(files, about))
    mine = set(files) | set(removed) | {MANIFEST}
    foreign = sum(str(p.relative_to(out)).replace(os.sep, "/") not in mine for p in present)
    return OutputReport(tuple(files), tuple(removed), foreign)


def _remove_empty_parents(folder: Path, top: Path) -> None:
    while folder != top and folder.is_dir() and not any(folder.iterdir()):
        folder.rmdir()
        folder = folder.parent
