"""The work of ``stereoplotter simulate``: load → run → render → write.

One procedure (no ``trials``): the transcript, the evaluation of the built model (values and
per point), a Markdown summary and a parallax map. ``trials=T``: the trials run in chunks under
a memory budget (``procedure.trials``); their per-trial measures are spooled to disk
(``trial_store``) and summarised per measure with Monte Carlo standard errors; with an output
folder the per-trial columns go to ``trials.npz``, the transcript and the map are of trial 0.

Load (scenario, instrument, errors, operator: :mod:`stereoplotter.io`) → run
(:mod:`stereoplotter.procedure.simulate`) → render (:mod:`stereoplotter.report.simulation`, the
map by :mod:`stereoplotter.plotting`) → write (:mod:`stereoplotter.io.atomic_write`). Every file
is written whole or not at all; the same seed gives byte-identical files. Imported by
:mod:`stereoplotter.commands.simulate` (and ``demo``) only when the command runs, so the library
is imported here at the top — but for the plotting, which only a written map needs.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from stereoplotter.instrument.sc1_complex import SC1Options
from stereoplotter.io.atomic_write import write_files
from stereoplotter.io.errors_file import load_error_model
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.operator_file import load_operator_model
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.io.trial_store import TrialStore
from stereoplotter.io.yaml_output import yaml_text
from stereoplotter.procedure.fidelity import Fidelity
from stereoplotter.procedure.operator import OperatorModel
from stereoplotter.procedure.simulate import SimulationResult, prepare_run, run_trials_chunk
from stereoplotter.procedure.trials import (
    DEFAULT_MEMORY_BUDGET_MB,
    chunk_trials_for,
    default_workers,
    iter_chunk_columns,
    run_info,
    split_chunk,
    summarise_columns,
    summarise_result,
)
from stereoplotter.report.plain_data import json_ready
from stereoplotter.report.simulation import simulation_markdown, trial0_texts

__all__ = [
    "SimulationOutcome",
    "run_simulation_command",
    "simulation_files",
    "write_simulation",
]

log = logging.getLogger(__name__)


def _parallax_png(result: SimulationResult) -> bytes:
    """The true residual y-parallax over the working-area grid (trial 0) as a PNG."""
    # imported here: matplotlib (≈ 1.5 s of start-up) only where a map is written (-o)
    from stereoplotter.plotting.encode import figure_bytes
    from stereoplotter.plotting.figures import plot_residual_y_parallax

    return figure_bytes(plot_residual_y_parallax(result), "png", dpi=100)


def _trial0_files(result: SimulationResult, lang: str = "en") -> dict[str, bytes]:
    """trial 0's transcript (text in ``lang``, JSON lines) and parallax map."""
    return {**trial0_texts(result, lang), "parallax.png": _parallax_png(result)}


def _evaluation_files(summary: dict[str, Any]) -> dict[str, bytes]:
    """evaluation.yaml and evaluation.md of a run's summary (plain data)."""
    return {
        "evaluation.yaml": yaml_text(json_ready(summary)).encode("utf-8"),
        "evaluation.md": simulation_markdown(summary).encode("utf-8"),
    }


def simulation_files(result: SimulationResult, lang: str = "en") -> dict[str, bytes]:
    """One run's transcript.txt, transcript.jsonl, parallax.png, evaluation.yaml, evaluation.md
    rendered in memory (a vectorised result: the summary over its trials, trial 0's
    transcript, in ``lang``)."""
    return {**_trial0_files(result, lang), **_evaluation_files(summarise_result(result))}


def write_simulation(
    result: SimulationResult, out_dir: str | Path, lang: str = "en"
) -> dict[str, Path]:
    """Write :func:`simulation_files` into ``out_dir``; name → path."""
    return write_files(out_dir, simulation_files(result, lang))


@dataclass
class SimulationOutcome:
    """What the command produced: the summary, its Markdown, the files written."""

    summary: dict[str, Any]
    text: str
    files: dict[str, Path]


def run_simulation_command(
    scenario_path: str | Path,
    instrument: str = "sc1",
    method: str = "setup",
    errors: str | None = None,
    seed: int | None = None,
    trials: int | None = None,
    backend: str = "closed-form",
    output: str | Path | None = None,
    *,
    memory_mb: float = DEFAULT_MEMORY_BUDGET_MB,
    progress: Callable[[int], None] | None = None,
    operator: str | Path | OperatorModel | None = None,
    practice: str = "operator",
    options: Sequence[str] = (),
    lang: str = "en",
    workers: int | None = None,
    fidelity: Fidelity | None = None,
) -> SimulationOutcome:
    """What ``stereoplotter simulate`` does: run, summarise, write the files if ``output``.

    ``seed`` defaults to the scenario's seed; ``errors`` is None (instrument defaults), "zero" or
    an errors YAML path. ``trials`` runs in chunks that fit ``memory_mb``; the summary holds
    statistics, never per-trial arrays (those go to ``trials.npz`` in ``output``).
    ``progress(n)`` is told the trials each finished chunk ran. ``operator`` is None (the
    assumed defaults), "zero" or a YAML of OperatorModel fields (:func:`load_operator_model`).
    ``practice`` is "operator" (remedies after a failed check) or "book" (§27 task 1, none).
    ``options`` names the SC complex's options fitted to the SC-1 (``correction_unit``,
    ``automatic_coordinatograph``; :class:`~stereoplotter.instrument.sc1_complex.SC1Options`).
    ``lang`` (``"ru"``/``"en"``) is the language of the transcript. ``workers``: processes for
    the chunks (default :func:`~stereoplotter.procedure.trials.default_workers`; the results do
    not depend on it). ``fidelity``: the setup-data procedure's mechanism switches
    (:mod:`~stereoplotter.procedure.fidelity`; None: the defaults).
    """
    scenario = load_scenario(scenario_path)
    spec = load_instrument(instrument)
    fitted = SC1Options.parse(options)  # checked against the instrument once, by prepare_run
    seed = scenario.seed if seed is None else seed
    prep = prepare_run(
        scenario,
        spec,
        method,
        load_error_model(errors, spec),
        seed,
        backend,
        operator=load_operator_model(operator),
        practice=practice,
        options=fitted,
        fidelity=fidelity,
    )
    out = None if output is None else Path(output)
    if trials is None:
        result = run_trials_chunk(prep, 0, None)
        summary = json_ready(summarise_result(result))
        files = {} if out is None else write_simulation(result, out, lang)
        if progress is not None:
            progress(1)
    else:
        workers = default_workers() if workers is None else workers
        chunk = split_chunk(trials, chunk_trials_for(memory_mb, method), workers)
        log.info("%d trials in chunks of %d (memory budget %g MB)", trials, chunk, memory_mb)
        info = None
        with TrialStore() as store:
            chunks = iter_chunk_columns(prep, trials, chunk, workers=workers, progress=progress)
            for result, columns in chunks:
                if result is not None:  # the first chunk: trial 0's transcript and map
                    info = run_info(result, trials)
                    trial0 = _trial0_files(result, lang) if out is not None else {}
                store.append(columns)
            extra = {"chunks": {"trials": chunk, "count": -(-trials // chunk)}}
            summary = json_ready(summarise_columns(info, store.columns(), extra))
            files = {}
            if out is not None:
                files = write_files(out, {**trial0, **_evaluation_files(summary)})
                store.write_npz(out / "trials.npz")
                files["trials.npz"] = out / "trials.npz"
    text = simulation_markdown(summary)
    if files:
        text += f"\nwritten: {', '.join(sorted(files))} in {out}\n"
    return SimulationOutcome(summary, text, files)
