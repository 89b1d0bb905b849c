"""Injected instrument errors: every error is a named term with a distribution and a source.

The defaults come from the instrument YAML (``errors.*``; all *assumed*, since no data sheet of
SC-1, SPR-3 or SD-3 was found — ``docs/instruments.md``). A run draws all terms at once from an
explicit :class:`numpy.random.Generator`, vectorised over trials, in a fixed term-major order
(term 1 for all trials, then term 2, …), so a seed reproduces a run. A procedure run draws them
from keyed streams instead (:meth:`ErrorModel.draw_keyed`: one stream per term), so trial t has
the same errors whichever chunk of a long run it falls in, and a per-trial oracle draws it alone.

Units inside: mm, rad, relative (ppm/10⁶); the YAML and reports use ′, ″ and ppm at the edges.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from stereoplotter.errors import ConfigError, describe_value, did_you_mean
from stereoplotter.instrument.principles import error_terms_for
from stereoplotter.random_streams import keyed_draws
from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = ["DISTRIBUTIONS", "ErrorModel", "ErrorTerm", "error_model_from_spec"]

#: normal: σ; uniform: half-width a (values in [−a, a]); constant: the value itself.
DISTRIBUTIONS = ("normal", "uniform", "constant")


@dataclass(frozen=True, slots=True)
class ErrorTerm:
    """One injected error.

    Attributes
    ----------
    name : str
        Dotted name, e.g. ``"zero_reading.X"`` or ``"setting.kappa_left"``.
    distribution : str
        One of :data:`DISTRIBUTIONS`.
    scale : float
        σ, half-width or value, in internal units (mm, rad, or relative for scale errors).
    unit : str
        Internal unit of ``scale`` ("mm", "rad" or "—").
    source_key : str
        The YAML key the default comes from.
    assumed : bool
        Whether that default is assumed.
    meaning : str
        What the term perturbs.
    """

    name: str
    distribution: str
    scale: float
    unit: str
    source_key: str
    assumed: bool
    meaning: str

    def draw(self, rng: np.random.Generator, trials: int | None) -> NDArray[np.float64] | float:
        """Values of this term: a float for ``trials=None``, an array of shape (trials,)."""
        size = None if trials is None else (trials,)
        if self.distribution == "normal":
            return rng.normal(0.0, self.scale, size) if self.scale else _zeros(size)
        if self.distribution == "uniform":
            return rng.uniform(-self.scale, self.scale, size) if self.scale else _zeros(size)
        return _zeros(size) + self.scale

    def draw_keyed(self, seed: int, start: int, stop: int) -> NDArray[np.float64]:
        """Trials ``start … stop−1`` of this term from its keyed stream ``"injected/" + name``."""
        n = stop - start
        if self.distribution == "constant" or not self.scale:
            return np.zeros(n) + (self.scale if self.distribution == "constant" else 0.0)
        key = "injected/" + self.name
        if self.distribution == "normal":
            z = keyed_draws(seed, key, start, stop, lambda rng, k: rng.standard_normal(k))
        else:
            z = keyed_draws(seed, key, start, stop, lambda rng, k: rng.uniform(-1.0, 1.0, k))
        return z * self.scale


def _zeros(size: tuple[int] | None) -> NDArray[np.float64] | float:
    return 0.0 if size is None else np.zeros(size)


_ARCMIN = np.pi / 180.0 / 60.0

#: Largest override of a term per internal unit: the largest ``errors.*`` value the instrument
#: schema accepts (100 mm of zero-reading scatter or sheet placement, 600′ of a setting angle,
#: 10⁴ ppm of counter scale error); a backlash at most 0.2 mm (``errors.backlash_*``: the 0.5 mm
#: overtravel of the unidirectional approach must clear the dead band).
_MAX_OVERRIDE = {"mm": 100.0, "rad": 600.0 * _ARCMIN, "—": 1.0e-2}
_MAX_OVERRIDE_GROUP = {"backlash": 0.2}
_UNIT_WORDS = {"mm": "mm", "rad": "rad", "—": "(relative)"}
#: Groups whose distribution an override may not change, and why.
_FIXED_DISTRIBUTION = {
    "backlash": ("constant", "a backlash is the size of the dead travel, never negative"),
}


# long: one entry per injected error term, in the fixed order of the draws; a table read top to
# bottom, which splitting would scatter.
#: A row of the error terms: (name, distribution, spec attribute of the scale, meaning, unit,
#: factor applied to the attribute's value).
_Row = tuple[str, str, str, str, str, float]

#: The coordinatograph's terms (rails, needle, sheet placement).
_COORDINATOGRAPH_ROWS: tuple[_Row, ...] = (
    (
        "coordinatograph.nonorthogonality",
        "normal",
        "coordinatograph_nonorthogonality_sigma",
        "angle error between the coordinatograph X and Y rails",
        "rad",
        1.0,
    ),
    (
        "coordinatograph.pen_play",
        "uniform",
        "pen_play_mm",
        "play of the needle in its holder (half-width = play/2)",
        "mm",
        0.5,
    ),
    *(
        (
            f"coordinatograph.sheet_placement_{axis}",
            "normal",
            "sheet_placement_sigma_mm",
            f"hand placement error of a sheet corner under the needle, {axis}",
            "mm",
            1.0,
        )
        for axis in ("x", "y")
    ),
)


#: Scales whose place of zero §26 uses as a known constant instead of finding it.
_KNOWN_ZEROS = frozenset({"bx", "dx_left", "dy_left", "dx_right", "dy_right"})


def _counter_rows() -> list[_Row]:
    """Zero readings, counter scale ratios and screw backlash."""
    # §26 finds the places of zero of X, Y, b_y and b_z (unknown, ``zero_reading_scatter_mm``);
    # it takes those of b_x and of the decentration scales as known instrument constants
    # (O_bx = MO_bx + b_x; the computed decentrations "taking their places of zero into
    # account"), so only their calibration error enters (``known_zero_error_mm``).
    rows: list[_Row] = [
        (
            f"zero_reading.{s}",
            "normal",
            "known_zero_error_mm" if s in _KNOWN_ZEROS else "zero_reading_scatter_mm",
            f"calibration error of the known zero reading (место нуля) of the {s} scale"
            if s in _KNOWN_ZEROS
            else f"error of the zero reading (место нуля) of the {s} scale",
            "mm",
            1.0,
        )
        for s in ("X", "Y", "bx", "by", "bz", "dx_left", "dy_left", "dx_right", "dy_right")
    ]
    # The absolute height counter reads D itself (stage 1 sets O_Z = n_л·f_пр on it): its zero
    # is a factory calibration, assumed good to one least count, not an unknown place of zero.
    rows.insert(
        2,
        (
            "zero_reading.Z",
            "normal",
            "z_least_count_mm",
            "calibration error of the absolute height counter (reads D), one least count",
            "mm",
            1.0,
        ),
    )
    rows += [
        (
            f"counter_scale.{c}",
            "normal",
            "counter_scale_error_ppm",
            f"relative gear/scale ratio error of the {c} counter",
            "—",
            1e-6,
        )
        for c in ("X", "Y", "Z")
    ]
    screws = (("X", "xy"), ("Y", "xy"), ("Z", "z"), ("bx", "xy"), ("by", "xy"), ("bz", "z"))
    rows += [
        (
            f"backlash.{a}",
            "constant",
            f"backlash_{kind}_mm",
            f"backlash (мёртвый ход) of the {a} screw",
            "mm",
            1.0,
        )
        for a, kind in screws
    ]
    return rows


def _setting_rows(spec: InstrumentSpec) -> list[_Row]:
    """Errors of setting f_пр, the base, κ and the decentrations, and the correction
    principle's own terms (:func:`~stereoplotter.instrument.principles.error_terms_for`)."""
    rows: list[_Row] = [
        (
            "setting.f_instrument",
            "normal",
            "f_instrument_setting_sigma_mm",
            "error of setting f_пр on its scale",
            "mm",
            1.0,
        ),
        *(
            (
                f"setting.{b}",
                "normal",
                "base_setting_sigma_mm",
                f"error of setting {b} on its scale",
                "mm",
                1.0,
            )
            for b in ("bx", "by", "bz")
        ),
    ]
    for side in ("left", "right"):
        rows.append(
            (
                f"setting.kappa_{side}",
                "normal",
                "kappa_setting_sigma",
                f"error of setting κ of the {side} cassette",
                "rad",
                1.0,
            )
        )
        rows += [
            (
                f"setting.{d}_{side}",
                "normal",
                "decentration_setting_sigma_mm",
                f"error of setting the decentration {d} of the {side} photo",
                "mm",
                1.0,
            )
            for d in ("dx", "dy")
        ]
        rows += [
            (name, "normal", attribute, meaning, unit, 1.0)
            for name, attribute, meaning, unit in error_terms_for(spec.principle, side)
        ]
    return rows


def _terms(spec: InstrumentSpec) -> list[ErrorTerm]:
    """Every error term of ``spec``, its scale read from the spec attribute of its row."""

    def term(name: str, dist: str, attribute: str, meaning: str, unit: str, factor: float):
        key = spec.key_of(attribute)
        value = float(getattr(spec, attribute)) * factor
        return ErrorTerm(name, dist, value, unit, key, spec.is_assumed(key), meaning)

    rows = [*_counter_rows(), *_setting_rows(spec), *_COORDINATOGRAPH_ROWS]
    return [term(*row) for row in rows]


@dataclass(frozen=True, slots=True)
class ErrorModel:
    """The set of injected error terms of one instrument.

    Build with :func:`error_model_from_spec`; :meth:`zero` switches everything off (the
    error-free instrument), :meth:`with_overrides` changes single terms.
    """

    instrument: str
    terms: tuple[ErrorTerm, ...]

    def term(self, name: str) -> ErrorTerm:
        """The term called ``name``."""
        for t in self.terms:
            if t.name == name:
                return t
        raise KeyError(f"no error term {name!r}; known: {', '.join(self.names)}")

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(t.name for t in self.terms)

    def zero(self) -> ErrorModel:
        """The same terms with every scale 0: an error-free instrument."""
        return replace(self, terms=tuple(replace(t, scale=0.0) for t in self.terms))

    def scaled(self, factor: float) -> ErrorModel:
        """Every scale multiplied by ``factor`` (e.g. 0 for error-free, 2 for a worn one)."""
        return replace(self, terms=tuple(replace(t, scale=t.scale * factor) for t in self.terms))

    def with_overrides(self, overrides: Mapping[str, Any], source: str = "<errors>") -> ErrorModel:
        """Terms changed by a mapping ``name → scale`` or ``name → {distribution, scale}``.

        A group prefix ("backlash", "zero_reading", …) sets every term of the group. Values are
        in internal units (mm, rad, relative). Unknown names or bad values raise
        :class:`~stereoplotter.errors.ConfigError` naming the file and the field.
        """
        terms = {t.name: t for t in self.terms}
        groups = {n.split(".")[0] for n in terms}
        for key, value in overrides.items():
            names = [n for n in terms if n == key or (key in groups and n.startswith(key + "."))]
            if not names:
                raise ConfigError(
                    source,
                    str(key),
                    "an error term or group: " + ", ".join(sorted(groups | set(terms))),
                    key,
                    did_you_mean(str(key), sorted(groups | set(terms))),
                )
            dist = None
            path = str(key)
            if isinstance(value, Mapping):
                unknown = [k for k in value if k not in ("distribution", "scale")]
                if unknown:
                    raise ConfigError(
                        source,
                        f"{key}.{unknown[0]}",
                        "no such field",
                        unknown[0],
                        "allowed here: distribution, scale",
                    )
                dist = value.get("distribution")
                value = value.get("scale")
                path = f"{key}.scale"
                if dist is not None and dist not in DISTRIBUTIONS:
                    raise ConfigError(
                        source, f"{key}.distribution", "one of " + ", ".join(DISTRIBUTIONS), dist
                    )
                fixed = _FIXED_DISTRIBUTION.get(names[0].split(".")[0])
                if dist is not None and fixed is not None and dist != fixed[0]:
                    raise ConfigError(
                        source, f"{key}.distribution", f"{fixed[0]} ({fixed[1]})", dist
                    )
            # the same unit for every term of a group: mm, rad or relative
            unit = terms[names[0]].unit
            high = _MAX_OVERRIDE_GROUP.get(names[0].split(".")[0], _MAX_OVERRIDE[unit])
            expected = (
                f"a finite number ≥ 0 and ≤ {high:g} {_UNIT_WORDS[unit]} (internal units; the "
                "largest the instrument files allow)"
            )
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise ConfigError(source, path, expected, describe_value(value))
            if not (-math.inf < value <= high and value >= 0):  # NaN fails; big ints compare
                raise ConfigError(source, path, expected, value)
            for name in names:
                terms[name] = replace(
                    terms[name],
                    scale=float(value),
                    distribution=dist or terms[name].distribution,
                    assumed=True,
                )
        return replace(self, terms=tuple(terms.values()))

    def draw(
        self, rng: np.random.Generator, trials: int | None = None
    ) -> dict[str, NDArray[np.float64] | float]:
        """All terms at once, in the fixed order of :attr:`terms`.

        Parameters
        ----------
        rng : numpy.random.Generator
        trials : int, optional
            None → floats (one instrument); T → arrays of shape (T,).
        """
        return {t.name: t.draw(rng, trials) for t in self.terms}

    def draw_keyed(
        self, seed: int, start: int = 0, stop: int | None = None
    ) -> dict[str, NDArray[np.float64] | float]:
        """Trials ``start … stop−1`` of every term from keyed streams (one stream per term).

        The value of trial t does not depend on how a run is cut into chunks
        (:func:`stereoplotter.random_streams.keyed_draws`); ``stop=None`` gives one instrument
        (trial ``start``) as floats.

        Examples
        --------
        >>> from stereoplotter.io.instrument_file import load_instrument
        >>> model = error_model_from_spec(load_instrument("sc1"))
        >>> a = model.draw_keyed(3, 0, 10)["backlash.X"]
        >>> b = model.draw_keyed(3, 7)["backlash.X"]
        >>> bool(a[7] == b)
        True
        """
        single = stop is None
        stop = start + 1 if single else stop
        out: dict[str, NDArray[np.float64] | float] = {}
        for t in self.terms:
            values = t.draw_keyed(seed, start, stop)
            out[t.name] = float(values[0]) if single else values
        return out

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready description: every term with its distribution, scale, unit and status."""
        return {
            t.name: {
                "distribution": t.distribution,
                "scale": t.scale,
                "unit": t.unit,
                "source": t.source_key,
                "assumed": t.assumed,
                "meaning": t.meaning,
            }
            for t in self.terms
        }


def error_model_from_spec(spec: InstrumentSpec) -> ErrorModel:
    """The default error model of an instrument, from its YAML ``errors.*`` parameters.

    Examples
    --------
    >>> from stereoplotter.io.instrument_file import load_instrument
    >>> model = error_model_from_spec(load_instrument("sc1"))
    >>> model.term("backlash.X").scale, model.term("backlash.X").assumed
    (0.005, True)
    >>> import numpy as np
    >>> model.zero().draw(np.random.default_rng(1))["zero_reading.X"]
    0.0
    """
    return ErrorModel(spec.key, tuple(_terms(spec)))
