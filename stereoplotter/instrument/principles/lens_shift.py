r"""SPR-3: lens-shift correction (the transformed bundle by shifting the lens on a swinging
arm); the photo moves under fixed measuring marks, and 12 φ, ω-dependent settings per pair.

Its kinematics (:class:`LensShift`), its settings and control names, its instrument-file field
and its error terms: :mod:`stereoplotter.instrument.principles.base` says what each is.
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

__all__ = ["LENS_SHIFT", "LensShift"]


@dataclass(frozen=True, slots=True)
class LensShift(CorrectionMechanism):
    r"""SPR-3: the lens is shifted by δ = e on a swinging arm of length L; the photo moves.

    The lens carrier swings about a pivot at height L above the lens; shifting it horizontally by
    |δ| = L sin ψ lifts it by L(1 − cos ψ), so the projection distance of the photo grows and

    .. math:: s = \frac{f'}{f' - (L - \sqrt{L^2 - \delta_x^2 - \delta_y^2})}

    ``arm_length_mm`` = 400 mm is ASSUMED (no drawing of the SPR-3 lens carrier was found; chosen
    so that the lift at 3° and f′ = 100 mm, |δ| = 5.2 mm, is 34 µm).
    """

    key: ClassVar[str] = "spr3_lens_shift"
    photo_moves: ClassVar[bool] = True
    arm_length_mm: float = 400.0

    def scale(self, f_mm, ta, to, ex, ey):
        f = np.asarray(f_mm, float)
        d2 = np.asarray(ex, float) ** 2 + np.asarray(ey, float) ** 2
        big = self.arm_length_mm
        # |δ| > L: the arm cannot reach, no such state (NaN). Only trial states of a solver's
        # search get there (budget, pair60: tan ω ≈ −7.6 inside a Newton step); the settled
        # settings stay within the ±3° range, where |δ| ≤ 11 mm.
        with np.errstate(invalid="ignore"):
            return f / (f - (big - np.sqrt(big * big - d2)))

    def scale_numeric(self, f_mm, ta, to, ex, ey):
        d = float(np.hypot(ex, ey))
        big = self.arm_length_mm
        # imported here: only this numeric cross-check needs scipy (≈ 1 s of start-up)
        from scipy.optimize import brentq

        psi = brentq(lambda a: big * np.sin(a) - d, -0.1, 1.5, xtol=1e-15) if d else 0.0
        return float(f_mm / (f_mm - big * (1.0 - np.cos(psi))))


LENS_SHIFT = Principle(
    "transformed_bundle_lens_shift_correction",
    LensShift,
    SchemaField(
        "correction.lens_arm_length_mm", "number", "mm", 0.0, 5000.0, low_open=True, required=False
    ),
    "arm_length_mm",
    {
        "k_alpha": "lens-shift mechanism δ_α",
        "k_omega": "lens-shift mechanism δ_ω",
        "dx": "photo-carriage decentration x",
        "dy": "photo-carriage decentration y",
    },
    SettingSequence(
        "transformed_bundle_lens_shift_correction",
        (
            inclination_setting("lens_alpha", "lens-shift mechanism kα", "θ_α", "alpha"),
            inclination_setting("lens_omega", "lens-shift mechanism kω", "θ_ω", "omega"),
            decentration_setting("photo_dx", "photo-carriage decentration x", "e_x", "alpha"),
            decentration_setting("photo_dy", "photo-carriage decentration y", "e_y", "omega"),
            decentration_setting(
                "mechanism_dx", "correction-mechanism decentration x", "c_x", "alpha"
            ),
            decentration_setting(
                "mechanism_dy", "correction-mechanism decentration y", "c_y", "omega"
            ),
            decentration_setting(
                "follower_dx", "follower decentration x (correction plate)", "u_x", "alpha"
            ),
            decentration_setting(
                "follower_dy", "follower decentration y (correction plate)", "u_y", "omega"
            ),
        ),
        12,
        "the 3 kinds of decentration (photo, correction mechanism, follower) × x, y × 2 photos, "
        "set after kα, kω are introduced",
        "assumed",
        "documented for the SPR-2 (12 settings depending on φ, ω: photo decentrations, "
        "decentrations of the correction mechanisms and of the followers); taken for the SPR-3",
        (
            "introduce dφ, dω: set kα, kω on the lens-shift mechanisms of each photo (stage 2 "
            "fits them on the fiducial marks)",
            "from the tables (arguments dφ, dω) set the photo-carriage decentrations e, the "
            "correction-mechanism decentrations c and the followers' decentrations u, all "
            "f′·tan α, f′·tan ω",
            "repeat the cycle until the check passes (the photo moves under the fixed marks)",
        ),
    ),
)
