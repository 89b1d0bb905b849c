"""The verification table as files: Markdown, CSV and JSON, and the ``verify`` entry point."""

from __future__ import annotations

import csv
import io
import json
import time
from pathlib import Path

from stereoplotter.io.geometry_file import geometry_from_file
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.paths import data_dir
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.io.yaml_files import atomic_write_bytes
from stereoplotter.verification import linear_mc as mc
from stereoplotter.verification import table
from stereoplotter.verification.table import (
    ROW_KEYS,
    closing_comparison,
    run_verification,
)

__all__ = [
    "book_instrument",
    "book_scenarios",
    "run_procedure_mc",
    "start_procedure_mc",
    "verify",
    "write_verification",
]

#: The book's §27 setting: the shipped scenarios of the procedure MC per overlap slot, and SC-1.
BOOK_SCENARIOS = {"60": "pair60.yaml", "80": "pair80.yaml"}
BOOK_INSTRUMENT = "sc1"


def book_scenarios() -> dict:
    """The shipped ``pair60``/``pair80`` scenarios, loaded, as "60"/"80" slots of the procedure MC.

    Always the shipped files (never a user folder's file of the same name): they are the book's.
    """
    folder = data_dir("scenarios")
    return {slot: load_scenario(folder / name) for slot, name in BOOK_SCENARIOS.items()}


def book_instrument(name: str = BOOK_INSTRUMENT):
    """The instrument of the procedure MC: the book's SC-1 (``sc1``, by name as ever), or the
    instrument ``name`` (``verify --instrument``)."""
    return load_instrument(name)


def run_procedure_mc(
    trials=None, seed=20240601, scenarios=None, progress=None, instrument=BOOK_INSTRUMENT
):
    """:func:`stereoplotter.verification.table.run_procedure_mc` with the files loaded here:
    ``scenarios`` (loaded, "60"/"80" → Scenario or None) default to the book's
    (:func:`book_scenarios`), the instrument by name (default the book's SC-1). ``trials``:
    None for the per-configuration defaults, 0 for none."""
    return start_procedure_mc(trials, seed, scenarios, instrument).result(progress)


def start_procedure_mc(trials=None, seed=20240601, scenarios=None, instrument=BOOK_INSTRUMENT):
    """:func:`stereoplotter.verification.table.start_procedure_mc` with the files loaded here
    (arguments as :func:`run_procedure_mc`): the runs start in worker processes."""
    if trials == 0:
        return table.PendingProcedureMC([], [], 1)
    if scenarios is None:
        scenarios = book_scenarios()
    spec = book_instrument(instrument) if any(scenarios.values()) else None
    return table.start_procedure_mc(trials, seed, scenarios, instrument=spec)


def _fmt(v, digits=4):
    if v is None:
        return "—"
    if isinstance(v, float):
        return f"{v:.{digits}g}" if abs(v) < 1e-3 or abs(v) >= 1e4 else f"{v:.{digits}f}"
    return str(v)


def _proc(r, key="mc_procedure"):
    if r.get(key) is None:
        return "—"
    return f"{_fmt(r[key])} ± {r[key + '_ci']:.2g}"


def _procedure_trials_text(trials) -> str:
    if trials == 0:
        return ""
    if trials is None:
        per = ", ".join(f"{k} {v}" for k, v in table.PROCEDURE_TRIALS.items())
        inst = ", ".join(f"{k} {v}" for k, v in table.INSTRUMENT_TRIALS.items())
        return f", procedure MC trials per run: {per}; with instrument errors: {inst}"
    return f", procedure MC trials = {trials}"


def _markdown(rows, closing, meta):
    lines = [
        "# Verification of Kushtin & Lyskov 1984, §27 and chapter 5",
        "",
        f"trials = {meta['trials']}, seed = {meta['seed']}, CI = ±{mc.CI_Z} s.e. (99.9 %),"
        f" runtime {meta['seconds']:.1f} s" + _procedure_trials_text(meta.get("procedure_trials")),
        "",
        "Verdicts are decided from the numbers (stereoplotter/verification/verdicts.py): a printed "
        "number agrees when the value rounded or truncated to its decimals equals it (both are "
        "shown), formula values within 0.5 %; `convention` and `not reproducible` are the "
        "row's own findings (docs/errata.md). *from printed inputs*: the book's arithmetic "
        "redone from its own printed intermediates.",
        "",
        "| eq | quantity | printed | from printed inputs | book | rigorous | covariance | "
        "linear MC ± CI | procedure MC ± CI | formula at the simulated geometry | procedure MC "
        "with instrument errors | verdict | note |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['eq']} | {r['quantity']} | {_fmt(r['printed'])} | "
            f"{_fmt(r.get('from_printed_inputs'))} | {_fmt(r['book'])} | "
            f"{_fmt(r['rigorous'])} | {_fmt(r['covariance'])} | {_fmt(r['mc_linear'])} ± "
            f"{r['mc_linear_ci']:.2g} | {_proc(r)} | {_fmt(r.get('mc_procedure_formula'))} | "
            f"{_proc(r, 'mc_procedure_instrument')} | {r['verdict']} | {r['note']} |"
        )
    lines += [
        "",
        "## Closing comparison (setup data vs conventional method)",
        "",
        "| overlap | book claim | printed setup/conv | book setup/conv (gain) | "
        "rigorous setup/conv (gain) | MC setup/conv | procedure MC setup/conv (gain) |",
        "|---|---|---|---|---|---|---|",
    ]
    for c in closing:
        lines.append(
            f"| {c['overlap']} | {c['book_claim']} | {_fmt(c['setup_printed'], 2)} / "
            f"{_fmt(c['conventional_printed'], 2)} | {_fmt(c['setup_book'])} / "
            f"{_fmt(c['conventional_book'])} ({c['gain_book']:+.0%}) | "
            f"{_fmt(c['setup_rigorous'])} / {_fmt(c['conventional_rigorous'])} "
            f"({c['gain_rigorous']:+.0%}) | {_fmt(c['setup_mc_linear'])} / "
            f"{_fmt(c['conventional_mc_linear'])} | {_fmt(c['setup_mc_procedure'])} / "
            f"{_fmt(c['conventional_mc_procedure'])}"
            + (f" ({c['gain_mc_procedure']:+.0%})" if c["gain_mc_procedure"] is not None else "")
            + " |"
        )
    return "\n".join(lines) + "\n"


def write_verification(
    rows: list[dict], out_dir, *, trials=None, seed=None, seconds=0.0, procedure_trials=None
):
    """Write ``verification.md``, ``verification.csv``, ``verification.json`` and
    ``closing_comparison.json`` to ``out_dir``, each whole or not at all.

    Returns
    -------
    list of pathlib.Path
        The files written.
    """
    out = Path(out_dir)
    closing = closing_comparison(rows)
    meta = {
        "trials": trials,
        "seed": seed,
        "seconds": seconds,
        "procedure_trials": procedure_trials,
    }
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=list(ROW_KEYS), extrasaction="ignore")
    w.writeheader()
    for r in rows:
        w.writerow({k: ("" if r.get(k) is None else r.get(k)) for k in ROW_KEYS})
    files = {
        "verification.md": _markdown(rows, closing, meta),
        "verification.csv": buf.getvalue(),
        "verification.json": json.dumps(rows, ensure_ascii=False, indent=1),
        "closing_comparison.json": json.dumps(closing, ensure_ascii=False, indent=1),
    }
    paths = []
    for name, text in files.items():
        atomic_write_bytes(out / name, text.encode("utf-8"))
        paths.append(out / name)
    return paths


def verify(
    trials: int = 60000,
    seed: int = 20240601,
    out_dir=None,
    geometry=None,
    progress=None,
    procedure_trials: int | None = None,
    procedure_scenarios=None,
):
    """Run and optionally write the verification (the entry point for ``stereoplotter verify``).

    ``geometry`` is a mapping of :data:`BOOK` keys or the path of a YAML file
    (:func:`geometry_from_file`: a scenario also becomes the procedure MC's scenario). Without a
    geometry the procedure MC runs on the book's scenarios (:func:`book_scenarios`); with a
    mapping it is skipped unless ``procedure_scenarios`` (loaded scenarios) are given.

    Returns
    -------
    rows : list of dict
    seconds : float
    """
    if isinstance(geometry, str | Path):
        geometry, scen = geometry_from_file(geometry)
        if procedure_scenarios is None:
            procedure_scenarios = scen
    elif procedure_scenarios is None and not geometry and procedure_trials != 0:
        procedure_scenarios = book_scenarios()
    instrument = book_instrument() if procedure_scenarios and procedure_trials != 0 else None
    t0 = time.perf_counter()
    rows = run_verification(
        trials=trials,
        seed=seed,
        geometry=geometry,
        progress=progress,
        procedure_trials=procedure_trials,
        procedure_scenarios=procedure_scenarios,
        instrument=instrument,
    )
    seconds = time.perf_counter() - t0
    if out_dir is not None:
        write_verification(
            rows,
            out_dir,
            trials=trials,
            seed=seed,
            seconds=seconds,
            procedure_trials=procedure_trials,
        )
    return rows, seconds
