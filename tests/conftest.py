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
