"""The records of a setup sheet: its options, the per-photo settings and the sheet itself.

Data only, shared by :mod:`.sheet` (which fills them) and :mod:`.readings` (which reads them), so
that neither imports the other's module for its types.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from stereoplotter.errors import StereoplotterError
from stereoplotter.geometry.similarity import SimilarityFit
from stereoplotter.setup.scale_choice import ScaleCandidate
from stereoplotter.setup.table24 import BlockResult

__all__ = ["PhotoSetup", "ScaleCandidate", "SetupOptions", "SetupRefusal", "SetupSheet"]


class SetupRefusal(StereoplotterError):
    """The instrument cannot take the scenario (no feasible scale pair, a setting beyond a stop)."""


@dataclass(frozen=True, slots=True)
class SetupOptions:
    """Choices behind the sheet; the defaults are the decisions of ``docs/setup-data.md``.

    Attributes
    ----------
    book_sign_n_right : bool
        Use the printed sign of (6.4) (n_п < n_л for a higher right station).
    horizontal_scale_denominator, vertical_scale_denominator : int or None
        Force M_г and/or M_в instead of choosing them (still range-checked).
    bz_scale_sense : int
        +1 (default): the b_z scale grows when the right pivot rises, so (6.11) reads
        O′_bz = O_bz + Δb_z and (6.14) O_bz = MO_bz + b_z′. −1: a scale counting the other way,
        which makes the printed minus of (6.11) right and turns (6.14) into MO_bz − b_z′.
    """

    book_sign_n_right: bool = False
    horizontal_scale_denominator: int | None = None
    vertical_scale_denominator: int | None = None
    bz_scale_sense: int = 1

    def __post_init__(self) -> None:
        if self.bz_scale_sense not in (1, -1):
            raise StereoplotterError(
                f"bz_scale_sense: expected +1 or -1, found {self.bz_scale_sense!r}"
            )


@dataclass(frozen=True, slots=True)
class PhotoSetup:
    """Per-photo settings of the sheet (angles in the instrument frame)."""

    name: str
    alpha: float
    omega: float
    kappa: float
    marks_measured_mm: dict[str, tuple[float, float]]
    transformed_book_mm: dict[str, float]
    transformed_rigorous_mm: dict[str, tuple[float, float]]
    mark_span_mm: float
    decentration_mm: tuple[float, float]
    correction_inclination: tuple[float, float]
    n: float

    @property
    def mark_span_at_zero_mm(self) -> float:
        """L⁰ = n·(y₃ − y₄) of the measured marks: the span L′ of marks 3–4 the counters show
        with the correction units at zero (stage 1), which the stage-1 check compares with
        (decision D5: (6.5)'s L, of the transformed y⁰, holds once the units are set; compared
        with it at zero units the check would bias n by tan²ω(1 + l²/f′²)). [mm]"""
        return self.n * (self.marks_measured_mm["3"][1] - self.marks_measured_mm["4"][1])


@dataclass(frozen=True, slots=True)
class SetupSheet:
    """The computed setup sheet (Table 24 plus the readings of the five stages).

    ``table24`` is the block of one the sheet was computed from
    (:func:`stereoplotter.setup.table24.compute_table24`); the serialiser reads it.
    """

    scenario: str
    instrument: str
    instrument_title: str
    frame_rotation: float
    frame_origin_m: tuple[float, float, float]
    focal_length_corrected_mm: float
    focal_length_corrected_per_photo_mm: tuple[float, ...]
    map_scale_denominator: int | None
    horizontal_scale_denominator: int
    vertical_scale_denominator: int
    f_instrument_mm: float
    transformation_coefficient: float
    n_left: float
    n_right: float
    base_mm: tuple[float, float, float]
    photos: tuple[PhotoSetup, ...]
    control_heights: tuple[dict[str, Any], ...]
    similarity: SimilarityFit | None
    similarity_point_ids: tuple[str, ...]
    corners: tuple[dict[str, Any], ...]
    readings: tuple[dict[str, Any], ...]
    tolerances: dict[str, float]
    assumed: dict[str, tuple[str, ...]]
    options: SetupOptions = field(default_factory=SetupOptions)
    depth_range_used_mm: tuple[float, float] = (math.nan, math.nan)
    exterior_sources: tuple[str, ...] = ()
    points_model_mm: tuple[dict[str, Any], ...] = ()
    table24: BlockResult | None = field(default=None, repr=False)
    #: The instrument's ``principle`` (selects its correction mechanism and control names).
    instrument_principle: str = ""
