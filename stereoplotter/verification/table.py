"""The verification table of §27 and the chapter-5 results it uses (``accuracy.md``).

:func:`run_verification` builds one row per numbered result, each with the printed value, the
book-mode and rigorous values, the linear Monte Carlo RMS with its CI half-width, the exact
covariance propagation on the same grid, a verdict and a note. The rows are data: each is an
:class:`~stereoplotter.verification.entry.Entry` built by a small named function of a topic module
(``rows_chapter5``: Tables 19, 20 and chapter 5; ``rows_setup_elements``: (6.28)–(6.38);
``rows_outcomes``: (6.39)–(6.46); ``rows_levelled``: (6.47)–(6.61)); :func:`_row_specs` lists
them in order. :func:`closing_comparison` is the book's closing claim (setup data vs the
conventional method at 60 % and 80 %). The files are written by
:mod:`stereoplotter.report.verification`.

Book geometry (§27): f = 70 mm, l = 85 mm, n = 1.42 (SC-1), c = 70 mm; 60 %: p = 70, a = 0;
80 %: p = 35, a = 35. Values are coefficients: m_x = m_y = m_xy = 1 for (6.31)-(6.50),
m_q = m_p = 1 (and m_xy = √2 m_p) for (6.45)-(6.61).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from stereoplotter.accuracy import setup_accuracy as sa
from stereoplotter.verification import linear_mc as mc
from stereoplotter.verification.entry import BOOK, RULE, Entry, Setting
from stereoplotter.verification.procedure_mc import procedure_mc
from stereoplotter.verification.rows_chapter5 import chapter5_entries
from stereoplotter.verification.rows_levelled import (
    closing_entries,
    conventional_term_entries,
    setup_residual_entries,
)
from stereoplotter.verification.rows_outcomes import conventional_entries, setup_outcome_entries
from stereoplotter.verification.rows_setup_elements import (
    setup_element_entries,
    unadjusted_generic_entries,
)
from stereoplotter.verification.verdicts import VERDICTS, decide

__all__ = [
    "BOOK",
    "ROW_KEYS",
    "VERDICTS",
    "attach_procedure_mc",
    "check_geometry",
    "closing_comparison",
    "run_procedure_mc",
    "run_verification",
]

ROW_KEYS = (
    "eq",
    "quantity",
    "printed",
    "from_printed_inputs",
    "book",
    "rigorous",
    "covariance",
    "mc_linear",
    "mc_linear_ci",
    "mc_procedure",
    "mc_procedure_ci",
    "verdict",
    "note",
)
PROCEDURE_NOTE = "no procedure MC (the simulated procedure does not measure this quantity)"
#: Default trials of the procedure MC (CI half-width ≈ 6–9 % at 99.9 %, ≈ 1 s per run).
PROCEDURE_TRIALS = 1500
def _row_specs(g) -> list[Entry]:
    """Every row of the table as an :class:`~stereoplotter.verification.entry.Entry`, in order
    (the order fixes each row's random stream)."""
    s = Setting.from_mapping(g)
    return [
        *chapter5_entries(s),
        *unadjusted_generic_entries(s),
        *setup_element_entries(s),
        *setup_outcome_entries(s),
        *conventional_entries(s),
        *setup_residual_entries(s),
        *conventional_term_entries(s),
        *closing_entries(s),
    ]


#: Accepted values of a flat ``--geometry`` mapping (keys of :data:`BOOK`), in mm or [—]: wide
#: round bounds around the book's setting that keep every formula finite.
def check_geometry(fields, geometry: dict) -> None:
    """Refuse a geometry outside the domain of the table's formulas, naming the field.

    The standard and control points sit at x_п = −c, a and −(p + a): they must be distinct
    (a > −c, a > −p/2), and the root of (5.54) must be real (it is for a = c − p, the default).
    Last, every formula is evaluated with floating-point errors raised, so nothing undefined
    reaches the Monte Carlo.
    """
    import warnings

    g = _normalise_geometry(geometry)
    for ov in ("60", "80"):
        a, c, p = g[f"a{ov}"], g["c"], g[f"p{ov}"]
        name = next((k for k in (f"a{ov}", f"p{ov}", "c") if k in geometry), f"a{ov}")
        found = f"a{ov} = {a:g}, c = {c:g}, p{ov} = {p:g} mm"
        if not (a + c > 0 and p + 2 * a > 0):
            raise fields.error(
                name,
                f"a{ov} > −c and a{ov} > −p{ov}/2 (distinct points x_п = −c, a, −(p + a))",
                found,
            )
        if not 1 / 48 + (6 * c**2 + 10 * a * c - 5 * p * (2 * a + c)) / (30 * (a + c) ** 2) > 0:
            raise fields.error(
                name,
                f"a geometry where the root of (5.54) is real, as it is for a{ov} = c − p{ov} "
                f"with p{ov} < 2c",
                found,
            )
    try:
        with np.errstate(all="raise"), warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            specs = _row_specs(g)
    except (ArithmeticError, ValueError, np.linalg.LinAlgError, RuntimeWarning) as exc:
        raise fields.error(
            "(geometry)",
            "values of " + ", ".join(BOOK) + " for which every formula of the table is defined",
            f"{type(exc).__name__}: {exc}",
        ) from None
    for entry in specs:
        values = [entry.printed, entry.book, entry.rigorous]
        values = [v for v in values if isinstance(v, int | float)]
        if not all(math.isfinite(v) for v in values):
            raise fields.error(
                "(geometry)",
                "values of " + ", ".join(BOOK) + " for which every formula of the table is "
                "finite",
                f"{entry.eq} {entry.quantity}: {values}",
            )


def _normalise_geometry(geometry) -> dict:
    g = dict(BOOK)
    if geometry:
        unknown = set(geometry) - set(BOOK)
        if unknown:
            raise ValueError(f"geometry keys {sorted(unknown)} are not among {sorted(BOOK)}")
        g.update({k: float(v) for k, v in geometry.items()})
        # the standard/control points sit at x_п ∈ {−c, a}: c − p = a unless a is given
        for ov in ("60", "80"):
            if f"p{ov}" in geometry and f"a{ov}" not in geometry:
                g[f"a{ov}"] = g["c"] - g[f"p{ov}"]
    return g


#: Rows with a procedure MC: eq → (overlap slot, method).
PROCEDURE_ROWS = {
    "(6.39)": ("60", "setup"),
    "(6.40)": ("80", "setup"),
    "(6.43)": ("60", "setup"),
    "(6.44)": ("80", "setup"),
    "(6.45)": ("60", "conventional"),
    "(6.46)": ("80", "conventional"),
    "(6.60)": ("60", "conventional"),
    "(6.61)": ("80", "conventional"),
}


def run_procedure_mc(
    trials=PROCEDURE_TRIALS, seed=20240601, scenarios=None, progress=None, *, instrument=None
):
    """The procedure MC of :mod:`stereoplotter.verification.procedure_mc` for the setup-data and the
    conventional method at each overlap slot.

    ``scenarios`` maps "60"/"80" to a loaded :class:`~stereoplotter.scenario.model.Scenario` (None
    for a slot skips it; None or empty: no procedure MC); the book's are the shipped ``pair60`` and
    ``pair80`` (:func:`stereoplotter.report.verification.book_scenarios`). ``instrument`` is the
    loaded :class:`~stereoplotter.instrument.spec.InstrumentSpec` (the book's SC-1), required
    when a slot is run.

    Returns
    -------
    dict
        (slot, method) → :func:`~stereoplotter.verification.procedure_mc.procedure_mc` result.
    """

    out = {}
    if not trials or not scenarios:
        return out
    todo = [(s, m) for s in ("60", "80") if scenarios.get(s) for m in ("setup", "conventional")]
    if todo and instrument is None:
        raise ValueError("instrument: expected the InstrumentSpec of the procedure MC, found None")
    for i, (slot, method) in enumerate(todo):
        out[(slot, method)] = procedure_mc(
            scenarios[slot], method, spec=instrument, trials=trials, seed=seed + 7 * i + 1
        )
        if progress is not None:
            progress(i + 1, len(todo), f"proc {slot}% {method[:4]}")
    return out


def _procedure_note(eq, res):
    """The note of a procedure-MC row: formula at the simulated geometry, first-order error and
    the mismatches of assumptions."""
    f, p, c, a, n, ll = res["f"], res["p"], res["c"], res["a"], res["n"], res["l"]
    head = (
        f"procedure MC ({res['scenario']}, T = {res['trials']}, σ = {res['sigma_mm'] * 1000:g} µm"
        f" photo): {res['coefficient']:.3f} ± {res['ci']:.3f}"
    )
    if res["method"] == "setup":
        ref = float(sa.setup_parallax_rms_from_pointing(f, p, c, ll, n, 1.0, mode="rigorous"))
        err = res["coefficient"] / ref - 1.0
        return (
            f"{head} per m_xy = n_л·σ against the unit-consistent formula at the simulated "
            f"geometry (p = {p:.2f}, c = {c:.2f}, l = {ll:g}, n_л = {n:.3f} of our SC-1 sheet, "
            f"not the book's 1.42; (6.37) at photo scale, f·m_y/(n·l_y)) {ref:.3f}: first-order "
            f"error {err:+.1%}; bias of the "
            f"error-free run {res['bias_mm'] * 1000:.1f} µm removed. Mismatches: only the "
            "monocular pointing σ of the operator; κ is cleared by y-parallax at standard points "
            "1-2 (D8), not from the fiducial readings of (6.36); ω, α by one knob setting per "
            "photo, not least squares of (6.31)/(6.33); tilted photos and relief of the scenario"
        )
    ref = float(sa.conventional_parallax_rms(a, c, p, f, 1.0, 1.0, "rigorous"))
    err = res["coefficient"] / ref - 1.0
    return (
        f"{head} per m_p = m_q against the rigorous formula at the simulated geometry "
        f"(a = {a:.2f}, c = {c:.2f}, p = {p:.2f}) {ref:.3f}: ratio {err:+.1%}. Measured: the "
        "heights as read on the slipped height scale, standard points at a = c − p, the height "
        "datum the mean of the four levelling heights (the formula's plane; the procedure as "
        "built slips at one point, which doubles the total — docs/accuracy.md); the stereo σ "
        "part agrees with the formula at the procedure's own levelling points, the y-parallax σ "
        "part stays above (5.54) by a remainder not yet explained. Mismatches: scaling by b_x on "
        "plan control, levelling on the scenario's control points (not at x_п ∈ {−c, a}, "
        f"y = ±c), relative orientation by (5.11); bias of the error-free run "
        f"{res['bias_mm'] * 1000:.1f}"
        " µm removed"
    )


def run_verification(
    trials: int = 60000,
    seed: int = 20240601,
    geometry=None,
    progress: Callable[[int, int, str], None] | None = None,
    procedure_trials: int = PROCEDURE_TRIALS,
    procedure_scenarios=None,
    instrument=None,
) -> list[dict]:
    """Compute the verification table.

    Parameters
    ----------
    trials : int
        Monte Carlo trials per row (60 000 gives half-widths ≤ 1.4 % at 99.9 %, ≤ 0.8 % at
        95 %; most rows, with several sources, are tighter).
    seed : int
        Seed of the ``numpy.random.Generator`` (one child stream per row).
    geometry : mapping, optional
        Overrides of :data:`BOOK` (keys f, l, n, c, p60, a60, p80, a80).
    progress : callable, optional
        ``progress(done, total, eq)`` after each row.
    procedure_trials : int
        Trials of the procedure MC per (overlap, method); 0 disables it.
    procedure_scenarios : mapping, optional
        "60"/"80" → loaded scenario of the procedure MC (None for a slot skips it; None: no
        procedure MC). The book's are the shipped ``pair60``, ``pair80``, loaded by the caller
        (:func:`stereoplotter.report.verification.book_scenarios`): this layer reads no files.
    instrument : InstrumentSpec, optional
        The instrument of the procedure MC (the book's SC-1); required with a scenario.

    Returns
    -------
    list of dict
        Rows with the keys :data:`ROW_KEYS` (plus ``units`` free text in ``quantity``).

    Examples
    --------
    >>> rows = run_verification(trials=200, seed=1, procedure_trials=0)
    >>> rows[0]["eq"], sorted(rows[0]) == sorted(ROW_KEYS)
    ('Table 19', True)
    """
    g = _normalise_geometry(geometry)
    proc = run_procedure_mc(procedure_trials, seed, procedure_scenarios, instrument=instrument)
    specs = _row_specs(g)
    rows = _rows(specs, trials, seed, progress, Setting.from_mapping(g).is_book)
    attach_procedure_mc(rows, proc)
    return rows


def attach_procedure_mc(rows: list[dict], proc: dict) -> list[dict]:
    """Fill ``mc_procedure``, ``mc_procedure_ci`` and the note from :func:`run_procedure_mc`."""
    for r in rows:
        pr = proc.get(PROCEDURE_ROWS.get(r["eq"], ()))
        if pr is None:
            continue
        r["mc_procedure"], r["mc_procedure_ci"] = pr["coefficient"], pr["ci"]
        r["note"] = r["note"].replace(PROCEDURE_NOTE, _procedure_note(r["eq"], pr))
    return rows


def _rows(specs: list[Entry], trials, seed, progress, at_book: bool = True):
    rngs = [np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(len(specs))]
    rows = []
    for i, e in enumerate(specs):
        rows.append(_row(e, trials, rngs[i], at_book))
        if progress is not None:
            progress(i + 1, len(specs), e.eq)
    return rows


def _verdict(e: Entry, at_book: bool) -> tuple[float | None, float | None, str, str]:
    """printed, from_printed_inputs, verdict and note of ``e``. The book's printed *numbers*
    (``e.digits`` set) and the arithmetic on them apply only at the book's geometry; elsewhere
    the verdict compares the book's formula with the rigorous one and the note says so."""
    number = e.digits is not None or e.book_only
    printed = e.printed if at_book or not number else None
    fpi = e.from_printed_inputs if at_book else None
    hand = None if e.verdict == RULE else e.verdict
    verdict, check = decide(
        printed, fpi, e.book, e.rigorous, digits=e.digits, upstream=e.upstream, hand=hand
    )
    if at_book:
        return printed, fpi, verdict, f"{check}. {e.note}"
    head = "geometry differs from the book's"
    if number:
        head += ": the book's printed number and its arithmetic do not apply"
    keep = not number or hand == "convention"
    return printed, fpi, verdict, f"{head}; {check}" + (f". {e.note}" if keep else "")


def _row(e: Entry, trials, rng, at_book: bool = True) -> dict:
    """The row of ``e``: its linear MC (``trials``, ``rng``) and covariance RMS."""
    # a squared statistic doubles the relative CI: four times the trials keep it ≤ 1 %
    r, h, _ = mc.mc_rms(e.model, 4 * trials if e.squared else trials, rng)
    cov = mc.covariance_rms(e.model)
    if e.squared:
        r, h, cov = r**2, 2 * r * h, cov**2
    printed, fpi, verdict, note = _verdict(e, at_book)
    return {
        "eq": e.eq,
        "quantity": e.quantity,
        "printed": printed,
        "from_printed_inputs": fpi,
        "book": e.book,
        "rigorous": e.rigorous,
        "covariance": cov * e.scale,
        "mc_linear": r * e.scale,
        "mc_linear_ci": h * e.scale,
        "mc_procedure": None,
        "mc_procedure_ci": None,
        "verdict": verdict,
        "note": note + "; " + PROCEDURE_NOTE,
    }


def closing_comparison(rows: list[dict]) -> list[dict]:
    """The book's closing claim (OCR L4022-4026) against the recomputed chain.

    Examples
    --------
    >>> rows = run_verification(trials=100, procedure_trials=0)
    >>> [r["overlap"] for r in closing_comparison(rows)]
    ['60 %', '80 %']
    """
    by = {r["eq"]: r for r in rows}
    out = []
    for ov, s, cv, claim in (
        ("60 %", "(6.58)", "(6.60)", "equal accuracy"),
        ("80 %", "(6.59)", "(6.61)", "setup data 20 % better"),
    ):
        row = {"overlap": ov, "book_claim": claim}
        for key in ("printed", "book", "rigorous", "mc_linear", "mc_procedure"):
            a, b = by[s][key], by[cv][key]
            row[f"setup_{key}"], row[f"conventional_{key}"] = a, b
            row[f"gain_{key}"] = None if a is None or b is None else 1.0 - a / b
        out.append(row)
    return out
