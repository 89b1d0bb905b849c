"""Synthetic blocks shared by the triangulation tests (made once per process, fixed seeds).

Not a conftest.py: a second module named ``conftest`` would shadow ``tests/conftest.py``, whose
units the other folders import as ``from conftest import …``.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from stereoplotter.triangulation.synth import SynthSpec, synthesize_block


@cache
def block10x4():
    """The acceptance block: 4 strips × 10 photos, σ 5 µm, control every 4 bases (seed 7)."""
    return synthesize_block(SynthSpec(), np.random.default_rng(7))


@cache
def exact_block():
    """3 strips × 6 photos measured without error (σ of 10⁻⁹ mm and m: the weights stay finite)."""
    spec = SynthSpec(
        strips=3,
        photos_per_strip=6,
        sigma_photo_mm=1e-9,
        sigma_control_m=1e-9,
        control_every_bases=2,
    )  # stations 0, 2, 4, 5: a cubic is determined
    return synthesize_block(spec, np.random.default_rng(3))
