"""Scenarios: the ground truth of a photo or a stereopair and the synthetic measurements made
from it (pure layer; files are read by :mod:`stereoplotter.io.scenario_file`)."""

from __future__ import annotations

from stereoplotter.scenario.model import (
    Camera,
    ErrorSettings,
    ExteriorOrientation,
    Frame,
    Hill,
    MapSheet,
    Photo,
    Point,
    Scenario,
    Terrain,
)
from stereoplotter.scenario.summary import summarize_scenario
from stereoplotter.scenario.synthetic import (
    Measurements,
    PhotoMeasurements,
    synthesize_measurements,
    working_area_grid_m,
)

__all__ = [
    "Camera",
    "ErrorSettings",
    "ExteriorOrientation",
    "Frame",
    "Hill",
    "MapSheet",
    "Measurements",
    "Photo",
    "PhotoMeasurements",
    "Point",
    "Scenario",
    "Terrain",
    "summarize_scenario",
    "synthesize_measurements",
    "working_area_grid_m",
]
