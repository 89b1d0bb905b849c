r"""Bundle block adjustment: every ray of every photo at once, on the collinearity equations.

Reference
---------
.. [1] Kushtin & Lyskov, *Фотограмметрия снимка и стереоскопических моделей*, Nedra, 1984, ch. 2,
   §13, Eqs. (2.50), (2.53); ch. 3, §17, Eqs. (3.6)–(3.11) (the resection this generalises).

The unknowns are the six elements (α, ω, κ, X_S, Y_S, Z_S) of every photo and X, Y, Z of every
point measured on two or more photos. The observations are the photo coordinates of every point
measurement (σ = ``Sigmas.photo_mm``) and the catalogue coordinates of the control points
(σ = ``Sigmas.control_plan_m`` on X, Y of full and plan points, ``control_height_m`` on Z of
full and height points): the datum comes from the control alone. Each Gauss–Newton step
linearises Eq. (2.53) per photo with the analytic Jacobian of the single-photo resection
(:mod:`stereoplotter.geometry.resection`, the same equations (3.6)), eliminates the points
(3 × 3 blocks) and solves the reduced normal equations of the photos (a sparse matrix of 6 × 6
blocks, one per pair of photos sharing a point) by sparse LU (SuperLU). Memory grows with the
number of observations: the reduced matrix holds one block per pair of rays of a point.

The first approximation is the plan similarity block of :func:`initial_approximation`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

from stereoplotter.errors import GeometryError
from stereoplotter.geometry.resection import _model_and_jacobian
from stereoplotter.triangulation.block import (
    Block,
    catalogue_local,
    interior_orientation,
    photo_coordinates,
)
from stereoplotter.triangulation.solution import BlockSolution, sparse_least_squares

__all__ = [
    "BundleProblem",
    "bundle_adjust",
    "bundle_block",
    "initial_approximation",
    "interior_orientation_covariance",
    "problem",
]


@dataclass(frozen=True, slots=True)
class BundleProblem:
    """The arrays of a bundle adjustment (all in the local system of §10).

    ``xy_mm`` (n_obs, 2) photo coordinates relative to the principal point; ``obs_photo``,
    ``obs_point`` their photo and point; ``control_point`` (n_c,) the points with catalogue
    coordinates ``control_m`` (n_c, 3) and weights ``control_weight`` (n_c, 3) [1/m², 0 where a
    coordinate is not given]; ``f_mm``; ``sigma_photo_mm``.
    """

    xy_mm: NDArray[np.float64]
    obs_photo: NDArray[np.int64]
    obs_point: NDArray[np.int64]
    n_photos: int
    n_points: int
    control_point: NDArray[np.int64]
    control_m: NDArray[np.float64]
    control_weight: NDArray[np.float64]
    f_mm: float
    sigma_photo_mm: float
    point_ids: tuple[str, ...] = ()


def problem(block: Block) -> BundleProblem:
    """The bundle problem of a block: interior orientation applied, control in the local system,
    points measured on fewer than two photos left out (they add nothing)."""
    rays = np.bincount(block.obs_point, minlength=len(block.point_ids))
    keep = rays[block.obs_point] >= 2
    where = {pid: i for i, pid in enumerate(block.point_ids)}
    local = catalogue_local(block)
    s = block.sigmas
    cp, cm, cw = [], [], []
    for k, p in enumerate(block.catalogue):
        if p.role != "control" or p.id not in where or rays[where[p.id]] < 2:
            continue
        plan = 0.0 if p.kind == "height" else 1.0 / s.control_plan_m**2
        height = 0.0 if p.kind == "plan" else 1.0 / s.control_height_m**2
        cp.append(where[p.id])
        cm.append(local[k])
        cw.append((plan, plan, height))
    return BundleProblem(
        xy_mm=interior_orientation(block)[keep],
        obs_photo=block.obs_photo[keep],
        obs_point=block.obs_point[keep],
        n_photos=len(block.photos),
        n_points=len(block.point_ids),
        control_point=np.array(cp, dtype=np.int64),
        control_m=np.array(cm, float).reshape(-1, 3),
        control_weight=np.array(cw, float).reshape(-1, 3),
        f_mm=block.camera.focal_length_mm,
        sigma_photo_mm=s.photo_mm,
        point_ids=block.point_ids,
    )


def initial_approximation(p: BundleProblem) -> tuple[NDArray, NDArray]:
    r"""First approximation of orientations (n_photos, 6) and points (n_points, 3).

    Every photo taken as vertical: its plan is a similarity of the photo coordinates,
    X + iY = A·(x + iy) + C (A = (Z_S − Z)/f·e^{iκ}, Eq. (2.52) with α = ω = 0), one A and C per
    photo, tied by the common points and to the plan control; all in one sparse linear least
    squares. Then κ = arg A, (X_S, Y_S) = C, Z_S = Z̄ + |A|·f with Z̄ the mean control height, and
    every point at Z̄. This is an assumption of this package (the photo-mosaic start of block
    adjustments), not a method of the book.

    Raises
    ------
    GeometryError
        Fewer than two plan control points, or a block whose photos are not all connected.
    """
    n_obs, npho = p.obs_photo.size, p.n_photos
    plan = np.flatnonzero(p.control_weight[:, 0] > 0)
    if plan.size < 2:
        raise GeometryError(f"the block has {plan.size} plan control points: expected at least 2")
    # unknowns: per photo (A_re, A_im, C_re, C_im), per point (X, Y)
    x, y = p.xy_mm[:, 0], p.xy_mm[:, 1]
    j4, i2 = 4 * p.obs_photo, 4 * npho + 2 * p.obs_point
    rows = np.concatenate([np.arange(n_obs)] * 4 + [np.arange(n_obs, 2 * n_obs)] * 4)
    cols = np.concatenate([j4, j4 + 1, j4 + 2, i2, j4, j4 + 1, j4 + 3, i2 + 1])
    vals = np.concatenate(
        [x, -y, np.ones(n_obs), -np.ones(n_obs), y, x, np.ones(n_obs), -np.ones(n_obs)]
    )
    cidx = 4 * npho + 2 * p.control_point[plan]
    w = 1e3  # control as strong observations: the plan datum of the mosaic
    nc = plan.size
    rows = np.concatenate([rows, 2 * n_obs + np.arange(2 * nc)])
    cols = np.concatenate([cols, cidx, cidx + 1])
    vals = np.concatenate([vals, np.full(2 * nc, w)])
    rhs = np.concatenate([np.zeros(2 * n_obs), w * p.control_m[plan, 0], w * p.control_m[plan, 1]])
    a = sp.csr_matrix((vals, (rows, cols)), shape=(2 * n_obs + 2 * nc, 4 * npho + 2 * p.n_points))
    used = np.zeros(a.shape[1], bool)
    used[cols] = True
    sol = np.zeros(a.shape[1])
    try:
        sol[used] = sparse_least_squares(a[:, used], rhs)
    except RuntimeError as exc:  # SuperLU: exactly singular
        raise GeometryError(
            f"the plan similarity block is singular ({exc}): expected every photo tied to the "
            "others by common points"
        ) from None
    A = sol[0 : 4 * npho : 4] + 1j * sol[1 : 4 * npho : 4]
    C = sol[2 : 4 * npho : 4] + 1j * sol[3 : 4 * npho : 4]
    zbar = (
        float(np.mean(p.control_m[p.control_weight[:, 2] > 0, 2]))
        if np.any(p.control_weight[:, 2] > 0)
        else 0.0
    )
    orient = np.column_stack(
        [np.zeros(npho), np.zeros(npho), np.angle(A), C.real, C.imag, zbar + np.abs(A) * p.f_mm]
    )
    pts = sol[4 * npho :].reshape(-1, 2)
    points = np.column_stack([pts, np.full(p.n_points, zbar)])
    return orient, points


def _linearise(p: BundleProblem, orient: NDArray, points: NDArray) -> tuple[NDArray, NDArray]:
    """Residuals v = measured − computed (n_obs, 2) [mm] and Jacobians ∂(x, y)/∂(photo elements)
    (n_obs, 2, 6) of Eq. (2.53), photo by photo (∂/∂(X, Y, Z) = −∂/∂(X_S, Y_S, Z_S))."""
    v = np.empty_like(p.xy_mm)
    jac = np.empty((p.xy_mm.shape[0], 2, 6))
    order = np.argsort(p.obs_photo, kind="stable")
    bounds = np.searchsorted(p.obs_photo[order], np.arange(p.n_photos + 1))
    for j in range(p.n_photos):
        rows = order[bounds[j] : bounds[j + 1]]
        if rows.size == 0:
            continue
        computed, jj = _model_and_jacobian(
            orient[j], points[p.obs_point[rows]], p.f_mm, np.zeros(2)
        )
        v[rows] = p.xy_mm[rows] - computed
        jac[rows] = jj
    return v, jac


@dataclass(frozen=True, slots=True)
class _Pairs:
    """Every ordered pair of measurements of the same point (the blocks of the reduced matrix)."""

    first: NDArray[np.int64]
    second: NDArray[np.int64]


def _pairs(obs_point: NDArray) -> _Pairs:
    order = np.argsort(obs_point, kind="stable")
    counts = np.bincount(obs_point)
    start = np.concatenate([[0], np.cumsum(counts)[:-1]])
    k = counts[obs_point[order]]
    first = np.repeat(order, k)
    offset = np.arange(first.size) - np.repeat(np.cumsum(k) - k, k)
    second = order[start[obs_point[first]] + offset]
    return _Pairs(first, second)


# long: one Gauss–Newton step: normal blocks, point elimination, reduced solve, back-substitution
def _step(p, orient, points, pairs, factor_only=False):
    """One Gauss–Newton step: corrections of orientations and points, [vv], and the factor."""
    v, jc = _linearise(p, orient, points)
    w = 1.0 / p.sigma_photo_mm**2
    jp = -jc[:, :, 3:]
    ncc = np.zeros((p.n_photos, 6, 6))
    np.add.at(ncc, p.obs_photo, w * np.einsum("nki,nkj->nij", jc, jc))
    bc = np.zeros((p.n_photos, 6))
    np.add.at(bc, p.obs_photo, w * np.einsum("nki,nk->ni", jc, v))
    npp = np.zeros((p.n_points, 3, 3))
    np.add.at(npp, p.obs_point, w * np.einsum("nki,nkj->nij", jp, jp))
    bp = np.zeros((p.n_points, 3))
    np.add.at(bp, p.obs_point, w * np.einsum("nki,nk->ni", jp, v))
    dc = p.control_m - points[p.control_point]
    npp[p.control_point] += np.einsum("ni,ij->nij", p.control_weight, np.eye(3))
    bp[p.control_point] += p.control_weight * dc
    vv = float(np.sum(v**2) * w + np.sum(p.control_weight * dc**2))
    unused = np.bincount(p.obs_point, minlength=p.n_points) == 0
    npp[unused] = np.eye(3)
    det = np.linalg.det(npp)
    scale3 = np.einsum("nii->n", npp) ** 3
    weak = np.flatnonzero(~(np.abs(det) > 1e-12 * scale3))
    if weak.size:
        name = p.point_ids[weak[0]] if p.point_ids else f"#{weak[0]}"
        raise GeometryError(
            f"point {name}: its rays do not fix it (measured on photos that see "
            "it along one line?): check the point identification"
        )
    pinv = np.linalg.inv(npp)
    ncp = w * np.einsum("nki,nkj->nij", jc, jp)  # per measurement, 6 × 3
    pt = p.obs_point[pairs.first]
    blocks = np.einsum("nij,njk,nlk->nil", ncp[pairs.first], pinv[pt], ncp[pairs.second])
    jf, js = p.obs_photo[pairs.first], p.obs_photo[pairs.second]
    r = (6 * jf[:, None, None] + np.arange(6)[None, :, None]) * np.ones((1, 1, 6), int)
    c = (6 * js[:, None, None] + np.arange(6)[None, None, :]) * np.ones((1, 6, 1), int)
    n6 = 6 * p.n_photos
    diag_r = (6 * np.arange(p.n_photos)[:, None, None] + np.arange(6)[None, :, None]) * np.ones(
        (1, 1, 6), int
    )
    diag_c = np.swapaxes(diag_r, 1, 2)
    s = sp.coo_matrix(
        (
            np.concatenate([ncc.ravel(), -blocks.ravel()]),
            (
                np.concatenate([diag_r.ravel(), r.ravel()]),
                np.concatenate([diag_c.ravel(), c.ravel()]),
            ),
        ),
        shape=(n6, n6),
    ).tocsc()
    reduced_p = np.einsum("nij,nj->ni", pinv, bp)
    rhs = bc.copy()
    np.add.at(rhs, p.obs_photo, -np.einsum("nij,nj->ni", ncp, reduced_p[p.obs_point]))
    scale = 1.0 / np.sqrt(s.diagonal())
    d = sp.diags(scale)
    try:
        scaled = (d @ s @ d).tocsc()
        lu = spla.splu(scaled, permc_spec="COLAMD")
    except RuntimeError as exc:
        raise GeometryError(
            f"the reduced normal equations are singular ({exc}): expected "
            "every photo tied to the block and at least 3 control points"
        ) from None
    delta_c = (scale * lu.solve(scale * rhs.ravel())).reshape(-1, 6)
    back = bp.copy()
    np.add.at(back, p.obs_point, -np.einsum("nji,nj->ni", ncp, delta_c[p.obs_photo]))
    delta_p = np.einsum("nij,nj->ni", pinv, back)
    delta_p[unused] = 0.0
    return delta_c, delta_p, vv, (lu, scale, scaled)


#: Above this many photo unknowns the inverse is not formed densely (8 · n² bytes: 288 MB at
#: 6000, i.e. 1000 photos) but column by column from the sparse factor (slow: minutes).
DENSE_INVERSE_LIMIT = 6000


def _covariances(factor, n_photos: int, sigma0: float, chunk: int = 64) -> tuple[NDArray, NDArray]:
    """σ₀²·(the 6 × 6 diagonal blocks of the inverse reduced matrix) and σ₀²·its blocks
    (j + 1, j) (photo j + 1 against photo j). Up to :data:`DENSE_INVERSE_LIMIT` unknowns by a
    dense Cholesky inverse (LAPACK potrf/potri: 1000 photos in about 20 s); beyond, in chunks
    of photos from the sparse factor (memory 6n × 6·chunk)."""
    lu, scale, scaled = factor
    if 6 * n_photos <= DENSE_INVERSE_LIMIT:
        c, _ = sla.cho_factor(scaled.toarray(), lower=True, overwrite_a=True, check_finite=False)
        inv, info = sla.lapack.dpotri(c, lower=1, overwrite_c=1)
        if info != 0:
            raise GeometryError(f"the reduced normal matrix is not positive definite ({info})")
        inv *= scale[:, None]  # in place: one n × n array; the lower triangle holds the inverse
        inv *= scale[None, :]
        k = np.arange(n_photos)
        blocks = inv.reshape(n_photos, 6, n_photos, 6)
        diag = np.tril(blocks[k, :, k, :]) + np.swapaxes(np.tril(blocks[k, :, k, :], -1), 1, 2)
        after = np.zeros((n_photos, 6, 6))
        after[:-1] = blocks[k[1:], :, k[:-1], :]
        return sigma0**2 * diag, sigma0**2 * after
    out = np.empty((n_photos, 6, 6))
    after = np.zeros((n_photos, 6, 6))
    for start in range(0, n_photos, chunk):
        stop = min(n_photos, start + chunk)
        k = np.arange(stop - start)
        cols = np.arange(6 * start, 6 * stop)
        e = np.zeros((6 * n_photos, cols.size))
        e[cols, np.arange(cols.size)] = scale[cols]
        x = (scale[:, None] * lu.solve(e)).reshape(n_photos, 6, stop - start, 6)
        out[start:stop] = x[start + k, :, k, :]
        nxt = k[start + k + 1 < n_photos]
        after[start + nxt] = x[start + nxt + 1, :, nxt, :]
    return sigma0**2 * out, sigma0**2 * after


def bundle_adjust(
    p: BundleProblem,
    initial: tuple[NDArray, NDArray] | None = None,
    *,
    max_iterations: int = 30,
    angle_tolerance: float = 1e-8,
    position_tolerance_m: float = 1e-4,
    covariance: bool = True,
) -> BlockSolution:
    r"""Least-squares bundle adjustment of a block (Gauss–Newton, reduced normal equations).

    Parameters
    ----------
    p : BundleProblem
    initial : (orientations, points), optional
        First approximation; by default :func:`initial_approximation`.
    max_iterations : int
    angle_tolerance : float
        Convergence when every |δα|, |δω|, |δκ| ≤ it (Eq. (3.8)'s ε₁). [rad] (default 0.002″)
    position_tolerance_m : float
        … and every |δX_S|, |δY_S|, |δZ_S| and point correction ≤ it (ε₂, ε₃). [m]
    covariance : bool
        Compute σ₀²·N⁻¹'s 6 × 6 blocks of the photos (Eq. (3.11)); the block of 1,000 photos
        took 2.8 s more than its adjustment (3.7 s) in ``benchmarks/bench_triangulation.py``,
        with a dense inverse of 8·(6n)² bytes (288 MB): see :data:`DENSE_INVERSE_LIMIT`.

    Returns
    -------
    BlockSolution
        σ₀ = √([pvv]/r) with r = observations − unknowns (Eq. (3.10), weights 1/σ²).

    Raises
    ------
    GeometryError
        No convergence, a singular system or too little control.
    """
    orient, points = initial if initial is not None else initial_approximation(p)
    orient, points = orient.copy(), points.copy()
    pairs = _pairs(p.obs_point)
    converged = False
    for it in range(1, max_iterations + 1):  # noqa: B007 (reported after the loop)
        dc, dp, _, factor = _step(p, orient, points, pairs)
        orient += dc
        points += dp
        if (
            np.all(np.abs(dc[:, :3]) <= angle_tolerance)
            and max(float(np.max(np.abs(dc[:, 3:]))), float(np.max(np.abs(dp))))
            <= position_tolerance_m
        ):
            converged = True
            break
    if not converged:
        raise GeometryError(
            f"the bundle adjustment did not converge in {max_iterations} iterations (last "
            f"corrections {np.max(np.abs(dc[:, :3])):.3g} rad, {np.max(np.abs(dp)):.3g} m): "
            "check the point identification and the control"
        )
    _, _, vv, factor = _step(p, orient, points, pairs)
    used = np.bincount(p.obs_point, minlength=p.n_points) > 0
    n_obs = 2 * p.obs_photo.size + int(np.count_nonzero(p.control_weight))
    redundancy = n_obs - 6 * p.n_photos - 3 * int(used.sum())
    sigma0 = float(np.sqrt(vv / redundancy)) if redundancy > 0 else float("nan")
    points[~used] = np.nan
    cov, after = _covariances(factor, p.n_photos, sigma0) if covariance else (None, None)
    notes = (f"redundancy {redundancy}",)
    return BlockSolution("bundle", orient, cov, points, it, sigma0, notes, after)


def interior_orientation_covariance(
    block: Block, p: BundleProblem, solution: BlockSolution
) -> NDArray[np.float64]:
    r"""Covariance (n_photos, 6, 6) the interior orientation adds to each photo's elements.

    The four marks of a photo are measured with the σ of a point; the error of the fiducial
    system they define moves every point of that photo together, which the adjustment (each
    measurement independent) does not see. Its effect on the photo's elements, the points held:
    C = σ²·G·D·Dᵀ·Gᵀ with D = ∂(x, y)/∂(the 8 mark coordinates) of the photo's points (central
    differences of :func:`~stereoplotter.triangulation.block.photo_coordinates`, the interior
    orientation the adjustment used) and G = (JᵀJ)⁻¹Jᵀ the least-squares map of photo
    residuals to the elements (J of Eq. (2.53) at the solution).
    """
    keep = np.bincount(block.obs_point, minlength=len(block.point_ids))[block.obs_point] >= 2
    rows_all = np.flatnonzero(keep)
    _, jac = _linearise(p, solution.orientations, np.nan_to_num(solution.points_m))
    out = np.zeros((p.n_photos, 6, 6))
    h = 1e-3  # mm: the interior orientation is linear in the marks to far below this
    for j in range(p.n_photos):
        mine = np.flatnonzero(p.obs_photo == j)
        if mine.size < 3:
            continue
        comparator = block.comparator_mm[rows_all[mine]]
        d = np.empty((2 * mine.size, 8))
        for k in range(8):
            e = np.zeros((4, 2))
            e.flat[k] = h
            marks = block.fiducials_mm[j]
            d[:, k] = (
                photo_coordinates(block.camera, comparator, marks + e)
                - photo_coordinates(block.camera, comparator, marks - e)
            ).ravel() / (2 * h)
        a = jac[mine].reshape(-1, 6)
        g = np.linalg.solve(a.T @ a, a.T)
        out[j] = block.sigmas.photo_mm**2 * g @ d @ d.T @ g.T
    return out


def bundle_block(block: Block, **options) -> BlockSolution:
    """:func:`bundle_adjust` of :func:`problem` of a block; with ``covariance`` (the default)
    each photo's covariance includes its interior orientation's
    (:func:`interior_orientation_covariance`)."""
    p = problem(block)
    s = bundle_adjust(p, **options)
    if s.covariances is None:
        return s
    extra = interior_orientation_covariance(block, p, s)
    notes = (*s.notes, "σ of the elements include the interior orientation's (4 marks per photo)")
    return dataclasses.replace(s, covariances=s.covariances + extra, notes=notes)
