"""Block mode at the edge: run a block file and write one sheet per model plus ``block.csv``."""

from __future__ import annotations

import csv
import io
import os
from pathlib import Path
from typing import Any

import yaml

from stereoplotter.io.block_file import load_block
from stereoplotter.io.yaml_files import atomic_write_text
from stereoplotter.report.sheet import setup_dict
from stereoplotter.setup.block import BlockResult, compute_block
from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = ["model_sheet", "run_block", "write_block"]

# --- running a block file and writing the sheets ---------------------------------------------


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


def model_sheet(result: BlockResult, i: int) -> dict[str, Any]:
    """The sheet of model ``i`` as plain data: :func:`stereoplotter.report.sheet.setup_dict`,
    the keys of the single-pair ``--json`` (None where a block model has no value; the key
    ``not_in_block_mode`` says why). ``status`` is "ok" or "refused", ``reason`` the refusal."""
    return setup_dict(result, i)


_CSV_OUT = (
    "model", "status", "reason_code", "scale_horizontal", "scale_vertical", "f_instrument_mm",
    "transformation_coefficient", "n_left", "n_right", "bx_mm", "by_mm", "bz_mm",
    "left_x2_mm", "left_y3_mm", "left_y4_mm", "right_x1_mm", "right_y3_mm", "right_y4_mm",
    "L_left_mm", "L_right_mm", "frame_rotation_deg", "reason",
)  # fmt: skip


def write_block(result: BlockResult, output_dir: str | os.PathLike[str]) -> None:
    """Write ``<output_dir>/<model>/sheet.yaml`` for every model and ``<output_dir>/block.csv``.

    Parameters
    ----------
    result : BlockResult
    output_dir : str or path-like
        Created if needed. Each file is written whole or not at all.

    Notes
    -----
    The sheet keys are those of the single-pair ``--json`` output where they exist
    (:func:`model_sheet`); values of Eqs. (6.1)–(6.6) of [1]_.
    """
    out = Path(output_dir)
    dumper = getattr(yaml, "CSafeDumper", yaml.SafeDumper)
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(_CSV_OUT)
    for i, model in enumerate(result.model_names):
        sheet = model_sheet(result, i)
        text = yaml.dump(sheet, Dumper=dumper, sort_keys=False, allow_unicode=True, width=100)
        atomic_write_text(out / model / "sheet.yaml", text)
        fid = sheet["fiducials_transformed_mm"]
        writer.writerow(
            [
                model, sheet["status"], sheet["reason_code"], sheet["scale_horizontal"],
                sheet["scale_vertical"], sheet["f_instrument_mm"],
                sheet["transformation_coefficient"], sheet["n_left"], sheet["n_right"],
                *sheet["base_mm"].values(), *fid["left"].values(), *fid["right"].values(),
                sheet["L_mm"]["left"], sheet["L_mm"]["right"], sheet["frame"]["rotation_deg"],
                sheet["reason"],
            ]
        )  # fmt: skip
    atomic_write_text(out / "block.csv", buffer.getvalue())

