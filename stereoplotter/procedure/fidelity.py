"""The procedure's mechanism switches, declared in one place.

Each way in which the simulated setup-data procedure departs from the assumptions under which
§27 derives (6.39)–(6.44) is one named option here: its choices, the default (a competent
operator working the book's stage texts, with its basis: a book line of Kushtin & Lyskov 1984,
or ``assumed`` and why) and the setting "as the formula assumes" (§27 task 1: "the angular and
linear elements are entered independently of one another and the geodetic orientation is not
refined", each element with the error of (6.32)–(6.38)). :meth:`Fidelity.as_formula` sets every
switch to the formula's assumption at once; ``verify`` and ``simulate`` set them with
``--as-formula`` and one flag each (:data:`MECHANISMS`).

The switches act on the setup-data method only (its stages 1–3); the conventional method has
its own configuration in the procedure Monte Carlo.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from typing import Any

__all__ = ["LINKAGE_VARIANTS", "MECHANISMS", "Fidelity", "Mechanism", "mechanism"]

#: The knob–decentration linkage → the instrument's decentration variant
#: (:data:`~stereoplotter.instrument.decentration_variants.DECENTRATION_VARIANTS`): "drag",
#: the knob drags the photo and plane decentrations (D1, "L"); "independent", the
#: decentrations stay where they are set, and are set before the k_ω, k_α fits ("B2": set
#: after them, as in the book's order, they would leave the fits made at zero decentration).
LINKAGE_VARIANTS = {"drag": "L", "independent": "B2"}


@dataclass(frozen=True)
class Mechanism:
    """One switch: the :class:`Fidelity` field ``name``, the command-line ``flag`` that sets it,
    its ``choices``, the ``default`` and its ``basis``, the ``as_formula`` setting and what the
    formula assumes there (``formula``)."""

    name: str
    flag: str
    choices: tuple[Any, ...]
    default: object
    basis: str
    as_formula: object
    formula: str

    def option(self, value: object) -> str:
        """The command line that sets ``value``: ``--flag value``."""
        return f"{self.flag} {value}"


#: Every mechanism by which the simulated setup-data procedure departs from the formula's
#: assumptions, in the order of the decomposition (``verify --json``, ``decomposition``).
MECHANISMS = (
    Mechanism(
        "bottom_stop",
        "--bottom-stop",
        ("both_ways", "one_way", "free"),
        "both_ways",
        "the book's rule (OCR L3763, L3773): the carriage is lowered to its bottom position, "
        "O_Z = n_л·f′_пр, and the correction is set both ways, O′_Z = O_Z + ΔZ (6.11). A ΔZ "
        "that would take the carriage past its bottom stop is reached by shortening f_пр "
        "(n = D/f_пр, (6.3)); a later correction the other way first gives that shortening "
        "back (f_пр towards the sheet's value), then raises the carriage. 'one_way': f_пр is "
        "shortened at the stop and never lengthened (the carriage is raised instead)",
        "free",
        "(6.39)–(6.44) have no f_пр term: f_пр stays at the sheet's value and every ΔZ is set "
        "on Z (no stop)",
    ),
    Mechanism(
        "bx_zero",
        "--bx-zero",
        ("two_pointings", "exact"),
        "two_pointings",
        "(6.38), OCR L3942: m_bx = √2·m_x/n, b_x's zero place MO_bx from two monocular "
        "pointings, the left and right marks on their cassette centres (as MO_by, OCR L3759): "
        "O_bx carries n_л·(e_п − e_л). 'exact': MO_bx the scale's nominal place of zero",
        "two_pointings",
        "(6.38): b_x set with √2·m_x/n",
    ),
    Mechanism(
        "kappa",
        "--kappa",
        ("y_parallax", "fiducials"),
        "y_parallax",
        "decision D8 (OCR L3793): 'orientation along the initial directions by κ_л and κ_п in "
        "the usual way', y-parallax cleared at standard points 1, 2. 'fiducials': κ from the "
        "fiducial readings of marks 3, 4 (OCR L3761, (6.36)), m_κ = m_x/(√2·l·n), no "
        "y-parallax judged",
        "fiducials",
        "(6.36): κ from the fiducials, m_κ = m_x/(√2·l_y·n), independent of the other elements",
    ),
    Mechanism(
        "tilts",
        "--tilts",
        ("knob_fit", "least_squares"),
        "knob_fit",
        "the book's stage 2 (OCR L3781–3787): k_ω fitted at mark 3 with the counter at "
        "MO_Y + n·y⁰₃, mark 4 checked (refit while it is off), k_α at mark 2 (1 on the right). "
        "'least_squares': k_ω fitted at mark 3 and at mark 4 and set to the mean of the two "
        "fits — with the zero reading at the cassette centre the least-squares solution of "
        "(6.33), Q_ωω = 3/(2a²) for a = l²/f",
        "least_squares",
        "(6.33)–(6.35): ω from the centre and marks 3, 4 by least squares",
    ),
    Mechanism(
        "fit_scale",
        "--fit-scale",
        ("as_set", "exact"),
        "as_set",
        "the book's stage 2 (OCR L3781, L3787): the fits' counter targets MO + n·x⁰, n·y⁰ are "
        "read on counters whose scale n = D/f_пр the stage-1 L-check set, with its error "
        "(δn/n ≈ √2·m/L from two pointings). 'exact': the targets scaled by the n the "
        "instrument actually has, so a fit carries only its own pointings",
        "exact",
        "(6.31)–(6.35): the tilts from the pointings at the centre and the marks, n exact",
    ),
    Mechanism(
        "stage3",
        "--stage3",
        ("fuse", "bx_only", "none"),
        "fuse",
        "the book's stage 3 (OCR L3803–3805): b_x until the mark fuses on a height control "
        "point at O_Z (6.15), then the orientation along the initial direction refined (D10). "
        "'bx_only': b_x fused, κ not cleared again; 'none': the model is left as stage 2 "
        "built it (only the heights are read)",
        "none",
        "§27 task 1: the elements entered independently, the geodetic orientation not refined "
        "(b_x from (6.38), κ from (6.36))",
    ),
    Mechanism(
        "passes",
        "--passes",
        (None, 1, 2, 3, 4, 6),
        None,
        "the book's stage texts: 'otherwise the setting is repeated' (OCR L3775), each loop "
        "until its check passes, bounded by the operator's max_iterations (assumed 6)",
        1,
        "each element set once from one measurement, (6.32)–(6.38): every loop makes one pass "
        "(no check stops it)",
    ),
    Mechanism(
        "linkage",
        "--linkage",
        (None, "drag", "independent"),
        None,
        "assumed: the instrument file's correction.decentration_linkage (the SC-1's: drag, "
        "decision D1; no source documents how the SC-1's knob moves its decentration)",
        "independent",
        "(6.21)→(6.22): the decentration errors are dropped (they are 'largely removed by the "
        "scaling'): the decentrations stay where they are set",
    ),
)


def mechanism(name: str) -> Mechanism:
    """The :data:`MECHANISMS` entry ``name``."""
    for m in MECHANISMS:
        if m.name == name:
            return m
    raise KeyError(name)


@dataclass(frozen=True)
class Fidelity:
    """The switches of :data:`MECHANISMS` for one run (defaults: the competent operator).

    Attributes
    ----------
    bottom_stop : {"both_ways", "one_way", "free"}
    bx_zero : {"two_pointings", "exact"}
    kappa : {"y_parallax", "fiducials"}
    tilts : {"knob_fit", "least_squares"}
    fit_scale : {"as_set", "exact"}
    stage3 : {"fuse", "bx_only", "none"}
    passes : int or None
        Every tolerance loop makes this many passes (no check stops it); None: until a check
        passes.
    linkage : {"drag", "independent"} or None
        None: the instrument's.

    Examples
    --------
    >>> Fidelity.as_formula().departures()
    ()
    >>> Fidelity().departures()
    ('bottom_stop', 'kappa', 'tilts', 'fit_scale', 'stage3', 'passes', 'linkage')
    """

    bottom_stop: str = "both_ways"
    bx_zero: str = "two_pointings"
    kappa: str = "y_parallax"
    tilts: str = "knob_fit"
    fit_scale: str = "as_set"
    stage3: str = "fuse"
    passes: int | None = None
    linkage: str | None = None

    def __post_init__(self) -> None:
        for f in fields(self):
            m = mechanism(f.name)
            value = getattr(self, f.name)
            if f.name == "passes":
                ok = value is None or (isinstance(value, int) and value >= 1)
            else:
                ok = value in m.choices
            if not ok:
                shown = ", ".join(str(c) for c in m.choices)
                raise ValueError(f"{m.flag}: expected one of {shown}, found {value!r}")

    @classmethod
    def as_formula(cls) -> Fidelity:
        """Every switch at the formula's assumption."""
        settings: dict[str, Any] = {m.name: m.as_formula for m in MECHANISMS}
        return cls(**settings)

    def departures(self) -> tuple[str, ...]:
        """The switches not at the formula's assumption, in :data:`MECHANISMS` order."""
        return tuple(m.name for m in MECHANISMS if getattr(self, m.name) != m.as_formula)

    def with_formula(self, name: str) -> Fidelity:
        """This with switch ``name`` at the formula's assumption."""
        setting: dict[str, Any] = {name: mechanism(name).as_formula}
        return replace(self, **setting)

    def variant(self, default: str) -> str:
        """The instrument's decentration variant for this linkage (``default``: the caller's
        variant where the linkage is the instrument's)."""
        return default if self.linkage is None else LINKAGE_VARIANTS[self.linkage]
