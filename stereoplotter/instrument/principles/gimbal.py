r"""SC-1: mechanical projection with the photo carrier tilted in a gimbal (the construction is
chosen: the SC-1 is described only as "universal, with mechanical projection").

Its kinematics (:class:`MechanicalProjection`), its settings and control names, its
instrument-file field and its error terms: :mod:`stereoplotter.instrument.principles.base` says
what each is.
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

__all__ = ["GIMBAL", "MechanicalProjection"]


@dataclass(frozen=True, slots=True)
class MechanicalProjection(CorrectionMechanism):
    r"""SC-1: mechanical projection, the photo carrier tilted in a gimbal (construction chosen).

    The carrier is tilted by θ (tan θ = |T|) about gimbal axes lying h below the emulsion; the
    emulsion rises by h(1 − cos θ) relative to the projection centre, so

    .. math:: s = \frac{f'}{f' - h(1 - 1/\sqrt{1 + T_\alpha^2 + T_\omega^2})}

    ``gimbal_offset_mm`` = 20 mm is ASSUMED (no SC-1 drawing found; the thickness of a glass plate
    holder plus its frame). The gimbal (tilting-carrier) construction is modelled because the
    SC-1 is described only as "universal, with mechanical projection"; see docs/instruments.md.
    """

    key: ClassVar[str] = "sc1_mechanical_projection"
    gimbal_offset_mm: float = 20.0

    def scale(self, f_mm, ta, to, ex, ey):
        f = np.asarray(f_mm, float)
        ta, to = np.asarray(ta, float), np.asarray(to, float)
        lift = self.gimbal_offset_mm * (1.0 - 1.0 / np.sqrt(1.0 + ta * ta + to * to))
        return f / (f - lift)

    def scale_numeric(self, f_mm, ta, to, ex, ey):
        t = float(np.hypot(ta, to))
        # imported here: only this numeric cross-check needs scipy (≈ 1 s of start-up)
        from scipy.optimize import brentq

        theta = brentq(lambda a: np.tan(a) - t, -0.1, 1.5, xtol=1e-15) if t else 0.0
        return float(f_mm / (f_mm - self.gimbal_offset_mm * (1.0 - np.cos(theta))))


GIMBAL = Principle(
    "mechanical_projection_transformed_bundle",
    MechanicalProjection,
    SchemaField("correction.gimbal_offset_mm", "number", "mm", 0.0, 500.0, required=False),
    "gimbal_offset_mm",
    {
        "k_alpha": "photo-carrier tilt α (gimbal)",
        "k_omega": "photo-carrier tilt ω (gimbal)",
        "dx": "photo-carrier decentration x",
        "dy": "photo-carrier decentration y",
    },
    SettingSequence(
        "mechanical_projection_transformed_bundle",
        (
            inclination_setting(
                "carrier_alpha", "photo-carrier tilt α (gimbal, k_α scale)", "θ_α", "alpha"
            ),
            inclination_setting(
                "carrier_omega", "photo-carrier tilt ω (gimbal, k_ω scale)", "θ_ω", "omega"
            ),
            decentration_setting("photo_dx", "photo-carrier decentration x", "d_x", "alpha"),
            decentration_setting("photo_dy", "photo-carrier decentration y", "d_y", "omega"),
        ),
        8,
        "2 tilts on the k_α, k_ω scales and 2 decentrations per photo",
        "assumed",
        "not documented for the SC-1; the book's §26 names the k_α, k_ω scales of the correction "
        "mechanisms and the decentration scales of each photo",
        (
            "tilt each photo carrier on its k_α, k_ω scales (stage 2 fits them on the fiducial "
            "marks)",
            "set the decentrations d_x, d_y on their scales (stage 2, after the fit)",
        ),
    ),
)
