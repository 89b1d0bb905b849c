r"""Options of the SC complex built around the SC-1; off by default.

* The systematic-error correction unit: corrects symmetric and asymmetric image errors
  (distortion, film deformation) within ±100 µm with an instrumental RMS of ±3 µm (documented,
  source SCX, ``facts.error_correction_unit_range_um`` / ``_rms_um`` in sc1.yaml). Modelled as:
  the corrected image error is the residual e_res ~ N(0, σ²) per coordinate with
  σ = 3 µm / √2 (so that the RMS of the 2-D residual vector is 3 µm — ASSUMED reading of "RMS
  ±3 µm" as the vector RMS); an input error beyond ±100 µm in either coordinate is refused.
* The automatic coordinatograph: a tracking servo follows the model point; modelled as a
  first-order lag x_pen(t) = x(t) − v·τ plus white noise σ_s. τ = 0.05 s and σ_s = 0.02 mm are
  ASSUMED (no SC data found; a small drafting servo). Enlargement photo → map up to 10 ×
  (documented, ``gears.max_photo_to_map_enlargement_automatic``).

Units: µm for image errors, mm and s for the servo. Randomness only through a Generator.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.errors import StereoplotterError
from stereoplotter.spec.instrument_spec import InstrumentSpec
from stereoplotter.spec.range_checks import RangeRefusal

__all__ = ["OPTION_NAMES", "AutomaticCoordinatograph", "ErrorCorrectionUnit", "SC1Options"]

_RANGE_KEY = "facts.error_correction_unit_range_um"
_RMS_KEY = "facts.error_correction_unit_rms_um"
_ENLARGE_KEY = "gears.max_photo_to_map_enlargement_automatic"
_AUTOMATIC_KEY = "coordinatograph.automatic_variant"

#: The switch names of ``simulate --option NAME`` and their :class:`SC1Options` fields.
OPTION_NAMES = {
    "correction_unit": "error_correction_unit",
    "automatic_coordinatograph": "automatic_coordinatograph",
}


@dataclass(frozen=True, slots=True)
class SC1Options:
    """Which options of the SC complex are fitted: none by default (a plain SC-1)."""

    error_correction_unit: bool = False
    automatic_coordinatograph: bool = False

    @property
    def names(self) -> tuple[str, ...]:
        """The switch names of the fitted options (``OPTION_NAMES`` keys)."""
        return tuple(k for k, field in OPTION_NAMES.items() if getattr(self, field))

    @classmethod
    def parse(cls, names: Iterable[str]) -> SC1Options:
        """The options of the switch names ``names``; an unknown name is refused in one line (the
        instrument is checked by :meth:`fitted_to`)."""
        fields = {}
        for name in names:
            if name not in OPTION_NAMES:
                raise StereoplotterError(
                    f"--option: expected one of {', '.join(OPTION_NAMES)}, found {name!r}"
                )
            fields[OPTION_NAMES[name]] = True
        return cls(**fields)

    def fitted_to(self, spec: InstrumentSpec) -> SC1Options:
        """These options, checked against ``spec``: an option the instrument file does not
        document (only the SC-1 of the SC complex has them) is refused in one line."""
        for name in self.names:
            key = _RANGE_KEY if name == "correction_unit" else _AUTOMATIC_KEY
            p = spec.parameters.get(key)
            if p is None or p.value is False:
                raise StereoplotterError(
                    f"--option {name}: the {spec.title} has no such unit (its instrument file "
                    f"has no {key}; the options belong to the SC complex built around the SC-1)"
                )
        return self

    @classmethod
    def from_names(cls, spec: InstrumentSpec, names: Iterable[str]) -> SC1Options:
        """The options ``names`` fitted to ``spec`` (:meth:`parse`, then :meth:`fitted_to`)."""
        return cls.parse(names).fitted_to(spec)


@dataclass(frozen=True, slots=True)
class ErrorCorrectionUnit:
    """The off-line systematic-error correction unit (range ±100 µm, RMS ±3 µm; SCX)."""

    range_um: float
    rms_um: float
    file: str = ""

    @classmethod
    def from_spec(cls, spec: InstrumentSpec) -> ErrorCorrectionUnit:
        """From sc1.yaml ``facts.error_correction_unit_range_um`` and ``_rms_um``."""
        rng_p, rms_p = spec.parameters.get(_RANGE_KEY), spec.parameters.get(_RMS_KEY)
        if rng_p is None or rms_p is None:
            raise RangeRefusal(
                f"{spec.title} has no error-correction unit ({_RANGE_KEY})",
                what="error-correction unit",
                value=float("nan"),
                low=0.0,
                high=0.0,
                status="documented",
                file="",
                key=_RANGE_KEY,
            )
        return cls(float(rng_p.value), float(rms_p.value), rng_p.file)

    @property
    def residual_sigma_um(self) -> float:
        """σ of the residual per coordinate: RMS/√2 (the documented RMS read as the vector RMS,
        ASSUMED). [µm]"""
        return self.rms_um / float(np.sqrt(2.0))

    def check_input_um(self, image_error_um: ArrayLike) -> float:
        """Refuse (like a stop) an image error beyond ±range in either coordinate; return the
        largest |error|. [µm]"""
        e = np.asarray(image_error_um, float)
        worst = float(np.max(np.abs(e))) if e.size else 0.0
        if worst > self.range_um:
            raise RangeRefusal(
                f"image error {worst:.1f} µm exceeds the SC-1 correction unit range "
                f"±{self.range_um:g} µm (documented; {self.file}: {_RANGE_KEY})",
                what="image error",
                value=worst,
                low=-self.range_um,
                high=self.range_um,
                status="documented",
                file=self.file,
                key=_RANGE_KEY,
            )
        return worst

    def residual_um(self, image_error_um: ArrayLike, rng: np.random.Generator) -> NDArray:
        """Image error left after correction, shape (..., 2). [µm]

        Refuses (like a stop) an input error beyond ±range in either coordinate.
        """
        e = np.asarray(image_error_um, float)
        self.check_input_um(e)
        return rng.normal(0.0, self.residual_sigma_um, e.shape)


@dataclass(frozen=True, slots=True)
class AutomaticCoordinatograph:
    """Tracking servo of the automatic coordinatograph (lag τ, noise σ_s; both ASSUMED)."""

    lag_s: float = 0.05
    sigma_mm: float = 0.02
    max_enlargement: float = 10.0

    @classmethod
    def from_spec(cls, spec: InstrumentSpec) -> AutomaticCoordinatograph:
        """Enlargement limit from ``gears.max_photo_to_map_enlargement_automatic`` (SCX: 10)."""
        p = spec.parameters.get(_ENLARGE_KEY)
        return cls(max_enlargement=float(p.value) if p is not None else 10.0)

    def check_enlargement(self, enlargement: float) -> None:
        """Refuse a photo → map enlargement beyond the documented 10 ×."""
        if not 0.0 < enlargement <= self.max_enlargement:
            raise RangeRefusal(
                f"photo-to-map enlargement {enlargement:.2f} × exceeds the automatic "
                f"coordinatograph's {self.max_enlargement:g} × (documented; {_ENLARGE_KEY})",
                what="enlargement",
                value=enlargement,
                low=0.0,
                high=self.max_enlargement,
                status="documented",
                file="",
                key=_ENLARGE_KEY,
            )

    def pen_mm(self, track_mm: ArrayLike, dt_s: float, rng: np.random.Generator) -> NDArray:
        """Pen positions for a tracked path sampled every ``dt_s``, shape (N, 2). [mm]

        First-order lag: pen = point − v·τ (v by finite differences) plus N(0, σ_s²).
        """
        p = np.asarray(track_mm, float)
        v = np.gradient(p, dt_s, axis=0) if len(p) > 1 else np.zeros_like(p)
        return p - v * self.lag_s + rng.normal(0.0, self.sigma_mm, p.shape)
