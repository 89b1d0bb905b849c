"""Reading a trainee's own setup sheet (``stereoplotter check-sheet``).

The trainee sheet has the layout of the program's ``sheet.yaml``
(:func:`stereoplotter.report.sheet.setup_dict`); every value may be missing (left out or
``null``): the check reports it, one line a value. The keys the program writes for information
only (annotations, scale choice, …) are accepted and ignored; any other key is refused with a
"did you mean". The values are flattened to the keys of :mod:`stereoplotter.setup.sheet_check`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pydantic import Field

from stereoplotter.io.validation import FileModel, number, text, validate
from stereoplotter.io.yaml_input import load_yaml_mapping

__all__ = ["TraineeSheet", "load_trainee_sheet"]

Num = number(description="a value the trainee computed") | None
Table = dict[str, Num]


class _Reading(FileModel):
    reading: text
    value: Num = None
    stage: Any = None
    step: Any = None
    zero_reading: Any = None
    unit: Any = None
    equation: Any = None
    formula: Any = None
    tolerance: Any = None
    note: Any = None
    book_form: Any = None
    zero_reading_definition: Any = None


class _Corner(FileModel):
    x: Num = None
    y: Num = None
    position: Any = None
    x_book_form: Any = None
    y_book_form: Any = None


class TraineeSheet(FileModel):
    """A trainee's setup sheet: the layout of ``sheet.yaml``, every value optional."""

    scale_horizontal: Num = None
    scale_vertical: Num = None
    f_instrument_mm: Num = None
    transformation_coefficient: Num = None
    n_left: Num = None
    n_right: Num = None
    base_mm: Table = Field(default_factory=dict)
    fiducials_transformed_mm: dict[str, Table] = Field(default_factory=dict)
    L_mm: Table = Field(default_factory=dict)
    decentrations_mm: dict[str, Table] = Field(default_factory=dict)
    control_heights_model_mm: Table = Field(default_factory=dict)
    sheet_corners_mm: dict[str, _Corner] = Field(default_factory=dict)
    readings: list[_Reading] = Field(default_factory=list)
    # written by the program for information; not compared
    scenario: Any = None
    block: Any = None
    model: Any = None
    instrument: Any = None
    instrument_title: Any = None
    status: Any = None
    reason: Any = None
    reason_code: Any = None
    scale_map: Any = None
    focal_length_corrected_mm: Any = None
    focal_length_corrected_per_photo_mm: Any = None
    fiducials_rigorous_mm: Any = None
    correction_inclinations_deg: Any = None
    instrument_settings: Any = None
    angles_deg: Any = None
    similarity: Any = None
    tolerances: Any = None
    frame: Any = None
    exterior_orientation: Any = None
    depth_range_used_mm: Any = None
    scale_choice: Any = None
    options: Any = None
    assumed: Any = None
    annotations: Any = None
    not_in_block_mode: Any = None
    seed: Any = None

    def flat(self) -> dict[str, float | None]:
        """The values under the keys of :mod:`stereoplotter.setup.sheet_check`."""
        out: dict[str, float | None] = {}
        for key in (
            "scale_horizontal",
            "scale_vertical",
            "f_instrument_mm",
            "transformation_coefficient",
            "n_left",
            "n_right",
        ):
            out[key] = getattr(self, key)
        for section in ("base_mm", "L_mm", "control_heights_model_mm"):
            for k, v in getattr(self, section).items():
                out[f"{section}.{k}"] = v
        for section in ("fiducials_transformed_mm", "decentrations_mm"):
            for photo, table in getattr(self, section).items():
                for k, v in table.items():
                    out[f"{section}.{photo}.{k}"] = v
        for corner, c in self.sheet_corners_mm.items():
            out[f"sheet_corners_mm.{corner}.x"] = c.x
            out[f"sheet_corners_mm.{corner}.y"] = c.y
        for r in self.readings:
            out[f"readings.{r.reading}"] = r.value
        return out


def load_trainee_sheet(path: str | Path) -> dict[str, float | None]:
    """Read and validate a trainee sheet; its values flattened (None: missing).

    Raises
    ------
    ConfigError
        One line naming the file, the field and what was expected.
    """
    data, source = load_yaml_mapping(path)
    return validate(TraineeSheet, data, source).flat()
