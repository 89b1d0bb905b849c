"""Procedure Monte Carlo: the formulas of §27 against the simulated operator (``accuracy.md`` 4).

:func:`procedure_mc` runs the real stages on the virtual SC-1 (``procedure.simulate``, closed-form
back-end, vectorised over trials) twice with the same seed — once with the operator's pointing
errors of the formula switched on, once with every error zero — and takes the x-parallax error
field δp of the built model (photo mm, at the ideal model position,
:mod:`stereoplotter.procedure.evaluation`)
on the formula's own integration domain. The difference of the two runs is the error the
pointing caused (the zero run carries the deterministic residue of the sheet's approximations,
reported as ``bias``). The statistic is the protocol's: sqrt(mean over trials and a uniform
midpoint grid of δp²), with a CI half-width of ``CI_Z`` standard errors from the per-trial mean
squares.

Configurations (chosen to match the formulas' assumptions as far as the model allows):

* ``method="setup"`` — (6.39)/(6.40) → (6.43)/(6.44): only the monocular pointing error σ of the
  operator (photo scale; the fiducial settings of stages 1–2); no injected instrument errors,
  ideal mechanics, exact counter reading and setting, no stereo / y-parallax judgment error.
  Coefficient = RMS / m_xy with m_xy = n_л·σ (the book's m_x is a counter error, (6.31)
  m_Δx = m_x/n). Domain of (6.27): x_л ∈ [0, c], y ∈ [−c, c]; no plane removal.
* ``method="conventional"`` — (6.45)/(6.46) = (6.60)/(6.61): y-parallax judgment σ_q = σ and
  stereo (x-parallax) judgment σ_p = σ (m_q = m_p), relative orientation by the six measured q and
  (5.11) (``relative="equations"``, least squares as (5.54) assumes), levelling on the scenario's
  four control points by the procedure itself; coefficient = RMS / σ. Domain of chapter 5:
  x_п ∈ [−c, 0], y ∈ [−c, c] (x_л = x_п + p). By default the measured quantity is the height
  as read on the slipped height scale (converted to parallax units), the standard points stand
  at a = c − p as in the formula, and the height datum is the mean of the four levelling heights
  re-observed with σ_p (the formula's plane); ``quantity``, ``standard_points`` and ``datum``
  select the other readings (δp at the ideal model position, the nadirs, the procedure's
  one-point slip) — ``docs/accuracy.md`` gives the numbers of each. ``levelling="book"``
  re-levels the built model at Fig. 39's control points and ``sources`` switches σ_q or σ_p
  off; :func:`levelling_formula` is the rigorous formula with the plane at any four points (the
  procedure levels on the scenario's control points, which moves the formula by +5 %).

* ``method="setup_control"`` — §27 task 2, setup data refined on control: the setup run above,
  then the built model levelled on Fig. 39's four control points by the least-squares plane
  through its δp there ((6.47)–(6.50) exact control heights, per m_xy; (6.58)/(6.59) control
  parallaxes observed with m_p = m_xy/√2, per m_p); domain of chapter 5. One setup run gives all
  three readings (``fields`` of the result).

Every run can carry the instrument's error terms at their σ (``instrument=True``, real
mechanics), and is estimated with the linear control variate of
:mod:`~stereoplotter.verification.control_variate` (unbiased; ``plain`` keeps the plain mean).

One configuration's run is made of the typed parts of :mod:`.procedure_run`; the points and δp
of a scenario and a built instrument are :mod:`.procedure_geometry`'s.
:mod:`.relative_orientation_mc` runs the conventional relative orientation alone (σ_q only,
fixed passes) against (5.54).
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.accuracy import setup_accuracy as sa
from stereoplotter.accuracy.chapter5 import (
    control_points,
    geodetic_orientation_parallax_rms,
    levelling_design,
    relative_orientation_design,
    relative_orientation_parallax_rms,
    standard_points,
)
from stereoplotter.procedure.fidelity import LINKAGE_VARIANTS, Fidelity
from stereoplotter.procedure.operator import OperatorModel
from stereoplotter.procedure.simulate import prepare_run
from stereoplotter.verification import decomposition as dc
from stereoplotter.verification.as_formula import RunResult
from stereoplotter.verification.linear_mc import (
    CI_Z,
    FloatArray,
    LinearModel,
    covariance_rms,
    grid_chapter5,
    relative_field_basis,
)
from stereoplotter.verification.procedure_geometry import (
    idealised_geometry,
    levelling_frame_points,
    scenario_geometry,
)
from stereoplotter.verification.procedure_run import (
    METHODS,
    FieldKey,
    ProcedureRun,
    mean_squares,
    method_operator,
)

if TYPE_CHECKING:
    from stereoplotter.scenario.model import Scenario
    from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = [
    "CONVENTIONAL_READINGS",
    "LINKAGE_VARIANTS",
    "METHODS",
    "SOURCES",
    "ConfigurationRun",
    "ProcedureOptions",
    "conventional_sources_mc",
    "idealised_geometry",
    "levelling_formula",
    "levelling_points_photo",
    "procedure_mc",
    "rms_ci",
    "run_configuration",
    "scenario_geometry",
]


#: The readings of a conventional run (``by_datum``; ``procedure_mc(measure=…)``).
CONVENTIONAL_READINGS = ("parallax", "slip", "plane", "book")
#: ``procedure_mc(sources=…)`` of the conventional method: which judgment errors are on.
SOURCES = ("both", "y_parallax", "stereo")


def levelling_formula(
    g: Mapping[str, float],
    x_right_mm: ArrayLike,
    y_mm: ArrayLike,
    grid: tuple[int, int] = (16, 32),
) -> dict[str, float]:
    """The rigorous M_p of the conventional method, (5.54) ⊕ (5.55), with the levelling plane
    fitted at the given control points instead of Fig. 39's x_п ∈ {−c, a}, y = ±c.

    The linear model of (6.60)/(6.61) (relative orientation by least squares on the six standard
    points, the plane's error from control heights with the parallax error m_p) on the chapter-5
    domain, propagated exactly (:func:`~stereoplotter.verification.linear_mc.covariance_rms`).
    ``g``: :func:`scenario_geometry` (a, c, p, f). Returns the coefficients per m_q = m_p:
    "y_parallax" (the (5.54) part), "stereo" (the (5.55) part) and "both" (their quadrature).

    Examples
    --------
    At Fig. 39's own points it is the rigorous (6.60), 0.6862:

    >>> from stereoplotter.accuracy.chapter5 import control_points
    >>> g = {"a": 0.0, "c": 70.0, "p": 70.0, "f": 70.0}
    >>> round(levelling_formula(g, *control_points(0.0, 70.0))["both"], 3)
    0.686
    """

    a, c, p, f = g["a"], g["c"], g["p"], g["f"]
    _, xs, ys = standard_points(a, p, c)
    lsq = np.linalg.pinv(relative_orientation_design(xs, ys, p, f))
    xg, yg = grid_chapter5(c, *grid)
    xc, yc = np.asarray(x_right_mm, float), np.asarray(y_mm, float)
    fit = levelling_design(xg, yg) @ np.linalg.pinv(levelling_design(xc, yc))
    out: dict[str, float] = {}
    for name, sq, sp in (("y_parallax", 1.0, 0.0), ("stereo", 0.0, 1.0), ("both", 1.0, 1.0)):
        model = LinearModel(
            relative_field_basis(xg, yg, p, f),
            lsq * sq,
            relative_field_basis(xc, yc, p, f),
            fit,
            sp,
            0.0,
        )
        out[name] = covariance_rms(model)
    return out


def levelling_points_photo(
    scenario: Scenario, spec: InstrumentSpec, g: Mapping[str, float]
) -> tuple[FloatArray, FloatArray]:
    """(x_п, y) [mm] of the procedure's four levelling points (the scenario's control points
    nearest standard points 3–6, ``conventional.levelling_points``) at the mean photo scale."""

    spec = replace(spec, standard_points_c_mm=g["c"])
    prep = prepare_run(scenario, spec, "conventional", "zero", 0, operator=OperatorModel().zero())
    _, lev = levelling_frame_points(prep)
    s = g["f"] / g["flying_height_m"]
    return lev[:, 0] * s - g["p"], lev[:, 1] * s


def rms_ci(ms: FloatArray, unit: float) -> tuple[float, float]:
    """(RMS, CI half-width) per ``unit`` from per-trial mean squares (``CI_Z`` s.e.)."""
    mean_ms = float(np.mean(ms))
    rms = math.sqrt(max(mean_ms, 0.0))
    se = float(np.std(ms, ddof=1)) / math.sqrt(len(ms))
    # a mean square at or below zero (a control-variate estimate can be): RMS 0, CI unbounded
    half = CI_Z * se / (2.0 * rms) if rms > 0.0 else math.inf
    return rms / unit, half / unit


def _check_options(method: str, **options: str) -> None:
    if method not in METHODS:
        raise ValueError(f"method: expected one of {METHODS}, found {method!r}")
    allowed = {
        "quantity": ("heights", "parallax"),
        "standard_points": ("book", "nadirs"),
        "datum": ("plane", "slip"),
        "levelling": ("procedure", "book"),
        "sources": SOURCES,
        "control": ("exact", "observed"),
    }
    for name, value in options.items():
        if value not in allowed[name]:
            raise ValueError(f"{name}: expected one of {allowed[name]}, found {value!r}")


def _field_name(method: str, quantity: str, levelling: str, datum: str, control: str) -> str:
    """The field whose mean square is the procedure's statistic."""
    if method == "setup":
        return "parallax"
    if method == "setup_control":
        return "levelled" if control == "exact" else "observed"
    if quantity == "parallax":
        return "parallax"
    return "book" if levelling == "book" else datum


def _formulas(
    method: str,
    scenario: Scenario,
    spec: InstrumentSpec,
    g: Mapping[str, float],
    sources: str,
    control: str,
    levelled: tuple[Mapping[str, float], Mapping[str, float]] | None = None,
) -> dict[str, float]:
    """The rigorous formula at the simulated geometry for the statistic (per its unit).
    ``levelled``: the two :func:`levelling_formula` results (procedure's points, Fig. 39's) if
    already computed."""
    f, p, c, a, n, ll = g["f"], g["p"], g["c"], g["a"], g["n"], g["l"]
    if method == "setup":
        return {
            "rigorous": float(
                sa.setup_parallax_rms_from_pointing(f, p, c, ll, n, 1.0, mode="rigorous")
            )
        }
    if method == "setup_control":
        if control == "exact":  # (6.47)–(6.50) per m_xy
            return {
                "rigorous": float(sa.setup_relative_residual_rms(a, c, f, ll, n, 1.0, "rigorous"))
            }
        # (6.58)/(6.59) per m_p with m_xy = √2 m_p and control parallaxes with m_p
        residual = sa.setup_relative_residual_rms(a, c, f, ll, n, math.sqrt(2.0), "rigorous")
        geodetic = geodetic_orientation_parallax_rms(a, c, p, f, 1.0, "rigorous")
        return {"rigorous": float(math.hypot(residual, geodetic))}
    part = {"both": None, "y_parallax": 0, "stereo": 1}[sources]
    terms = (
        relative_orientation_parallax_rms(a, c, p, 1.0, "rigorous"),
        geodetic_orientation_parallax_rms(a, c, p, f, 1.0, "rigorous"),
    )
    rig = math.hypot(*terms) if part is None else terms[part]
    if levelled is None:
        levelled = (
            levelling_formula(g, *levelling_points_photo(scenario, spec, g)),
            levelling_formula(g, *control_points(a, c)),
        )
    return {
        "rigorous": float(rig),
        "procedure": levelled[0][sources],
        "book": levelled[1][sources],
    }


@dataclass(frozen=True)
class ProcedureOptions:
    """The options of :func:`procedure_mc` (keyword arguments there; defaults as here).

    Attributes
    ----------
    sigma_mm : float
        The operator's σ (photo scale): monocular pointing (setup) or σ_q = σ_p (conventional).
    grid : tuple of int
        Midpoint grid of the statistic (nx, ny).
    quantity : {"heights", "parallax"}
        Conventional only (``docs/accuracy.md``, "The conventional method: levelling, height
        datum and error-free floor"): the
        height read on the slipped height scale in parallax units (what M_p measures) or δp at
        the ideal model position (counts the b_x scale error and the model's datum).
    standard_points : {"book", "nadirs"}
        Conventional only: Fig. 39 at a = c − p (the formula's layout) or a = 0.
    datum : {"plane", "slip"}
        Conventional only: the formula's levelling offset (the four levelling heights, each
        with σ_p) or the procedure's (the height scale slipped at one levelling point).
    levelling : {"procedure", "book"}
        Conventional only: the model as the procedure levelled it (the scenario's four control
        points nearest standard points 3–6) or re-levelled by the least-squares plane through
        its height errors at Fig. 39's x_п ∈ {−c, a}, y = ±c, each observed with σ_p.
    sources : {"both", "y_parallax", "stereo"}
        Conventional only: σ_q = σ_p = σ, σ_q only or σ_p only.
    control : {"exact", "observed"}
        "setup_control" only: exact control heights (per m_xy, (6.47)–(6.50)) or each control
        parallax observed with m_p = m_xy/√2 (per m_p, (6.58)/(6.59)).
    instrument : bool
        Every injected instrument error term of ``spec`` at its configured σ and the real
        mechanics (backlash), besides the operator's σ; the unit stays the operator's.
    control_variate : bool
        The estimator with the linear control variate
        (:mod:`~stereoplotter.verification.control_variate`; unbiased, its CI ≈ 10–40×
        narrower); False: the plain mean.
    decompose : bool
        Setup methods: each reading's ``decomposition`` (:mod:`.decomposition`); False: None
        (a run read only for its value or its per-trial mean squares skips its first-order
        fields).
    measure : tuple of str or None
        Conventional only: the readings measured, of "parallax", "slip", "plane" and "book"
        (``by_datum`` holds these; the statistic's own is always measured); None: every one.
    passes : int or None
        Every loop makes this many passes (no check ever passes); None: as ``fidelity`` says.
    linkage : {"drag", "independent"} or None
        The knob–decentration linkage (:data:`LINKAGE_VARIANTS`); None: as ``fidelity`` says
        (its None: the instrument's ``correction.decentration_linkage``).
    fidelity : Fidelity or None
        The mechanism switches of the setup-data procedure
        (:mod:`~stereoplotter.procedure.fidelity`); None: the defaults. ``passes`` and
        ``linkage``, where given, override its own.
    """

    sigma_mm: float = 0.01
    grid: tuple[int, int] = (16, 32)
    quantity: str = "heights"
    standard_points: str = "book"
    datum: str = "plane"
    levelling: str = "procedure"
    sources: str = "both"
    control: str = "exact"
    instrument: bool = False
    control_variate: bool = True
    decompose: bool = True
    measure: tuple[str, ...] | None = None
    passes: int | None = None
    linkage: str | None = None
    fidelity: Fidelity | None = None

    def switches(self, spec: InstrumentSpec) -> Fidelity:
        """The run's :class:`Fidelity`, ``passes`` and ``linkage`` applied, the linkage
        resolved (:meth:`linkage_of`)."""
        f = self.fidelity or Fidelity()
        passes = f.passes if self.passes is None else self.passes
        return replace(f, passes=passes, linkage=self.linkage_of(spec))

    def linkage_of(self, spec: InstrumentSpec) -> str:
        """The run's knob–decentration linkage: ``linkage``, else the fidelity's, else the
        instrument's ``correction.decentration_linkage``."""
        f = self.fidelity or Fidelity()
        linkage: str = self.linkage or f.linkage or spec.decentration_linkage
        return linkage


def procedure_mc(
    scenario: Scenario,
    method: str = "setup",
    *,
    spec: InstrumentSpec,
    trials: int = 600,
    seed: int = 20240601,
    **options: Any,
) -> RunResult:
    """Run the procedure MC for one scenario and method (see the module docstring).

    ``method`` (:data:`METHODS`): "setup" (§27 task 1: stages 1–5 with the operator's monocular
    pointing σ; δp on the (6.27) domain per m_xy = n_л·σ, (6.39)–(6.44)); "setup_control" (§27
    task 2: the same run levelled on Fig. 39's four control points by the least-squares plane
    through the δp there; the chapter-5 domain); "conventional". ``options``: the fields of
    :class:`ProcedureOptions`. ``scenario`` and ``spec`` (the book's SC-1) are loaded by the
    caller; this layer reads no files.

    Returns
    -------
    dict
        ``coefficient`` (per m_xy, m_p or m_q as above), ``ci`` (half-width), ``plain``
        (coefficient, ci of the plain mean), ``formula`` (``rigorous`` at the simulated
        geometry; conventional also :func:`levelling_formula` at the procedure's levelling
        points, ``procedure``, and at Fig. 39's, ``book``), ``rms_mm``, ``bias_mm`` (RMS δp of
        the error-free run), ``per_trial``, the geometry (f, l, n, f_instrument, p, c, a,
        overlap), ``seconds``; setup methods also ``fields`` (the three readings, each with its
        ``decomposition``, :mod:`.decomposition`), conventional ``by_datum`` and the options.

    Examples
    --------
    >>> from stereoplotter.io.paths import data_dir
    >>> from stereoplotter.io.scenario_file import load_scenario
    >>> from stereoplotter.io.instrument_file import load_instrument
    >>> sc = load_scenario(data_dir("scenarios") / "pair60.yaml")
    >>> r = procedure_mc(sc, "setup", spec=load_instrument("sc1"), trials=20, seed=1)
    >>> 0.3 < r["coefficient"] < 3.0
    True
    """
    t0 = time.perf_counter()
    o = ProcedureOptions(**options)
    _check_options(
        method,
        **{k: getattr(o, k) for k in ("quantity", "standard_points", "datum", "levelling")},
        **{k: getattr(o, k) for k in ("sources", "control")},
    )
    g = scenario_geometry(scenario, spec)
    linkage = o.linkage_of(spec)
    runs = run_configuration(scenario, spec, method, trials, seed, o, g, linkage)
    out = _result(scenario, spec, method, o, g, linkage, runs)
    return {**out, "trials": int(trials), "seed": int(seed), "seconds": time.perf_counter() - t0}


def _result(
    scenario: Scenario,
    spec: InstrumentSpec,
    method: str,
    o: ProcedureOptions,
    g: dict[str, float],
    linkage: str,
    runs: ConfigurationRun,
    formulas: dict[str, float] | None = None,
) -> RunResult:
    """The result of :func:`procedure_mc` from the per-trial mean squares of its run(s)."""
    plain, controlled, d_zero, units = runs
    name = _field_name(method, o.quantity, o.levelling, o.datum, o.control)
    best = controlled or plain
    unit = units[name]
    coefficient, ci = rms_ci(best[name], unit)
    if formulas is None:
        formulas = _formulas(method, scenario, spec, g, o.sources, o.control)
    out = {
        **_extras(scenario, spec, method, o, g, plain, best, units),
        "method": method,
        "scenario": scenario.name,
        "sigma_mm": o.sigma_mm,
        "instrument": bool(o.instrument),
        "instrument_key": spec.key,
        "linkage": linkage,
        "fidelity": o.switches(spec),
        "control_variate": bool(controlled),
        "coefficient": coefficient,
        "ci": ci,
        "plain": rms_ci(plain[name], unit),
        "formula": formulas,
        "rms_mm": coefficient * unit,
        "bias_mm": float(np.sqrt(np.mean(d_zero**2))),
        "per_trial": np.sqrt(plain[name]) / unit,
    }
    return {**out, **g}


#: Key prefixes of the acts of each judgment source of the conventional method (σ_q: the
#: y-parallax judgments ``q/…``; σ_p: the stereo judgments ``stereo/…`` and the observed
#: levelling heights ``mc/datum/…``, ``mc/book/…`` of the conventional run, :mod:`.procedure_run`).
SOURCE_PREFIXES = {"y_parallax": ("q/",), "stereo": ("stereo/", "mc/datum/", "mc/book/")}


def conventional_sources_mc(
    scenario: Scenario,
    *,
    spec: InstrumentSpec,
    trials: dict[str, int],
    seed: int = 20240601,
    **options: Any,
) -> dict[str, RunResult]:
    """:func:`procedure_mc` of the conventional method for several ``sources`` at once, as one
    run: ``trials`` maps a source (:data:`SOURCES`) to its trials, laid out in blocks of one run
    with σ_q = σ_p = σ whose acts of the sources a block leaves out draw 0 on its trials
    (:class:`~stereoplotter.verification.control_variate.SourceNoise`). A block's trials are those
    of a run with only its sources on (the draws keyed by trial: block b holds trials
    first_b … first_b + T_b − 1 of ``seed``), so each result is that of ``procedure_mc`` on those
    trials; the error-free run, the linearisation and the procedure's per-act overhead are shared.
    Returns source → result (as :func:`procedure_mc`; ``first_trial`` its block's start).
    """
    t0 = time.perf_counter()
    if "sources" in options:
        raise ValueError("sources: given by the keys of trials")
    unknown = set(trials) - set(SOURCES)
    if unknown:
        raise ValueError(f"trials: expected sources among {SOURCES}, found {sorted(unknown)}")
    o = ProcedureOptions(**options)
    _check_options("conventional", **{k: getattr(o, k) for k in ("quantity", "standard_points")})
    g = scenario_geometry(scenario, spec)
    linkage = o.linkage_of(spec)
    names = list(trials)
    bounds = np.cumsum([0] + [int(trials[k]) for k in names])
    off_of = {
        prefix: np.concatenate([np.full(int(trials[k]), k not in ("both", src)) for k in names])
        for src, prefixes in SOURCE_PREFIXES.items()
        for prefix in prefixes
    }
    plain, controlled, d_zero, units = run_configuration(
        scenario, spec, "conventional", int(bounds[-1]), seed, o, g, linkage, off_of
    )
    lev = levelling_formula(g, *levelling_points_photo(scenario, spec, g))
    book = levelling_formula(g, *control_points(g["a"], g["c"]))
    out: dict[str, RunResult] = {}
    for k, first, last in zip(names, bounds[:-1], bounds[1:], strict=True):
        ok = replace(o, sources=k)
        plain_k, controlled_k = (
            {n: v[first:last] for n, v in d.items()} for d in (plain, controlled)
        )
        formulas = _formulas("conventional", scenario, spec, g, k, o.control, (lev, book))
        runs = ConfigurationRun(plain_k, controlled_k, d_zero, units)
        res = _result(scenario, spec, "conventional", ok, g, linkage, runs, formulas)
        out[k] = {**res, "trials": int(last - first), "seed": int(seed), "first_trial": int(first)}
    seconds = time.perf_counter() - t0
    return {k: {**v, "seconds": seconds} for k, v in out.items()}


class ConfigurationRun(NamedTuple):
    """The runs of one configuration (:func:`run_configuration`): per-trial mean squares
    (``plain``, ``controlled``; :class:`MeanSquares`), the error-free δp and the unit of each
    field [photo mm]."""

    plain: dict[FieldKey, FloatArray]
    controlled: dict[FieldKey, FloatArray]
    error_free_dp: FloatArray
    units: dict[str, float]


def run_configuration(
    scenario: Scenario,
    spec: InstrumentSpec,
    method: str,
    trials: int,
    seed: int,
    options: ProcedureOptions,
    geometry: dict[str, float],
    linkage: str,
    sources_off: Mapping[str, NDArray[np.bool_]] | None = None,
) -> ConfigurationRun:
    """The runs of :func:`procedure_mc` with ``options`` at ``geometry``
    (:func:`scenario_geometry`) and ``linkage`` (resolved: "drag" or "independent").
    ``sources_off``: key prefix → (trials,) mask of the trials whose acts of that prefix draw 0
    (:func:`conventional_sources_mc`; the run then has every source on)."""
    sources = "both" if sources_off else options.sources
    c, p, n = geometry["c"], geometry["p"], geometry["n"]
    operator = method_operator(method, options.sigma_mm, c, p, n, sources)
    unit = operator.unit_mm
    measure = None
    if method == "conventional":
        units = dict.fromkeys(CONVENTIONAL_READINGS, unit)
        sigma_control = 0.0
        if options.measure is not None:
            unknown = set(options.measure) - set(CONVENTIONAL_READINGS)
            if unknown:
                raise ValueError(
                    f"measure: expected readings among {CONVENTIONAL_READINGS}, "
                    f"found {sorted(unknown)}"
                )
            o = options
            statistic = _field_name(method, o.quantity, o.levelling, o.datum, o.control)
            measure = tuple(dict.fromkeys((*options.measure, statistic)))
    else:  # m_p = m_xy/√2 of the observed control parallaxes
        units = {"parallax": unit, "levelled": unit, "observed": unit / math.sqrt(2.0)}
        sigma_control = units["observed"]
    run = ProcedureRun(
        scenario=scenario,
        spec=replace(spec, standard_points_c_mm=c),
        method=method,
        seed=seed,
        trials=int(trials),
        operator=operator,
        geometry=geometry,
        grid=options.grid,
        variant=LINKAGE_VARIANTS[linkage],
        fidelity=options.switches(spec),
        instrument_errors=bool(options.instrument),
        control_variate=options.control_variate,
        standard_points_at_a=method == "conventional" and options.standard_points == "book",
        sigma_control_mm=sigma_control,
        sources_off=sources_off,
        decompose=options.decompose,
        measure=measure,
    )
    ms = mean_squares(run)
    return ConfigurationRun(ms.plain, ms.controlled, ms.error_free_dp, units)


def _keyed(ms: Mapping[FieldKey, FloatArray], kind: str) -> list[tuple[str, FloatArray]]:
    """(name, values) of the items of ``ms`` whose key is a tuple (``kind``, name)."""
    return [(k[1], v) for k, v in ms.items() if isinstance(k, tuple) and k[0] == kind]


def _extras(
    scenario: Scenario,
    spec: InstrumentSpec,
    method: str,
    o: ProcedureOptions,
    g: dict[str, float],
    plain: Mapping[FieldKey, FloatArray],
    best: Mapping[FieldKey, FloatArray],
    units: Mapping[str, float],
) -> dict[str, Any]:
    """The method's own parts of the result: the three readings of a setup run with their
    decompositions, or the conventional run's readings by datum and its options."""
    if method == "conventional":
        unit = units["plane"]
        datums = [k for k in CONVENTIONAL_READINGS if k in best]
        return {
            "by_datum": {k: rms_ci(best[k], unit) for k in datums},
            **{k: getattr(o, k) for k in ("quantity", "standard_points", "datum", "levelling")},
            "sources": o.sources,
        }
    fields: dict[str, dict[str, Any]] = {}
    for key, m, c in (
        ("parallax", "setup", "exact"),
        ("levelled", "setup_control", "exact"),
        ("observed", "setup_control", "observed"),
    ):
        cf, h = rms_ci(best[key], units[key])
        ref = _formulas(m, scenario, spec, g, o.sources, c)["rigorous"]
        decomposition = None
        if o.decompose:
            ms = {s: plain[(key, s)] for s, _ in dc.LEVELS}
            decomposition = dc.rms_steps(ref, {**ms, "procedure": plain[key]}, units[key])
        fields[key] = {
            "coefficient": cf,
            "ci": h,
            "plain": rms_ci(plain[key], units[key]),
            "formula": ref,
            "decomposition": decomposition,
            "mean_squares": plain[key],  # per trial, photo mm² (paired switch steps)
            "unit": units[key],
        }
    extra: dict[str, Any] = {"fields": fields}
    extra["element_rms"] = {
        name: float(np.sqrt(np.mean(v))) for name, v in _keyed(plain, "element")
    }
    if method == "setup_control":
        extra["control"] = o.control
    return extra
