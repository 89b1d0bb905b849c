"""Physical and unit constants, each with its unit and source.

Units inside the package (``docs/conventions.md``): mm in the photo, the instrument and the model;
m on the ground; radians for every angle. Anything else carries its unit in the name.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = [
    "ARCSEC_PER_RAD",
    "DEG_PER_RAD",
    "KRASOVSKY",
    "MM_PER_M",
    "UM_PER_MM",
    "Ellipsoid",
]

#: Arc-seconds per radian, 648000/π. The book rounds to ρ″ = 206 265″ (OCR L364); the relative
#: difference, 9.4e-7, is below every digit the book prints.
ARCSEC_PER_RAD: float = 648000.0 / math.pi
#: Degrees per radian.
DEG_PER_RAD: float = 180.0 / math.pi
#: Millimetres per metre: the factor 1000 of (6.6) and (6.7) that turns ground metres into model
#: millimetres at scale 1:M.
MM_PER_M: float = 1000.0
#: Micrometres per millimetre.
UM_PER_MM: float = 1000.0


@dataclass(frozen=True, slots=True)
class Ellipsoid:
    """A reference ellipsoid of revolution.

    Parameters
    ----------
    name : str
        Name as used in the book and by PROJ (``ellps=``).
    a_m : float
        Semi-major axis. [m]
    inverse_flattening : float
        1/f. [—]
    proj_name : str
        The PROJ ellipsoid identifier.
    """

    name: str
    a_m: float
    inverse_flattening: float
    proj_name: str

    @property
    def flattening(self) -> float:
        """f = 1/inverse_flattening. [—]"""
        return 1.0 / self.inverse_flattening

    @property
    def b_m(self) -> float:
        """Semi-minor axis b = a(1 − f). [m]"""
        return self.a_m * (1.0 - self.flattening)

    @property
    def e2(self) -> float:
        """First eccentricity squared e² = f(2 − f). [—]"""
        f = self.flattening
        return f * (2.0 - f)

    @property
    def second_e2(self) -> float:
        """Second eccentricity squared e′² = e²/(1 − e²). [—] (book: 0.0067385254, OCR L1151)"""
        return self.e2 / (1.0 - self.e2)

    @property
    def polar_radius_c_m(self) -> float:
        """Polar radius of curvature c = a²/b. [m] (book: 6 399 698.9 m, Table 3, OCR L1179)"""
        return self.a_m**2 / self.b_m


#: The Krasovsky (1940) ellipsoid of the SK-42 system: a from the constant term of N in (2.10) and
#: (2.16) (OCR L947, L1021); 1/f = 298.3, the standard value, consistent with the printed e′².
KRASOVSKY = Ellipsoid(
    name="Krasovsky 1940", a_m=6378245.0, inverse_flattening=298.3, proj_name="krass"
)
