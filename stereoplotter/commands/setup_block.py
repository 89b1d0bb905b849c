"""``stereoplotter setup BLOCK``: block mode, one sheet per model of a block file.

Load the block file (:mod:`stereoplotter.io.block_file`) → compute every model in one call
(:func:`stereoplotter.setup.block.compute_block`) → render each model's ``sheet.yaml`` and
``block.csv`` (:func:`stereoplotter.report.block.block_files`) → write. Part of the ``setup``
command (:mod:`stereoplotter.commands.setup`); imported by it only for a block file, so the
library is imported here at the top.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np

from stereoplotter.errors import StereoplotterError
from stereoplotter.io.atomic_write import write_files
from stereoplotter.io.block_file import load_block
from stereoplotter.report.block import block_files, model_sheet
from stereoplotter.report.plain_data import json_text
from stereoplotter.setup.block import BlockResult, compute_block
from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = ["run", "run_block", "write_block"]


def run_block(
    path: str | os.PathLike[str],
    spec: InstrumentSpec,
    output_dir: str | os.PathLike[str] | None = None,
    book_sign: bool = False,
) -> BlockResult:
    """Load a block file, compute every model (:func:`compute_block`) and optionally write it.

    Parameters
    ----------
    path : str or path-like
        The block YAML (:func:`load_block`).
    spec : InstrumentSpec
    output_dir : str or path-like, optional
        Where to write ``<model>/sheet.yaml`` and ``block.csv`` (:func:`write_block`).
    book_sign : bool
        (6.4) with the printed sign.

    Returns
    -------
    BlockResult

    Notes
    -----
    Eqs. (6.1)–(6.6) of [1]_ via :func:`compute_block`; (6.7)/(6.8) are not part of block mode.
    """
    block = load_block(path)
    result = compute_block(
        block.camera.focal_length_mm,
        block.camera.fiducial_array_mm(),
        block.centre_left_m,
        block.angles_left,
        block.centre_right_m,
        block.angles_right,
        block.terrain_m,
        spec,
        block.map_scale_denominator,
        principal_point_mm=block.camera.principal_point_mm,
        height_points_m=block.height_points_m,
        horizontal_scale_denominator=block.horizontal_scale_denominator,
        vertical_scale_denominator=block.vertical_scale_denominator,
        book_sign=book_sign,
        model_names=block.model_names,
        height_point_ids=block.height_point_ids,
        name=block.name,
    )
    if output_dir is not None:
        write_block(result, output_dir)
    return result


def write_block(result: BlockResult, output_dir: str | os.PathLike[str]) -> None:
    """Write ``<output_dir>/<model>/sheet.yaml`` for every model and ``<output_dir>/block.csv``
    (:func:`~stereoplotter.report.block.block_files`), each whole or not at all; the folder is
    created if needed."""
    write_files(output_dir, block_files(result))


def run(args: argparse.Namespace, spec: InstrumentSpec) -> int:
    """``setup`` on a block file: one sheet per model."""
    if args.horizontal_scale is not None or args.vertical_scale is not None or args.seed:
        raise StereoplotterError(
            f"{args.scenario}: a block file sets its scales in its own 'scales' field; "
            "--horizontal-scale, --vertical-scale and --seed apply to single pairs only"
        )
    out = (
        None if (args.json and args.output is None) else Path(args.output or "stereoplotter-setup")
    )
    result = run_block(args.scenario, spec, out, book_sign=args.book_sign)
    sheets = [model_sheet(result, i) for i in range(len(result))]
    if args.json:
        sys.stdout.write(
            json_text({"block": result.name, "instrument": spec.key, "models": sheets})
        )
        return 0
    accepted = int(np.sum(result.accepted))
    lines = [f"block {result.name} on {spec.title}: {accepted} of {len(result)} models set up"]
    for i, sheet in enumerate(sheets):
        if result.accepted[i]:
            lines.append(
                f"  {result.model_names[i]}: M_г = 1:{sheet['scale_horizontal']}, "
                f"M_в = 1:{sheet['scale_vertical']}, n_л = {sheet['n_left']:.5f}, "
                f"n_п = {sheet['n_right']:.5f}"
            )
        else:
            lines.append(f"  {result.model_names[i]}: REFUSED: {result.reason(i)}")
    lines.append(f"written: <model>/sheet.yaml and block.csv in {out}")
    sys.stdout.write("\n".join(lines) + "\n")
    return 0
