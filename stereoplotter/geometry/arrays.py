"""The array form the vectorised equations take their arguments in."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["floats"]


def floats(v: ArrayLike) -> NDArray[np.float64]:
    """``v`` as a float64 array (not copied when it is one already), so that an equation
    broadcasts over scalars and arrays alike."""
    return np.asarray(v, dtype=float)
