"""SK-42 map-sheet nomenclature (разграфка и номенклатура топографических карт) → sheet frame.

The Soviet (and Russian) topographic map series divides the 1:1 000 000 sheets (4° of latitude,
6° of longitude; a letter A–V for the latitude band from the equator and a column number 1–60
from 180°) into the larger scales:

=========== ================================ ============== =====================
scale       nomenclature example             sheet size     parts of the parent
=========== ================================ ============== =====================
1:1 000 000 ``N-35``                         4° × 6°        —
1:500 000   ``N-35-Б``                       2° × 3°        4 (А Б В Г)
1:200 000   ``N-35-XXIV``                    40′ × 1°       36 (I … XXXVI)
1:100 000   ``N-35-14``                      20′ × 30′      144 (1 … 144)
1:50 000    ``N-35-14-А``                    10′ × 15′      4 (А Б В Г)
1:25 000    ``N-35-14-А-б``                  5′ × 7′30″     4 (а б в г)
1:10 000    ``N-35-14-А-б-3``                2′30″ × 3′45″  4 (1 2 3 4)
1:5 000     ``N-35-14-(37)``                 1′15″ × 1′52.5″ 256 of the 1:100 000
1:2 000     ``N-35-14-(37-д)``               25″ × 37.5″    9 of the 1:5 000 (а … и)
=========== ================================ ============== =====================

Parts are numbered row by row from the north-west corner; the four quarters А Б В Г (а б в г,
1 2 3 4) are NW, NE, SW, SE. Latin transliterations are accepted: A B V G for А Б В Г (and the
lower-case a b v g), and a b v g d e zh z i for а … и. Southern-hemisphere sheets are not supported.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from fractions import Fraction

from stereoplotter.errors import StereoplotterError

__all__ = ["SheetBounds", "sheet_bounds"]

_BAND_LETTERS = "ABCDEFGHIJKLMNOPQRSTUV"
_QUARTERS_UPPER = {"А": 0, "Б": 1, "В": 2, "Г": 3, "A": 0, "B": 1, "V": 2, "G": 3}
_QUARTERS_LOWER = {"а": 0, "б": 1, "в": 2, "г": 3, "a": 0, "b": 1, "v": 2, "g": 3}
_NINTHS = {c: i for i, c in enumerate("абвгдежзи")}
_NINTHS.update({c: i for i, c in enumerate(["a", "b", "v", "g", "d", "e", "zh", "z", "i"])})
_ROMAN = {
    "I": 1,
    "V": 5,
    "X": 10,
    "L": 50,
}


@dataclass(frozen=True, slots=True)
class SheetBounds:
    """Geographic frame of a map sheet on the Krasovsky ellipsoid (SK-42).

    Attributes
    ----------
    nomenclature : str
    scale_denominator : int
    south_deg, north_deg, west_deg, east_deg : float
        Latitude and longitude of the frame. [deg]
    zone : int
        The 6° Gauss–Krüger zone of the 1:1 000 000 column.
    """

    nomenclature: str
    scale_denominator: int
    south_deg: float
    north_deg: float
    west_deg: float
    east_deg: float
    zone: int

    def corners_deg(self) -> list[tuple[float, float]]:
        """Corners (latitude, longitude) NW, NE, SE, SW. [deg]"""
        return [
            (self.north_deg, self.west_deg),
            (self.north_deg, self.east_deg),
            (self.south_deg, self.east_deg),
            (self.south_deg, self.west_deg),
        ]


def _roman(text: str) -> int | None:
    if not re.fullmatch(r"[IVXL]+", text):
        return None
    total, previous = 0, 0
    for ch in reversed(text):
        value = _ROMAN[ch]
        total += -value if value < previous else value
        previous = max(previous, value)
    return total


def _part(south, west, height, width, rows, cols, index):
    # Exact rational arithmetic, so that neighbouring sheets share their edges to the last bit.
    row, col = divmod(index, cols)
    h, w = Fraction(height) / rows, Fraction(width) / cols
    north = south + height
    return north - (row + 1) * h, west + col * w, h, w


def _fail(nomenclature: str, why: str) -> StereoplotterError:
    return StereoplotterError(
        f"map sheet nomenclature {nomenclature!r}: {why}; expected e.g. 'N-35-14' (1:100 000), "
        "'N-35-14-А-б-3' (1:10 000), 'N-35-14-(37)' (1:5 000) or 'N-35-14-(37-д)' (1:2 000)"
    )


def sheet_bounds(nomenclature: str) -> SheetBounds:
    """Geographic frame of an SK-42 map sheet from its nomenclature.

    Parameters
    ----------
    nomenclature : str
        For example ``"N-35-14-А-б-3"``.

    Returns
    -------
    SheetBounds

    Raises
    ------
    StereoplotterError
        An unknown or malformed nomenclature, naming the faulty part.

    Examples
    --------
    >>> b = sheet_bounds("N-35-14-А-б-3")
    >>> b.scale_denominator, b.zone
    (10000, 5)
    >>> round(b.south_deg * 60, 3), round(b.west_deg * 60, 3)  # 55°35′, 24°37′30″
    (3335.0, 1477.5)
    """
    text = nomenclature.strip()
    parts = re.split(r"-(?![^(]*\))", text)
    frame, zone = _million_sheet(nomenclature, parts)
    rest = parts[2:]
    if rest:
        _second_part(frame, rest)
    if rest and rest[0].startswith("("):
        _plan_parts(frame, rest)
    if rest and frame.scale == 100_000:
        frame.quarter(rest.pop(0), _QUARTERS_UPPER, 50_000)
    if rest and frame.scale == 50_000:
        frame.quarter(rest.pop(0), _QUARTERS_LOWER, 25_000)
    if rest and frame.scale == 25_000:
        part = rest.pop(0)
        if part not in {"1", "2", "3", "4"}:
            raise _fail(nomenclature, f"1:10 000 part {part!r} is not one of 1/2/3/4")
        frame.divide(2, 2, int(part) - 1, 10_000)
    if rest:
        raise _fail(nomenclature, f"unexpected part {rest[0]!r} after the 1:{frame.scale} sheet")
    south, west = frame.south, frame.west
    north, east = south + frame.height, west + frame.width
    return SheetBounds(
        text, frame.scale, float(south), float(north), float(west), float(east), zone
    )


@dataclass
class _Frame:
    """The sheet being subdivided: exact south, west, height, width [°] and its scale."""

    nomenclature: str
    south: Fraction
    west: Fraction
    height: Fraction
    width: Fraction
    scale: int

    def divide(self, rows: int, cols: int, index: int, new_scale: int) -> None:
        self.south, self.west, self.height, self.width = _part(
            self.south, self.west, self.height, self.width, rows, cols, index
        )
        self.scale = new_scale

    def quarter(self, part: str, table: dict[str, int], new_scale: int) -> None:
        if part not in table:
            raise _fail(
                self.nomenclature,
                f"{part!r} is not one of {'/'.join(table)} for 1:{new_scale:,}".replace(",", " "),
            )
        self.divide(2, 2, table[part], new_scale)


def _million_sheet(nomenclature: str, parts: list[str]) -> tuple[_Frame, int]:
    """The 1:1 000 000 sheet of the band letter and column, and its 6° zone."""
    if len(parts) < 2:
        raise _fail(nomenclature, "too few parts")
    band = parts[0].upper()
    if len(band) != 1 or band not in _BAND_LETTERS:
        raise _fail(nomenclature, f"latitude band {parts[0]!r} is not a letter A–V")
    try:
        column = int(parts[1])
    except ValueError:
        raise _fail(nomenclature, f"column {parts[1]!r} is not a number 1–60") from None
    if not 1 <= column <= 60:
        raise _fail(nomenclature, f"column {column} is outside 1–60")
    south = Fraction(4 * _BAND_LETTERS.index(band))
    west = Fraction(6 * (column - 31))
    zone = column - 30 if column > 30 else column + 30
    return _Frame(nomenclature, south, west, Fraction(4), Fraction(6), 1_000_000), zone


def _second_part(frame: _Frame, rest: list[str]) -> None:
    """The part after the column: 1:500 000 (А–Г alone), 1:200 000 (I–XXXVI alone) or
    1:100 000 (1–144); consumed from ``rest``."""
    nomenclature = frame.nomenclature
    first = rest.pop(0)
    roman = _roman(first)
    if first in _QUARTERS_UPPER and not rest:
        frame.quarter(first, _QUARTERS_UPPER, 500_000)
    elif roman is not None and not rest:
        if not 1 <= roman <= 36:
            raise _fail(nomenclature, f"1:200 000 part {first} is outside I–XXXVI")
        frame.divide(6, 6, roman - 1, 200_000)
    else:
        if not first.isdigit() or not 1 <= int(first) <= 144:
            raise _fail(nomenclature, f"1:100 000 part {first!r} is not a number 1–144")
        frame.divide(12, 12, int(first) - 1, 100_000)


def _plan_parts(frame: _Frame, rest: list[str]) -> None:
    """The last part "(n)" (1:5 000) or "(n-x)" (1:2 000); consumed from ``rest``."""
    nomenclature = frame.nomenclature
    m = re.fullmatch(r"\((\d+)(?:-(\w+))?\)", rest.pop(0))
    if m is None or not 1 <= int(m.group(1)) <= 256 or rest:
        raise _fail(
            nomenclature,
            "1:5 000 part must be '(n)' with n in 1–256, or '(n-x)' for 1:2 000, and come last",
        )
    frame.divide(16, 16, int(m.group(1)) - 1, 5_000)
    if m.group(2) is not None:
        if m.group(2) not in _NINTHS:
            raise _fail(nomenclature, f"1:2 000 part {m.group(2)!r} is not one of а–и")
        frame.divide(3, 3, _NINTHS[m.group(2)], 2_000)


def zone_of_longitude(longitude_deg: float) -> int:
    """The 6° Gauss–Krüger zone number (1–60) of an eastern longitude. [deg]"""
    return math.floor(longitude_deg / 6.0) % 60 + 1
