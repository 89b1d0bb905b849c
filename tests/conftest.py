"""Shared test settings: units as named multipliers so tolerances read as "0.05 * um"."""

from __future__ import annotations

import numpy as np
from hypothesis import settings

from stereoplotter.constants import ARCSEC_PER_RAD

mm = 1.0  # internal length unit of the photo, instrument and model
um = 1e-3 * mm
m = 1.0  # internal length unit on the ground
arcsec = 1.0 / ARCSEC_PER_RAD  # in radians
deg = np.pi / 180.0

settings.register_profile("ci", max_examples=60, deadline=None, derandomize=True)
settings.register_profile("dev", max_examples=60, deadline=None)
settings.load_profile("ci")


def node_paths(node, path=()):
    """Every path below the root of a parsed YAML document (keys and list indices), children
    before their parent: the places a fuzz test may mutate."""
    paths = []
    if isinstance(node, dict):
        for k, v in node.items():
            paths += node_paths(v, (*path, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            paths += node_paths(v, (*path, i))
    if path:
        paths.append(path)
    return paths


def value_at(node, path):
    """The value at a path of :func:`node_paths`."""
    for k in path:
        node = node[k]
    return node
