r"""The named decentration variants of the instrument model (``kinematics.md`` §4.1, §5): how
turning a correction knob moves the decentrations, and in which order the setup sets them."""

from __future__ import annotations

from dataclasses import dataclass

from stereoplotter.errors import StereoplotterError

__all__ = ["DECENTRATION_VARIANTS", "LINKAGES", "DecentrationVariant", "decentration_variant"]

#: Allowed linkages between a correction knob and the decentrations (``kinematics.md`` §4.1):
#: "L" both the photo decentration e and the plane decentration c follow the knob (D1),
#: "A" only the photo decentration follows, "B" the decentrations are independent.
LINKAGES = ("L", "A", "B")


@dataclass(frozen=True, slots=True)
class DecentrationVariant:
    """A named decentration variant of the instrument model (``kinematics.md`` §4.1, §5).

    Attributes
    ----------
    name : str
        "L", "A", "B", "B2" or "S".
    linkage : str
        How turning a correction knob moves the decentrations, one of :data:`LINKAGES`.
    decentrations_first : bool
        The computed decentrations are set before the k_ω, k_α fits (B2) instead of after them.
    strict_per_axis : bool
        The correction unit is the strict per-axis mechanism (α only in x, ω only in y).
    description : str
        One line for tables.
    """

    name: str
    linkage: str
    decentrations_first: bool
    strict_per_axis: bool
    description: str


#: The variants compared in ``kinematics.md`` §5 [1]; "L" is the canonical one (decision D1).
DECENTRATION_VARIANTS: dict[str, DecentrationVariant] = {
    v.name: v
    for v in (
        DecentrationVariant("L", "L", False, False, "canonical: dependent decentration (D1)"),
        DecentrationVariant("A", "A", False, False, "only the photo decentration follows"),
        DecentrationVariant("B", "B", False, False, "book order, independent decentrations"),
        DecentrationVariant("B2", "B", True, False, "independent, decentrations set first"),
        DecentrationVariant("S", "L", False, True, "strict per-axis unit, linkage as L"),
    )
}


def decentration_variant(name: str) -> DecentrationVariant:
    """The :class:`DecentrationVariant` called ``name``.

    Raises
    ------
    StereoplotterError
        ``name`` is not one of :data:`DECENTRATION_VARIANTS`.

    Examples
    --------
    >>> decentration_variant("B2").decentrations_first
    True
    """
    try:
        return DECENTRATION_VARIANTS[name]
    except KeyError:
        raise StereoplotterError(
            f"unknown decentration variant {name!r}; expected one of "
            f"{', '.join(DECENTRATION_VARIANTS)}"
        ) from None
