"""stereoplotter: virtual SC-1, SPR-3 and SD-3 stereoplotters and their setup data.

Kushtin & Lyskov, *Фотограмметрия снимка и стереоскопических моделей* (Nedra, 1984), chapter 6.
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("stereoplotter")
except PackageNotFoundError:  # pragma: no cover - running from a source tree without install
    __version__ = "0.0.0+unknown"

__all__ = ["__version__"]
