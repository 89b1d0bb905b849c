"""The ``verify --geometry`` file: a scenario, or a flat mapping of the table's geometry."""

from __future__ import annotations

from stereoplotter.errors import ConfigError
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.io.yaml_files import Fields, load_yaml_mapping
from stereoplotter.verification.procedure_mc import scenario_geometry
from stereoplotter.verification.table import BOOK, check_geometry

__all__ = ["geometry_from_file"]


_MM_POSITIVE = {"unit": "mm", "low": 1.0, "high": 500.0}
_GEOMETRY_LIMITS = {
    "f": {"unit": "mm", "low": 1.0, "high": 1000.0},
    "l": _MM_POSITIVE,
    "n": {"unit": "—", "low": 0.01, "high": 100.0},
    "c": _MM_POSITIVE,
    "p60": _MM_POSITIVE,
    "a60": {"unit": "mm", "low": -500.0, "high": 500.0},
    "p80": _MM_POSITIVE,
    "a80": {"unit": "mm", "low": -500.0, "high": 500.0},
}


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
        fields = Fields(source)
        fields.mapping(data, "", tuple(BOOK))
        geometry = {k: fields.number(data, k, "", **_GEOMETRY_LIMITS[k]) for k in data}
        check_geometry(fields, geometry)
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
        check_geometry(Fields(source), g)
        return g, {"60": scenario, "80": None}
    g.update(c=2 * p, p60=2 * p, a60=0.0, p80=p, a80=p)
    check_geometry(Fields(source), g)
    return g, {"60": None, "80": scenario}
