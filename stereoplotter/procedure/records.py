"""Typed procedure state: tolerance checks, stage records, control heights, sheet readings.

Every array field has the run's shape: (T,) for a vectorised run of T trials, () for a single
procedure (or a per-trial oracle), so the same records serve both.

:class:`SheetReadings` is the operator's view of the setup sheet's printed readings
(``SetupSheet.readings``, built by :mod:`stereoplotter.setup.readings`): the procedure takes
every target reading from it, zero reading (MO) + the printed signed value, and computes none.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.errors import StereoplotterError

if TYPE_CHECKING:  # pragma: no cover
    from stereoplotter.setup.sheet import SetupSheet

__all__ = [
    "Check",
    "ControlHeight",
    "Remedy",
    "SheetPose",
    "SheetReading",
    "SheetReadings",
    "StageRecord",
]


@dataclass(frozen=True, slots=True)
class Check:
    """A tolerance check of the procedure: |residual| ≤ tolerance, per trial.

    Attributes
    ----------
    name : str
        As in the transcript and the summary, e.g. ``"stage 1: |L − L′|"``.
    residual : ndarray, shape (T,) or ()
        The last residual judged (the worst of its points). [unit]
    tolerance : ndarray or None
        None for a check without a tolerance (reported only). [unit]
    passed : ndarray of bool or None
        |residual| ≤ tolerance; None without a tolerance.
    iterations : ndarray of int or None
        Passes of the check's loop (bounded by ``OperatorModel.max_iterations``); None for a
        single look.
    unit : str
        "mm" (model or table) or "m" (ground heights).
    """

    name: str
    residual: NDArray[np.float64]
    tolerance: NDArray[np.float64] | None
    passed: NDArray[np.bool_] | None
    iterations: NDArray[np.int64] | None
    unit: str = "mm"


@dataclass(frozen=True, slots=True)
class Remedy:
    """What the operator did after a check failed (``--practice operator``), per trial.

    Method-neutral: the setup-data method and the conventional method record their remedies
    the same way (the transcript logs each act with ``remedy=`` its name).

    Attributes
    ----------
    name : str
        E.g. ``"stage 2: refine the relative orientation"``.
    check : str
        The check it answers (a key of the run's checks).
    applied : ndarray of bool, shape (T,) or ()
        The check had failed, so the remedy was applied.
    rounds : ndarray of int
        Rounds of the remedy used (0 where not applied), bounded by
        ``OperatorModel.max_iterations``.
    passed : ndarray of bool
        The check passed after the remedy (equal to the check's final ``passed``).
    """

    name: str
    check: str
    applied: NDArray[np.bool_]
    rounds: NDArray[np.int64]
    passed: NDArray[np.bool_]


@dataclass(frozen=True, slots=True)
class StageRecord:
    """Iterations a stage (or a loop within it) used, per trial.

    Attributes
    ----------
    stage : str
        "1" … "5", "2/kappa", "C1" … (the transcript's stage names).
    iterations : ndarray of int, shape (T,) or ()
    """

    stage: str
    iterations: NDArray[np.int64]


@dataclass(frozen=True, slots=True)
class ControlHeight:
    """A height control point of stage 3 with the sheet's reading for it.

    Attributes
    ----------
    id : str
    model_height_mm : float
        Z_i of (6.6) on the sheet. [mm]
    ground_m : ndarray, shape (3,)
        The point in the scenario's local frame (its ground truth). [m]
    """

    id: str
    model_height_mm: float
    ground_m: NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class SheetPose:
    """The sheet's placement on the coordinatograph table (stages 4–5): a rotation by
    ``angle`` about the pin, sheet point ``pivot_sheet`` lying at table point ``pivot_table``.

    Attributes
    ----------
    angle : ndarray, shape (T,) or () [rad]
    pivot_sheet, pivot_table : ndarray, shape (T, 2) or (2,) [mm]
    """

    angle: NDArray[np.float64]
    pivot_sheet: NDArray[np.float64]
    pivot_table: NDArray[np.float64]

    def table_of(self, sheet_point_mm: ArrayLike) -> NDArray[np.float64]:
        """Table position of a sheet point (sheet frame = ideal table frame). [mm]"""
        c, s = np.cos(self.angle), np.sin(self.angle)
        d = np.asarray(sheet_point_mm, float) - self.pivot_sheet
        x = c * d[..., 0] - s * d[..., 1]
        y = s * d[..., 0] + c * d[..., 1]
        return self.pivot_table + np.stack([x, y], axis=-1)

    def to_dict(self) -> dict[str, Any]:
        """The fields by name (reports)."""
        return {
            "angle": self.angle,
            "pivot_sheet": self.pivot_sheet,
            "pivot_table": self.pivot_table,
        }


@dataclass(frozen=True, slots=True)
class SheetReading:
    """One printed reading of the setup sheet: ``zero_reading`` (an MO, or "" for an absolute
    value) + ``value`` (signed).

    Attributes
    ----------
    name : str
        The sheet's name of the reading, e.g. ``"O_Y3,л"``, ``"corner 4: O_X"``.
    zero_reading : str
        ``"MO_Y"``, ``"MO_X,п"``, ``"MO_bx"``, ``"MO_dx"``, … or "".
    value : float
        The printed signed value. [unit]
    unit : str
    stage : int
    """

    name: str
    zero_reading: str
    value: float
    unit: str
    stage: int

    def target(self, zero: ArrayLike | None = None) -> NDArray[np.float64] | float:
        """The reading to set: zero + value (``zero`` required iff the reading has an MO)."""
        if not self.zero_reading:
            if zero is not None:
                raise StereoplotterError(f"{self.name} is an absolute reading (no zero reading)")
            return self.value
        if zero is None:
            raise StereoplotterError(f"{self.name} needs its zero reading {self.zero_reading}")
        reading: NDArray[np.float64] | float = cast(Any, zero) + self.value
        return reading


class SheetReadings(Mapping[str, SheetReading]):
    """The sheet's printed readings by name (``SetupSheet.readings``).

    Examples
    --------
    >>> rows = ({"stage": 1, "reading": "O_bx", "zero_reading": "MO_bx", "value": 2.5,
    ...          "unit": "mm"},)
    >>> r = SheetReadings(rows)["O_bx"]
    >>> r.target(0.0), r.zero_reading
    (2.5, 'MO_bx')
    """

    def __init__(self, rows: tuple[dict[str, Any], ...]):
        self._rows: dict[str, SheetReading] = {}
        for row in rows:
            reading = SheetReading(
                str(row["reading"]),
                str(row["zero_reading"]),
                float(row["value"]),
                str(row["unit"]),
                int(row["stage"]),
            )
            if reading.name in self._rows:
                raise StereoplotterError(f"setup sheet: reading {reading.name!r} printed twice")
            self._rows[reading.name] = reading

    @classmethod
    def of(cls, sheet: SetupSheet) -> SheetReadings:
        """The readings of ``sheet``."""
        return cls(sheet.readings)

    def __getitem__(self, name: str) -> SheetReading:
        try:
            return self._rows[name]
        except KeyError:
            raise StereoplotterError(
                f"setup sheet: no reading {name!r}; readings: {', '.join(self._rows)}"
            ) from None

    def __iter__(self) -> Iterator[str]:
        return iter(self._rows)

    def __len__(self) -> int:
        return len(self._rows)
