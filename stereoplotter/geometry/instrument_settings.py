r"""Each instrument's own φ, ω-dependent settings and the formulas that give them (issue 11).

Shared geometry: the setup-data computer prints these settings for the instrument of the sheet
(:mod:`stereoplotter.report.sheet`) and the simulated operator names them in the transcript;
both take the values from here and from :mod:`stereoplotter.geometry.tilt_correction`.

What is documented (a German report on the Soviet affine plotters): the SD stereograph has **8**
setting elements — the inclinations of the correction plates are primary, the photo
decentrations follow from them ("mittelbar"); on the SPR-2 one introduces dφ, dω and then sets,
from tables with the arguments dφ, dω, **12** settings that depend on φ, ω: the photo
decentrations, the decentrations of the correction mechanisms and the decentrations of the
followers on the correction plates, repeating the cycle (counted here per pair: 3 kinds × x, y ×
2 photos). The SC-1 is documented only through the book's §26 (k_α, k_ω scales of the correction
mechanisms and decentration scales); its count is not documented.

The values are derived, not documented (the book: "by the well-known formulas", §26 item 3):
the plane geometry of the transformed bundle makes the photo decentration and the decentration of
the correction mechanism both f′·tan α (f′·tan ω) — the unique values that make the plane
correction exact on the axes — and the plate (or carrier) inclination θ with tan θ = k·tan α
(Drobyshev's k = f_пр/f′). The follower of an SPR correction plate sits at the plate's pivot, so
its decentration takes the same value (ASSUMED reading: the plate is pivoted at the decentred
point at the instrument principal distance, where the rod's horizontal offset equals the photo
coordinate). The virtual instruments hold one decentration pair per photo for all kinds
(decision D2 of docs/instruments.md): a setting error is common to the kinds.

Units: mm, degrees for display; radians inside.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from stereoplotter.geometry.tilt_correction import correction_inclination, decentration

__all__ = [
    "SETTING_SEQUENCES",
    "Setting",
    "SettingSequence",
    "sequence_for",
    "setting_values",
]


@dataclass(frozen=True, slots=True)
class Setting:
    """One setting of one photo.

    Attributes
    ----------
    key : str
        Identifier (``plate_alpha``, ``photo_dx`` …).
    name : str
        The instrument's own name of the setting.
    symbol : str
    unit : str
        ``"deg"`` (an inclination) or ``"mm"`` (a decentration).
    formula : str
        How the value follows from α or ω of the photo (instrument frame).
    kind : str
        ``"primary"`` (set by the operator, the fit of stage 2) or ``"derived"`` (follows from
        the primary one: "mittelbar", from the tables on the SPR).
    tilt : str
        ``"alpha"`` or ``"omega"``: the tilt it depends on.
    """

    key: str
    name: str
    symbol: str
    unit: str
    formula: str
    kind: str
    tilt: str


@dataclass(frozen=True, slots=True)
class SettingSequence:
    """An instrument's settings per photo, their documented count and the order of setting.

    ``phi_omega_dependent`` counts the settings per pair the way its source counts them;
    ``counted`` names which settings that count holds; ``count_status`` is ``documented`` or
    ``assumed``.
    """

    principle: str
    settings: tuple[Setting, ...]
    phi_omega_dependent: int
    counted: str
    count_status: str
    count_basis: str
    sequence: tuple[str, ...]


_INCL = "tan θ = k·tan {t}"
_DEC = "f′·tan {t}"


def _incl(key: str, name: str, symbol: str, tilt: str) -> Setting:
    t = "α" if tilt == "alpha" else "ω"
    return Setting(key, name, symbol, "deg", _INCL.format(t=t), "primary", tilt)


def _dec(key: str, name: str, symbol: str, tilt: str, formula: str | None = None) -> Setting:
    t = "α" if tilt == "alpha" else "ω"
    return Setting(key, name, symbol, "mm", formula or _DEC.format(t=t), "derived", tilt)


SETTING_SEQUENCES: dict[str, SettingSequence] = {
    "transformed_bundle_correction_planes": SettingSequence(
        "transformed_bundle_correction_planes",
        (
            _incl("plate_alpha", "correction-plate inclination (α)", "θ_α", "alpha"),
            _incl("plate_omega", "correction-plate inclination (ω)", "θ_ω", "omega"),
            _dec(
                "photo_dx",
                "photo decentration x (from the plate)",
                "d_x",
                "alpha",
                "(f′/k)·tan θ_α = f′·tan α",
            ),
            _dec(
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
    "transformed_bundle_lens_shift_correction": SettingSequence(
        "transformed_bundle_lens_shift_correction",
        (
            _incl("lens_alpha", "lens-shift mechanism kα", "θ_α", "alpha"),
            _incl("lens_omega", "lens-shift mechanism kω", "θ_ω", "omega"),
            _dec("photo_dx", "photo-carriage decentration x", "e_x", "alpha"),
            _dec("photo_dy", "photo-carriage decentration y", "e_y", "omega"),
            _dec("mechanism_dx", "correction-mechanism decentration x", "c_x", "alpha"),
            _dec("mechanism_dy", "correction-mechanism decentration y", "c_y", "omega"),
            _dec("follower_dx", "follower decentration x (correction plate)", "u_x", "alpha"),
            _dec("follower_dy", "follower decentration y (correction plate)", "u_y", "omega"),
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
    "mechanical_projection_transformed_bundle": SettingSequence(
        "mechanical_projection_transformed_bundle",
        (
            _incl("carrier_alpha", "photo-carrier tilt α (gimbal, k_α scale)", "θ_α", "alpha"),
            _incl("carrier_omega", "photo-carrier tilt ω (gimbal, k_ω scale)", "θ_ω", "omega"),
            _dec("photo_dx", "photo-carrier decentration x", "d_x", "alpha"),
            _dec("photo_dy", "photo-carrier decentration y", "d_y", "omega"),
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
}


def sequence_for(principle: str) -> SettingSequence | None:
    """The settings of an instrument ``principle`` (None: not one of the three instruments)."""
    return SETTING_SEQUENCES.get(principle)


def setting_values(
    sequence: SettingSequence, f_prime_mm: float, k: float, alpha: float, omega: float
) -> NDArray[np.float64]:
    """Values of ``sequence.settings`` for one photo, in their units (deg or mm).

    Parameters
    ----------
    f_prime_mm : float
        f′ of the photo. [mm]
    k : float
        Transformation coefficient f_пр/f′. [—]
    alpha, omega : float
        Tilts of the photo in the instrument frame. [rad]

    Returns
    -------
    ndarray
        θ = atan(k·tan t) in degrees for the inclinations (DRO60 eq. (4)), f′·tan t in mm for
        the decentrations (the plane geometry, e = c).
    """
    out = []
    for s in sequence.settings:
        t = alpha if s.tilt == "alpha" else omega
        if s.unit == "deg":
            out.append(math.degrees(float(correction_inclination(k, t))))
        else:
            out.append(float(decentration(f_prime_mm, t)))
    return np.asarray(out, float)
