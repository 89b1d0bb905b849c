"""Synthetic blocks shared by the triangulation tests (made once per session, fixed seeds)."""

from __future__ import annotations

import numpy as np
import pytest

from stereoplotter.triangulation.synth import SynthSpec, synthesize_block


@pytest.fixture(scope="session")
def block10x4():
    """The acceptance block: 4 strips × 10 photos, σ 5 µm, control every 4 bases (seed 7)."""
    return synthesize_block(SynthSpec(), np.random.default_rng(7))


@pytest.fixture(scope="session")
def exact_block():
    """3 strips × 6 photos measured without error (σ of 10⁻⁹ mm and m: the weights stay finite)."""
    spec = SynthSpec(strips=3, photos_per_strip=6, sigma_photo_mm=1e-9, sigma_control_m=1e-9)
    return synthesize_block(spec, np.random.default_rng(3))
