"""The book's §27 setting, loaded: the shipped ``pair60``/``pair80`` scenarios and the SC-1."""

from __future__ import annotations

from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.paths import data_dir
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.scenario.model import Scenario
from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = ["BOOK_INSTRUMENT", "BOOK_SCENARIOS", "book_instrument", "book_scenarios"]

#: The book's §27 setting: the shipped scenarios of the procedure MC per overlap slot, and SC-1.
BOOK_SCENARIOS = {"60": "pair60.yaml", "80": "pair80.yaml"}
BOOK_INSTRUMENT = "sc1"


def book_scenarios() -> dict[str, Scenario]:
    """The shipped ``pair60``/``pair80`` scenarios, loaded, as "60"/"80" slots of the procedure MC.

    Always the shipped files (never a user folder's file of the same name): they are the book's.
    """
    folder = data_dir("scenarios")
    return {slot: load_scenario(folder / name) for slot, name in BOOK_SCENARIOS.items()}


def book_instrument(name: str = BOOK_INSTRUMENT) -> InstrumentSpec:
    """The instrument of the procedure MC: the book's SC-1 (``sc1``, by name as ever), or the
    instrument ``name`` (``verify --instrument``)."""
    return load_instrument(name)
