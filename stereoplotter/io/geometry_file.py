"""The ``verify --geometry`` file: a scenario, or a flat mapping of the table's geometry
(:class:`GeometryFile`)."""

from __future__ import annotations

from functools import partial
from types import SimpleNamespace

from pydantic import ConfigDict

from stereoplotter.errors import ConfigError
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.io.validation import FileModel, number, validate
from stereoplotter.io.yaml_input import load_yaml_mapping
from stereoplotter.verification.procedure_mc import scenario_geometry
from stereoplotter.verification.table import check_geometry

__all__ = ["GeometryFile", "geometry_from_file"]

_MM_POSITIVE = number("mm", 1.0, 500.0)
_MM = number("mm", -500.0, 500.0)


class GeometryFile(FileModel):
    """The flat form of a ``verify --geometry`` file: any of the table's geometry values (the
    others keep the book's setting); a file with ``camera`` is a scenario instead."""

    model_config = ConfigDict(
        extra="forbid", frozen=True, title="stereoplotter verify --geometry file (flat form)"
    )

    f: number("mm", 1.0, 1000.0, description="focal length f") | None = None  # type: ignore[valid-type]
    l: _MM_POSITIVE | None = None  # type: ignore[valid-type]  # noqa: E741
    n: number("—", 0.01, 100.0) | None = None  # type: ignore[valid-type]
    c: _MM_POSITIVE | None = None  # type: ignore[valid-type]
    p60: _MM_POSITIVE | None = None  # type: ignore[valid-type]
    a60: _MM | None = None  # type: ignore[valid-type]
    p80: _MM_POSITIVE | None = None  # type: ignore[valid-type]
    a80: _MM | None = None  # type: ignore[valid-type]


def _errors(source: str) -> SimpleNamespace:
    """What :func:`check_geometry` reports through: ``.error(field, expected, found)``."""
    return SimpleNamespace(error=partial(ConfigError, source))


def geometry_from_file(path) -> tuple[dict, dict]:
    """Geometry overrides from a YAML file: a scenario (has ``camera``) or a flat mapping.

    A scenario gives f (camera), l (mean fiducial distance), n = n_л of the SC-1 sheet and its
    photo base p = B·f/H̄ at the scenario's photo scale; below 70 % overlap p is the 60 % slot
    (c = p, a = 0, and the 80 % slot the book's relation p/2, a = c − p/2), above it the 80 % slot
    (c = 2p, a = p; 60 % slot p = c, a = 0). A flat mapping gives keys of :data:`BOOK`.

    Returns
    -------
    geometry : dict
        Keys of :data:`BOOK`.
    procedure_scenarios : dict
        ``{"60": Scenario or None, "80": Scenario or None}`` for the procedure MC (the loaded
        scenario in its slot).
    """
    data, source = load_yaml_mapping(path)
    if "camera" not in data:
        doc = validate(GeometryFile, data, source)
        geometry = {k: v for k, v in doc.model_dump().items() if v is not None}
        check_geometry(_errors(source), geometry)
        return geometry, {"60": None, "80": None}
    scenario = load_scenario(path)  # every problem of the file as one ConfigError
    if not scenario.is_stereopair:
        raise ConfigError(
            source,
            "photos",
            "a stereopair (photos left and right) for --geometry",
            f"{len(scenario.photos)} photo(s)",
        )
    sg = scenario_geometry(scenario, load_instrument("sc1"))
    p = sg["p"]
    g = {"f": sg["f"], "l": sg["l"], "n": sg["n"]}
    if sg["overlap"] < 0.7:
        g.update(c=p, p60=p, a60=0.0, p80=p / 2, a80=p / 2)
        check_geometry(_errors(source), g)
        return g, {"60": scenario, "80": None}
    g.update(c=2 * p, p60=2 * p, a60=0.0, p80=p, a80=p)
    check_geometry(_errors(source), g)
    return g, {"60": None, "80": scenario}
