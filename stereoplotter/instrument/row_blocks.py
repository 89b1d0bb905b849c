"""Element-wise maps on large broadcasts, evaluated a block of leading rows at a time (the same
numbers, the temporaries in cache instead of main memory)."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["ROWS_BLOCK_ELEMENTS", "ndim", "rowwise"]

#: Elements of one block of rows when an element-wise map is evaluated on a large broadcast (a
#: convention: the block's dozen temporaries, 8 bytes an element, stay in a core's cache). [—]
ROWS_BLOCK_ELEMENTS = 1 << 14


def ndim(value: Any) -> int:
    """The number of axes of an array; 0 for a scalar or ``None``."""
    return getattr(value, "ndim", 0)


def rowwise(fn: Any, args: tuple[Any, ...], outputs: int) -> tuple[NDArray[np.float64], ...]:
    """``fn(*args)`` — ``outputs`` arrays, each element from the same elements of ``args`` by
    IEEE arithmetic (+, −, ×, ÷) alone — evaluated a block of leading rows at a time where the
    arrays broadcast to more than two blocks of :data:`ROWS_BLOCK_ELEMENTS` over two or more
    axes (the per-trial maps of a (T, points) grid): the same numbers, each rounded alike in any
    block, with the temporaries in cache instead of main memory. ``None`` and scalars pass.

    Examples
    --------
    >>> a = np.linspace(0.0, 1.0, 50_000).reshape(2500, 20)
    >>> b = np.linspace(1.0, 3.0, 20)
    >>> fn = lambda u, v: (u * v + 1.0, u / v)
    >>> all(np.array_equal(p, q) for p, q in zip(rowwise(fn, (a, b), 2), fn(a, b)))
    True
    """
    if not any(ndim(a) >= 2 for a in args):
        return tuple(fn(*args))
    shape = np.broadcast_shapes(*(np.shape(a) for a in args if a is not None))
    size = int(np.prod(shape))
    if size <= 2 * ROWS_BLOCK_ELEMENTS:
        return tuple(fn(*args))
    rows = max(1, ROWS_BLOCK_ELEMENTS * shape[0] // size)
    lead = len(shape)
    cut = [isinstance(a, np.ndarray) and a.ndim == lead and a.shape[0] == shape[0] for a in args]
    out = tuple(np.empty(shape) for _ in range(outputs))
    for r in range(0, shape[0], rows):
        part = fn(*(a[r : r + rows] if c else a for a, c in zip(args, cut, strict=True)))
        for o, v in zip(out, part, strict=True):
            o[r : r + rows] = v
    return out
