r"""Correction mechanisms of the three instruments behind one interface (issue 11).

Every mechanism realises the transformed bundle of ``kinematics.md`` §3.3 (the correction plane
with a common change of F, :class:`~stereoplotter.instrument.kinematics.UnitMap`) and adds the
second-order term of its own construction as a scale factor ``s`` of the photo point before the
decentration: (u, v) = s·τ·(ξ, η) − e. Each ``s`` equals 1 at zero tilt and has zero slope there
(first-order equivalence with the transformed-bundle relations, shown in
``tests/instrument/test_correction_mechanisms.py``); its second-order part is what makes the
instruments differ. Each mechanism gives ``scale`` in closed form and ``scale_numeric`` by a
numeric solve of its linkage (``scipy.optimize.brentq``), which the tests compare.

Mechanism dimensions are not documented: each is ``assumed`` with its basis (class docstrings,
docs/instruments.md).

Units: mm; T = tan of the represented tilt [—].
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import brentq

from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = [
    "CorrectionMechanism",
    "LensShift",
    "MechanicalProjection",
    "PlaneFollower",
    "control_name",
    "mark_phrase",
    "mechanism_for",
    "mechanism_for_principle",
]


@dataclass(frozen=True, slots=True)
class CorrectionMechanism:
    """Interface: the factor s(T_α, T_ω, e_x, e_y; f′) of one correction unit."""

    key: ClassVar[str] = "canonical"
    photo_moves: ClassVar[bool] = False

    def scale(self, f_mm: ArrayLike, ta: ArrayLike, to: ArrayLike, ex: ArrayLike, ey: ArrayLike):
        """Closed form of s. [—]"""
        raise NotImplementedError

    def scale_numeric(self, f_mm: float, ta: float, to: float, ex: float, ey: float) -> float:
        """s from a numeric solve of the linkage (scalar). [—]"""
        raise NotImplementedError


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

        t = brentq(dist, 0.5, 2.0, xtol=1e-15, rtol=1e-15)
        t0 = (f_mm + self.follower_radius_mm) / f_mm
        return float(t * f_mm / const - (t0 - 1.0) * f_mm / const)


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
        psi = brentq(lambda a: big * np.sin(a) - d, -0.1, 1.5, xtol=1e-15) if d else 0.0
        return float(f_mm / (f_mm - big * (1.0 - np.cos(psi))))


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
        theta = brentq(lambda a: np.tan(a) - t, -0.1, 1.5, xtol=1e-15) if t else 0.0
        return float(f_mm / (f_mm - self.gimbal_offset_mm * (1.0 - np.cos(theta))))


_BY_PRINCIPLE = {
    "transformed_bundle_correction_planes": PlaneFollower,
    "transformed_bundle_lens_shift_correction": LensShift,
    "mechanical_projection_transformed_bundle": MechanicalProjection,
}


_DIMENSION_KEYS = {
    PlaneFollower: ("correction.follower_radius_mm", "follower_radius_mm"),
    LensShift: ("correction.lens_arm_length_mm", "arm_length_mm"),
    MechanicalProjection: ("correction.gimbal_offset_mm", "gimbal_offset_mm"),
}


def mechanism_for_principle(principle: str) -> CorrectionMechanism | None:
    """The mechanism of an instrument's ``principle`` with its default dimension (None: the
    canonical unit, s = 1)."""
    cls = _BY_PRINCIPLE.get(principle)
    return cls() if cls is not None else None


def mechanism_for(spec: InstrumentSpec) -> CorrectionMechanism | None:
    """The instrument's mechanism, its dimension from the YAML leaf when present (assumed)."""
    cls = _BY_PRINCIPLE.get(spec.principle)
    if cls is None:
        return None
    key, field_name = _DIMENSION_KEYS[cls]
    p = spec.parameters.get(key)
    return cls(**{field_name: float(p.value)}) if p is not None else cls()


#: Each instrument's own names of the correction controls (issue 11, deliverable 6); keys are
#: the virtual instrument's control prefixes ``k_alpha``, ``k_omega``, ``dx``, ``dy``.
_CONTROLS: dict[str, dict[str, str]] = {
    PlaneFollower.key: {
        "k_alpha": "correction plane kα (follower)",
        "k_omega": "correction plane kω (follower)",
        "dx": "photo decentration x (from the plane settings)",
        "dy": "photo decentration y (from the plane settings)",
    },
    LensShift.key: {
        "k_alpha": "lens-shift mechanism δ_α",
        "k_omega": "lens-shift mechanism δ_ω",
        "dx": "photo-carriage decentration x",
        "dy": "photo-carriage decentration y",
    },
    MechanicalProjection.key: {
        "k_alpha": "photo-carrier tilt α (gimbal)",
        "k_omega": "photo-carrier tilt ω (gimbal)",
        "dx": "photo-carrier decentration x",
        "dy": "photo-carrier decentration y",
    },
}


def control_name(principle: str, control: str) -> str:
    """``control`` (``k_alpha_left``, ``dx_right`` …) with the instrument's own name added."""
    mech = mechanism_for_principle(principle)
    if mech is None:
        return control
    prefix = control.rsplit("_", 1)[0]
    own = _CONTROLS[mech.key].get(prefix)
    return control if own is None else f"{own} ({control})"


def mark_phrase(principle: str, mark: str) -> str:
    """How the fiducial meets the mark: the SPR-3 moves the photo under a fixed mark."""
    mech = mechanism_for_principle(principle)
    if mech is not None and mech.photo_moves:
        return f"the photo carriage brings mark {mark} under the fixed measuring mark"
    return f"mark {mark} is under the measuring mark"
