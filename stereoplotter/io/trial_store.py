"""Per-trial columns of a long run, spooled to disk chunk by chunk, read back one at a time.

A run of 10⁶ trials has about a hundred measures per trial (``procedure.trials.trial_columns``):
0.8 GB in float64, more than the memory a run may hold. :class:`TrialStore` appends each chunk's
columns to one raw file per column in a folder (a temporary one unless given), so memory holds
one chunk; :meth:`TrialStore.columns` yields the whole columns one after another for the
summary (mapped, read only when used); :meth:`TrialStore.write_npz` streams them into
``trials.npz``.

Why ``.npz`` rather than Parquet: it is numpy's own format (no extra dependency such as pyarrow),
``numpy.load`` opens it lazily column by column, and it can be written column by column here, so
even 10⁶ trials never sit in memory at once. The file is an uncompressed ZIP (random residuals
do not compress); each member ``<measure>.npy`` is one column of shape (T,).
"""

from __future__ import annotations

import os
import shutil
import tempfile
import zipfile
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from stereoplotter.errors import StereoplotterError
from stereoplotter.io.atomic_write import atomic_stream

__all__ = ["TrialStore"]

#: Bytes copied at a time from a spool file into ``trials.npz``.
_COPY_BLOCK = 1 << 20


class TrialStore:
    """Columns of a run, appended chunk by chunk (a stateful spool on disk).

    Parameters
    ----------
    folder : path, optional
        Where the spool files go; default a temporary folder removed by :meth:`close`.
    """

    def __init__(self, folder: str | os.PathLike[str] | None = None):
        self._tmp = None if folder is not None else tempfile.TemporaryDirectory(prefix="sp-")
        self.folder = Path(folder if folder is not None else self._tmp.name)
        self.folder.mkdir(parents=True, exist_ok=True)
        self.names: list[str] = []
        self.dtypes: dict[str, np.dtype[Any]] = {}
        self.trials = 0

    def _file(self, index: int) -> Path:
        return self.folder / f"column{index:04d}.bin"

    def append(self, columns: Mapping[str, NDArray[Any]]) -> None:
        """Add one chunk: every column of the run, shape (t,) each, in any order."""
        if not self.names:
            self.names = list(columns)
            self.dtypes = {k: np.asarray(v).dtype for k, v in columns.items()}
        elif set(columns) != set(self.names):
            missing = sorted(set(self.names) ^ set(columns))
            raise StereoplotterError(f"trial columns changed between chunks: {missing}")
        lengths = {len(v) for v in columns.values()}
        if len(lengths) != 1:
            raise StereoplotterError(f"trial columns of one chunk differ in length: {lengths}")
        for i, name in enumerate(self.names):
            a = np.ascontiguousarray(columns[name], dtype=self.dtypes[name])
            with open(self._file(i), "ab") as f:
                a.tofile(f)
        self.trials += lengths.pop()

    def column(self, name: str) -> NDArray[Any]:
        """One whole column, shape (T,)."""
        i = self.names.index(name)
        return np.fromfile(self._file(i), dtype=self.dtypes[name])

    def columns(self) -> Iterator[tuple[str, NDArray[Any]]]:
        """(name, whole column) one after another, in the order of the first chunk.

        Each column is the spool file mapped read-only, not read: it takes memory only while it
        is used, so a consumer that takes a few columns ahead of the one it works on (the
        summary's threads) holds no more than those it works on (at 10⁶ trials a column is
        8 MB).
        """
        for i, name in enumerate(self.names):
            yield name, np.memmap(self._file(i), dtype=self.dtypes[name], mode="r")

    def write_npz(self, path: str | os.PathLike[str]) -> None:
        """Write ``trials.npz`` (one member per column), whole or not at all.

        Each member is the ``.npy`` header and then the spool file copied a block at a time,
        so that memory holds no whole column (10⁷ trials are 80 MB a column).
        """
        with (
            atomic_stream(path) as f,
            zipfile.ZipFile(f, "w", zipfile.ZIP_STORED, allowZip64=True) as zf,
        ):
            for i, name in enumerate(self.names):
                header = {
                    "descr": np.lib.format.dtype_to_descr(self.dtypes[name]),
                    "fortran_order": False,
                    "shape": (self.trials,),
                }
                info = zipfile.ZipInfo(name + ".npy", date_time=(1980, 1, 1, 0, 0, 0))
                with zf.open(info, "w", force_zip64=True) as member:
                    np.lib.format.write_array_header_1_0(member, header)
                    with open(self._file(i), "rb") as column:
                        shutil.copyfileobj(column, member, _COPY_BLOCK)

    def close(self) -> None:
        """Remove the spool files (and the temporary folder)."""
        for i in range(len(self.names)):
            self._file(i).unlink(missing_ok=True)
        if self._tmp is not None:
            self._tmp.cleanup()

    def __enter__(self) -> TrialStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
