r"""SD-3: correction plates (the transformed bundle by correction planes) — a follower ball
rides on each plate; the plate inclinations are primary, the photo decentrations follow.

Its kinematics (:class:`PlaneFollower`), its settings and control names, its instrument-file
field and its error terms: :mod:`stereoplotter.instrument.principles.base` says what each is.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from stereoplotter.instrument.principles.base import (
    CorrectionMechanism,
    Principle,
    SchemaField,
    SettingSequence,
    decentration_setting,
    inclination_setting,
)

__all__ = ["PLATES", "PlaneFollower"]


@dataclass(frozen=True, slots=True)
class PlaneFollower(CorrectionMechanism):
    r"""SD-3: a follower ball of radius r slides on the correction plane.

    The plane Z + X·T_α + Y·T_ω = f′ + c·T (``kinematics.md`` §3.3) carries the follower; the
    carriage (ball centre) on the rod lies at normal distance r from it. The instrument is
    adjusted at zero tilt, so the ball offsets the plane constant by r(√(1 + T_α² + T_ω²) − 1):

    .. math:: s = 1 + \frac{r(\sqrt{1+T_\alpha^2+T_\omega^2}-1)}{f' + c_x T_\alpha + c_y T_\omega}

    with c = e (decision D2). ``follower_radius_mm`` = 5 mm is ASSUMED (no drawing of the SD-3
    follower was found; a ball of a few millimetres is the usual follower of a cam plate).
    """

    key: ClassVar[str] = "sd3_plane_follower"
    follower_radius_mm: float = 5.0

    def scale(self, f_mm, ta, to, ex, ey):
        ta, to = np.asarray(ta, float), np.asarray(to, float)
        num = np.asarray(f_mm, float) + np.asarray(ex, float) * ta + np.asarray(ey, float) * to
        return 1.0 + self.follower_radius_mm * (np.sqrt(1.0 + ta * ta + to * to) - 1.0) / num

    def scale_numeric(self, f_mm, ta, to, ex, ey):
        # Ball centre on the plumb rod (0, 0, z·f′ scale): find the scale τ′ at which its normal
        # distance from the plane equals r, relative to the same at zero tilt (distance r at f′+r).
        n = np.array([ta, to, 1.0])
        const = f_mm + ex * ta + ey * to

        def dist(t):
            return (t * f_mm - const) / np.linalg.norm(n) - self.follower_radius_mm

        # imported here: only this numeric cross-check needs scipy (≈ 1 s of start-up)
        from scipy.optimize import brentq

        t = brentq(dist, 0.5, 2.0, xtol=1e-15, rtol=1e-15)
        t0 = (f_mm + self.follower_radius_mm) / f_mm
        return float(t * f_mm / const - (t0 - 1.0) * f_mm / const)


PLATES = Principle(
    "transformed_bundle_correction_planes",
    PlaneFollower,
    SchemaField("correction.follower_radius_mm", "number", "mm", 0.0, 100.0, required=False),
    "follower_radius_mm",
    {
        "k_alpha": "correction plane kα (follower)",
        "k_omega": "correction plane kω (follower)",
        "dx": "photo decentration x (from the plane settings)",
        "dy": "photo decentration y (from the plane settings)",
    },
    SettingSequence(
        "transformed_bundle_correction_planes",
        (
            inclination_setting("plate_alpha", "correction-plate inclination (α)", "θ_α", "alpha"),
            inclination_setting("plate_omega", "correction-plate inclination (ω)", "θ_ω", "omega"),
            decentration_setting(
                "photo_dx",
                "photo decentration x (from the plate)",
                "d_x",
                "alpha",
                "(f′/k)·tan θ_α = f′·tan α",
            ),
            decentration_setting(
                "photo_dy",
                "photo decentration y (from the plate)",
                "d_y",
                "omega",
                "(f′/k)·tan θ_ω = f′·tan ω",
            ),
        ),
        8,
        "2 plate inclinations (primary) and 2 photo decentrations (derived) per photo",
        "documented",
        "SD stereograph: 8 setting elements, the plate inclinations primary, the photo "
        "decentrations mediated (report on the Soviet affine plotters, ISP Comm. II)",
        (
            "incline the correction plates of each photo to θ_α, θ_ω (stage 2 fits them on the "
            "fiducial marks: the k_α, k_ω knobs)",
            "the photo decentrations follow from the plate settings, d = (f′/k)·tan θ (on the "
            "virtual SD-3 the linkage carries them, decision D1); check their scales",
        ),
    ),
)
