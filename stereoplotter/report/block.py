"""Block mode's files: one sheet per model plus ``block.csv``."""

from __future__ import annotations

import csv
import io
from typing import Any

from stereoplotter.io.yaml_output import yaml_text
from stereoplotter.report.sheet import setup_dict
from stereoplotter.setup.block import BlockResult

__all__ = ["block_files", "model_sheet"]


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


def block_files(result: BlockResult) -> dict[str, bytes]:
    """``<model>/sheet.yaml`` for every model and ``block.csv``, rendered in memory.

    Notes
    -----
    The sheet keys are those of the single-pair ``--json`` output where they exist
    (:func:`model_sheet`); values of Eqs. (6.1)–(6.6) of [1]_.
    """
    files: dict[str, bytes] = {}
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(_CSV_OUT)
    for i, model in enumerate(result.model_names):
        sheet = model_sheet(result, i)
        text = yaml_text(sheet, width=100, c_emitter=True)
        files[f"{model}/sheet.yaml"] = text.encode("utf-8")
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
    files["block.csv"] = buffer.getvalue().encode("utf-8")
    return files
