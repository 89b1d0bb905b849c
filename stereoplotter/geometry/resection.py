r"""Single-photo space resection: rigorous least squares on the collinearity equations (2.53).

Reference
---------
.. [1] Kushtin & Lyskov, *Фотограмметрия снимка и стереоскопических моделей*, Moscow: Nedra,
   1984, ch. 3, §17 "Joint determination of the elements of orientation", pp. 75–80
   (OCR L1851–1982), and §18, pp. 80–93 (OCR L1983–2300).

§17 of [1]_ solves the resection by successive approximations on the linearised collinearity
equations (3.3)/(3.6) in the ground-plane form (3.1), and updates the unknowns by (3.7). This
module solves the same problem in the image-space form (2.53) by Gauss–Newton with an analytic
Jacobian, i.e. it minimises the photo-coordinate residuals, which is the usual weighting when the
photo coordinates are the measured quantities. The book's own step-by-step method of §18 is in
:mod:`stereoplotter.geometry.resection_book`.

Conventions (``docs/conventions.md`` §1, §4, §5)
-------------------------------------------------
* Photo coordinates x, y [mm] in the fiducial system; principal point (x₀, y₀) [mm]; focal
  length f [mm]. Object coordinates X, Y, Z [m], right-handed, Z up.
* α, ω, κ [rad] define M of Eq. (2.50) (:func:`~stereoplotter.geometry.rotation.rotation_matrix`).
* The unknowns are ordered (α, ω, κ, X_S, Y_S, Z_S); the covariance matrix uses that order and
  the units rad and m.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.constants import ARCSEC_PER_RAD
from stereoplotter.errors import GeometryError
from stereoplotter.geometry.collinearity import object_to_photo
from stereoplotter.geometry.rotation import (
    angles_from_matrix,
    rotation_matrix,
    rotation_x,
    rotation_y,
    rotation_z,
)

__all__ = [
    "ResectionResult",
    "initial_exterior_orientation",
    "model_and_jacobian",
    "space_resection",
]

#: Generators of the elementary rotations: d/dθ R_X(θ) = G_X·R_X(θ), and so on.
_G_X = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
_G_Y = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 0.0], [-1.0, 0.0, 0.0]])
_G_Z = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])

#: Relative size of the second singular value below which a point set counts as collinear.
_COLLINEAR_RATIO = 1e-6


@dataclass(frozen=True, slots=True)
class ResectionResult:
    """Exterior orientation of one photo from a space resection.

    Attributes
    ----------
    alpha, omega, kappa : float
        Longitudinal tilt α, transverse tilt ω and swing κ of Eq. (2.50). [rad]
    projection_centre_m : ndarray, shape (3,)
        X_S, Y_S, Z_S. [m]
    residuals_mm : ndarray, shape (n, 2)
        Measured minus computed photo coordinates (x, y) of each point at the solution. [mm]
    rms_residual_mm : float
        Root mean square of all 2n residual components. [mm]
    redundancy : int
        2n − 6, the number of observations minus the number of unknowns. [—]
    sigma0_mm : float or None
        A posteriori standard deviation of unit weight, √([vv]/(2n − 6)) as in Eq. (3.10) of
        [1]_ (one photo coordinate has unit weight); None when the redundancy is 0. [mm]
    covariance : ndarray, shape (6, 6), or None
        σ₀²·(JᵀJ)⁻¹ for (α, ω, κ, X_S, Y_S, Z_S) in rad and m (Eq. (3.11) of [1]_ gives its
        diagonal); None when the redundancy is 0. [rad², rad·m, m²]
    iterations : int
        Gauss–Newton iterations performed. [—]
    converged : bool
        Whether the last correction fell below the tolerances.
    """

    alpha: float
    omega: float
    kappa: float
    projection_centre_m: NDArray[np.float64]
    residuals_mm: NDArray[np.float64]
    rms_residual_mm: float
    redundancy: int
    sigma0_mm: float | None
    covariance: NDArray[np.float64] | None
    iterations: int
    converged: bool

    @property
    def angles(self) -> NDArray[np.float64]:
        """(α, ω, κ). [rad]"""
        return np.array([self.alpha, self.omega, self.kappa])

    @property
    def rotation(self) -> NDArray[np.float64]:
        """M of Eq. (2.50) for (α, ω, κ). [—]"""
        return rotation_matrix(self.alpha, self.omega, self.kappa)

    @property
    def standard_errors(self) -> NDArray[np.float64] | None:
        """√diag(covariance) for (α, ω, κ, X_S, Y_S, Z_S) [rad, m], or None (Eq. (3.11) of [1]_)."""
        if self.covariance is None:
            return None
        return np.sqrt(np.diag(self.covariance))


def _validate(
    photo_mm: ArrayLike, points_m: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    photo = np.asarray(photo_mm, dtype=float)
    points = np.asarray(points_m, dtype=float)
    if photo.ndim != 2 or photo.shape[1] != 2:
        raise GeometryError(f"photo_mm must have shape (n, 2), got {photo.shape}")
    if points.ndim != 2 or points.shape[1] != 3:
        raise GeometryError(f"points_m must have shape (n, 3), got {points.shape}")
    if photo.shape[0] != points.shape[0]:
        raise GeometryError(
            f"photo_mm has {photo.shape[0]} points but points_m has {points.shape[0]}"
        )
    n = photo.shape[0]
    if n < 3:
        raise GeometryError(
            f"space resection needs at least 3 control points (6 unknowns), got {n}"
        )
    if not (np.all(np.isfinite(photo)) and np.all(np.isfinite(points))):
        raise GeometryError("photo_mm and points_m must be finite (found NaN or inf)")
    for name, xyz, unit in (("points_m", points, "m"), ("photo_mm", photo, "mm")):
        diff = xyz[:, None, :] - xyz[None, :, :]
        dist = np.sqrt(np.sum(diff**2, axis=-1))
        scale = float(np.max(dist))
        i, j = np.nonzero(np.triu(dist <= 1e-9 * max(scale, 1.0), k=1))
        if i.size:
            raise GeometryError(
                f"{name}: points {i[0]} and {j[0]} coincide ({xyz[i[0]].tolist()} {unit}); "
                "every control point must be distinct"
            )
        s = np.linalg.svd(xyz - xyz.mean(axis=0), compute_uv=False)
        if s[1] <= _COLLINEAR_RATIO * s[0]:
            raise GeometryError(
                f"{name}: the {n} control points are collinear (singular values {s.tolist()}); "
                "the resection needs points that span a plane"
            )
    return photo, points


def initial_exterior_orientation(
    photo_mm: ArrayLike,
    points_m: ArrayLike,
    focal_length_mm: float,
    principal_point_mm: ArrayLike = (0.0, 0.0),
) -> NDArray[np.float64]:
    r"""Approximate exterior orientation of a near-vertical photo.

    Parameters
    ----------
    photo_mm : array_like, shape (n, 2)
        Photo coordinates x, y of the control points. [mm]
    points_m : array_like, shape (n, 3)
        Object coordinates X, Y, Z of the same points. [m]
    focal_length_mm : float
        f. [mm]
    principal_point_mm : array_like, shape (2,)
        x₀, y₀. [mm]

    Returns
    -------
    ndarray, shape (6,)
        (α, ω, κ, X_S, Y_S, Z_S) with α = ω = 0. [rad, rad, rad, m, m, m]

    Notes
    -----
    The photo is taken as vertical (α = ω = 0, as the book does for the first approximation of
    plan photos, §18 of [1]_). Then X − X_S = s·R(κ)·(x − x₀) in plan, with s = (Z_S − Z)/f. A
    plane similarity X + iY = a·(x + iy) + b fitted by linear least squares gives
    κ = arg a, the nadir (X_S, Y_S) = b and the scale |a| [m/mm]; Z_S = mean(Z) + |a|·f.
    This is an *assumption* of this package, not a method of the book.
    """
    photo, points = _validate(photo_mm, points_m)
    xy = photo - np.asarray(principal_point_mm, dtype=float)
    z_photo = xy[:, 0] + 1j * xy[:, 1]
    z_ground = points[:, 0] + 1j * points[:, 1]
    design = np.column_stack([z_photo, np.ones_like(z_photo)])
    (a, b), *_ = np.linalg.lstsq(design, z_ground, rcond=None)
    if abs(a) == 0.0:
        raise GeometryError("cannot form an initial approximation: photo and ground scale is zero")
    height = float(np.mean(points[:, 2])) + abs(a) * float(focal_length_mm)
    return np.array([0.0, 0.0, float(np.angle(a)), b.real, b.imag, height])


def model_and_jacobian(
    params: NDArray[np.float64],
    points: NDArray[np.float64],
    f: float,
    principal_point: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Computed photo coordinates (n, 2) of Eq. (2.53) and their Jacobian (n, 2, 6)."""
    alpha, omega, kappa = params[:3]
    centre = params[3:]
    m = rotation_matrix(alpha, omega, kappa)
    ry, rx, rz = rotation_y(-alpha), rotation_x(omega), rotation_z(kappa)
    # Derivatives of M = R_Y(−α)·R_X(ω)·R_Z(κ) of Eq. (2.50).
    dm = np.stack([-_G_Y @ m, ry @ _G_X @ rx @ rz, m @ _G_Z])
    delta = points - centre
    u = delta @ m  # u = Mᵀ·Δ, Eq. (2.49)
    du_angles = np.einsum("kji,nj->nki", dm, delta)  # (n, 3 angles, 3)
    du_centre = -np.broadcast_to(m, (points.shape[0], 3, 3))  # ∂u_i/∂S_k = −M_ki
    du = np.concatenate([du_angles, du_centre], axis=1)  # (n, 6, 3)
    if np.any(u[:, 2] >= 0.0):
        bad = np.nonzero(u[:, 2] >= 0.0)[0].tolist()
        raise GeometryError(
            f"control points {bad} lie behind the camera at the current approximation; "
            "give a better `initial` exterior orientation"
        )
    u1, u2, u3 = u[:, 0:1], u[:, 1:2], u[:, 2:3]
    xy = object_to_photo(points, centre, m, f, principal_point)  # Eq. (2.53)
    jx = -f * (du[:, :, 0] * u3 - u1 * du[:, :, 2]) / u3**2
    jy = -f * (du[:, :, 1] * u3 - u2 * du[:, :, 2]) / u3**2
    return xy, np.stack([jx, jy], axis=1)


# long: the docstring (parameters, Eqs. (3.6)–(3.11), a Table 7 example) is 70 lines; code ~27
def space_resection(
    photo_mm: ArrayLike,
    points_m: ArrayLike,
    focal_length_mm: float,
    principal_point_mm: ArrayLike = (0.0, 0.0),
    initial: ArrayLike | None = None,
    *,
    angle_tolerance: float = 1e-6 / ARCSEC_PER_RAD,
    position_tolerance_m: float = 1e-7,
    max_iterations: int = 50,
    raise_on_failure: bool = True,
) -> ResectionResult:
    r"""Exterior orientation of a photo from three or more control points (space resection).

    Parameters
    ----------
    photo_mm : array_like, shape (n, 2)
        Measured photo coordinates x, y of the control points, n ≥ 3. [mm]
    points_m : array_like, shape (n, 3)
        Object coordinates X, Y, Z of the control points. [m]
    focal_length_mm : float
        f. [mm]
    principal_point_mm : array_like, shape (2,)
        x₀, y₀. [mm]
    initial : array_like, shape (6,), optional
        Approximate (α, ω, κ, X_S, Y_S, Z_S) [rad, m]. By default
        :func:`initial_exterior_orientation` (vertical photo, plane similarity), which converges
        for near-vertical aerial photos (tilts of a few degrees, any swing).
    angle_tolerance : float
        Convergence threshold ε₁ of Eq. (3.8) on |δα|, |δω|, |δκ|. [rad] (default 1e-6″)
    position_tolerance_m : float
        Convergence threshold ε₂, ε₃ of Eq. (3.8) on |δX_S|, |δY_S|, |δZ_S|. [m]
    max_iterations : int
        Maximum number of Gauss–Newton iterations. [—]
    raise_on_failure : bool
        If True (default), raise :class:`~stereoplotter.errors.GeometryError` when the iteration
        does not converge; otherwise return the last iterate with ``converged=False``.

    Returns
    -------
    ResectionResult
        The six elements, residuals, RMS, σ₀, covariance, iteration count and convergence flag.

    Raises
    ------
    GeometryError
        Fewer than 3 points, coincident or collinear points, points behind the camera, a
        singular normal matrix, or no convergence within ``max_iterations``.

    Notes
    -----
    Implements the resection of §17 of [1]_: Eq. (2.53) is linearised in the six elements of
    exterior orientation (the system (3.6) of [1]_, here in image space), solved by least
    squares and the elements are updated by Eq. (3.7) until the corrections satisfy Eq. (3.8).
    The precision follows from Eqs. (3.10)–(3.11): σ₀ = √([vv]/(2n − 6)) and
    C = σ₀²·(JᵀJ)⁻¹. The Jacobian is analytic, from M = R_Y(−α)·R_X(ω)·R_Z(κ) of Eq. (2.50).

    Examples
    --------
    The four control points of Table 7 of [1]_, imaged with the true orientation:

    >>> import numpy as np
    >>> from stereoplotter.geometry.collinearity import object_to_photo
    >>> from stereoplotter.geometry.rotation import rotation_matrix
    >>> points = [[2100, 1400, 2], [3500, 1400, 85], [3500, 15, 19], [2100, 3, 51]]
    >>> m = rotation_matrix(*np.radians([3.0, 2.0, -3.0]))
    >>> photo = object_to_photo(points, [2800, 700, 750], m, 75.0)
    >>> result = space_resection(photo, points, 75.0)
    >>> np.round(np.degrees(result.angles), 6)
    array([ 3.,  2., -3.])
    >>> np.round(result.projection_centre_m, 3)
    array([2800.,  700.,  750.])
    """
    data = _inputs(photo_mm, points_m, focal_length_mm, principal_point_mm)
    params = _initial_params(*data, initial)
    tolerances = angle_tolerance, position_tolerance_m
    params, its, converged = _iterate(params, data, tolerances, max_iterations, raise_on_failure)
    return _resection_result(params, *data, its, converged)


def _inputs(photo_mm, points_m, focal_length_mm, principal_point_mm) -> tuple:
    """(photo, points, f, principal point) of :func:`space_resection`, checked."""
    photo, points = _validate(photo_mm, points_m)
    f = float(focal_length_mm)
    if not f > 0.0:
        raise GeometryError(f"focal_length_mm must be positive, got {focal_length_mm!r}")
    return photo, points, f, np.asarray(principal_point_mm, dtype=float)


def _iterate(
    params: NDArray[np.float64],
    data: tuple,
    tolerances: tuple[float, float],
    max_iterations: int,
    raise_on_failure: bool,
) -> tuple[NDArray[np.float64], int, bool]:
    """Gauss–Newton steps, Eq. (3.7), until the corrections satisfy Eq. (3.8) (``tolerances``:
    ε₁ [rad] on the angles, ε₂ = ε₃ [m] on the centre) or ``max_iterations`` (arguments and
    failure as :func:`space_resection`). Returns the elements, the iterations used and whether
    they converged."""
    angle_tolerance, position_tolerance_m = tolerances
    converged = False
    iterations = 0
    for iterations in range(1, max_iterations + 1):  # noqa: B007 (reported after the loop)
        delta = _gauss_newton_step(params, *data)
        params = params + delta  # Eq. (3.7)
        if np.all(np.abs(delta[:3]) <= angle_tolerance) and np.all(
            np.abs(delta[3:]) <= position_tolerance_m
        ):  # Eq. (3.8)
            converged = True
            break
    if not converged and raise_on_failure:
        raise GeometryError(
            f"space resection did not converge in {max_iterations} iterations (last corrections "
            f"{(np.abs(delta[:3]) * ARCSEC_PER_RAD).max():.3g} arcsec, "
            f"{np.abs(delta[3:]).max():.3g} m); give a better `initial` or check the point "
            "identification"
        )
    return params, iterations, converged


def _initial_params(photo, points, f, pp, initial) -> NDArray[np.float64]:
    """The starting (α, ω, κ, X_S, Y_S, Z_S): ``initial`` checked, or the vertical-photo guess."""
    if initial is None:
        return initial_exterior_orientation(photo, points, f, pp)
    params = np.asarray(initial, dtype=float).copy()
    if params.shape != (6,):
        raise GeometryError(
            f"initial must be (alpha, omega, kappa, X_S, Y_S, Z_S), got shape {params.shape}"
        )
    return params


def _gauss_newton_step(params, photo, points, f, pp) -> NDArray[np.float64]:
    """The least-squares correction of the linearised system (3.6) at ``params``."""
    computed, jac = model_and_jacobian(params, points, f, pp)
    v = (photo - computed).reshape(-1)
    a = jac.reshape(-1, 6)
    # Column scaling: angles (rad) and positions (m) differ by orders of magnitude.
    scale = np.sqrt(np.sum(a**2, axis=0))
    if np.any(scale == 0.0):
        raise GeometryError("the Jacobian has a zero column: the geometry fixes no element")
    a_scaled = a / scale
    s = np.linalg.svd(a_scaled, compute_uv=False)
    if s[-1] <= 1e-10 * s[0]:
        raise GeometryError(
            "the normal equations are singular (condition "
            f"{s[0] / s[-1]:.3g}): the control points do not determine all six elements"
        )
    delta_scaled, *_ = np.linalg.lstsq(a_scaled, v, rcond=None)
    return delta_scaled / scale


def _resection_result(params, photo, points, f, pp, iterations, converged) -> ResectionResult:
    """Residuals and precision (Eqs. (3.10)–(3.11)) at the final ``params``."""
    n = photo.shape[0]
    # Re-express the angles in their principal range via the matrix (α, κ in (−π, π]).
    alpha, omega, kappa = (float(t) for t in angles_from_matrix(rotation_matrix(*params[:3])))
    params[:3] = (alpha, omega, kappa)
    computed, jac = model_and_jacobian(params, points, f, pp)
    residuals = photo - computed
    rms = float(np.sqrt(np.mean(residuals**2)))
    redundancy = 2 * n - 6
    sigma0: float | None = None
    covariance: NDArray[np.float64] | None = None
    if redundancy > 0:
        sigma0 = float(np.sqrt(np.sum(residuals**2) / redundancy))  # Eq. (3.10)
        a = jac.reshape(-1, 6)
        covariance = sigma0**2 * np.linalg.inv(a.T @ a)  # Eq. (3.11)
    return ResectionResult(
        alpha=alpha,
        omega=omega,
        kappa=kappa,
        projection_centre_m=params[3:].copy(),
        residuals_mm=residuals,
        rms_residual_mm=rms,
        redundancy=redundancy,
        sigma0_mm=sigma0,
        covariance=covariance,
        iterations=iterations,
        converged=converged,
    )
