"""Writing output files whole or not at all, with the user's umask.

Every file the program writes goes through :func:`atomic_stream` (a temporary file in the same
folder, renamed onto the target when complete); :func:`write_files` writes a set of files
rendered beforehand, so a rendering error leaves nothing behind.
"""

from __future__ import annotations

import logging
import os
import secrets
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import BinaryIO

__all__ = [
    "atomic_stream",
    "atomic_write_bytes",
    "atomic_write_text",
    "fsync_folder",
    "write_files",
]

log = logging.getLogger(__name__)


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to ``path`` whole or not at all (:func:`atomic_stream`)."""
    with atomic_stream(path) as f:
        f.write(data)


@contextmanager
def atomic_stream(path: str | os.PathLike[str]) -> Iterator[BinaryIO]:
    """A binary file that appears under ``path`` whole or not at all, for streamed writing.

    The bytes go to a new temporary file in the same folder (``.NAME.XXXXXXXXXXXX.tmp``); when
    the ``with`` block ends without an exception they are flushed to disk and the file is renamed
    onto ``path`` (:func:`os.replace`, atomic on one file system). The temporary file is created
    with mode 0o666, which the kernel reduces by the process umask as for any ``open``: 0644
    under umask 022, 0600 under 077 (and a default ACL of the folder applies as usual). On any
    exception, ``KeyboardInterrupt`` included, the temporary file is removed and ``path`` is left
    as it was.
    """
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp, fd = _create_temporary(target)
    try:
        with os.fdopen(fd, "wb") as f:
            yield f
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, target)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    fsync_folder(target.parent)


def _create_temporary(target: Path) -> tuple[Path, int]:
    """A new, empty file next to ``target`` (mode 0o666 less the umask) and its descriptor."""
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0)
    for _ in range(100):
        tmp = target.parent / f".{target.name}.{secrets.token_hex(6)}.tmp"
        try:
            return tmp, os.open(tmp, flags, 0o666)
        except FileExistsError:
            continue
    raise FileExistsError(f"{target.parent}: no free temporary file name for {target.name}")


def fsync_folder(folder: Path) -> None:
    """Make a rename or a swap in ``folder`` durable where the platform allows it (best effort)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def atomic_write_text(path: str | os.PathLike[str], text: str) -> None:
    """Write UTF-8 ``text`` to ``path`` whole or not at all."""
    atomic_write_bytes(path, text.encode("utf-8"))


def write_files(folder: str | os.PathLike[str], files: Mapping[str, bytes]) -> dict[str, Path]:
    """Write each ``name → bytes`` of ``files`` into ``folder`` (names may hold a sub-folder),
    each whole or not at all (:func:`atomic_write_bytes`), in the order given.

    Returns
    -------
    dict
        name → the path written.
    """
    out = Path(folder)
    paths = {}
    for name, data in files.items():
        atomic_write_bytes(out / name, data)
        paths[name] = out / name
    log.info("wrote %s in %s", ", ".join(sorted(files)), out)
    return paths
