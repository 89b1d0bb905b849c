"""One row of the verification table as data (:class:`Entry`), its procedure measure
(:class:`ProcedureMeasure`), the geometry the rows are computed at (:class:`Setting`) and the
declaration of rows (:class:`DeclaredRows`), shared by the row modules ``rows_*``.

A row is declared once: a function of :class:`Setting` that returns its :class:`Entry` (equation,
printed value, book and rigorous formulas, linear model, verdict rule, procedure measure),
decorated by its module's :class:`DeclaredRows`; the table concatenates the modules' lists.

Book geometry (§27): f = 70 mm, l = 85 mm, n = 1.42 (SC-1), c = 70 mm; 60 %: p = 70, a = 0;
80 %: p = 35, a = 35.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from typing import NamedTuple

from stereoplotter.accuracy import chapter5 as c5
from stereoplotter.accuracy import setup_accuracy as sa
from stereoplotter.verification import linear_mc as mc

__all__ = [
    "BOOK",
    "CONVENTION_NOTE",
    "GENERIC_SIGMAS",
    "RULE",
    "DeclaredRows",
    "Entry",
    "ProcedureMeasure",
    "Setting",
    "both_photos",
]

BOOK = {
    "f": 70.0,
    "l": 85.0,
    "n": 1.42,
    "c": 70.0,
    "p60": 70.0,
    "a60": 0.0,
    "p80": 35.0,
    "a80": 35.0,
}
#: Verdict of a row decided from its numbers (:mod:`stereoplotter.verification.verdicts`).
RULE = "rule"
#: Note of a row whose book and rigorous values differ, off the book's geometry, by the reading
#: of the control heights' error (docs/errata.md (5.17)/(5.20)).
CONVENTION_NOTE = (
    "convention: two readings of the control heights' error, the book's (p/f)·m_p and the "
    "rigorous m_p of (5.42) (k·m_p without the factor p/f); they agree only at p = f "
    "(docs/errata.md (5.17)/(5.20))"
)
#: σ's of the setup elements for (6.28)–(6.30) (the book gives the formula, not the σ's).
GENERIC_SIGMAS = {
    "base_x": 0.005,
    "alpha": 1.0e-4,
    "omega": 1.5e-4,
    "kappa": 1.0e-4,
    "base_z": 0.02,
}


class ProcedureMeasure(NamedTuple):
    """What the procedure Monte Carlo measures for a row: the run of configuration ``config``
    (``verification.table.PROCEDURE_CONFIGS``) at the overlap ``slot`` ("60" or "80"), its
    reading ``field`` (a field of the setup run, "parallax", "levelled" or "observed"; None: the
    conventional run's statistic) and ``scaled`` (the value × f/p, the row's unit k of
    (k·p/f)·m_p)."""

    slot: str
    config: str
    field: str | None = None
    scaled: bool = False


@dataclass(frozen=True, kw_only=True)
class Entry:
    """A row of the table before its Monte Carlo: the formula values and the linear model.

    ``model`` is a :class:`~stereoplotter.verification.linear_mc.LinearModel`; its MC and
    covariance RMS are multiplied by ``scale``. ``squared``: the row reports a cofactor (the
    square of the model's σ), not a σ.

    ``verdict`` is :data:`RULE` (decided from the numbers by
    :func:`~stereoplotter.verification.verdicts.decide`) or a hand verdict (``convention``,
    ``not reproducible``) whose ``note`` says why. ``from_printed_inputs``: the book's arithmetic
    redone from its own printed intermediates (book geometry only). ``digits``: decimals of a
    printed *number* (None: ``printed`` is a printed formula evaluated at the geometry; a printed
    number exists at the book's geometry only). ``upstream``: the equation whose error the row
    inherits when it disagrees with the rigorous value. ``book_only``: ``printed`` is a formula
    with coefficients evaluated for the book's geometry ((6.41), (6.42)), void elsewhere.
    ``procedure``: what the procedure Monte Carlo measures for the row (None: it measures
    nothing the row states).
    """

    eq: str
    quantity: str
    printed: float | None
    book: float
    rigorous: float
    model: mc.LinearModel
    verdict: str
    note: str
    scale: float = 1.0
    squared: bool = False
    from_printed_inputs: float | None = None
    digits: int | None = None
    upstream: str | None = None
    book_only: bool = False
    procedure: ProcedureMeasure | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "book", float(self.book))
        object.__setattr__(self, "rigorous", float(self.rigorous))

    @property
    def identity(self) -> str:
        """The row's identity, the key of its linear Monte Carlo stream: its equation and its
        quantity (unique in the table), so that adding, removing or reordering rows leaves every
        other row's draws as they were."""
        return f"{self.eq} | {self.quantity}"


def both_photos(s: Mapping[str, float]) -> dict[str, float]:
    """Setup-element σ's of one photo (keys of :data:`GENERIC_SIGMAS`) for both photos."""
    return {
        "base_x": s["base_x"],
        "base_z": s["base_z"],
        "alpha_left": s["alpha"],
        "alpha_right": s["alpha"],
        "omega_left": s["omega"],
        "omega_right": s["omega"],
        "kappa_left": s["kappa"],
        "kappa_right": s["kappa"],
    }


@dataclass(frozen=True)
class Setting:
    """The table's geometry (keys of :data:`BOOK`) and the models every topic shares."""

    f: float
    l: float  # noqa: E741 (the book's l)
    n: float
    c: float
    p60: float
    a60: float
    p80: float
    a80: float

    @classmethod
    def from_mapping(cls, g: Mapping[str, float]) -> Setting:
        return cls(**{k: g[k] for k in BOOK})

    @property
    def is_book(self) -> bool:
        """The book's geometry: only there do its printed numbers apply."""
        return all(getattr(self, k) == v for k, v in BOOK.items())

    @property
    def r2(self) -> float:
        return math.sqrt(2.0)

    def convention_off_book(self, entry: Entry) -> Entry:
        """``entry`` at the book's geometry; elsewhere its book and rigorous values differ by the
        control-height convention: verdict ``convention``, note :data:`CONVENTION_NOTE`."""
        if self.is_book:
            return entry
        return dataclasses.replace(entry, verdict="convention", note=CONVENTION_NOTE)

    def slot(self, overlap: str) -> tuple[float, float]:
        """(a, p) of the "60" or "80" % slot."""
        return (self.a60, self.p60) if overlap == "60" else (self.a80, self.p80)

    def setup_sigmas(self, m_xy: float = 1.0) -> dict[str, float]:
        """Book-mode σ's of the setup elements (6.31)–(6.38) per m_xy."""
        sigmas: dict[str, float] = sa.setup_element_sigmas(
            self.f, self.l, self.n, m_xy, mode="book"
        )
        return sigmas

    def unadjusted(self, a: float, p: float, sigmas: Mapping[str, float]) -> mc.LinearModel:
        """Setup data without levelling, both photos' element errors (problem 1)."""
        return mc.setup_model(self.f, p, a, self.c, both_photos(sigmas), levelled=False)

    def levelled(
        self, a: float, p: float, sigmas: Mapping[str, float], control: float = 0.0
    ) -> mc.LinearModel:
        """Setup data after levelling on control with σ ``control`` [mm] (problem 2)."""
        return mc.setup_model(
            self.f,
            p,
            a,
            self.c,
            both_photos(sigmas),
            levelled=True,
            sigma_control_mm=control,
        )

    def conventional(self, a: float, p: float, sq: float = 1.0, sc: float = 1.0) -> mc.LinearModel:
        """Conventional method: relative orientation (σ_q = ``sq``) and levelling (σ = ``sc``)."""
        return mc.relative_orientation_model(a, self.c, p, self.f, sq, sigma_control_mm=sc)

    def conventional_values(self, a: float, p: float) -> list[float]:
        """printed, book, rigorous of the conventional M_p/m_p (m_q = m_p = 1)."""
        return [
            sa.conventional_parallax_rms(a, self.c, p, self.f, 1.0, 1.0, m)
            for m in ("printed", "book", "rigorous")
        ]

    def single_model(self, a: float, p: float) -> mc.LinearModel:
        """Relative orientation with m_q = m_p/√2, control and white error m_p = 1 ((5.56))."""
        return mc.relative_orientation_model(
            a, self.c, p, self.f, 1 / self.r2, sigma_control_mm=1.0, sigma_white_mm=1.0
        )

    def geodetic(self, a: float, p: float, mode: str) -> float:
        """(5.55) m_p,г/m_p over the pair in ``mode``."""
        return float(c5.geodetic_orientation_parallax_rms(a, self.c, p, self.f, 1.0, mode))


#: A row's declaration: the function that computes its :class:`Entry` at a :class:`Setting`.
RowBuilder = Callable[[Setting], Entry]


class DeclaredRows:
    """The rows of one topic module, in the order they are declared (the table's order).

    A row is declared once, by decorating the function that returns its :class:`Entry`::

        ROWS = DeclaredRows()

        @ROWS.row
        def eq_6_38(s: Setting) -> Entry:
            return Entry(eq="(6.38)", ...)

    :meth:`each_overlap` declares one row per overlap slot ("60", then "80") from a function of
    the setting and the slot. The table (``verification.table.ROW_MODULES``) concatenates the
    modules' lists; a row's random stream is keyed by its identity, not by its place.
    """

    def __init__(self) -> None:
        self._builders: list[RowBuilder] = []

    def row(self, build: RowBuilder) -> RowBuilder:
        """Declare the row ``build`` computes (a decorator; ``build`` is returned as it was)."""
        self._builders.append(build)
        return build

    def each_overlap(
        self, build: Callable[[Setting, str], Entry]
    ) -> Callable[[Setting, str], Entry]:
        """Declare two rows, ``build(s, "60")`` and ``build(s, "80")`` (a decorator)."""
        for overlap in ("60", "80"):
            self._builders.append(_AtOverlap(build, overlap))
        return build

    def __iter__(self) -> Iterator[RowBuilder]:
        return iter(self._builders)

    def __len__(self) -> int:
        return len(self._builders)

    def entries(self, s: Setting) -> list[Entry]:
        """Every declared row's :class:`Entry` at ``s``, in the declared order."""
        return [build(s) for build in self._builders]


@dataclass(frozen=True)
class _AtOverlap:
    """A row of :meth:`DeclaredRows.each_overlap`: ``build`` at one overlap slot."""

    build: Callable[[Setting, str], Entry]
    overlap: str

    def __call__(self, s: Setting) -> Entry:
        return self.build(s, self.overlap)
