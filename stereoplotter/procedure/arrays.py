"""The array types of the procedure's annotations: values over the trials of a run.

A value of a vectorised run is an array over its T trials, shape (T,) (or () for a single run);
a mask marks the trials an act applies to (None: all of them).
"""

from __future__ import annotations

from typing import Any, TypeAlias

import numpy as np
from numpy.typing import NDArray

__all__ = ["Active", "Floats", "Mask", "Value", "max_abs_last"]

#: Values over the trials, float64. [the quantity's unit]
Floats: TypeAlias = NDArray[np.float64]
#: A mask over the trials.
Mask: TypeAlias = NDArray[np.bool_]
#: The trials an act applies to: a mask, or None for all.
Active: TypeAlias = Mask | None
#: A value over the trials or a scalar of one run, as numpy's arithmetic returns it (an array,
#: a numpy scalar or a float): loosely typed where numpy's stubs cannot follow the broadcasting.
Value: TypeAlias = Any


#: Longest last axis reduced column by column in :func:`max_abs_last` (a convention: numpy's
#: reduction along a short contiguous axis costs ≈ 40 ns an element, ≈ 15× a column's
#: element-wise maximum on (8 000, 6); from ≈ 30 columns on, numpy's own is as fast).
_COLUMNS_MAX = 16


def max_abs_last(v: Floats) -> Floats:
    """``np.max(np.abs(v), axis=-1)``: the largest |·| along the last axis, the same values. A
    short last axis (≤ :data:`_COLUMNS_MAX`) of a stack of values (T, n) is reduced as n
    element-wise maxima of the columns: a maximum of absolute values (no −0, a NaN wins in
    either) is the same number taken in any order.

    Examples
    --------
    >>> v = np.array([[1.0, -3.0, 2.0], [-0.0, 0.5, np.nan]])
    >>> max_abs_last(v).tolist()
    [3.0, nan]
    """
    if v.ndim < 2 or not 0 < v.shape[-1] <= _COLUMNS_MAX:
        out: Floats = np.max(np.abs(v), axis=-1)
        return out
    worst: Floats = np.abs(v[..., 0])
    for j in range(1, v.shape[-1]):
        np.maximum(worst, np.abs(v[..., j]), out=worst)
    return worst
