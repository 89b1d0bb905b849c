"""The one figure encoder: a matplotlib Figure as PNG or PDF bytes, reproducibly.

No date, no program name in the file (the ``Software`` chunk of a PNG, ``Creator``, ``Producer``
and ``CreationDate`` of a PDF): the same figure gives the same bytes, so every output file of a
command is byte-identical for the same inputs. Writing the bytes is :mod:`stereoplotter.io`'s.
"""

from __future__ import annotations

import io
from typing import Any, Literal

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # after the back-end is chosen

__all__ = ["figure_bytes"]

#: Metadata entries matplotlib would fill in with the version or the time, left out.
_NO_METADATA = {
    "png": {"Software": None},
    "pdf": {"Creator": None, "Producer": None, "CreationDate": None},
}


def figure_bytes(
    figure: Any, fmt: Literal["png", "pdf"] = "png", dpi: float = 100, *, close: bool = True
) -> bytes:
    """``figure`` encoded as ``fmt``; ``dpi`` applies to PNG (a PDF is vector, at the figure's
    own dpi). ``close``: release the figure from pyplot afterwards (False to encode it again,
    e.g. the setup sheet as PDF, then PNG)."""
    buffer = io.BytesIO()
    if fmt == "png":
        figure.savefig(buffer, format="png", dpi=dpi, metadata=_NO_METADATA["png"])
    else:
        figure.savefig(buffer, format=fmt, metadata=_NO_METADATA[fmt])
    if close:
        plt.close(figure)
    return buffer.getvalue()
