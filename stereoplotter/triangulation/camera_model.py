r"""The camera of a self-calibrating bundle: principal distance, principal point and distortion.

The measured photo coordinates (relative to the certificate's principal point) are modelled as

    x = x₀ + x̄ + x̄·(k₁r² + k₂r⁴) + p₁(r² + 2x̄²) + 2p₂x̄ȳ,
    y = y₀ + ȳ + ȳ·(k₁r² + k₂r⁴) + p₂(r² + 2ȳ²) + 2p₁x̄ȳ,     r² = x̄² + ȳ²,

with (x̄, ȳ) the collinearity image of Eq. (2.53) at principal distance f: Brown's radial
(k₁, k₂) and decentring (p₁, p₂) distortion added to the ideal image (the book's Eq. (2.53) is
the case of all seven at their certificate values: f certified, the rest 0). Units: f, x₀, y₀
[mm]; k₁ [mm⁻²], k₂ [mm⁻⁴]; p₁, p₂ [mm⁻¹].
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["CAMERA_PARAMETERS", "CAMERA_UNITS", "camera_image"]

#: The parameters in the order of a camera vector.
CAMERA_PARAMETERS = ("f", "x0", "y0", "k1", "k2", "p1", "p2")
CAMERA_UNITS = ("mm", "mm", "mm", "mm⁻²", "mm⁻⁴", "mm⁻¹", "mm⁻¹")


def camera_image(
    ideal_mm: NDArray[np.float64], camera: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The measured image of ideal points (module docstring).

    Parameters
    ----------
    ideal_mm : ndarray, shape (n, 2)
        x̄, ȳ of Eq. (2.53) at the camera's f. [mm]
    camera : ndarray, shape (7,)
        f, x₀, y₀, k₁, k₂, p₁, p₂ (:data:`CAMERA_PARAMETERS`).

    Returns
    -------
    xy : ndarray (n, 2)
        The modelled measurement. [mm]
    d : ndarray (n, 2, 2)
        ∂(x, y)/∂(x̄, ȳ) (the chain factor of every other derivative). [—]
    jac : ndarray (n, 2, 7)
        ∂(x, y)/∂(camera), f through x̄ = f·(…): ∂x̄/∂f = x̄/f.
    """
    f, x0, y0, k1, k2, p1, p2 = (float(v) for v in camera)
    x, y = ideal_mm[:, 0], ideal_mm[:, 1]
    r2 = x * x + y * y
    radial = k1 * r2 + k2 * r2 * r2
    dradial = 2.0 * k1 + 4.0 * k2 * r2  # ∂radial/∂x = x·dradial
    xy = np.column_stack(
        [
            x0 + x + x * radial + p1 * (r2 + 2 * x * x) + 2 * p2 * x * y,
            y0 + y + y * radial + p2 * (r2 + 2 * y * y) + 2 * p1 * x * y,
        ]
    )
    d = np.empty((x.size, 2, 2))
    d[:, 0, 0] = 1.0 + radial + x * x * dradial + 6 * p1 * x + 2 * p2 * y
    d[:, 0, 1] = x * y * dradial + 2 * p1 * y + 2 * p2 * x
    d[:, 1, 0] = x * y * dradial + 2 * p2 * x + 2 * p1 * y
    d[:, 1, 1] = 1.0 + radial + y * y * dradial + 6 * p2 * y + 2 * p1 * x
    jac = np.zeros((x.size, 2, 7))
    jac[:, :, 0] = np.einsum("nij,nj->ni", d, ideal_mm / f)
    jac[:, 0, 1] = 1.0
    jac[:, 1, 2] = 1.0
    jac[:, 0, 3], jac[:, 1, 3] = x * r2, y * r2
    jac[:, 0, 4], jac[:, 1, 4] = x * r2 * r2, y * r2 * r2
    jac[:, 0, 5], jac[:, 1, 5] = r2 + 2 * x * x, 2 * x * y
    jac[:, 0, 6], jac[:, 1, 6] = 2 * x * y, r2 + 2 * y * y
    return xy, d, jac
