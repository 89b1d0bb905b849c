"""Procedure Monte Carlo of the conventional relative orientation alone against (5.54): the
simulated operator's C1 and C2 by (5.11) on an ideal instrument with only the y-parallax
judgment error (``docs/accuracy.md``, "The conventional relative orientation alone against
(5.54)"). The geometry helpers are the procedure Monte Carlo's (``procedure_geometry``)."""

from __future__ import annotations

import math
import time
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np

from stereoplotter.accuracy.chapter5 import levelling_design, relative_orientation_parallax_rms
from stereoplotter.procedure import conventional as cv
from stereoplotter.procedure.operator import OperatorModel
from stereoplotter.procedure.run import build_run
from stereoplotter.procedure.simulate import prepare_run
from stereoplotter.verification.linear_mc import CI_Z, FloatArray
from stereoplotter.verification.procedure_geometry import (
    control_frame_points,
    domain_points,
    dp_at,
    idealised_geometry,
    scenario_geometry,
    standard_points_at_a,
)

if TYPE_CHECKING:
    from stereoplotter.procedure.run import PreparedRun, Run
    from stereoplotter.scenario.model import Scenario
    from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = ["relative_orientation_mc"]


def _relative_only(prep: PreparedRun, first: int, trials: int | None) -> Run:
    """C1, the calibration and C2 by (5.11) on trials ``first … first + trials − 1`` (None: one
    error-free trial); returns the run."""

    # rigid screws whatever ``prep`` says: the experiment isolates the relative orientation;
    # "book": no remedy between C1 and C2 (the run is not the simulated procedure)
    run = build_run(prep, first, trials, transcript=False, ideal_mechanics=True, practice="book")
    cv.c1_interior(run)
    cal = cv.calibrate(run, cv.levelling_points(run.scene, run.sheet))
    cv.c2_relative_by_equations(run, cal, passes=prep.operator.max_iterations)
    return run


def _midpoint_grid(c: float, grid: tuple[int, int]) -> tuple[FloatArray, FloatArray]:
    """The midpoints of an nx × ny grid over x_п ∈ [−c, 0], y ∈ [−c, c], flattened. [mm]"""
    nx, ny = grid
    xs = -c + (np.arange(nx) + 0.5) * c / nx
    ys = -c + (np.arange(ny) + 0.5) * 2 * c / ny
    x, y = np.meshgrid(xs, ys, indexing="ij")
    return x.ravel(), y.ravel()


def relative_orientation_mc(
    scenario: Scenario,
    *,
    spec: InstrumentSpec,
    trials: int = 2000,
    seed: int = 20240601,
    sigma_mm: float = 0.01,
    ideal_geometry: bool = False,
    chunk: int = 2000,
    grid: tuple[int, int] = (16, 32),
) -> dict[str, Any]:
    """Procedure MC of the conventional relative orientation alone, the quantity of (5.54).

    The simulated operator runs C1 and C2 by the six measured q and (5.11) on an ideal instrument
    (no injected errors, ideal mechanics, exact counters) with only the y-parallax judgment
    error σ_q; standard points at Fig. 39 with a = c − p and ordinate c; a fixed number of passes
    (``OperatorModel.max_iterations``). The statistic: RMS over trials and the midpoint grid of
    x_п ∈ [−c, 0], y ∈ [−c, c] of δp (this run minus the error-free run) after removing the
    least-squares plane through δp at the four control points x_п ∈ {−c, a}, y = ±c (the
    error-free levelling (5.54) assumes), per m_q = σ_q. CI: ``CI_Z`` standard errors.

    ``ideal_geometry``: run on :func:`idealised_geometry` (vertical photos, flat terrain).

    Returns
    -------
    dict
        ``coefficient``, ``ci``, ``formula`` ((5.54) rigorous at the simulated a, c, p),
        ``unlevelled`` (RMS/σ_q without the plane removal), ``trials``, geometry, ``seconds``.
    """
    t0 = time.perf_counter()
    sc = idealised_geometry(scenario) if ideal_geometry else scenario
    g = scenario_geometry(sc, spec)
    spec = replace(spec, standard_points_c_mm=g["c"])
    zero = OperatorModel().zero()
    preps = [
        standard_points_at_a(
            prepare_run(sc, spec, "conventional", "zero", seed, operator=o, ideal_mechanics=True),
            g,
        )
        for o in (zero, replace(zero, y_parallax_sigma_mm=sigma_mm))
    ]
    run0 = _relative_only(preps[0], 0, None)
    sheet = run0.sheet
    pts = domain_points(
        sc, sheet, (g["p"] - g["c"], g["p"]), g["c"], g["p"], g["f"], g["flying_height_m"], grid
    )
    cpts, xc, yc = control_frame_points(sc, sheet, g)
    d0, d0c = (dp_at(sc, sheet, run0.op.inst, q) for q in (pts, cpts))
    xg, yg = _midpoint_grid(g["c"], grid)
    plane = levelling_design(xg, yg) @ np.linalg.pinv(levelling_design(xc, yc))
    ms = np.empty(int(trials))
    raw = np.empty(int(trials))
    for first in range(0, int(trials), int(chunk)):
        n = min(int(chunk), int(trials) - first)
        run = _relative_only(preps[1], first, n)
        d = dp_at(sc, sheet, run.op.inst, pts) - d0
        dc = dp_at(sc, sheet, run.op.inst, cpts) - d0c
        ms[first : first + n] = np.mean((d - dc @ plane.T) ** 2, axis=-1)
        raw[first : first + n] = np.mean(d**2, axis=-1)
    mean_ms = float(np.mean(ms))
    rms = math.sqrt(mean_ms)
    half = CI_Z * rms * (float(np.std(ms, ddof=1)) / math.sqrt(len(ms))) / (2.0 * mean_ms)
    formula = float(relative_orientation_parallax_rms(g["a"], g["c"], g["p"], 1.0, "rigorous"))
    return {
        "scenario": scenario.name,
        "ideal_geometry": bool(ideal_geometry),
        "trials": int(trials),
        "seed": int(seed),
        "sigma_mm": sigma_mm,
        "coefficient": rms / sigma_mm,
        "ci": half / sigma_mm,
        "formula": formula,
        "unlevelled": math.sqrt(float(np.mean(raw))) / sigma_mm,
        "seconds": time.perf_counter() - t0,
        **g,
    }
