r"""Selected inverse of the bundle's reduced normal matrix, without forming the dense inverse.

The reduced matrix S of the photos (6 × 6 blocks, one per pair of photos that share a point) is
banded once its photos are ordered by reverse Cuthill–McKee (SciPy's ``csgraph``): every pair of
photos that share a point lies within ``w`` positions of each other. Cut into super-blocks of
``w`` photos, S is block-tridiagonal, and the blocks of S⁻¹ on and next to the diagonal, which
hold every pair of photos sharing a point, follow from the recursions of the block Cholesky
factorisation (Takahashi's equations for a block-tridiagonal matrix)::

    D₀ = A₀₀,   D_k = A_kk − A_k,k−1 · D_{k−1}⁻¹ · A_k−1,k            (forward)
    G_last = D_last⁻¹,   X = A_k+1,k · D_k⁻¹,
    G_k+1,k = −G_k+1,k+1 · X,   G_kk = D_k⁻¹ − Xᵀ · G_k+1,k           (backward)

Work (6w)³ per super-block and memory 3·(6w)² per super-block: linear in the number of photos
for a block of given strip length. A pair of photos further apart (e.g. the last photo of a strip
and the first of the next) is solved from the sparse LU factor, six columns per photo.
All on the matrix scaled to unit diagonal (angles in rad and centres in m differ by 10⁶).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray
from scipy.sparse.csgraph import reverse_cuthill_mckee

from stereoplotter.errors import GeometryError

__all__ = ["SelectedInverse", "selected_inverse"]


@dataclass(frozen=True, slots=True)
class SelectedInverse:
    """The blocks of S⁻¹ of photos within ``width`` positions (in ``order``) of each other.

    ``order`` the photos in band order, ``position`` the inverse permutation; ``diag`` (nb, 6w,
    6w) and ``lower`` (nb − 1, 6w, 6w) the super-blocks G_kk and G_k+1,k of the scaled inverse;
    ``scale`` (6n,) the unit-diagonal scaling; ``reduced`` the unscaled S (for far pairs).
    """

    order: NDArray[np.int64]
    position: NDArray[np.int64]
    width: int
    diag: NDArray[np.float64]
    lower: NDArray[np.float64]
    scale: NDArray[np.float64]
    reduced: sp.csc_matrix

    def blocks(self, a: NDArray, b: NDArray) -> NDArray[np.float64]:
        """(S⁻¹)_ab, the 6 × 6 blocks of photos a and b (arrays of equal length), (m, 6, 6)."""
        a, b = np.asarray(a, np.int64), np.asarray(b, np.int64)
        w = self.width
        pa, pb = self.position[a], self.position[b]
        ka, kb, ra, rb = pa // w, pb // w, pa % w, pb % w
        nb = self.diag.shape[0]
        out = np.empty((a.size, 6, 6))
        d4 = self.diag.reshape(nb, w, 6, w, 6)
        same = ka == kb
        out[same] = d4[ka[same], ra[same], :, rb[same], :]
        if nb > 1:
            l4 = self.lower.reshape(nb - 1, w, 6, w, 6)
            below = ka == kb + 1
            out[below] = l4[kb[below], ra[below], :, rb[below], :]
            above = kb == ka + 1
            out[above] = np.swapaxes(l4[ka[above], rb[above], :, ra[above], :], 1, 2)
            far = np.flatnonzero(~(same | below | above))
        else:
            far = np.zeros(0, np.int64)
        if far.size:
            out[far] = self._far(a[far], b[far])
        s = self.scale.reshape(-1, 6)
        return s[a][:, :, None] * out * s[b][:, None, :]

    def _far(self, a: NDArray, b: NDArray) -> NDArray[np.float64]:
        """Scaled blocks of far pairs from the sparse LU factor (six columns per photo b)."""
        d = sp.diags(self.scale)
        lu = spla.splu((d @ self.reduced @ d).tocsc(), permc_spec="COLAMD")
        n6 = self.reduced.shape[0]
        out = np.empty((a.size, 6, 6))
        for photo in np.unique(b):
            e = np.zeros((n6, 6))
            e[6 * photo + np.arange(6), np.arange(6)] = 1.0
            x = lu.solve(e).reshape(-1, 6, 6)
            mine = np.flatnonzero(b == photo)
            out[mine] = x[a[mine]]
        return out


def _cho_inverse(m: NDArray, k: int) -> NDArray[np.float64]:
    try:
        c = sla.cho_factor(m, lower=True, check_finite=False)
    except np.linalg.LinAlgError:
        raise GeometryError(
            f"the reduced normal matrix is not positive definite (super-block {k})"
        ) from None
    inv = sla.cho_solve(c, np.eye(m.shape[0]), check_finite=False)
    return (inv + inv.T) / 2.0


# long: the two recursions of the block-tridiagonal selected inverse, with the band ordering
def selected_inverse(reduced: sp.spmatrix) -> SelectedInverse:
    """The :class:`SelectedInverse` of a symmetric positive definite matrix of 6 × 6 blocks.

    Raises
    ------
    GeometryError
        The matrix is not positive definite.
    """
    s = sp.csr_matrix(reduced)
    n6 = s.shape[0]
    n = n6 // 6
    diag = s.diagonal()
    scale = 1.0 / np.sqrt(np.where(diag > 0, diag, 1.0))
    coo = s.tocoo()
    graph = sp.csr_matrix((np.ones(coo.row.size), (coo.row // 6, coo.col // 6)), shape=(n, n))
    order = reverse_cuthill_mckee(graph, symmetric_mode=True).astype(np.int64)
    position = np.empty(n, np.int64)
    position[order] = np.arange(n)
    width = max(1, int(np.max(np.abs(position[coo.row // 6] - position[coo.col // 6]), initial=0)))
    nb = -(-n // width)
    m = 6 * width
    new = 6 * position[np.arange(n6) // 6] + np.arange(n6) % 6
    scaled = sp.csr_matrix(
        (coo.data * scale[coo.row] * scale[coo.col], (new[coo.row], new[coo.col])),
        shape=(6 * nb * width, 6 * nb * width),
    )
    pad = np.arange(n6, 6 * nb * width)
    scaled = scaled + sp.csr_matrix((np.ones(pad.size), (pad, pad)), shape=scaled.shape)
    inv = np.empty((nb, m, m))
    lower = np.empty((max(nb - 1, 0), m, m))
    prev = None
    for k in range(nb):
        sl = slice(k * m, (k + 1) * m)
        a = scaled[sl, sl].toarray()
        if k > 0:
            off = scaled[sl, (k - 1) * m : k * m].toarray()  # A_k,k−1
            lower[k - 1] = off
            a -= off @ prev @ off.T
        inv[k] = prev = _cho_inverse(a, k)
    g = inv  # overwritten in place by G_kk, from the last super-block back
    for k in range(nb - 2, -1, -1):
        x = lower[k] @ g[k]  # A_k+1,k · D_k⁻¹
        lower[k] = -g[k + 1] @ x
        g[k] = g[k] - x.T @ lower[k]
        g[k] = (g[k] + g[k].T) / 2.0
    return SelectedInverse(order, position, width, g, lower, scale, sp.csc_matrix(reduced))
