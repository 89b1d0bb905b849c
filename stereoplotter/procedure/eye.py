"""The operator's eye: how finely the simulated operator judges parallax (physiology, optics).

The operator looks at the photos through the instrument's binocular observation system. Two
figures of human stereo vision (the photogrammetry textbook's, ``docs/procedure.md`` §The
operator's eye):

* stereo acuity of the first kind, Δγ₁ ≈ 30″: the smallest difference of the parallactic angles
  of two *points* at which they are seen at different depths;
* stereo acuity of the second kind, Δγ₂ ≈ 10″: the same for two parallel *lines*.

Optics: a length s on the photo, seen through a system of angular magnification V referred to the
viewing distance d (the conventional 250 mm of distinct vision to which a magnification is
referred), subtends θ = V·s/d at the eye; an angle δ at the eye is the photo length

    s = δ · d / V.                                                               (eye 1)

The two judgements of the procedure (``procedure.operator``):

* the fused mark — x-parallax cleared, the floating mark set on the ground: the mark and the
  image point are two points at different depths, first kind: σ_p = Δγ₁·d/V;
* y-parallax — the half-images of the mark and of the detail under it are aligned across the
  base, an alignment of edges (lines), second kind: σ_q = Δγ₂·d/V.

The acuity is taken as one standard deviation of the judgement (the 84 % point of the
psychometric function Φ(s/σ)), an **assumed** reading of the textbook's "smallest difference
perceived" (a threshold, not a σ). The mapping of the two kinds to the two judgements is a
decision of this project (**assumed**: no source maps the lines' 10″ to y-parallax); the book's
own m_p = √2·m_q (ch. 5, used with (5.54)) orders them the same way. Published measurements on
analog plotters (``docs/procedure.md``, §The eye's figures against published measurements): the
standard error of a y-parallax measurement is "normally 0.01 mm or less" on precision plotters
and the book's m_q is 0.015 mm — σ_q = 2.02 µm is below that range; a point's setting error
from repeated settings is 4 µm, the order of σ_p = 6.06 µm. ``procedure.eye_range`` measures the
pass rates across that range.

A check is a detection: at a point with true y-parallax q the operator *sees* y-parallax over the
tolerance T (¼ of the mark) when |q + e| > T, e ~ N(0, σ_q): the psychometric function

    P_look(q) = Φ((−T − q)/σ_q) + Φ((q − T)/σ_q).                                (eye 2)

A competent operator looks again (a new pointing, a new judgement) before declaring a failure:
the point fails when both looks see it, P_fail(q) = P_look(q)² (:data:`LOOKS`; **assumed**, no
published detection rule was found).

Units: mm on the photo, radians inside, arcseconds in the constants.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

__all__ = [
    "ACUITY_FIRST_KIND_ARCSEC",
    "ACUITY_SECOND_KIND_ARCSEC",
    "DEFAULT_MAGNIFICATION",
    "DEFAULT_VIEWING_DISTANCE_MM",
    "EYE_MODES",
    "LEGACY_SIGMA_MM",
    "LOOKS",
    "Eye",
    "ObservationSystem",
    "angle_to_photo_mm",
    "look_probability",
]

#: Stereo acuity of the first kind (two points), the textbook's "approximately 30″". [″]
ACUITY_FIRST_KIND_ARCSEC = 30.0
#: Stereo acuity of the second kind (two parallel lines), the textbook's 10″. [″]
ACUITY_SECOND_KIND_ARCSEC = 10.0
#: Magnification of the observation system where the instrument file gives none (assumed, as
#: the shipped files: ``observation.magnification``). [×]
DEFAULT_MAGNIFICATION = 6.0
#: Viewing distance to which a magnification is referred, the conventional distance of
#: distinct vision (assumed where the instrument file gives none). [mm]
DEFAULT_VIEWING_DISTANCE_MM = 250.0
#: The free σ of an operator without the eye model: σ_p = σ_q = 0.010 mm,
#: ``OperatorModel(eye="sigma")``. [mm]
LEGACY_SIGMA_MM = 0.010
#: "physiological": σ_p, σ_q from the eye (default); "sigma": the legacy free σ.
EYE_MODES = ("physiological", "sigma")
#: Looks at a point before a failure is declared (the first, and one remeasure).
LOOKS = 2

_ARCSEC = math.pi / (180.0 * 3600.0)


def angle_to_photo_mm(angle_arcsec: float, magnification: float, viewing_distance_mm: float) -> Any:
    """(eye 1): the photo length [mm] that subtends ``angle_arcsec`` at the eye.

    Examples
    --------
    >>> round(angle_to_photo_mm(10.0, 6.0, 250.0) * 1000.0, 3)  # µm
    2.02
    """
    if magnification <= 0 or viewing_distance_mm <= 0:
        raise ValueError("magnification and viewing distance must be positive")
    return angle_arcsec * _ARCSEC * viewing_distance_mm / magnification


def _phi(x: float) -> float:
    return 0.5 * math.erfc(-x / math.sqrt(2.0))


def look_probability(q_mm: float, tolerance_mm: float, sigma_mm: float) -> float:
    """(eye 2): probability that one look sees |q| over the tolerance.

    Examples
    --------
    >>> round(look_probability(0.0125, 0.0125, 0.002), 3)  # at the tolerance: one half
    0.5
    """
    if sigma_mm == 0.0:
        return float(abs(q_mm) > tolerance_mm)
    t, q, s = tolerance_mm, q_mm, sigma_mm
    return _phi((-t - q) / s) + _phi((q - t) / s)


@dataclass(frozen=True, slots=True)
class ObservationSystem:
    """The instrument's binocular: magnification V [×] and viewing distance d [mm], each with
    its status ("documented" or "assumed") and basis as the instrument file gives them."""

    magnification: float
    viewing_distance_mm: float
    magnification_status: str = "assumed"
    viewing_distance_status: str = "assumed"
    magnification_basis: str = "default of the eye model (not in the instrument file)"
    viewing_distance_basis: str = "default of the eye model (not in the instrument file)"

    @classmethod
    def from_spec(cls, spec: Any) -> ObservationSystem:
        """From ``observation.magnification`` and ``observation.viewing_distance_mm`` of an
        instrument spec (the defaults, assumed, where the file has none)."""
        params = getattr(spec, "parameters", {}) or {}
        out: dict[str, Any] = {}
        for key, name, default in (
            ("observation.magnification", "magnification", DEFAULT_MAGNIFICATION),
            ("observation.viewing_distance_mm", "viewing_distance", DEFAULT_VIEWING_DISTANCE_MM),
        ):
            p = params.get(key)
            attr = "magnification" if name == "magnification" else "viewing_distance_mm"
            if p is None:
                out[attr] = default
                continue
            out[attr] = float(p.value)
            out[f"{name}_status"] = p.status
            out[f"{name}_basis"] = p.basis or ", ".join(p.source)
        return cls(**out)


@dataclass(frozen=True, slots=True)
class Eye:
    """The operator's eye at an observation system: the derived judgement figures.

    Examples
    --------
    >>> eye = Eye(ObservationSystem(6.0, 250.0))
    >>> round(eye.y_parallax_sigma_mm * 1000, 2), round(eye.stereo_sigma_mm * 1000, 2)
    (2.02, 6.06)
    """

    system: ObservationSystem
    acuity_first_arcsec: float = ACUITY_FIRST_KIND_ARCSEC
    acuity_second_arcsec: float = ACUITY_SECOND_KIND_ARCSEC

    @property
    def stereo_sigma_mm(self) -> float:
        """σ_p of the fused mark (x-parallax judged zero), first kind, photo scale. [mm]"""
        s = self.system
        sigma: float = angle_to_photo_mm(
            self.acuity_first_arcsec, s.magnification, s.viewing_distance_mm
        )
        return sigma

    @property
    def y_parallax_sigma_mm(self) -> float:
        """σ_q of a y-parallax judgement, second kind, photo scale. [mm]"""
        s = self.system
        sigma: float = angle_to_photo_mm(
            self.acuity_second_arcsec, s.magnification, s.viewing_distance_mm
        )
        return sigma

    def check_pass_probability(self, q_mm: Any, tolerance_mm: float, looks: int = LOOKS) -> Any:
        """Probability that the six-point check passes at true y-parallaxes ``q_mm`` (one per
        point, independent looks; a point fails when all ``looks`` see it). [—]

        Examples
        --------
        >>> eye = Eye(ObservationSystem(6.0, 250.0))
        >>> eye.check_pass_probability([0.0] * 6, 0.0125) > 0.999999
        True
        """
        p = 1.0
        for q in q_mm:
            p *= 1.0 - look_probability(float(q), tolerance_mm, self.y_parallax_sigma_mm) ** looks
        return p

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: the inputs with their status and the derived figures. [µm, ″, ×, mm]"""
        s = self.system
        return {
            "acuity_first_kind_arcsec": self.acuity_first_arcsec,
            "acuity_second_kind_arcsec": self.acuity_second_arcsec,
            "magnification": s.magnification,
            "magnification_status": s.magnification_status,
            "viewing_distance_mm": s.viewing_distance_mm,
            "viewing_distance_status": s.viewing_distance_status,
            "stereo_sigma_um": self.stereo_sigma_mm * 1000.0,
            "y_parallax_sigma_um": self.y_parallax_sigma_mm * 1000.0,
            "looks_before_failure": LOOKS,
        }
