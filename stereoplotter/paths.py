"""Where the shipped data live: ``instruments/`` and ``scenarios/``.

Searched in this order: the folder named by the environment variable ``STEREOPLOTTER_DATA``; the
current directory; the source tree the package was installed from (an editable install or a run
from a clone). The first folder that has the sub-folder wins.
"""

from __future__ import annotations

import os
from pathlib import Path

__all__ = ["DEFAULT_SCENARIO", "data_dir", "list_data_files"]

#: The scenario the README's main job runs.
DEFAULT_SCENARIO = "pair60.yaml"


def _candidates() -> list[Path]:
    roots = []
    if os.environ.get("STEREOPLOTTER_DATA"):
        roots.append(Path(os.environ["STEREOPLOTTER_DATA"]))
    roots.append(Path.cwd())
    roots.append(Path(__file__).resolve().parent.parent)
    return roots


def data_dir(kind: str) -> Path | None:
    """The first existing ``kind`` folder (``"instruments"`` or ``"scenarios"``), or None."""
    for root in _candidates():
        if (root / kind).is_dir():
            return root / kind
    return None


def list_data_files(kind: str) -> list[Path]:
    """The ``*.yaml`` files of the ``kind`` folder, sorted by name."""
    folder = data_dir(kind)
    return sorted(folder.glob("*.yaml")) if folder else []
