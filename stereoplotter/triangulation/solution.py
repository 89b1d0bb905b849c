"""The result every triangulation method returns, and its comparison with control and check points.

Angles [rad], coordinates [m] in the block's local system of §10, photo residuals [mm].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

from stereoplotter.geometry.collinearity import object_to_photo
from stereoplotter.geometry.intersection import space_intersection
from stereoplotter.geometry.rotation import rotation_matrix
from stereoplotter.triangulation.block import Block, catalogue_local, interior_orientation

__all__ = [
    "BlockSolution",
    "CatalogueResiduals",
    "catalogue_residuals",
    "forward_intersection",
    "photo_residuals",
    "sparse_least_squares",
]


@dataclass(frozen=True, slots=True)
class BlockSolution:
    """Exterior orientation of every photo of a block from one method.

    Attributes
    ----------
    method : str
        ``"bundle"``, ``"strip"``, ``"polygon"``.
    orientations : ndarray, shape (n_photos, 6)
        α, ω, κ [rad], X_S, Y_S, Z_S [m] per photo (order of ``Block.photos``).
    covariances : ndarray, shape (n_photos, 6, 6), or None
        Their covariance in rad and m (None where the method gives none).
    points_m : ndarray, shape (n_points, 3)
        Adjusted or intersected object points (order of ``Block.point_ids``; NaN where the method
        determines none). [m]
    iterations : int
        Iterations of the method's adjustment. [—]
    sigma0 : float
        A posteriori standard deviation of unit weight (1 when the a priori σ were right). [—]
    notes : tuple of str
        What the method did that a reader of the report needs (e.g. the control it used).
    next_covariances : ndarray, shape (n_photos, 6, 6), or None
        Covariance of photo j + 1 against photo j (the next in ``Block.photos``; zero for the
        last), for the pairs of the setup; None where the method gives none.
    point_covariances : ndarray, shape (n_points, 3, 3), or None
        Covariance of each object point's X, Y, Z [m²] (NaN where the method determines the
        point not); None where the method gives none.
    """

    method: str
    orientations: NDArray[np.float64]
    covariances: NDArray[np.float64] | None
    points_m: NDArray[np.float64]
    iterations: int
    sigma0: float
    notes: tuple[str, ...] = ()
    next_covariances: NDArray[np.float64] | None = None
    point_covariances: NDArray[np.float64] | None = None

    @property
    def point_standard_errors(self) -> NDArray[np.float64] | None:
        """σ of each point's X, Y, Z, shape (n_points, 3) [m] (NaN where undetermined), or None."""
        if self.point_covariances is None:
            return None
        with np.errstate(invalid="ignore"):
            return np.sqrt(np.einsum("nii->ni", self.point_covariances))

    def pair_covariance(self, j: int) -> NDArray[np.float64] | None:
        """12 × 12 covariance of photos j and j + 1 (rad, m), or None."""
        if self.covariances is None or self.next_covariances is None:
            return None
        c = np.zeros((12, 12))
        c[:6, :6], c[6:, 6:] = self.covariances[j], self.covariances[j + 1]
        c[6:, :6] = self.next_covariances[j]
        c[:6, 6:] = self.next_covariances[j].T
        return c

    @property
    def standard_errors(self) -> NDArray[np.float64] | None:
        """√diag of each photo's covariance, shape (n_photos, 6) [rad, m], or None."""
        if self.covariances is None:
            return None
        return np.sqrt(np.einsum("nii->ni", self.covariances))


@dataclass(frozen=True, slots=True)
class CatalogueResiduals:
    """Catalogue points compared with the triangulation.

    ``index`` into ``Block.catalogue``; ``computed_m`` the point by the triangulation,
    ``catalogue_m`` by the catalogue (both local) [m]; ``residuals_m`` = computed − catalogue [m];
    ``rays`` the number of photos that measured it.
    """

    index: NDArray[np.int64]
    computed_m: NDArray[np.float64]
    catalogue_m: NDArray[np.float64]
    residuals_m: NDArray[np.float64]
    rays: NDArray[np.int64]

    def rms(self, block: Block, role: str) -> NDArray[np.float64]:
        """RMS of X, Y, Z residuals over the points of ``role`` (plan of height points and
        height of plan points left out), shape (3,). [m]"""
        kinds = np.array([block.catalogue[i].kind for i in self.index])
        roles = np.array([block.catalogue[i].role for i in self.index])
        v = self.residuals_m.copy()
        v[kinds == "height", :2] = np.nan
        v[kinds == "plan", 2] = np.nan
        v = v[roles == role]
        with np.errstate(invalid="ignore"):
            return np.sqrt(np.nanmean(v**2, axis=0)) if v.size else np.full(3, np.nan)


def photo_residuals(block: Block, solution: BlockSolution) -> NDArray[np.float64]:
    """Measured minus computed photo coordinates (Eq. (2.53)) of every measurement, (n_obs, 2)
    [mm]; NaN for points the solution does not determine."""
    xy = interior_orientation(block)
    o = solution.orientations[block.obs_photo]
    m = rotation_matrix(o[:, 0], o[:, 1], o[:, 2])
    computed = object_to_photo(
        solution.points_m[block.obs_point], o[:, 3:], m, block.camera.focal_length_mm
    )
    return xy - computed


def forward_intersection(block: Block, solution: BlockSolution, points: NDArray) -> NDArray:
    """Each point (indices into ``Block.point_ids``) from the first and last photos that measured
    it, by Eq. (2.52) (space intersection); NaN for a point measured on fewer than two photos."""
    xy = interior_orientation(block)
    out = np.full((points.size, 3), np.nan)
    f = block.camera.focal_length_mm
    order = np.argsort(block.obs_point, kind="stable")
    bounds = np.searchsorted(block.obs_point[order], np.arange(len(block.point_ids) + 1))
    for k, i in enumerate(points):
        rows = order[bounds[i] : bounds[i + 1]]
        if rows.size < 2:
            continue
        a, b = rows[0], rows[-1]
        oa, ob = (
            solution.orientations[block.obs_photo[a]],
            solution.orientations[block.obs_photo[b]],
        )
        out[k] = space_intersection(
            xy[a], xy[b], oa[3:], rotation_matrix(*oa[:3]), ob[3:], rotation_matrix(*ob[:3]), f
        ).points_m
    return out


def catalogue_residuals(block: Block, solution: BlockSolution) -> CatalogueResiduals:
    """Catalogue points measured on the photos: the solution's point (or, where the method
    gives none, the space intersection of the two most distant rays) minus the catalogue."""
    where = {pid: i for i, pid in enumerate(block.point_ids)}
    index = np.array([k for k, p in enumerate(block.catalogue) if p.id in where], dtype=np.int64)
    points = np.array([where[block.catalogue[k].id] for k in index], dtype=np.int64)
    computed = solution.points_m[points].copy()
    missing = np.flatnonzero(np.any(~np.isfinite(computed), axis=1))
    if missing.size:
        computed[missing] = forward_intersection(block, solution, points[missing])
    local = catalogue_local(block)[index]
    rays = np.bincount(block.obs_point, minlength=len(block.point_ids))[points]
    return CatalogueResiduals(index, computed, local, computed - local, rays)


def sparse_least_squares(a: sp.spmatrix, b: NDArray) -> NDArray[np.float64]:
    """Least squares of a sparse full-rank system by its normal equations, scaled to unit
    diagonal and factored by sparse LU (SuperLU).

    Raises RuntimeError when singular: exactly, or a pivot below 10⁻¹⁰ of the largest (at unit
    diagonal a rank defect leaves pivots at rounding level, ~10⁻¹⁴; a weak but determined
    geometry keeps them orders above 10⁻¹⁰).
    """
    n = (a.T @ a).tocsc()
    scale = 1.0 / np.sqrt(n.diagonal())
    d = sp.diags(scale)
    lu = spla.splu((d @ n @ d).tocsc())
    pivots = np.abs(lu.U.diagonal())
    if pivots.min() < 1e-10 * pivots.max():
        raise RuntimeError(
            f"singular normal matrix (pivot ratio {pivots.min() / pivots.max():.1e})"
        )
    return scale * lu.solve(scale * (a.T @ b))
