r"""What every correction principle declares, and the pieces they share.

A *principle* (``principle:`` of an instrument file) is one way of building the correction of
the transformed bundle (``kinematics.md`` §3.3) into an instrument. Each has one module in this
package holding all that belongs to it:

* its kinematics — a :class:`CorrectionMechanism`: the factor s(T_α, T_ω, e_x, e_y; f′) of one
  correction unit in closed form and by a numeric solve of its linkage;
* its settings — a :class:`SettingSequence`: the φ, ω-dependent settings per photo, their
  documented or assumed count and the operator's order of setting them, with the instrument's
  own names of the controls;
* its schema fields — :class:`SchemaField`: the instrument-file leaves it adds (plain data;
  :mod:`stereoplotter.io.instrument_file` builds the validator from them, so no pydantic here);
* its error terms — :meth:`Principle.error_terms`: the injected setting errors of its
  correction controls (:mod:`stereoplotter.instrument.error_model`).

Every mechanism adds the second-order term of its own construction as a scale factor ``s`` of
the photo point before the decentration: (u, v) = s·τ·(ξ, η) − e. Each ``s`` equals 1 at zero
tilt and has zero slope there (first-order equivalence with the transformed-bundle relations,
shown in ``tests/instrument/test_correction_mechanisms.py``); its second-order part is what makes
the instruments differ. Mechanism dimensions are not documented: each is ``assumed`` with its
basis (class docstrings, docs/instruments.md).

Units: mm; T = tan of the represented tilt [—]; degrees for display, radians inside.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.geometry.tilt_correction import correction_inclination, decentration
from stereoplotter.spec.schema_fields import SchemaField

__all__ = [
    "CORRECTION_SETTING_TERMS",
    "CorrectionMechanism",
    "Principle",
    "SchemaField",
    "Setting",
    "SettingSequence",
    "correction_setting_terms",
    "setting_values",
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


#: The injected setting errors of a unit's correction controls: (term name per side, spec
#: attribute of its σ, meaning, unit) — the same k_α, k_ω scale error on all three instruments.
CORRECTION_SETTING_TERMS = tuple(
    (
        f"setting.correction_{c}_{{side}}",
        "correction_setting_sigma",
        f"error of a k_{c} setting of the {{side}} correction mechanism",
        "rad",
    )
    for c in ("alpha", "omega")
)


def correction_setting_terms(
    side: str, table: tuple[tuple[str, str, str, str], ...] = CORRECTION_SETTING_TERMS
) -> tuple[tuple[str, str, str, str], ...]:
    """The rows of ``table`` for the ``side`` unit (the canonical unit's without a principle)."""
    return tuple((n.format(side=side), a, m.format(side=side), u) for n, a, m, u in table)


@dataclass(frozen=True)
class Principle:
    """One correction principle: everything an instrument of it needs, in one place.

    Attributes
    ----------
    name : str
        The ``principle:`` of the instrument file.
    mechanism : type
        Its :class:`CorrectionMechanism`.
    dimension : SchemaField
        The instrument-file leaf of the mechanism's dimension (optional, assumed).
    dimension_field : str
        The mechanism's attribute that leaf sets.
    controls : mapping
        The instrument's own names of the correction controls, by the virtual instrument's
        control prefix (``k_alpha``, ``k_omega``, ``dx``, ``dy``).
    settings : SettingSequence
        Its φ, ω-dependent settings and their order.
    """

    name: str
    mechanism: type[CorrectionMechanism]
    dimension: SchemaField
    dimension_field: str
    controls: Mapping[str, str]
    settings: SettingSequence
    setting_terms: tuple[tuple[str, str, str, str], ...] = CORRECTION_SETTING_TERMS

    @property
    def schema_fields(self) -> tuple[SchemaField, ...]:
        """The instrument-file leaves this principle adds."""
        return (self.dimension,)

    def mechanism_with(self, value: float | None = None) -> CorrectionMechanism:
        """The mechanism, with the dimension ``value`` when given (else its default). [mm]"""
        if value is None:
            return self.mechanism()
        return self.mechanism(**{self.dimension_field: float(value)})

    def error_terms(self, side: str) -> tuple[tuple[str, str, str, str], ...]:
        """(name, spec attribute of σ, meaning, unit) of the correction-setting errors of the
        ``side`` unit, in the order they are drawn."""
        return correction_setting_terms(side, self.setting_terms)


_INCL = "tan θ = k·tan {t}"
_DEC = "f′·tan {t}"


def inclination_setting(key: str, name: str, symbol: str, tilt: str) -> Setting:
    t = "α" if tilt == "alpha" else "ω"
    return Setting(key, name, symbol, "deg", _INCL.format(t=t), "primary", tilt)


def decentration_setting(
    key: str, name: str, symbol: str, tilt: str, formula: str | None = None
) -> Setting:
    t = "α" if tilt == "alpha" else "ω"
    return Setting(key, name, symbol, "mm", formula or _DEC.format(t=t), "derived", tilt)


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
