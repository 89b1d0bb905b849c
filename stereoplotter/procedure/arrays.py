"""The array types of the procedure's annotations: values over the trials of a run.

A value of a vectorised run is an array over its T trials, shape (T,) (or () for a single run);
a mask marks the trials an act applies to (None: all of them).
"""

from __future__ import annotations

from typing import Any, TypeAlias

import numpy as np
from numpy.typing import NDArray

__all__ = ["Active", "Floats", "Mask", "Value"]

#: Values over the trials, float64. [the quantity's unit]
Floats: TypeAlias = NDArray[np.float64]
#: A mask over the trials.
Mask: TypeAlias = NDArray[np.bool_]
#: The trials an act applies to: a mask, or None for all.
Active: TypeAlias = Mask | None
#: A value over the trials or a scalar of one run, as numpy's arithmetic returns it (an array,
#: a numpy scalar or a float): loosely typed where numpy's stubs cannot follow the broadcasting.
Value: TypeAlias = Any
