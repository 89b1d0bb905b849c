"""Issue 11: the three correction mechanisms, closed form versus a numeric solve of the linkage.

Independent computations: each mechanism's ``scale`` (closed form) is compared with
``scale_numeric`` (scipy brentq on the linkage: ball-to-plane distance, arm angle, gimbal angle);
the self-test rows of each instrument are recomputed with the numeric linkage in place of the
closed form; first-order equivalence with the transformed bundle is a numeric slope check.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pytest

from stereoplotter.instrument.principles import (
    LensShift,
    MechanicalProjection,
    PlaneFollower,
    mechanism_for,
)
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.procedure.selftest import SyntheticPair, residual_table

MECHANISMS = [PlaneFollower(), LensShift(), MechanicalProjection()]
F = 100.0


@pytest.mark.parametrize("mech", MECHANISMS, ids=lambda m: m.key)
@pytest.mark.parametrize("tilt_deg", [0.5, 1.0, 3.0, -2.0])
def test_closed_form_equals_numeric_linkage(mech, tilt_deg):
    ta = np.tan(np.radians(tilt_deg))
    to = np.tan(np.radians(-0.7 * tilt_deg))
    ex, ey = F * ta, F * to
    closed = float(mech.scale(F, ta, to, ex, ey))
    numeric = mech.scale_numeric(F, ta, to, ex, ey)
    assert closed == pytest.approx(numeric, abs=1e-13)


@pytest.mark.parametrize("mech", MECHANISMS, ids=lambda m: m.key)
def test_first_order_equals_transformed_bundle(mech):
    """s = 1 + O(T²): zero value and zero slope at zero tilt (numeric slope), curvature ≠ 0."""
    h = 1e-4

    def s(t):
        return mech.scale_numeric(F, t, 0.5 * t, F * t, 0.5 * F * t)

    assert s(0.0) == pytest.approx(1.0, abs=1e-15)
    slope = (s(h) - s(-h)) / (2 * h)
    assert abs(slope) < 1e-6  # a first-order term would give |slope| ~ dimension/f' ~ 0.05–4
    curvature = (s(h) - 2 * s(0.0) + s(-h)) / h**2
    assert abs(curvature) > 1e-3  # the second-order term is what differs between instruments


@dataclass(frozen=True, slots=True)
class _NumericLinkage:
    """Wraps a mechanism so that the unit uses the numeric linkage solve, element by element."""

    inner: object
    key: ClassVar[str] = "numeric"

    def scale(self, f_mm, ta, to, ex, ey):
        b = np.broadcast_arrays(*(np.asarray(v, float) for v in (f_mm, ta, to, ex, ey)))
        out = np.empty(b[0].shape)
        for i in np.ndindex(out.shape):
            out[i] = self.inner.scale_numeric(*(float(v[i]) for v in b))
        return out


@pytest.mark.parametrize("name", ["sc1", "spr3", "sd3"])
def test_selftest_rows_reproduced_by_numeric_linkage(name):
    spec = load_instrument(name)
    mech = mechanism_for(spec)
    pair = SyntheticPair(projection_distance_max_mm=float(spec.projection_distance_max_mm))
    closed = [r for r in residual_table(pair, (0.5, 1.0, 3.0), mech) if r["unit"] == mech.key]
    numeric = [
        r
        for r in residual_table(pair, (0.5, 1.0, 3.0), _NumericLinkage(mech))
        if r["unit"] == "numeric"
    ]
    for a, b in zip(closed, numeric, strict=True):
        assert a["max_q_um"] == pytest.approx(b["max_q_um"], rel=1e-9, abs=1e-9)
        assert a["height_deformation_permille"] == pytest.approx(
            b["height_deformation_permille"], rel=1e-9, abs=1e-12
        )


def test_three_instruments_give_three_tables():
    tables = []
    for name in ("sc1", "spr3", "sd3"):
        mech = mechanism_for(load_instrument(name))
        rows = residual_table(SyntheticPair(), (3.0,), mech)
        tables.append(next(r["max_q_um"] for r in rows if r["unit"] == mech.key))
    # measured at 3°: SC-1 24.09, SPR-3 25.43, SD-3 22.19 µm (canonical unit 22.58 µm)
    assert min(abs(a - b) for i, a in enumerate(tables) for b in tables[i + 1 :]) > 0.3
