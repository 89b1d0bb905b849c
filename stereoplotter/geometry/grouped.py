"""Sums over groups of unequal sizes, each as ``numpy.sum`` of the group alone gives it.

``numpy.sum`` adds a run of 8 or more numbers pairwise, so a running sum over a group (``bincount``,
``add.reduceat``) can differ from it in the last bit; a computation done for many groups at once
then prints differently from the same computation done for one. :func:`group_sums` stacks the
groups of each size as the rows of one array and sums the rows: the sum of each row is the sum of
that group alone, to the bit.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["group_sums"]


def group_sums(values: ArrayLike, start: ArrayLike) -> NDArray[np.float64]:
    """The sum of each group of ``values``, group ``i`` being ``values[start[i]:start[i + 1]]``.

    Parameters
    ----------
    values : array_like, shape (n,)
    start : array_like of int, shape (G + 1,)
        Non-decreasing, ``start[0] = 0``, ``start[-1] = n`` (an empty group sums to 0).

    Returns
    -------
    ndarray, shape (G,)
        ``numpy.sum(values[start[i]:start[i + 1]])`` of each group, to the bit.

    Examples
    --------
    >>> group_sums([1.0, 2.0, 3.0, 4.0, 5.0], [0, 2, 2, 5]).tolist()
    [3.0, 0.0, 12.0]
    """
    v = np.asarray(values, float)
    first = np.asarray(start, np.intp)
    if len(first) == 2:  # one group
        return np.array([v[first[0] : first[1]].sum()])
    size = np.diff(first)
    out = np.zeros(len(size))
    for n in np.unique(size).tolist():
        if n == 0:
            continue
        members = np.flatnonzero(size == n)
        out[members] = v[first[members, None] + np.arange(n)].sum(axis=1)
    return out
