"""stereoplotter: virtual SC-1, SPR-3 and SD-3 stereoplotters and their setup data.

Kushtin & Lyskov, *Фотограмметрия снимка и стереоскопических моделей* (Nedra, 1984), chapter 6.

The public API (``docs/api.md``)::

    from stereoplotter import load_scenario, load_instrument, compute_setup_sheet, simulate, verify

    scenario = load_scenario("pair60")            # a shipped name or a YAML path
    spec = load_instrument("sc1")
    sheet = compute_setup_sheet(scenario, spec)   # Table 24 and the readings of the five stages
    run = simulate(scenario, spec, trials=1000)   # the simulated operator on the virtual instrument
    rows, seconds = verify(trials=20_000)         # the accuracy formulas (6.19)-(6.61)

The names are resolved on first use (PEP 562), so ``import stereoplotter`` stays light and a
module of one layer never loads the layers above it through the package.
"""

from __future__ import annotations

from importlib import import_module
from importlib.metadata import PackageNotFoundError, version
from typing import Any

try:
    __version__ = version("stereoplotter")
except PackageNotFoundError:  # pragma: no cover - running from a source tree without install
    __version__ = "0.0.0+unknown"

#: public name → module that defines it
_API = {
    "load_scenario": "stereoplotter.io.scenario_file",
    "load_instrument": "stereoplotter.io.instrument_file",
    "load_block": "stereoplotter.io.block_file",
    "compute_setup_sheet": "stereoplotter.setup.sheet",
    "compute_block": "stereoplotter.setup.block",
    "simulate": "stereoplotter.procedure.simulate",
    "verify": "stereoplotter.commands.verification",
    "run_verification": "stereoplotter.verification.table",
    "evaluate_model": "stereoplotter.procedure.evaluation",
    "Instrument": "stereoplotter.instrument.virtual",
    "ErrorModel": "stereoplotter.instrument.error_model",
    "OperatorModel": "stereoplotter.procedure.operator",
    "StereoplotterError": "stereoplotter.errors",
}

__all__ = ["__version__", *sorted(_API)]


def __getattr__(name: str) -> Any:
    # Imported here, not at the top: a lazy attribute keeps `import stereoplotter` (and every
    # pure sub-module, which imports this package first) free of the upper layers.
    if name in _API:
        value = getattr(import_module(_API[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'stereoplotter' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_API))
