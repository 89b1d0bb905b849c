r"""The α-ω-κ rotation matrix of Eq. (2.50) and its alternative angles t, α₀, κ₀ (2.51), (2.55).

Reference
---------
.. [1] Куштин (Kushtin) & Лысков (Lyskov), *Фотограмметрия снимка и стереоскопических моделей*,
   Moscow: Nedra, 1984, ch. 2, §12–§13, pp. 52–62 (OCR L1340–1500).

Conventions (``docs/conventions.md`` §4)
----------------------------------------
* α (longitudinal tilt) turns about the Y axis, first; ω (transverse tilt) about the new X′ axis;
  κ (swing) about the new Z″ axis: the φ-ω-κ family, **not** the ω-φ-κ order of most Western texts.
* M = R_Y(−α)·R_X(ω)·R_Z(κ), with the standard right-handed *active* rotations R. The columns of
  M are the photo axes x, y, z expressed in the object system X, Y, Z (Z up).
* α > 0 tilts the optical axis towards +X, ω > 0 towards +Y, κ > 0 turns the photo axes
  counter-clockwise seen from +Z.

Shapes: every function broadcasts its angle arguments; a matrix result has shape
``broadcast_shape + (3, 3)``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "alternative_angles_from_matrix",
    "angles_from_matrix",
    "rotation_matrix",
    "rotation_matrix_from_alternative_angles",
    "rotation_x",
    "rotation_y",
    "rotation_z",
]


def _rotation(theta: ArrayLike, axis: int) -> NDArray[np.float64]:
    theta = np.asarray(theta, dtype=float)
    c, s = np.cos(theta), np.sin(theta)
    m = np.zeros((*theta.shape, 3, 3))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    m[..., axis, axis] = 1.0
    m[..., i, i] = c
    m[..., j, j] = c
    m[..., i, j] = -s
    m[..., j, i] = s
    return m


def rotation_x(theta: ArrayLike) -> NDArray[np.float64]:
    """Active right-handed rotation about X: [[1, 0, 0], [0, c, −s], [0, s, c]]. θ [rad]."""
    return _rotation(theta, 0)


def rotation_y(theta: ArrayLike) -> NDArray[np.float64]:
    """Active right-handed rotation about Y: [[c, 0, s], [0, 1, 0], [−s, 0, c]]. θ [rad]."""
    return _rotation(theta, 1)


def rotation_z(theta: ArrayLike) -> NDArray[np.float64]:
    """Active right-handed rotation about Z: [[c, −s, 0], [s, c, 0], [0, 0, 1]]. θ [rad]."""
    return _rotation(theta, 2)


def rotation_matrix(alpha: ArrayLike, omega: ArrayLike, kappa: ArrayLike) -> NDArray[np.float64]:
    r"""Direction-cosine matrix of a photo from α, ω, κ.

    Parameters
    ----------
    alpha, omega, kappa : float or ndarray
        Longitudinal tilt α, transverse tilt ω, swing κ of Eq. (2.50). [rad]

    Returns
    -------
    ndarray, shape (..., 3, 3)
        M = [[a₁, a₂, a₃], [b₁, b₂, b₃], [c₁, c₂, c₃]]; columns are the photo axes in X, Y, Z. [—]

    Notes
    -----
    Implements Eq. (2.50) of [1]_ (§13, OCR L1427):

    .. math::
        a_1 = \cos\alpha\cos\kappa - \sin\alpha\sin\omega\sin\kappa,\;
        a_2 = -\cos\alpha\sin\kappa - \sin\alpha\sin\omega\cos\kappa,\;
        a_3 = -\sin\alpha\cos\omega

        b_1 = \cos\omega\sin\kappa,\; b_2 = \cos\omega\cos\kappa,\; b_3 = -\sin\omega

        c_1 = \sin\alpha\cos\kappa + \cos\alpha\sin\omega\sin\kappa,\;
        c_2 = -\sin\alpha\sin\kappa + \cos\alpha\sin\omega\cos\kappa,\;
        c_3 = \cos\alpha\cos\omega

    i.e. M = R_Y(−α)·R_X(ω)·R_Z(κ). Note the minus on α.

    Examples
    --------
    >>> import numpy as np
    >>> m = rotation_matrix(np.radians(3.0), 0.0, 0.0)
    >>> round(float(m[0, 2]), 6)  # a3 = -sin(alpha)
    -0.052336
    """
    alpha, omega, kappa = np.broadcast_arrays(
        np.asarray(alpha, float), np.asarray(omega, float), np.asarray(kappa, float)
    )
    return rotation_y(-alpha) @ rotation_x(omega) @ rotation_z(kappa)


def angles_from_matrix(
    rotation: ArrayLike,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    r"""α, ω, κ from a direction-cosine matrix (inverse of Eq. (2.50)).

    Parameters
    ----------
    rotation : ndarray, shape (..., 3, 3)
        Orthonormal matrix M of Eq. (2.50). [—]

    Returns
    -------
    alpha, omega, kappa : ndarray
        tan α = −a₃/c₃, sin ω = −b₃, tan κ = b₁/b₂ (quadrant-correct via atan2). [rad]

    Notes
    -----
    Follows from Eq. (2.50) of [1]_; the same relations are used in (2.55) (OCR L1497).
    Valid for |ω| < 90°.
    """
    m = np.asarray(rotation, dtype=float)
    alpha = np.arctan2(-m[..., 0, 2], m[..., 2, 2])
    omega = np.arcsin(np.clip(-m[..., 1, 2], -1.0, 1.0))
    kappa = np.arctan2(m[..., 1, 0], m[..., 1, 1])
    return alpha, omega, kappa


def rotation_matrix_from_alternative_angles(
    direction_t: ArrayLike, tilt: ArrayLike, kappa0: ArrayLike
) -> NDArray[np.float64]:
    r"""Direction-cosine matrix from the alternative angles t, α₀, κ₀.

    Parameters
    ----------
    direction_t : float or ndarray
        Direction angle t of the principal vertical. [rad]
    tilt : float or ndarray
        Tilt α₀ of the photo. [rad]
    kappa0 : float or ndarray
        Swing κ₀ counted from the principal vertical. [rad]

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Notes
    -----
    Implements Eq. (2.51) of [1]_ (§13, OCR L1431–1460) in the product form

    .. math:: M = R_Z(t)\,R_Y(-\alpha_0)\,R_Z(\kappa_0 - 90^\circ)

    This is **not** the identity at t = α₀ = κ₀ = 0: it equals (2.50) with κ = −90°.
    """
    t, a0, k0 = np.broadcast_arrays(
        np.asarray(direction_t, float), np.asarray(tilt, float), np.asarray(kappa0, float)
    )
    return rotation_z(t) @ rotation_y(-a0) @ rotation_z(k0 - np.pi / 2)


def alternative_angles_from_matrix(
    rotation: ArrayLike,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    r"""t, α₀, κ₀ from a direction-cosine matrix.

    Returns
    -------
    direction_t, tilt, kappa0 : ndarray
        tan t = b₃/a₃ (quadrant from a₃ = −sin α₀ cos t, b₃ = −sin α₀ sin t);
        sin α₀ = √(c₁² + c₂²) (α₀ from atan2 with c₃); tan κ₀ = c₁/c₂. [rad]

    Notes
    -----
    Implements Eq. (2.55) of [1]_ (OCR L1497). For α₀ = 0, t and κ₀ are not separately defined;
    then t = 0 is returned and κ₀ carries the whole swing.
    """
    m = np.asarray(rotation, dtype=float)
    a3, b3 = m[..., 0, 2], m[..., 1, 2]
    c1, c2, c3 = m[..., 2, 0], m[..., 2, 1], m[..., 2, 2]
    tilt = np.arctan2(np.hypot(c1, c2), c3)
    vertical = np.hypot(a3, b3) < 1e-15
    direction_t = np.where(vertical, 0.0, np.arctan2(-b3, -a3))
    kappa0 = np.where(
        vertical, np.arctan2(m[..., 1, 0], m[..., 1, 1]) + np.pi / 2, np.arctan2(c1, c2)
    )
    return direction_t, tilt, kappa0
