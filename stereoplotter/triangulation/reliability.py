r"""Blunder detection and reliability of a bundle adjustment after Baarda.

Reference
---------
.. [1] W. Baarda, *A testing procedure for use in geodetic networks*, Netherlands Geodetic
   Commission, Publications on Geodesy 2(5), 1968 (data snooping, the B-method, internal and
   external reliability).

Every observation l (a photo coordinate x or y of a point measurement, a catalogue X, Y or height
of a control point) with a priori σ_l gets, from the cofactor matrix of its residual
Q_vv = Q_ll − A·N⁻¹·Aᵀ (its diagonal element from the selected inverse, no dense inverse):

* the redundancy number r = q_vv/σ_l² (0 < r ≤ 1; Σr = the redundancy of the adjustment);
* the standardized residual w = v/√q_vv (the a priori σ₀ = 1: Baarda's w-test), N(0, 1) when
  the observation holds no blunder;
* the minimal detectable blunder MDB = δ₀·σ_l/√r, δ₀ = k + z_{β₀}, k = z_{1−α₀/2}: a blunder
  of that size is found with probability β₀ (internal reliability);
* its effect on the point's coordinates, ∇X = Q_xx·Aᵀ·P·e·MDB (external reliability) [m], and
  Baarda's factor δ̄₀ = δ₀·√((1 − r)/r).

The test level α₀ of one w-test: by default chosen so that the block of n tested observations
has a family-wise error rate α = 5 % (Šidák: α₀ = 1 − (1 − α)^(1/n); k ≈ 4.4 for 2 000
observations) — with the classical α₀ = 0.001 (k = 3.29) a block of 2 000 observations flags
two good ones on average. β₀ = 80 % (Baarda's value). The global test of σ₀: [pvv] ~ χ²(r)
when the a priori σ hold.

Data snooping is iterated: the observation of largest |w| above k is removed (a photo
measurement with both its coordinates, a control coordinate alone; a point left with one ray
loses it too), the block readjusted from the previous solution, and the test repeated until no
|w| exceeds k.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import stats

from stereoplotter.triangulation.block import Block
from stereoplotter.triangulation.bundle import (
    Adjusted,
    BundleProblem,
    bundle_adjusted,
    centre_residuals,
    interior_orientation_covariance,
    problem,
)
from stereoplotter.triangulation.solution import BlockSolution

__all__ = [
    "ROBUST",
    "Flag",
    "GlobalTest",
    "ObservationReliability",
    "RobustResult",
    "SnoopingResult",
    "critical_values",
    "global_test",
    "observation_reliability",
    "robust",
    "snoop",
    "snooped_block",
]

#: Names of the control observations by coordinate (local X, Y and Z; Z is the height the
#: catalogue's σ_height applies to).
CONTROL_NAMES = ("X_m", "Y_m", "height_m")
PHOTO_NAMES = ("x_mm", "y_mm")
#: … and of the measured projection centres (local X, Y, Z of the antenna).
CENTRE_NAMES = ("centre_X_m", "centre_Y_m", "centre_Z_m")
#: |ρ| of two w above which the two blunders cannot be told apart (Baarda's separability).
INSEPARABLE = 0.99


def _cross(p: BundleProblem, adj: Adjusted, a: NDArray, b: NDArray) -> NDArray[np.float64]:
    """A_a·N⁻¹·A_bᵀ (m, 2, 2) for pairs of measurements a, b of the same point, A = [J_c, J_p,
    J_g] (photo elements, point, free camera parameters), from the blocks of N⁻¹ (σ-free)."""
    n = adj.normals
    i = p.obs_point[a]
    qpp = adj.solution.point_covariances[i] / adj.solution.sigma0**2
    q = adj.inverse
    jca, jcb, jpa, jpb = n.jc[a], n.jc[b], n.jp[a], n.jp[b]
    out = (
        np.einsum("nki,nij,nlj->nkl", jca, q.blocks(p.obs_photo[a], p.obs_photo[b]), jcb)
        + np.einsum("nki,nij,nlj->nkl", jca, adj.qcp[a], jpb)
        + np.einsum("nki,nji,nlj->nkl", jpa, adj.qcp[b], jcb)
        + np.einsum("nki,nij,nlj->nkl", jpa, qpp, jpb)
    )
    if n.jg is not None and adj.qgp is not None:
        jga, jgb = n.jg[a], n.jg[b]
        qgp = adj.qgp[i]
        out += (
            np.einsum("nki,nij,nlj->nkl", jca, q.cg(p.obs_photo[a]), jgb)
            + np.einsum("nki,nji,nlj->nkl", jga, q.cg(p.obs_photo[b]), jcb)
            + np.einsum("nki,nji,nlj->nkl", jpa, qgp, jgb)
            + np.einsum("nki,nij,nlj->nkl", jga, qgp, jpb)
            + np.einsum("nki,ij,nlj->nkl", jga, q.qgg, jgb)
        )
    return out


def _w_correlations(p: BundleProblem, adj: Adjusted, o: int, c: int) -> tuple[NDArray, NDArray]:
    """ρ of w of photo coordinate (o, c) with every coordinate of the measurements of its
    point, (m, 2), and those measurements' rows. Q_vv,ab = Q_ll,ab − A_a·N⁻¹·A_bᵀ."""
    rows = np.flatnonzero(p.obs_point == p.obs_point[o])
    sig2 = 1.0 / p.photo_weights()[rows]
    qvv = -_cross(p, adj, np.full(rows.size, o), rows)[:, c, :]
    own = rows == o
    qvv[own, c] += sig2[own, c]
    diag = np.maximum(sig2 - np.einsum("nkk->nk", _cross(p, adj, rows, rows)), 1e-12 * sig2)
    rho = qvv / np.sqrt(diag * diag[own, c][0])
    return rho, rows


def critical_values(n_tests: int, alpha: float = 0.05, beta0: float = 0.80, alpha0=None):
    """(α₀, k, δ₀): the level of one w-test, its critical value and the non-centrality of a
    blunder found with probability β₀. α₀ by Šidák from the family-wise α over ``n_tests``
    unless given."""
    if alpha0 is None:
        alpha0 = 1.0 - (1.0 - alpha) ** (1.0 / max(1, n_tests))
    k = float(stats.norm.isf(alpha0 / 2.0))
    return float(alpha0), k, k + float(stats.norm.ppf(beta0))


@dataclass(frozen=True, slots=True)
class GlobalTest:
    """The χ² test of σ₀: [pvv] against χ²(r) at level α (two-sided): ``sigma0``, the
    ``redundancy``, ``p_value`` (of a σ₀ at least this far from 1), the acceptance interval
    of σ₀ (``low``, ``high``) and ``passed``."""

    sigma0: float
    redundancy: int
    p_value: float
    low: float
    high: float
    passed: bool


def global_test(sigma0: float, redundancy: int, alpha: float = 0.05) -> GlobalTest:
    """:class:`GlobalTest` of σ₀ on ``redundancy`` degrees of freedom."""
    chi = sigma0**2 * redundancy
    lo = float(np.sqrt(stats.chi2.ppf(alpha / 2, redundancy) / redundancy))
    hi = float(np.sqrt(stats.chi2.isf(alpha / 2, redundancy) / redundancy))
    p = 2.0 * min(float(stats.chi2.cdf(chi, redundancy)), float(stats.chi2.sf(chi, redundancy)))
    return GlobalTest(sigma0, redundancy, p, lo, hi, lo <= sigma0 <= hi)


@dataclass(frozen=True, slots=True)
class ObservationReliability:
    """Per observation of a bundle problem.

    Photo coordinates, shape (n_obs, 2) for x, y: ``photo_v`` [mm], ``photo_r`` [—],
    ``photo_w`` [—], ``photo_mdb`` [mm], ``photo_effect`` (n_obs, 2) |∇X| of the point
    [m]; control coordinates, shape (n_control, 3) for X, Y, Z (NaN where not given):
    ``control_v`` [m], ``control_r``, ``control_w``, ``control_mdb`` [m],
    ``control_effect`` [m]; measured projection centres, shape (n_centres, 3) for X, Y, Z:
    ``centre_v`` [m], ``centre_r``, ``centre_w``, ``centre_mdb`` [m]. ``delta0`` and ``k`` of
    :func:`critical_values`.
    """

    photo_v: NDArray[np.float64]
    photo_r: NDArray[np.float64]
    photo_w: NDArray[np.float64]
    photo_mdb: NDArray[np.float64]
    photo_effect: NDArray[np.float64]
    control_v: NDArray[np.float64]
    control_r: NDArray[np.float64]
    control_w: NDArray[np.float64]
    control_mdb: NDArray[np.float64]
    control_effect: NDArray[np.float64]
    centre_v: NDArray[np.float64]
    centre_r: NDArray[np.float64]
    centre_w: NDArray[np.float64]
    centre_mdb: NDArray[np.float64]
    alpha0: float
    k: float
    delta0: float

    @property
    def n_tests(self) -> int:
        return int(
            self.photo_w.size
            + np.count_nonzero(np.isfinite(self.control_w))
            + np.count_nonzero(np.isfinite(self.centre_w))
        )


# long: Q_vv of the photo and control observations, then w, r, MDB and the effect, vectorised
def observation_reliability(
    p: BundleProblem, adj: Adjusted, alpha: float = 0.05, beta0: float = 0.80, alpha0=None
) -> ObservationReliability:
    """:class:`ObservationReliability` of every observation of a converged adjustment (with
    covariances)."""
    if adj.inverse is None or adj.qcp is None:
        raise ValueError("the adjustment was made without covariances")
    n, s = adj.normals, adj.solution
    sig2 = 1.0 / p.photo_weights()  # (n_obs, 2) [mm²]
    qpp = s.point_covariances / s.sigma0**2
    jc, jp, qcp = n.jc, n.jp, adj.qcp
    qpi = qpp[p.obs_point]
    every = np.arange(p.obs_photo.size)
    hat = np.einsum("nkk->nk", _cross(p, adj, every, every))  # diag of A·Q·Aᵀ per measurement
    qvv = np.maximum(sig2 - hat, 1e-12 * sig2)
    pr = qvv / sig2
    pv = n.v
    # the point's shift by a unit error of each coordinate: Q_p,x·Aᵀ·P·e
    effect = np.einsum("nji,nkj->nki", qcp, jc) + np.einsum("nij,nkj->nki", qpi, jp)
    if n.jg is not None and adj.qgp is not None:
        effect += np.einsum("nji,nkj->nki", adj.qgp[p.obs_point], n.jg)
    effect /= sig2[:, :, None]
    nc = p.control_point.size
    with np.errstate(divide="ignore", invalid="ignore"):
        given = p.control_weight > 0
        sc2 = np.where(given, 1.0 / np.where(given, p.control_weight, 1.0), np.nan)
        qc = qpp[p.control_point]
        cq = np.where(given, np.maximum(sc2 - np.einsum("nii->ni", qc), 1e-12 * sc2), np.nan)
        cr = cq / sc2
        cv = np.where(given, p.control_m - s.points_m[p.control_point], np.nan)
        ceff = np.where(given[:, :, None], np.swapaxes(qc, 1, 2) / sc2[:, :, None], np.nan)
    gv, gr, gq, gs2 = _centre_cofactors(p, adj)
    n_tests = pv.size + int(np.count_nonzero(given)) + int(np.count_nonzero(np.isfinite(gq)))
    a0, k, d0 = critical_values(n_tests, alpha, beta0, alpha0)
    pmdb = d0 * np.sqrt(sig2 / pr)
    with np.errstate(invalid="ignore"):
        cmdb = d0 * np.sqrt(sc2 / cr)
        c_effect = np.linalg.norm(ceff, axis=2) * cmdb if nc else np.zeros((0, 3))
    return ObservationReliability(
        pv,
        pr,
        pv / np.sqrt(qvv),
        pmdb,
        np.linalg.norm(effect, axis=2) * pmdb,
        cv,
        cr,
        cv / np.sqrt(cq),
        cmdb,
        c_effect,
        gv,
        gr,
        gv / np.sqrt(gq),
        d0 * np.sqrt(gs2 / gr),
        a0,
        k,
        d0,
    )


def _centre_cofactors(p: BundleProblem, adj: Adjusted):
    """Residual, redundancy number, q_vv and a priori variance (n_centres, 3) of the measured
    projection centres (NaN where a coordinate is not weighted)."""
    if not p.centre_photo.size:
        empty = np.zeros((0, 3))
        return empty, empty, empty, empty
    v, jg = centre_residuals(p, adj.solution.orientations)
    qcc = adj.inverse.blocks(p.centre_photo, p.centre_photo)
    hat = np.einsum("nki,nij,nkj->nk", jg, qcc, jg)
    given = p.centre_weight > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        s2 = np.where(given, 1.0 / np.where(given, p.centre_weight, 1.0), np.nan)
        q = np.where(given, np.maximum(s2 - hat, 1e-12 * s2), np.nan)
    return np.where(given, v, np.nan), q / s2, q, s2


@dataclass(frozen=True, slots=True)
class Flag:
    """An observation data snooping found: ``photo`` ('' for a catalogue observation),
    ``point`` ('' for a measured projection centre), ``observation`` (x_mm, y_mm, X_m, Y_m,
    height_m, centre_X_m, centre_Y_m, centre_Z_m), ``w`` and ``mdb`` (in the
    observation's unit) when it was the largest |w| above k, ``round`` of the snooping;
    ``inseparable`` the other observations of the point whose w correlates with this one's by
    |ρ| ≥ :data:`INSEPARABLE` ("photo x_mm"): the blunder is found but cannot be told from
    them (e.g. x on a point of three photos of one strip), and all of them were removed."""

    photo: str
    point: str
    observation: str
    w: float
    mdb: float
    round: int
    inseparable: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True)
class SnoopingResult:
    """Iterated data snooping: the first adjustment (all observations) and the last (the flagged
    ones removed), their problems, the flags in order, the reliability of the last, its global
    test, of the measurements of the first problem those kept in the last (``kept``), and the
    reliability and global test of the first."""

    first: Adjusted
    last: Adjusted
    problem_first: BundleProblem
    problem_last: BundleProblem
    flags: tuple[Flag, ...]
    reliability: ObservationReliability
    global_test: GlobalTest
    kept: NDArray[np.bool_]
    reliability_first: ObservationReliability
    global_test_first: GlobalTest
    method: str = "snooping"


def _remove_measurement(p: BundleProblem, keep: NDArray[np.bool_]) -> BundleProblem:
    """The problem with the measurements of ``keep`` only; points left with one ray lose it,
    control of points without two rays is dropped."""
    rays = np.bincount(p.obs_point[keep], minlength=p.n_points)
    keep = keep & (rays[p.obs_point] >= 2)
    rays = np.bincount(p.obs_point[keep], minlength=p.n_points)
    ck = rays[p.control_point] >= 2
    return dataclasses.replace(
        p,
        xy_mm=p.xy_mm[keep],
        obs_photo=p.obs_photo[keep],
        obs_point=p.obs_point[keep],
        obs_index=p.obs_index[keep],
        photo_factor=None if p.photo_factor is None else p.photo_factor[keep],
        control_point=p.control_point[ck],
        control_m=p.control_m[ck],
        control_weight=p.control_weight[ck],
    )


def snoop(
    p: BundleProblem,
    *,
    alpha: float = 0.05,
    beta0: float = 0.80,
    alpha0: float | None = None,
    max_rounds: int = 50,
    first: Adjusted | None = None,
) -> SnoopingResult:
    """Iterated data snooping of a bundle problem (module docstring). k is fixed by the number of
    observations of the first adjustment."""
    adj0 = first if first is not None else bundle_adjusted(p)
    rel = rel0 = observation_reliability(p, adj0, alpha, beta0, alpha0)
    a0 = rel.alpha0
    adj, q, flags = adj0, p, []
    for rnd in range(1, max_rounds + 1):
        removed = _remove_largest(q, adj, rel, rnd)
        if removed is None:
            break
        q, flag = removed
        flags.append(flag)
        s = adj.solution
        start = (s.orientations, np.where(np.isfinite(s.points_m), s.points_m, 0.0))
        adj = bundle_adjusted(q, start)
        rel = observation_reliability(q, adj, alpha, beta0, a0)
    kept = np.isin(p.obs_index, q.obs_index)
    g = global_test(adj.solution.sigma0, adj.redundancy, alpha)
    g0 = global_test(adj0.solution.sigma0, adj0.redundancy, alpha)
    return SnoopingResult(adj0, adj, p, q, tuple(flags), rel, g, kept, rel0, g0)


def _largest(
    w: NDArray[np.float64], nan_as_zero: bool = True
) -> tuple[tuple[int, ...] | None, float]:
    """Index and value of the largest |w| (NaN as 0 when ``nan_as_zero``); (None, 0) when
    there is none."""
    aw = np.nan_to_num(np.abs(w), nan=0.0) if nan_as_zero else np.abs(w)
    if not aw.size:
        return None, 0.0
    best = np.unravel_index(int(np.argmax(aw)), aw.shape)
    return best, aw[best]


def _remove_largest(
    q: BundleProblem, adj: Adjusted, rel: ObservationReliability, rnd: int
) -> tuple[BundleProblem, Flag] | None:
    """One round of data snooping: the observation with the largest |w| flagged and removed
    (the problem without it and its flag), or None when no |w| is above k. A centre coordinate
    goes only when its |w| is strictly the largest; on a tie a photo coordinate goes before a
    control coordinate."""
    best_p, wp = _largest(rel.photo_w, nan_as_zero=False)
    best_c, wc = _largest(rel.control_w)
    best_g, wg = _largest(rel.centre_w)
    if max(wp, wc, wg) <= rel.k:
        return None
    if wg > max(wp, wc):
        return _remove_centre(q, rel, best_g, rnd)
    if wp >= wc:
        return _remove_photo_measurement(q, adj, rel, best_p, rnd)
    return _remove_control(q, rel, best_c, rnd)


def _remove_centre(
    q: BundleProblem, rel: ObservationReliability, best: tuple[int, ...], rnd: int
) -> tuple[BundleProblem, Flag]:
    """A measured projection centre's coordinate flagged and given weight 0."""
    g, c = best
    flag = Flag(
        q.photo_ids[q.centre_photo[g]],
        "",
        CENTRE_NAMES[c],
        float(rel.centre_w[g, c]),
        float(rel.centre_mdb[g, c]),
        rnd,
    )
    weight = q.centre_weight.copy()
    weight[g, c] = 0.0
    return dataclasses.replace(q, centre_weight=weight), flag


def _remove_photo_measurement(
    q: BundleProblem,
    adj: Adjusted,
    rel: ObservationReliability,
    best: tuple[int, ...],
    rnd: int,
) -> tuple[BundleProblem, Flag]:
    """A photo measurement flagged and removed, with the measurements whose w it cannot be
    told from (|ρ| ≥ :data:`INSEPARABLE`)."""
    o, c = best
    rho, rows = _w_correlations(q, adj, o, c)
    alike = np.abs(rho) >= INSEPARABLE
    alike[rows == o, c] = False
    others = tuple(
        f"{q.photo_ids[q.obs_photo[rows[b]]]} {PHOTO_NAMES[d]}"
        for b, d in zip(*np.nonzero(alike), strict=True)
    )
    flag = Flag(
        q.photo_ids[q.obs_photo[o]],
        q.point_ids[q.obs_point[o]],
        PHOTO_NAMES[c],
        float(rel.photo_w[o, c]),
        float(rel.photo_mdb[o, c]),
        rnd,
        others,
    )
    keep = np.ones(q.obs_photo.size, bool)
    keep[o] = False
    keep[rows[np.any(alike, axis=1)]] = False
    return _remove_measurement(q, keep), flag


def _remove_control(
    q: BundleProblem, rel: ObservationReliability, best: tuple[int, ...], rnd: int
) -> tuple[BundleProblem, Flag]:
    """A control coordinate flagged and given weight 0."""
    k, c = best
    flag = Flag(
        "",
        q.point_ids[q.control_point[k]],
        CONTROL_NAMES[c],
        float(rel.control_w[k, c]),
        float(rel.control_mdb[k, c]),
        rnd,
    )
    weight = q.control_weight.copy()
    weight[k, c] = 0.0
    return dataclasses.replace(q, control_weight=weight), flag


def snooped_block(
    block: Block,
    *,
    reject: bool = False,
    alpha: float = 0.05,
    alpha0: float | None = None,
    self_calibration: tuple[str, ...] = (),
    robust_method: str | None = None,
) -> tuple[BlockSolution, SnoopingResult]:
    """Bundle adjustment of a block with iterated data snooping: the solution of all
    observations, or with ``reject`` the one without the flagged observations; each photo's
    covariance includes its interior orientation's, as :func:`~stereoplotter.triangulation.
    bundle.bundle_block` gives it. ``self_calibration``: the camera parameters adjusted with the
    block (:func:`~stereoplotter.triangulation.bundle.problem`). ``robust_method`` (one of
    :data:`ROBUST`): robust re-weighting instead of data snooping; its solution is the
    re-weighted one (``reject`` implied) and its flags the observations it down-weighted."""
    p = problem(block, self_calibration)
    if robust_method is not None:
        first = bundle_adjusted(p)
        rb = robust(p, robust_method, alpha=alpha, alpha0=alpha0, first=first)
        rel0 = observation_reliability(p, first, alpha, 0.80, alpha0)
        result = SnoopingResult(
            first,
            rb.adjusted,
            p,
            rb.problem,
            rb.flags,
            rb.reliability,
            global_test(rb.adjusted.solution.sigma0, rb.adjusted.redundancy, alpha),
            np.ones(p.obs_photo.size, bool),
            rel0,
            global_test(first.solution.sigma0, first.redundancy, alpha),
            f"robust ({robust_method}, {rb.iterations} rounds)",
        )
        reject = True
    else:
        result = snoop(p, alpha=alpha, alpha0=alpha0)
    adj, q = (result.last, result.problem_last) if reject else (result.first, p)
    s = adj.solution
    extra = interior_orientation_covariance(block, q, s)
    notes = (*s.notes, "σ of the elements include the interior orientation's (4 marks per photo)")
    if robust_method is not None:
        notes = (*notes, f"{result.method}: {len(result.flags)} observations down-weighted")
    elif reject and result.flags:
        notes = (*notes, f"{len(result.flags)} flagged observations removed (--reject)")
    return dataclasses.replace(s, covariances=s.covariances + extra, notes=notes), result


#: The robust weight functions of the standardized residual t (c the critical value k):
#: Huber f = min(1, c/|t|); Danish (exponential) f = 1 for |t| ≤ c, exp(1 − |t|/c) beyond.
ROBUST = ("huber", "danish")


def _robust_factor(t: NDArray, c: float, method: str) -> NDArray:
    a = np.abs(np.nan_to_num(t, nan=0.0))
    if method == "huber":
        return np.minimum(1.0, c / np.maximum(a, 1e-300))
    return np.where(a <= c, 1.0, np.exp(1.0 - a / c))


@dataclass(frozen=True, slots=True)
class RobustResult:
    """Robust re-weighting: the last adjustment and its problem (weights scaled), the weight
    factors of the photo coordinates (n_obs, 2) and control coordinates (n_control, 3), the
    standardized residuals t of the last adjustment with the a priori σ, the observations
    whose factor fell below 1 as :class:`Flag` (w = t), its reliability and iterations."""

    adjusted: Adjusted
    problem: BundleProblem
    photo_factor: NDArray[np.float64]
    control_factor: NDArray[np.float64]
    flags: tuple[Flag, ...]
    reliability: ObservationReliability
    iterations: int


# long: iteratively re-weighted least squares with the tests' standardized residuals
def robust(
    p: BundleProblem,
    method: str = "danish",
    *,
    alpha: float = 0.05,
    beta0: float = 0.80,
    alpha0: float | None = None,
    max_iterations: int = 20,
    first: Adjusted | None = None,
) -> RobustResult:
    """Robust re-weighting of a bundle problem (iteratively re-weighted least squares).

    Each round: t = v/(σ·√r) with the a priori σ of each observation and its redundancy number
    r in the current adjustment (the w-test's statistic had the observation its a priori weight);
    the weight factor f(t) of :data:`ROBUST` with c = k of :func:`critical_values`; readjust,
    until no factor changes by more than 0.01 (at most ``max_iterations`` rounds). Photo and
    control coordinates are re-weighted; measured centres keep their weights.
    """
    if method not in ROBUST:
        raise ValueError(f"robust: expected one of {', '.join(ROBUST)}, found {method!r}")
    adj = first if first is not None else bundle_adjusted(p)
    rel = observation_reliability(p, adj, alpha, beta0, alpha0)
    k = rel.k
    fp = np.ones(p.xy_mm.shape)
    fc = np.ones(p.control_weight.shape)
    q = p
    for it in range(1, max_iterations + 1):  # noqa: B007 (reported after the loop)
        # t = v/(σ·√r): w = v/√q_vv had σ²/f for the weight, so t = w/√f
        tp = rel.photo_w / np.sqrt(fp)
        with np.errstate(invalid="ignore"):
            tc = rel.control_w / np.sqrt(fc)
        new_p = _robust_factor(tp, k, method)
        new_c = np.where(p.control_weight > 0, _robust_factor(tc, k, method), 1.0)
        change = max(float(np.max(np.abs(new_p - fp), initial=0.0)),
                     float(np.max(np.abs(new_c - fc), initial=0.0)))  # fmt: skip
        fp, fc = new_p, new_c
        q = dataclasses.replace(p, photo_factor=fp, control_weight=p.control_weight * fc)
        s = adj.solution
        start = (s.orientations, np.where(np.isfinite(s.points_m), s.points_m, 0.0))
        adj = bundle_adjusted(q, start)
        rel = observation_reliability(q, adj, alpha, beta0, rel.alpha0)
        if change <= 0.01:
            break
    flags = [
        Flag(q.photo_ids[q.obs_photo[o]], q.point_ids[q.obs_point[o]], PHOTO_NAMES[c],
             float(rel.photo_w[o, c] / np.sqrt(fp[o, c])), float(rel.photo_mdb[o, c]), it)
        for o, c in zip(*np.nonzero(fp < 1.0), strict=True)
    ]  # fmt: skip
    flags += [
        Flag("", q.point_ids[q.control_point[j]], CONTROL_NAMES[c],
             float(rel.control_w[j, c] / np.sqrt(fc[j, c])), float(rel.control_mdb[j, c]), it)
        for j, c in zip(*np.nonzero(fc < 1.0), strict=True)
    ]  # fmt: skip
    flags.sort(key=lambda f: -abs(f.w))
    return RobustResult(adj, q, fp, fc, tuple(flags), rel, it)
