"""The work of ``stereoplotter verify`` and the ``verify`` of the public API.

Load (a geometry or scenario file, the book's scenarios and SC-1: :mod:`stereoplotter.io`) → run
(:func:`stereoplotter.verification.table.run_verification`, the procedure MC in worker
processes) → render (:mod:`stereoplotter.report.verification`, the figures by
:mod:`stereoplotter.plotting`) → write (:mod:`stereoplotter.io.atomic_write`). Imported by
:mod:`stereoplotter.commands.verify` only when the command runs (and by the public API), so the
library is imported here at the top.
"""

from __future__ import annotations

import argparse
import ctypes
import os
import sys
import time
from pathlib import Path

from stereoplotter.commands.arguments import fidelity_from_args
from stereoplotter.io.atomic_write import write_files
from stereoplotter.io.book_setting import BOOK_INSTRUMENT, book_instrument, book_scenarios
from stereoplotter.io.geometry_file import geometry_from_file
from stereoplotter.progress import step_progress
from stereoplotter.report.plain_data import json_text
from stereoplotter.report.verification import verification_console, verification_files
from stereoplotter.verification.table import (
    attach_procedure_mc,
    run_verification,
    start_procedure_mc,
)

__all__ = [
    "reuse_freed_memory",
    "run_verify_command",
    "start_book_procedure_mc",
    "verify",
    "write_verification",
]


def verify(
    trials: int = 60000,
    seed: int = 20240601,
    out_dir=None,
    geometry=None,
    progress=None,
    procedure_trials: int | None = None,
    procedure_scenarios=None,
    linkage: str | None = None,
):
    """Run and optionally write the verification (the entry point for ``stereoplotter verify``).

    ``geometry`` is a mapping of :data:`BOOK` keys or the path of a YAML file
    (:func:`geometry_from_file`: a scenario also becomes the procedure MC's scenario). Without a
    geometry the procedure MC runs on the book's scenarios (:func:`book_scenarios`); with a
    mapping it is skipped unless ``procedure_scenarios`` (loaded scenarios) are given.
    ``linkage``: "drag" or "independent" for the procedure MC (None: the instrument file's).

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
        linkage=linkage,
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


def write_verification(
    rows: list[dict], out_dir, *, trials=None, seed=None, seconds=0.0, procedure_trials=None
):
    """Write ``verification.md``, ``verification.csv``, ``verification.json`` and
    ``closing_comparison.json`` (:func:`~stereoplotter.report.verification.verification_files`)
    to ``out_dir``, each whole or not at all.

    Returns
    -------
    list of pathlib.Path
        The files written.
    """
    files = verification_files(
        rows, trials=trials, seed=seed, seconds=seconds, procedure_trials=procedure_trials
    )
    return list(write_files(out_dir, files).values())


def start_book_procedure_mc(
    trials, seed, scenarios=None, instrument=BOOK_INSTRUMENT, linkage=None, fidelity=None
):
    """:func:`stereoplotter.verification.table.start_procedure_mc` on loaded inputs:
    ``scenarios`` ("60"/"80" → Scenario or None) default to the book's (:func:`book_scenarios`),
    the instrument is loaded by name (default the book's SC-1) when a slot runs. ``trials``:
    None for the per-configuration defaults, 0 for none. ``linkage``: "drag", "independent"
    or None (the instrument file's). ``fidelity``: the setup method's mechanism switches
    (:class:`~stereoplotter.procedure.fidelity.Fidelity`, None: the defaults)."""
    if trials == 0:
        return start_procedure_mc(0, seed, {})
    if scenarios is None:
        scenarios = book_scenarios()
    spec = book_instrument(instrument) if any(scenarios.values()) else None
    return start_procedure_mc(
        trials, seed, scenarios, instrument=spec, linkage=linkage, fidelity=fidelity
    )


def _figures(rows: list[dict], proc: dict, seed: int, geometry) -> dict[str, bytes]:
    """error_maps.png, verification_chart.png and mc_histograms.png, encoded in memory."""
    # imported here: matplotlib loads only when figures are drawn (the API's verify draws none)
    from stereoplotter.plotting.accuracy import (
        plot_error_maps,
        plot_mc_histograms,
        plot_verification_chart,
    )
    from stereoplotter.plotting.encode import figure_bytes

    return {
        "error_maps.png": figure_bytes(plot_error_maps()),
        "verification_chart.png": figure_bytes(plot_verification_chart(rows).figure),
        "mc_histograms.png": figure_bytes(
            plot_mc_histograms(rows, proc, seed=seed, geometry=geometry)
        ),
    }


#: glibc's ``mallopt`` parameters (malloc.h): M_TRIM_THRESHOLD, M_MMAP_THRESHOLD.
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
#: Arrays below this size come from the heap, and up to this much freed heap is kept [bytes].
REUSED_HEAP_BYTES = {_M_MMAP_THRESHOLD: 128 * 2**20, _M_TRIM_THRESHOLD: 256 * 2**20}


def reuse_freed_memory() -> bool:
    """Let this process (and the workers it forks) reuse freed memory for the procedure MC's
    chunk arrays (tens of MB each, allocated and freed per chunk and act) instead of mapping
    fresh, zeroed pages for each: glibc serves an allocation above its mmap threshold (at most
    32 MiB by default) by mmap and returns it to the system when freed. On the default ``verify``
    this removed ≈ 85 % of the page faults and ≈ 2 s of system CPU of ≈ 19 s, with the same peak
    memory (``benchmarks/README.md``); values are unchanged (only where memory comes from).
    Returns whether the C library took the settings (False off glibc)."""
    try:
        if not os.confstr("CS_GNU_LIBC_VERSION"):  # glibc only
            return False
        mallopt = ctypes.CDLL(None).mallopt
    except (ValueError, OSError, AttributeError):
        return False
    return all(mallopt(param, value) == 1 for param, value in REUSED_HEAP_BYTES.items())


def run_verify_command(args: argparse.Namespace) -> int:
    """``verify``: the linear rows here while the procedure MC runs in worker processes; then
    the table, the files (figures first, in memory: every file whole or not at all) and the
    console summary or JSON."""
    reuse_freed_memory()  # before the workers are forked: they inherit it
    geometry, scenarios = None, None
    if args.geometry:
        geometry, scenarios = geometry_from_file(args.geometry)
    # the procedure MC once, shared by the table and the histograms; its runs go on in worker
    # processes while the linear rows are computed
    t0 = time.perf_counter()
    pending = start_book_procedure_mc(
        args.procedure_trials,
        args.seed,
        scenarios,
        args.instrument,
        args.linkage,
        fidelity_from_args(args),
    )
    with step_progress("verify") as progress:
        rows, seconds = verify(
            trials=args.trials,
            seed=args.seed,
            out_dir=None,
            geometry=geometry,
            progress=progress,
            procedure_trials=0,
        )
    with step_progress("procedure MC") as progress:
        proc = pending.result(progress)
    seconds = time.perf_counter() - t0  # the table and the procedure MC (running alongside)
    if proc:
        attach_procedure_mc(rows, proc)
    if args.output:
        figures = _figures(rows, proc, args.seed, geometry)
        files = verification_files(
            rows,
            trials=args.trials,
            seed=args.seed,
            seconds=seconds,
            procedure_trials=args.procedure_trials,
        )
        write_files(args.output, {**files, **figures})
    if args.json:
        sys.stdout.write(json_text(rows))
        return 0
    sys.stdout.write(
        verification_console(
            rows, trials=args.trials, seed=args.seed, seconds=seconds, output=args.output
        )
    )
    return 0
