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
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

from stereoplotter.errors import GeometryError
from stereoplotter.geometry.resection import model_and_jacobian
from stereoplotter.geometry.rotation import rotation_matrix
from stereoplotter.triangulation.block import (
    Block,
    catalogue_local,
    centres_local,
    interior_orientation,
    photo_coordinates,
)
from stereoplotter.triangulation.camera_model import CAMERA_PARAMETERS, camera_image
from stereoplotter.triangulation.selected_inverse import SelectedInverse, selected_inverse
from stereoplotter.triangulation.solution import BlockSolution, sparse_least_squares

__all__ = [
    "Adjusted",
    "BundleProblem",
    "MeasurementPairs",
    "Normals",
    "PhotoCofactors",
    "bundle_adjust",
    "bundle_adjusted",
    "bundle_block",
    "initial_approximation",
    "interior_orientation_covariance",
    "measurement_pairs",
    "normals",
    "photo_cofactors",
    "point_cofactors",
    "problem",
]


@dataclass(frozen=True, slots=True)
class BundleProblem:
    """The arrays of a bundle adjustment (all in the local system of §10).

    ``xy_mm`` (n_obs, 2) photo coordinates relative to the principal point; ``obs_photo``,
    ``obs_point`` their photo and point; ``control_point`` (n_c,) the points with catalogue
    coordinates ``control_m`` (n_c, 3) and weights ``control_weight`` (n_c, 3) [1/m², 0 where a
    coordinate is not given]; ``f_mm``; ``sigma_photo_mm``; ``point_ids`` and ``photo_ids``
    (for messages); ``obs_index`` each measurement's row in the block; ``centre_photo`` (n_g,)
    the photos with a measured projection centre (GNSS antenna) ``centre_m`` (n_g, 3), weights
    ``centre_weight`` (n_g, 3) [1/m²], ``lever_arm_m`` (3,) the antenna in the camera system;
    ``camera_free`` the camera parameters adjusted with the block (self-calibration, names of
    :data:`~stereoplotter.triangulation.camera_model.CAMERA_PARAMETERS`; none by default);
    ``photo_factor`` (n_obs, 2) factors of the photo coordinates' weights (None: all 1).
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
    photo_ids: tuple[str, ...] = ()
    obs_index: NDArray[np.int64] | None = None
    centre_photo: NDArray[np.int64] = dataclasses.field(
        default_factory=lambda: np.zeros(0, np.int64)
    )
    centre_m: NDArray[np.float64] = dataclasses.field(default_factory=lambda: np.zeros((0, 3)))
    centre_weight: NDArray[np.float64] = dataclasses.field(default_factory=lambda: np.zeros((0, 3)))
    lever_arm_m: NDArray[np.float64] = dataclasses.field(default_factory=lambda: np.zeros(3))
    camera_free: tuple[str, ...] = ()
    photo_factor: NDArray[np.float64] | None = None

    def photo_weights(self) -> NDArray[np.float64]:
        """Weight of each photo coordinate, (n_obs, 2) [1/mm²]: 1/σ² times ``photo_factor``
        (robust re-weighting; 1 by default)."""
        w = np.full(self.xy_mm.shape, 1.0 / self.sigma_photo_mm**2)
        return w if self.photo_factor is None else w * self.photo_factor

    @property
    def free(self) -> NDArray[np.int64]:
        """Indices into :data:`CAMERA_PARAMETERS` of the camera parameters adjusted."""
        return np.array([CAMERA_PARAMETERS.index(n) for n in self.camera_free], np.int64)

    def camera0(self) -> NDArray[np.float64]:
        """The certificate's camera: f and zero principal point offset and distortion."""
        return np.array([self.f_mm, 0, 0, 0, 0, 0, 0], float)

    def __post_init__(self) -> None:
        if self.obs_index is None:  # the measurements of the block, in its order
            object.__setattr__(self, "obs_index", np.arange(self.obs_photo.size))

    def photo_ids_of(self, photos: NDArray) -> str:
        """The photo numbers of indices, comma-separated (``#j`` where the problem has none)."""
        return ", ".join(
            self.photo_ids[j] if self.photo_ids else f"#{j}" for j in np.asarray(photos).ravel()
        )


def problem(block: Block, self_calibration: tuple[str, ...] = ()) -> BundleProblem:
    """The bundle problem of a block: interior orientation applied, control in the local system,
    points measured on fewer than two photos left out (they add nothing); the camera parameters
    of ``self_calibration`` (names of :data:`~stereoplotter.triangulation.camera_model.
    CAMERA_PARAMETERS`) adjusted with the block."""
    unknown = [n for n in self_calibration if n not in CAMERA_PARAMETERS]
    if unknown:
        raise GeometryError(
            f"self-calibration: expected parameters among {', '.join(CAMERA_PARAMETERS)}, "
            f"found {unknown[0]!r}"
        )
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
    gp, gm = centres_local(block)
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
        photo_ids=block.photos,
        obs_index=np.flatnonzero(keep),
        centre_photo=gp,
        centre_m=gm,
        centre_weight=np.tile(
            [1.0 / s.centre_plan_m**2, 1.0 / s.centre_plan_m**2, 1.0 / s.centre_height_m**2],
            (gp.size, 1),
        ),
        lever_arm_m=np.asarray(block.lever_arm_m, float),
        camera_free=tuple(n for n in CAMERA_PARAMETERS if n in self_calibration),
    )


def initial_approximation(p: BundleProblem) -> tuple[NDArray, NDArray]:
    r"""First approximation of orientations (n_photos, 6) and points (n_points, 3).

    Every photo taken as vertical: its plan is a similarity of the photo coordinates,
    X + iY = A·(x + iy) + C (A = (Z_S − Z)/f·e^{iκ}, Eq. (2.52) with α = ω = 0), one A and C per
    photo, tied by the common points and to the plan control and the measured centres' plan;
    all in one sparse linear least squares. Then κ = arg A, (X_S, Y_S) = C, Z_S = Z̄ + |A|·f
    with Z̄ the mean control height (without height control: the mean of Z_S − |A|·f of the
    measured centres), a measured centre's Z_S its own, and every point at Z̄. This is an
    assumption of this package (the photo-mosaic start of block adjustments), not a method of
    the book.

    Raises
    ------
    GeometryError
        Fewer than two plan control points and measured centres, or a block whose photos are
        not all connected.
    """
    n_obs, npho = p.obs_photo.size, p.n_photos
    plan = np.flatnonzero(p.control_weight[:, 0] > 0)
    gj = p.centre_photo
    if plan.size + gj.size < 2:
        raise GeometryError(
            f"the block has {plan.size} plan control points and {gj.size} measured projection "
            "centres: expected at least 2 of them"
        )
    # unknowns: per photo (A_re, A_im, C_re, C_im), per point (X, Y)
    x, y = p.xy_mm[:, 0], p.xy_mm[:, 1]
    j4, i2 = 4 * p.obs_photo, 4 * npho + 2 * p.obs_point
    rows = np.concatenate([np.arange(n_obs)] * 4 + [np.arange(n_obs, 2 * n_obs)] * 4)
    cols = np.concatenate([j4, j4 + 1, j4 + 2, i2, j4, j4 + 1, j4 + 3, i2 + 1])
    vals = np.concatenate(
        [x, -y, np.ones(n_obs), -np.ones(n_obs), y, x, np.ones(n_obs), -np.ones(n_obs)]
    )
    # control and measured centres as strong observations: the plan datum of the mosaic
    w = 1e3
    cidx = np.concatenate([4 * npho + 2 * p.control_point[plan], 4 * gj + 2])
    target = np.concatenate([p.control_m[plan, :2], p.centre_m[:, :2]])
    nc = cidx.size
    rows = np.concatenate([rows, 2 * n_obs + np.arange(2 * nc)])
    cols = np.concatenate([cols, cidx, cidx + 1])
    vals = np.concatenate([vals, np.full(2 * nc, w)])
    rhs = np.concatenate([np.zeros(2 * n_obs), w * target[:, 0], w * target[:, 1]])
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
    heights = p.control_weight[:, 2] > 0
    if np.any(heights):
        zbar = float(np.mean(p.control_m[heights, 2]))
    elif gj.size:  # the ground below the measured centres
        zbar = float(np.mean(p.centre_m[:, 2] - np.abs(A[gj]) * p.f_mm))
    else:
        zbar = 0.0
    orient = np.column_stack(
        [np.zeros(npho), np.zeros(npho), np.angle(A), C.real, C.imag, zbar + np.abs(A) * p.f_mm]
    )
    orient[gj, 5] = p.centre_m[:, 2]
    pts = sol[4 * npho :].reshape(-1, 2)
    points = np.column_stack([pts, np.full(p.n_points, zbar)])
    return orient, points


def _linearise(
    p: BundleProblem, orient: NDArray, points: NDArray, camera: NDArray | None = None
) -> tuple[NDArray, NDArray, NDArray]:
    """Residuals v = measured − computed (n_obs, 2) [mm], Jacobians ∂(x, y)/∂(photo elements)
    (n_obs, 2, 6) of Eq. (2.53), photo by photo (∂/∂(X, Y, Z) = −∂/∂(X_S, Y_S, Z_S)), and
    ∂(x, y)/∂(free camera parameters) (n_obs, 2, n_free) (:mod:`~stereoplotter.triangulation.
    camera_model`; the certificate's camera by default)."""
    cam = p.camera0() if camera is None else camera
    v = np.empty_like(p.xy_mm)
    jac = np.empty((p.xy_mm.shape[0], 2, 6))
    jg = np.empty((p.xy_mm.shape[0], 2, p.free.size))
    order = np.argsort(p.obs_photo, kind="stable")
    bounds = np.searchsorted(p.obs_photo[order], np.arange(p.n_photos + 1))
    plain = not p.camera_free and np.all(cam[1:] == 0.0)
    for j in range(p.n_photos):
        rows = order[bounds[j] : bounds[j + 1]]
        if rows.size == 0:
            continue
        computed, jj = model_and_jacobian(
            orient[j], points[p.obs_point[rows]], float(cam[0]), np.zeros(2)
        )
        if not plain:
            computed, d, jcam = camera_image(computed, cam)
            jj = np.einsum("nij,njk->nik", d, jj)
            jg[rows] = jcam[:, :, p.free]
        v[rows] = p.xy_mm[rows] - computed
        jac[rows] = jj
    return v, jac, jg


def centre_residuals(p: BundleProblem, orient: NDArray) -> tuple[NDArray, NDArray]:
    """Residuals v = measured − computed (n_g, 3) [m] of the measured projection centres and
    their Jacobian ∂(antenna)/∂(photo elements) (n_g, 3, 6): antenna = S + M·e, M of
    Eq. (2.50), e the lever arm (∂M/∂angles by central differences, h = 10⁻⁶ rad: error
    ~10⁻¹² of |e|)."""
    o = orient[p.centre_photo]
    e = p.lever_arm_m
    m = rotation_matrix(o[:, 0], o[:, 1], o[:, 2])
    computed = o[:, 3:] + m @ e
    jac = np.zeros((o.shape[0], 3, 6))
    jac[:, :, 3:] = np.eye(3)
    h = 1e-6
    for k in range(3):
        d = np.zeros(3)
        d[k] = h
        plus = rotation_matrix(o[:, 0] + d[0], o[:, 1] + d[1], o[:, 2] + d[2])
        minus = rotation_matrix(o[:, 0] - d[0], o[:, 1] - d[1], o[:, 2] - d[2])
        jac[:, :, k] = (plus - minus) @ e / (2 * h)
    return p.centre_m - computed, jac


@dataclass(frozen=True, slots=True)
class MeasurementPairs:
    """Every ordered pair of measurements of the same point (the blocks of the reduced matrix)."""

    first: NDArray[np.int64]
    second: NDArray[np.int64]


def measurement_pairs(obs_point: NDArray) -> MeasurementPairs:
    """Every ordered pair (itself included) of the observations of each point, ``obs_point``
    being each observation's point index."""
    order = np.argsort(obs_point, kind="stable")
    counts = np.bincount(obs_point)
    start = np.concatenate([[0], np.cumsum(counts)[:-1]])
    k = counts[obs_point[order]]
    first = np.repeat(order, k)
    offset = np.arange(first.size) - np.repeat(np.cumsum(k) - k, k)
    second = order[start[obs_point[first]] + offset]
    return MeasurementPairs(first, second)


@dataclass(frozen=True, slots=True)
class Normals:
    """The normal equations of one linearisation, the points eliminated (σ-free: weights 1/σ²).

    ``v`` (n_obs, 2) photo residuals [mm]; ``jc`` (n_obs, 2, 6) ∂(x, y)/∂(photo elements) and
    ``jp`` (n_obs, 2, 3) ∂(x, y)/∂(X, Y, Z) of Eq. (2.53); ``ncp`` (n_obs, 6, 3) each
    measurement's Jcᵀ·w·Jp; ``pinv`` (n_points, 3, 3) the inverse point blocks N_pp⁻¹ (control
    weights included); ``reduced`` the reduced matrix N_cc − N_cp·N_pp⁻¹·N_pc (sparse, 6 × 6
    blocks); ``rhs`` its right side (n_photos, 6); ``bp`` the points' right side; ``vv`` [pvv].
    With free camera parameters (n_g of them) the border: ``jg`` (n_obs, 2, n_g) their
    Jacobian, ``ngp`` (n_obs, n_g, 3) each measurement's Jgᵀ·w·Jp, ``sgc`` (n_g, 6·n_photos)
    and ``sgg`` (n_g, n_g) the reduced border, ``rg`` (n_g,) its right side.
    """

    v: NDArray[np.float64]
    jc: NDArray[np.float64]
    jp: NDArray[np.float64]
    ncp: NDArray[np.float64]
    pinv: NDArray[np.float64]
    reduced: sp.csc_matrix
    rhs: NDArray[np.float64]
    bp: NDArray[np.float64]
    vv: float
    unused: NDArray[np.bool_]
    jg: NDArray[np.float64] | None = None
    ngp: NDArray[np.float64] | None = None
    sgc: NDArray[np.float64] | None = None
    sgg: NDArray[np.float64] | None = None
    rg: NDArray[np.float64] | None = None


def normals(
    p: BundleProblem,
    orient: NDArray,
    points: NDArray,
    pairs: MeasurementPairs,
    camera: NDArray | None = None,
) -> Normals:
    """The reduced normal equations of the bundle at (orient, points, camera) (:class:`Normals`).

    Raises
    ------
    GeometryError
        A point whose rays do not fix it (names the point and its photos).
    """
    v, jc, jg = _linearise(p, orient, points, camera)
    w = p.photo_weights()  # (n_obs, 2) [1/mm²]
    jp = -jc[:, :, 3:]
    ncc, bc, npp, bp, vv = _normal_blocks(p, orient, points, v, jc, jp, w)
    unused = np.bincount(p.obs_point, minlength=p.n_points) == 0
    npp[unused] = np.eye(3)
    _check_points_fixed(p, npp)
    pinv = np.linalg.inv(npp)
    ncp = np.einsum("nki,nk,nkj->nij", jc, w, jp)  # per measurement, 6 × 3
    s = _reduced_matrix(p, ncc, ncp, pinv, pairs)
    reduced_p = np.einsum("nij,nj->ni", pinv, bp)
    rhs = bc.copy()
    np.add.at(rhs, p.obs_photo, -np.einsum("nij,nj->ni", ncp, reduced_p[p.obs_point]))
    if not p.camera_free:
        return Normals(v, jc, jp, ncp, pinv, s, rhs, bp, vv, unused)
    ngp, sgc, sgg, rg = _camera_border(p, v, jc, jp, jg, w, ncp, pinv, pairs, reduced_p)
    return Normals(v, jc, jp, ncp, pinv, s, rhs, bp, vv, unused, jg, ngp, sgc, sgg, rg)


def _normal_blocks(
    p: BundleProblem,
    orient: NDArray,
    points: NDArray,
    v: NDArray,
    jc: NDArray,
    jp: NDArray,
    w: NDArray,
) -> tuple[NDArray, NDArray, NDArray, NDArray, float]:
    """The diagonal blocks of the normals and their right-hand sides: per photo (6 × 6, with
    the measured projection centres) and per point (3 × 3, with the control), and [vv]."""
    ncc = np.zeros((p.n_photos, 6, 6))
    np.add.at(ncc, p.obs_photo, np.einsum("nki,nk,nkj->nij", jc, w, jc))
    bc = np.zeros((p.n_photos, 6))
    np.add.at(bc, p.obs_photo, np.einsum("nki,nk,nk->ni", jc, w, v))
    npp = np.zeros((p.n_points, 3, 3))
    np.add.at(npp, p.obs_point, np.einsum("nki,nk,nkj->nij", jp, w, jp))
    bp = np.zeros((p.n_points, 3))
    np.add.at(bp, p.obs_point, np.einsum("nki,nk,nk->ni", jp, w, v))
    dc = p.control_m - points[p.control_point]
    npp[p.control_point] += np.einsum("ni,ij->nij", p.control_weight, np.eye(3))
    bp[p.control_point] += p.control_weight * dc
    vv = float(np.sum(w * v**2) + np.sum(p.control_weight * dc**2))
    if p.centre_photo.size:
        vg, jcentre = centre_residuals(p, orient)
        wg = p.centre_weight
        np.add.at(ncc, p.centre_photo, np.einsum("nki,nk,nkj->nij", jcentre, wg, jcentre))
        np.add.at(bc, p.centre_photo, np.einsum("nki,nk,nk->ni", jcentre, wg, vg))
        vv += float(np.sum(wg * vg**2))
    return ncc, bc, npp, bp, vv


def _check_points_fixed(p: BundleProblem, npp: NDArray) -> None:
    """Raise :class:`GeometryError` for the first point whose 3 × 3 normal block is singular."""
    det = np.linalg.det(npp)
    scale3 = np.einsum("nii->n", npp) ** 3
    weak = np.flatnonzero(~(np.abs(det) > 1e-12 * scale3))
    if weak.size:
        i = weak[0]
        name = p.point_ids[i] if p.point_ids else f"#{i}"
        seen = p.photo_ids_of(p.obs_photo[p.obs_point == i])
        raise GeometryError(
            f"point {name}: its {seen.count(',') + 1 if seen else 0} rays (photos {seen}) do not "
            "fix it (they lie along one line): expected rays from two photos at an angle; check "
            "the point identification"
        )


def _reduced_matrix(
    p: BundleProblem, ncc: NDArray, ncp: NDArray, pinv: NDArray, pairs: MeasurementPairs
) -> sp.csc_matrix:
    """The orientations' reduced normal matrix (6·photos square, sparse): the photo blocks
    less, for each pair of measurements of one point, N_cp·N_pp⁻¹·N_pc."""
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
    return sp.coo_matrix(
        (
            np.concatenate([ncc.ravel(), -blocks.ravel()]),
            (
                np.concatenate([diag_r.ravel(), r.ravel()]),
                np.concatenate([diag_c.ravel(), c.ravel()]),
            ),
        ),
        shape=(n6, n6),
    ).tocsc()


def _camera_border(
    p: BundleProblem,
    v: NDArray,
    jc: NDArray,
    jp: NDArray,
    jg: NDArray,
    w: NDArray,
    ncp: NDArray,
    pinv: NDArray,
    pairs: MeasurementPairs,
    reduced_p: NDArray,
) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """The free camera parameters' border of the reduced normals, points eliminated: N_gp per
    measurement, the camera × orientations block, the camera block and its right-hand side."""
    pt = p.obs_point[pairs.first]
    js = p.obs_photo[pairs.second]
    ng = jg.shape[2]
    ngp = np.einsum("nki,nk,nkj->nij", jg, w, jp)
    ngc = np.einsum("nki,nk,nkj->nij", jg, w, jc)
    sgc = np.zeros((ng, p.n_photos, 6))
    np.add.at(sgc, (slice(None), p.obs_photo), np.swapaxes(ngc, 0, 1))
    cross = np.einsum("nij,njk,nlk->nil", ngp[pairs.first], pinv[pt], ncp[pairs.second])
    np.add.at(sgc, (slice(None), js), -np.swapaxes(cross, 0, 1))
    sgg = np.einsum("nki,nk,nkj->ij", jg, w, jg)
    sgg -= np.einsum("nij,njk,nlk->il", ngp[pairs.first], pinv[pt], ngp[pairs.second])
    rg = np.einsum("nki,nk,nk->i", jg, w, v) - np.einsum("nij,nj->i", ngp, reduced_p[p.obs_point])
    return ngp, sgc.reshape(ng, -1), sgg, rg


def _step(p, orient, points, pairs, camera=None):
    """One Gauss–Newton step: corrections of orientations, points and the free camera
    parameters, [vv], the normals. The camera's border by its Schur complement:
    X = S⁻¹·S_cg, (S_gg − S_gc·X)·δg = r_g − S_gc·S⁻¹·r_c, δc = S⁻¹·r_c − X·δg."""
    n = normals(p, orient, points, pairs, camera)
    s = n.reduced
    scale = 1.0 / np.sqrt(s.diagonal())
    d = sp.diags(scale)
    try:
        scaled = (d @ s @ d).tocsc()
        lu = spla.splu(scaled, permc_spec="COLAMD")
    except RuntimeError as exc:
        raise GeometryError(
            f"the reduced normal equations are singular ({exc}): expected "
            "every photo tied to the block and at least 3 control points" + weakest_photos(p, s)
        ) from None
    delta_c = scale * lu.solve(scale * n.rhs.ravel())
    delta_g = np.zeros(0)
    if n.sgc is not None:
        x = scale[:, None] * lu.solve(scale[:, None] * n.sgc.T)
        delta_g = np.linalg.solve(n.sgg - n.sgc @ x, n.rg - n.sgc @ delta_c)
        delta_c = delta_c - x @ delta_g
    delta_c = delta_c.reshape(-1, 6)
    back = n.bp.copy()
    np.add.at(back, p.obs_point, -np.einsum("nji,nj->ni", n.ncp, delta_c[p.obs_photo]))
    if n.ngp is not None:
        np.add.at(back, p.obs_point, -np.einsum("nji,j->ni", n.ngp, delta_g))
    delta_p = np.einsum("nij,nj->ni", n.pinv, back)
    delta_p[n.unused] = 0.0
    return delta_c, delta_p, n.vv, n, delta_g


def weakest_photos(p: BundleProblem, reduced: sp.spmatrix, count: int = 4) -> str:
    """``"; weakest photos …"`` for a message: the photos whose own 6 × 6 block of the reduced
    matrix (at unit diagonal) is worst conditioned — those beyond 10⁴ times the median
    condition (at most ``count``; else the worst one) — each with its condition and the number
    of points it measured."""
    n = p.n_photos
    d = reduced.diagonal()
    scale = 1.0 / np.sqrt(np.where(d > 0, d, 1.0))
    blocks = np.zeros((n, 6, 6))
    coo = sp.coo_matrix(reduced)
    mine = coo.row // 6 == coo.col // 6
    np.add.at(
        blocks,
        (coo.row[mine] // 6, coo.row[mine] % 6, coo.col[mine] % 6),
        coo.data[mine] * scale[coo.row[mine]] * scale[coo.col[mine]],
    )
    with np.errstate(all="ignore"):
        cond = np.linalg.cond(blocks)
    cond = np.where(np.isfinite(cond), cond, np.inf)
    order = np.argsort(-cond, kind="stable")
    bad = order[cond[order] > 1e4 * np.median(cond)][:count]
    worst = bad if bad.size else order[:1]
    points = np.bincount(p.obs_photo, minlength=n)
    text = ", ".join(
        f"{p.photo_ids_of([j])} (condition {cond[j]:.1e}, {points[j]} points)" for j in worst
    )
    return f"; weakest photos {text}"


def _check_photos(p: BundleProblem) -> None:
    """Refuse a photo that measured fewer than 3 points (its six elements are not fixed)."""
    points = np.bincount(p.obs_photo, minlength=p.n_photos)
    few = np.flatnonzero(points < 3)
    if few.size:
        raise GeometryError(
            f"photo {p.photo_ids_of(few[:1])} measured {points[few[0]]} points of two or more "
            f"photos: expected at least 3, well spread, to fix its six elements"
            + (f" (also photos {p.photo_ids_of(few[1:6])})" if few.size > 1 else "")
        )


@dataclass(frozen=True, slots=True)
class PhotoCofactors:
    """Q of the photos' elements (σ-free), with the camera's border when it is adjusted:
    Q_cc = S⁻¹ + X·Q_gg·Xᵀ, Q_cg = −X·Q_gg, Q_gg = (S_gg − S_gc·X)⁻¹, X = S⁻¹·S_cg.

    ``inverse`` the selected inverse of S; ``x`` (n_photos, 6, n_g) and ``qgg`` (n_g, n_g),
    None without free camera parameters."""

    inverse: SelectedInverse
    x: NDArray[np.float64] | None = None
    qgg: NDArray[np.float64] | None = None

    def blocks(self, a: NDArray, b: NDArray) -> NDArray[np.float64]:
        """Q_cc of photos a and b, (m, 6, 6)."""
        out = self.inverse.blocks(a, b)
        if self.x is not None:
            out = out + np.einsum("nij,jk,nlk->nil", self.x[a], self.qgg, self.x[b])
        return out

    def cg(self, a: NDArray) -> NDArray[np.float64]:
        """Q_cg of photos a against the camera, (m, 6, n_g)."""
        return -np.einsum("nij,jk->nik", self.x[a], self.qgg)


def photo_cofactors(p: BundleProblem, n: Normals) -> PhotoCofactors:
    """:class:`PhotoCofactors` at the normals ``n``."""
    sel = selected_inverse(n.reduced)
    if n.sgc is None:
        return PhotoCofactors(sel)
    s = n.reduced
    scale = 1.0 / np.sqrt(s.diagonal())
    d = sp.diags(scale)
    lu = spla.splu((d @ s @ d).tocsc(), permc_spec="COLAMD")
    x = scale[:, None] * lu.solve(scale[:, None] * n.sgc.T)
    qgg = np.linalg.inv(n.sgg - n.sgc @ x)
    return PhotoCofactors(sel, x.reshape(p.n_photos, 6, -1), (qgg + qgg.T) / 2.0)


def _photo_covariances(q: PhotoCofactors, n_photos: int, sigma0: float):
    """σ₀²·(the 6 × 6 diagonal blocks of Q_cc) and σ₀²·its blocks (j + 1, j) (photo j + 1
    against photo j; zero for the last), from the selected inverse (no dense inverse)."""
    k = np.arange(n_photos)
    diag = q.blocks(k, k)
    after = np.zeros((n_photos, 6, 6))
    if n_photos > 1:
        after[:-1] = q.blocks(k[1:], k[:-1])
    return sigma0**2 * diag, sigma0**2 * after


def point_cofactors(
    p: BundleProblem, n: Normals, q: PhotoCofactors, pairs: MeasurementPairs
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64] | None]:
    r"""Q_pp (n_points, 3, 3) of every point, Q_cp (n_obs, 6, 3) of each measurement's photo
    against its point and Q_gp (n_points, n_g, 3) of the camera against the points (None
    without free camera parameters): the blocks of N⁻¹ (σ-free) by block elimination of the
    points,

        Q_c_j,p_i = −Σ_k (Q_c_j,c_k·N_c_k,p_i + Q_c_j,g·N_g,p_i)·N_pp,i⁻¹,
        Q_pp,i = N_pp,i⁻¹ + N_pp,i⁻¹·(Σ_j,k N_p_i,x_j·Q_x_j,x_k·N_x_k,p_i)·N_pp,i⁻¹,

    the sums over the photos j, k that measured point i (x = photo elements and camera; every
    such pair is in the selected inverse). Unused points: NaN."""
    qcc = q.blocks(p.obs_photo[pairs.first], p.obs_photo[pairs.second])
    t = np.zeros((p.obs_photo.size, 6, 3))
    np.add.at(t, pairs.first, np.einsum("nij,njk->nik", qcc, n.ncp[pairs.second]))
    inner = np.zeros((p.n_points, 3, 3))
    tg = None
    if n.ngp is not None:
        ng = n.ngp.shape[1]
        g_i = np.zeros((p.n_points, ng, 3))
        np.add.at(g_i, p.obs_point, n.ngp)
        qcg = q.cg(p.obs_photo)
        t += np.einsum("nij,njk->nik", qcg, g_i[p.obs_point])
        tg = np.einsum("ij,njk->nik", q.qgg, g_i)
        np.add.at(tg, p.obs_point, np.einsum("nji,njk->nik", qcg, n.ncp))
        inner += np.einsum("nji,njk->nik", g_i, tg)
    np.add.at(inner, p.obs_point, np.einsum("nji,njk->nik", n.ncp, t))
    qpp = n.pinv + np.einsum("nij,njk,nkl->nil", n.pinv, inner, n.pinv)
    qpp[n.unused] = np.nan
    qcp = -np.einsum("nij,njk->nik", t, n.pinv[p.obs_point])
    qgp = -np.einsum("nij,njk->nik", tg, n.pinv) if tg is not None else None
    return qpp, qcp, qgp


@dataclass(frozen=True, slots=True)
class Adjusted:
    """A converged bundle adjustment with what its precision and reliability are computed from:
    the solution, the normals at it, the photos' cofactors (None without covariances), the
    measurement pairs, the redundancy, Q_cp (n_obs, 6, 3), Q_gp (n_points, n_g, 3) and the
    camera (f, x₀, y₀, k₁, k₂, p₁, p₂; the certificate's unless self-calibrated)."""

    solution: BlockSolution
    normals: Normals
    inverse: PhotoCofactors | None
    pairs: MeasurementPairs
    redundancy: int
    qcp: NDArray[np.float64] | None
    qgp: NDArray[np.float64] | None = None
    camera: NDArray[np.float64] | None = None


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
        Compute σ₀²·N⁻¹'s 6 × 6 blocks of the photos (Eq. (3.11)) and the 3 × 3 blocks of every
        point, from the selected inverse of the reduced matrix
        (:mod:`~stereoplotter.triangulation.selected_inverse`; no dense inverse).

    Returns
    -------
    BlockSolution
        σ₀ = √([pvv]/r) with r = observations − unknowns (Eq. (3.10), weights 1/σ²).

    Raises
    ------
    GeometryError
        No convergence (names the photos of worst condition), a singular system or too little
        control.
    """
    return bundle_adjusted(
        p,
        initial,
        max_iterations=max_iterations,
        angle_tolerance=angle_tolerance,
        position_tolerance_m=position_tolerance_m,
        covariance=covariance,
    ).solution


def bundle_adjusted(
    p: BundleProblem,
    initial: tuple[NDArray, NDArray] | None = None,
    *,
    max_iterations: int = 30,
    angle_tolerance: float = 1e-8,
    position_tolerance_m: float = 1e-4,
    covariance: bool = True,
) -> Adjusted:
    """:func:`bundle_adjust` with the normals and the selected inverse at the solution
    (:class:`Adjusted`)."""
    _check_photos(p)
    orient, points = initial if initial is not None else initial_approximation(p)
    orient, points = orient.copy(), points.copy()
    camera = p.camera0()
    r = float(np.max(np.linalg.norm(p.xy_mm, axis=1))) if p.xy_mm.size else 1.0
    # a camera correction's largest effect on a photo coordinate, per unit [mm]
    reach = np.array([r / p.f_mm, 1.0, 1.0, r**3, r**5, 3 * r**2, 3 * r**2])[p.free]
    pairs = measurement_pairs(p.obs_point)
    converged = False
    for it in range(1, max_iterations + 1):  # noqa: B007 (reported after the loop)
        dc, dp, _, n, dg = _step(p, orient, points, pairs, camera)
        orient += dc
        points += dp
        camera[p.free] += dg
        if (
            np.all(np.abs(dc[:, :3]) <= angle_tolerance)
            and max(float(np.max(np.abs(dc[:, 3:]))), float(np.max(np.abs(dp))))
            <= position_tolerance_m
            and np.all(np.abs(dg) * reach <= 1e-5)  # 0.01 µm on the photo
        ):
            converged = True
            break
    if not converged:
        raise GeometryError(
            f"the bundle adjustment did not converge in {max_iterations} iterations (last "
            f"corrections {np.max(np.abs(dc[:, :3])):.3g} rad, {np.max(np.abs(dp)):.3g} m)"
            + weakest_photos(p, n.reduced)
            + ": expected each of them to see well-spread points; check the point "
            "identification and the control"
        )
    n = normals(p, orient, points, pairs, camera)
    used = ~n.unused
    n_obs = (
        2 * p.obs_photo.size
        + int(np.count_nonzero(p.control_weight))
        + int(np.count_nonzero(p.centre_weight))
    )
    redundancy = n_obs - 6 * p.n_photos - 3 * int(used.sum()) - p.free.size
    sigma0 = float(np.sqrt(n.vv / redundancy)) if redundancy > 0 else float("nan")
    points[~used] = np.nan
    notes = (f"redundancy {redundancy}",)
    if not covariance:
        s = BlockSolution("bundle", orient, None, points, it, sigma0, notes)
        return Adjusted(s, n, None, pairs, redundancy, None, None, camera)
    try:
        q = photo_cofactors(p, n)
    except (GeometryError, np.linalg.LinAlgError) as exc:
        raise GeometryError(f"{exc}{weakest_photos(p, n.reduced)}") from None
    cov, after = _photo_covariances(q, p.n_photos, sigma0)
    qpp, qcp, qgp = point_cofactors(p, n, q, pairs)
    s = BlockSolution(
        "bundle", orient, cov, points, it, sigma0, notes, after, point_covariances=sigma0**2 * qpp
    )
    return Adjusted(s, n, q, pairs, redundancy, qcp, qgp, camera)


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
    rows_all = p.obs_index
    _, jac, _ = _linearise(p, solution.orientations, np.nan_to_num(solution.points_m))
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
