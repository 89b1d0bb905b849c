"""Triangulation → setup: forms from triangulated orientations against forms from the truth.

:func:`chain_comparison` computes every pair's sheet twice — from the job written by
``triangulate`` and from the job of the true orientations (``block synth`` writes it) — and the
σ of each sheet value propagated from the triangulation's 12 × 12 covariance of the pair's two
photos (linear: central differences of the sheet in each of the 12 elements, all perturbed
pairs in one vectorised Table 24 call,
:func:`stereoplotter.setup.sheet.compute_sheets_from_measurements`). A value agrees when
|triangulated − true| ≤ k·σ. Values the instrument fixes (σ < 10⁻⁹ of their unit: n_left and
b_y of the SC-1) are left out.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from stereoplotter.commands.setup_job import compute_job
from stereoplotter.geometry.rotation import angles_from_matrix, rotation_matrix
from stereoplotter.io.job_file import Job, load_job
from stereoplotter.setup.records import SetupOptions, SetupSheet
from stereoplotter.setup.sheet import compute_sheets_from_measurements
from stereoplotter.triangulation.block import Block
from stereoplotter.triangulation.solution import BlockSolution

__all__ = ["QUANTITIES", "ChainRow", "chain_comparison", "chain_markdown"]

#: Sheet values compared: name, unit, extractor.
QUANTITIES = (
    ("n_left", "—", lambda s: s.n_left),
    ("n_right", "—", lambda s: s.n_right),
    ("bx", "mm", lambda s: s.base_mm[0]),
    ("by", "mm", lambda s: s.base_mm[1]),
    ("bz", "mm", lambda s: s.base_mm[2]),
    ("alpha_left", "rad", lambda s: s.photos[0].alpha),
    ("omega_left", "rad", lambda s: s.photos[0].omega),
    ("kappa_left", "rad", lambda s: s.photos[0].kappa),
    ("alpha_right", "rad", lambda s: s.photos[1].alpha),
    ("omega_right", "rad", lambda s: s.photos[1].omega),
    ("kappa_right", "rad", lambda s: s.photos[1].kappa),
    ("L_left", "mm", lambda s: s.photos[0].mark_span_mm),
    ("L_right", "mm", lambda s: s.photos[1].mark_span_mm),
)
_FIXED = 1e-9  # σ below this: a value the instrument fixes
_STEP = np.array([1e-6, 1e-6, 1e-6, 1e-3, 1e-3, 1e-3])  # rad, m: well inside the linear range


@dataclass(frozen=True, slots=True)
class ChainRow:
    """One sheet value of one pair: triangulated, true, their difference and its σ."""

    pair: str
    quantity: str
    unit: str
    triangulated: float
    true: float
    sigma: float

    @property
    def ratio(self) -> float:
        """|triangulated − true| / σ. [—]"""
        return abs(self.triangulated - self.true) / self.sigma if self.sigma > _FIXED else np.inf


def _values(sheet: SetupSheet) -> NDArray[np.float64]:
    return np.array([get(sheet) for _, _, get in QUANTITIES], float)


def _perturbed(args: dict, k: int, sign: float) -> dict:
    """The pair's sheet arguments with element k (0–11: left α ω κ X Y Z, right …) moved."""
    photo, e = divmod(k, 6)
    centres = np.array(args["centres_m"], float).copy()
    rotations = np.array(args["rotations"], float).copy()
    if e < 3:
        angles = np.array(angles_from_matrix(rotations[photo]), float)
        angles[e] += sign * _STEP[e]
        rotations[photo] = rotation_matrix(*angles)
    else:
        centres[photo, e - 3] += sign * _STEP[e]
    return {**args, "centres_m": centres, "rotations": rotations}


def _drawn(args: dict, deltas: NDArray) -> list[dict]:
    """The pair's sheet arguments with its 12 elements moved by each row of ``deltas``."""
    out = []
    centres = np.array(args["centres_m"], float)
    angles = [np.array(angles_from_matrix(m), float) for m in np.array(args["rotations"], float)]
    for d in deltas:
        rot = np.array([rotation_matrix(*(angles[k] + d[6 * k : 6 * k + 3])) for k in range(2)])
        out.append({**args, "centres_m": centres + d.reshape(2, 6)[:, 3:], "rotations": rot})
    return out


def chain_comparison(
    job_path: str | os.PathLike[str],
    truth_job_path: str | os.PathLike[str],
    block: Block,
    solution: BlockSolution,
    draws: int = 0,
    rng: np.random.Generator | None = None,
) -> list[ChainRow]:
    """Every accepted pair's sheet values, triangulated against true, with propagated σ.

    The jobs must be the block's (pairs of consecutive photos; local frame, as
    :mod:`stereoplotter.io.triangulated_job` writes them); ``solution`` must carry covariances.
    ``draws`` = 0: linear propagation (central differences); > 0: Monte Carlo, the σ of the
    sheet values over ``draws`` draws of the pair's 12 elements from their covariance (with
    ``rng``) — needed for values that depend on the tilts to second order near zero tilt (the
    mark spans L), where the linear σ vanishes.
    """
    if draws:
        return _chain_monte_carlo(job_path, truth_job_path, block, solution, draws, rng)
    job, truth = load_job(job_path), load_job(truth_job_path)
    tri, ref = compute_job(job), compute_job(truth)
    options = _options(job)
    index = {p: j for j, p in enumerate(block.photos)}
    rows: list[ChainRow] = []
    ready = [(p, q) for p, q in zip(tri.pairs, ref.pairs, strict=True) if p.sheet and q.sheet]
    batch = []
    for p, _ in ready:
        assert p.measured is not None
        args = p.measured.sheet_arguments()
        batch += [_perturbed(args, k, s) for k in range(12) for s in (1.0, -1.0)]
    sheets = compute_sheets_from_measurements(
        batch, spec=tri.spec, options=options, source=job.source, name=job.name
    )
    for n, (p, q) in enumerate(ready):
        assert p.sheet is not None and q.sheet is not None
        plus_minus = sheets[24 * n : 24 * (n + 1)]
        if any(not isinstance(s, SetupSheet) for s in plus_minus):
            continue
        v = np.array([_values(s) for s in plus_minus]).reshape(12, 2, -1)
        jac = (v[:, 0] - v[:, 1]).T / (2.0 * np.tile(_STEP, 2))
        cov = solution.pair_covariance(index[str(p.pair.left)])
        assert cov is not None, "the solution has no covariances"
        sigma = np.sqrt(np.einsum("qi,ij,qj->q", jac, cov, jac))
        a, b = _values(p.sheet), _values(q.sheet)
        rows += [
            ChainRow(p.pair.name, name, unit, float(a[i]), float(b[i]), float(sigma[i]))
            for i, (name, unit, _) in enumerate(QUANTITIES)
        ]
    return rows


def _chain_monte_carlo(job_path, truth_job_path, block, solution, draws, rng) -> list[ChainRow]:
    rng = rng if rng is not None else np.random.default_rng(0)
    job, truth = load_job(job_path), load_job(truth_job_path)
    tri, ref = compute_job(job), compute_job(truth)
    index = {p: j for j, p in enumerate(block.photos)}
    ready = [(p, q) for p, q in zip(tri.pairs, ref.pairs, strict=True) if p.sheet and q.sheet]
    batch = []
    for p, _ in ready:
        assert p.measured is not None
        cov = solution.pair_covariance(index[str(p.pair.left)])
        assert cov is not None, "the solution has no covariances"
        deltas = rng.multivariate_normal(np.zeros(12), cov, size=draws)
        batch += _drawn(p.measured.sheet_arguments(), deltas)
    sheets = compute_sheets_from_measurements(
        batch, spec=tri.spec, options=_options(job), source=job.source, name=job.name
    )
    rows: list[ChainRow] = []
    for n, (p, q) in enumerate(ready):
        assert p.sheet is not None and q.sheet is not None
        drawn = [s for s in sheets[draws * n : draws * (n + 1)] if isinstance(s, SetupSheet)]
        sigma = np.std(np.array([_values(s) for s in drawn]), axis=0, ddof=1)
        a, b = _values(p.sheet), _values(q.sheet)
        rows += [
            ChainRow(p.pair.name, name, unit, float(a[i]), float(b[i]), float(sigma[i]))
            for i, (name, unit, _) in enumerate(QUANTITIES)
        ]
    return rows


def _options(job: Job) -> SetupOptions:
    return SetupOptions(
        book_sign_n_right=job.book_sign,
        horizontal_scale_denominator=job.horizontal_scale,
        vertical_scale_denominator=job.vertical_scale,
        bz_scale_sense=job.bz_scale_sense,
    )


def chain_markdown(rows: list[ChainRow], k: float) -> str:
    """A table per quantity: pairs, max |Δ|/σ, RMS Δ/σ, and whether all agree within k·σ."""
    lines = [
        "| quantity | unit | pairs | RMS Δ | RMS σ | max \\|Δ\\|/σ | RMS Δ/σ |",
        "|---|---|---:|---:|---:|---:|---:|",
    ]
    for name, unit, _ in QUANTITIES:
        r = [x for x in rows if x.quantity == name and x.sigma > _FIXED]
        if not r:
            continue
        d = np.array([x.triangulated - x.true for x in r])
        s = np.array([x.sigma for x in r])
        lines.append(
            f"| {name} | {unit} | {len(r)} | {np.sqrt(np.mean(d**2)):.3g} | "
            f"{np.sqrt(np.mean(s**2)):.3g} | {np.max(np.abs(d) / s):.2f} | "
            f"{np.sqrt(np.mean((d / s) ** 2)):.2f} |"
        )
    worst = max((x.ratio for x in rows if x.sigma > _FIXED), default=0.0)
    lines += ["", f"All values within {k:g}σ: {'yes' if worst <= k else 'no'} (max {worst:.2f}σ)."]
    return "\n".join(lines) + "\n"
