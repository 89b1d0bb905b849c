"""The results store of a study: an xarray Dataset in a Zarr folder, written cell by cell.

:func:`open_store` creates the store from the study's empty Dataset (every value NaN, every
cell's ``status`` 0) or reopens an existing one after checking it holds the same study (the
SHA-256 of the study document, attribute ``study_sha256``). :meth:`StudyStore.write_cell`
writes one finished cell's values and then its ``status``: a cell whose status is not 0 is
complete on disk, so a killed run resumes by skipping those cells (:meth:`StudyStore.done`).

Unlike the other outputs, the store is written piecewise on purpose (a study may run for hours);
a reader sees the finished cells, the others NaN with status 0.

Zarr format 2: its fixed-width text arrays (check names, refusal messages) have a stable
specification; format 3 has none for them yet.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr
import zarr

from stereoplotter.errors import StereoplotterError

__all__ = ["CELLS_PER_CHUNK", "StudyStore", "open_results", "open_store"]

#: Cells per Zarr chunk along ``cell`` (a write rewrites one chunk: small enough to be cheap,
#: large enough that a 10⁴-cell study has few files per variable).
CELLS_PER_CHUNK = 64


class StudyStore:
    """An open results store (see the module docstring)."""

    def __init__(self, path: Path):
        self.path = path
        self._group = zarr.open_group(str(path), mode="r+")

    def done(self) -> set[int]:
        """The cells already written (status done or refused)."""
        status = np.asarray(self._group["status"][:])
        return {int(i) for i in np.flatnonzero(status != 0)}

    def write_cell(self, cell: int, values: dict[str, Any]) -> None:
        """Write one cell's values, its status last."""
        for name, value in values.items():
            if name != "status":
                self._group[name][cell, ...] = value
        self._group["status"][cell] = values["status"]


def open_store(
    path: str | os.PathLike[str], empty: xr.Dataset, fingerprint: str, study: dict
) -> StudyStore:
    """Create the store from ``empty`` or reopen the one at ``path`` (same study only)."""
    target = Path(path)
    if target.exists():
        try:
            attrs = dict(zarr.open_group(str(target), mode="r").attrs)
        except Exception as exc:  # any reason it is no Zarr group: one line
            raise StereoplotterError(
                f"{target}: expected a study results store (Zarr), found {type(exc).__name__}"
            ) from None
        if attrs.get("study_sha256") != fingerprint:
            raise StereoplotterError(
                f"{target}: expected the results of this study, found another study's "
                f"({attrs.get('study', '?')}); write to a new folder or delete it"
            )
        return StudyStore(target)
    ds = empty.copy()
    ds.attrs.update(
        study_sha256=fingerprint,
        study_file=json.dumps(study, ensure_ascii=False, sort_keys=True, default=str),
    )
    encoding = {
        name: {"chunks": (min(CELLS_PER_CHUNK, ds.sizes["cell"]), *ds[name].shape[1:])}
        for name in ds.data_vars
    }
    tmp = target.with_name(target.name + ".partial")
    if tmp.exists():
        shutil.rmtree(tmp)
    ds.to_zarr(str(tmp), mode="w", encoding=encoding, consolidated=True, zarr_format=2)
    os.replace(tmp, target)
    return StudyStore(target)


def open_results(path: str | os.PathLike[str]) -> xr.Dataset:
    """The Dataset of a results store, loaded into memory."""
    target = Path(path)
    if not (target / ".zgroup").exists():
        raise StereoplotterError(
            f"{target}: expected a study results store (Zarr), found no .zgroup"
        )
    with xr.open_zarr(str(target), consolidated=True) as ds:
        return ds.load()
