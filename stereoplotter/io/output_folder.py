"""An output folder a run owns: refused when it holds another run's files, replaced whole on
``--force``, with a manifest of what was written.

:func:`write_outputs` writes a set of rendered files (name → bytes, names may hold one
sub-folder such as ``101-102/sheet.pdf``) into a folder:

* a new or empty folder is written;
* a folder that holds anything is refused (one line) unless ``force``: its files may be another
  job's or an earlier run's, and mixing them with this run's leaves a folder nobody can read;
* with ``force`` the previous outputs are replaced as a whole: the new run (every file and the
  manifest) is written into a staging folder beside the target, the files no run of ours wrote
  (not in the previous manifest; without one, not in the pair folders of an earlier version: a
  folder holding only ``sheet.*`` files) are linked into it and counted, and the staging folder
  takes the target's place in one step; the previous run's files this one does not write are
  gone with the old folder. An interrupt at any moment leaves the previous complete run or the
  new one, never a mix, and no temporary file (:func:`write_outputs`).

The manifest (:data:`MANIFEST`, JSON) lists every file with its size and SHA-256 and who wrote
it; it holds no clock, so the same job gives the same manifest, byte for byte.
"""

from __future__ import annotations

import ctypes
import glob
import hashlib
import json
import os
import secrets
import shutil
import signal
import stat
import sys
import threading
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from stereoplotter.errors import StereoplotterError
from stereoplotter.io.atomic_write import fsync_folder, write_files

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
    """Write ``files`` and their manifest into ``folder`` (the rules in the module docstring),
    all old or all new: the run is written into a staging folder beside ``folder``
    (``.NAME.staging-XXXX``), the files no run wrote are linked into it, and it takes the place
    of ``folder`` in one step (:func:`_swap`, with SIGINT and SIGTERM held back), so an
    interrupt at any moment leaves the previous complete run or the new one. An interrupted
    run's staging folder is removed on the way out, and any left by a killed run is removed (an
    old folder moved aside and not yet replaced is put back) by the next run.

    Raises
    ------
    StereoplotterError
        ``folder`` is a file, or holds files and ``force`` is not given (one line; nothing is
        written).
    """
    shown = Path(folder)
    out = Path(os.path.realpath(folder))  # "." or a link: the folder itself, beside its parent
    _recover(out)
    if out.exists() and not out.is_dir():
        raise StereoplotterError(f"{shown}: -o: expected a folder, found a file")
    present = _entries(out) if out.exists() else []
    previous, who = _previous(out) if present else (set(), "")
    if present and not force:
        raise StereoplotterError(
            f"{shown}: -o: expected a new or empty output folder, found {len(present)} files "
            f"({who}): give --force to replace them, or another folder"
        )
    out.parent.mkdir(parents=True, exist_ok=True)
    staging = _new_folder(out.parent, f".{out.name}.staging-")
    try:
        mine = set(files) | previous | {MANIFEST}
        foreign = [p for p in present if _name(p, out) not in mine]
        removed = sorted(n for n in previous - set(files) - {MANIFEST}
                         if (out / n).is_file() or (out / n).is_symlink())  # fmt: skip
        for path in foreign:  # the operator's own files go on living in the new folder
            _link(path, staging / path.relative_to(out))
        write_files(staging, {**files, MANIFEST: manifest_bytes(files, about)})
        if out.exists():  # the folder keeps the permissions it had
            os.chmod(staging, stat.S_IMODE(out.stat().st_mode))
        with _signals_held():  # a signal meanwhile is delivered after the swap
            _swap(staging, out)
            shutil.rmtree(staging, ignore_errors=True)  # the previous run
    finally:
        with _signals_held():  # nor is the clean-up of an interrupted run cut short
            shutil.rmtree(staging, ignore_errors=True)
    return OutputReport(tuple(files), tuple(removed), len(foreign))


def _name(path: Path, top: Path) -> str:
    return str(path.relative_to(top)).replace(os.sep, "/")


def _new_folder(parent: Path, prefix: str) -> Path:
    """A new empty folder ``prefix`` + 12 hex digits in ``parent``, mode 0o777 less the umask
    (as any folder the user makes)."""
    for _ in range(100):
        path = parent / f"{prefix}{secrets.token_hex(6)}"
        try:
            path.mkdir(0o777)
            return path
        except FileExistsError:
            continue
    raise FileExistsError(f"{parent}: no free name for a staging folder")


def _link(source: Path, target: Path) -> None:
    """``target`` the same file as ``source`` (a hard link; a copy where links are refused)."""
    target.parent.mkdir(parents=True, exist_ok=True)
    try:
        os.link(source, target, follow_symlinks=False)
    except OSError:
        shutil.copy2(source, target, follow_symlinks=False)


_ASIDE = ".old-"


def _recover(out: Path) -> None:
    """Undo what a killed run left beside ``out``: its staging folders are removed; a previous
    run moved aside (``.NAME.old-XXXX``) is put back when ``out`` is missing, else removed."""
    parent = out.parent
    if not parent.is_dir():
        return
    for path in sorted(parent.glob(f".{glob.escape(out.name)}.*")):
        rest = path.name[len(out.name) + 2 :]
        if not path.is_dir() or path.is_symlink():
            continue
        if rest.startswith("old-") and not out.exists():
            os.replace(path, out)
        elif rest.startswith(("staging-", "old-")):
            shutil.rmtree(path, ignore_errors=True)


def _swap(staging: Path, out: Path) -> None:
    """``staging`` takes the place of ``out`` in one step, the previous folder left at
    ``staging`` (removed by the caller): an exchange of the two names where the system has one
    (Linux renameat2 RENAME_EXCHANGE), else ``out`` moved aside and ``staging`` renamed onto it
    (a kill between the two renames is undone by :func:`_recover`). The caller holds SIGINT and
    SIGTERM back meanwhile (:func:`_signals_held`)."""
    if not out.exists():
        os.rename(staging, out)
        staging.mkdir()  # an empty one for the caller to remove
    elif not _exchange(staging, out):
        aside = out.parent / f".{out.name}{_ASIDE}{staging.name.rsplit('-', 1)[-1]}"
        os.rename(out, aside)
        os.rename(staging, out)
        os.rename(aside, staging)
    fsync_folder(out.parent)


@contextmanager
def _signals_held() -> Iterator[None]:
    """SIGINT and SIGTERM held back inside the block and delivered after it (to the handlers
    they had): the Python handlers swapped for ones that remember the signal (in the main
    thread, where Python handles signals; elsewhere nothing is held)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    got: list[int] = []
    handlers = {s: signal.signal(s, lambda n, f: got.append(n))
                for s in (signal.SIGINT, signal.SIGTERM)}  # fmt: skip
    try:
        yield
    finally:
        for s, handler in handlers.items():
            signal.signal(s, handler)
        if got:
            handler = handlers[got[0]]
            if callable(handler):
                handler(got[0], None)
            elif handler == signal.SIG_DFL:
                signal.raise_signal(got[0])


def _exchange(a: Path, b: Path) -> bool:
    """Exchange the names ``a`` and ``b`` atomically (Linux ``renameat2``); False where the
    system has no such call."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        renameat2 = libc.renameat2
    except (OSError, AttributeError):
        return False
    at_fdcwd, rename_exchange = -100, 2
    done = renameat2(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange)
    if done != 0:
        errno = ctypes.get_errno()
        if errno in (38, 22, 95):  # ENOSYS, EINVAL, EOPNOTSUPP: no exchange on this system
            return False
        raise OSError(errno, os.strerror(errno), str(b))
    return True

