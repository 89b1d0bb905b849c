"""What ``stereoplotter simulate`` prints and writes.

One procedure (no ``--trials``): the transcript, the evaluation of the built model (values and
per point), a Markdown summary and a parallax map. ``--trials T``: the trials run in chunks
under a memory budget (``procedure.trials``); their per-trial measures are spooled to disk
(``trial_store``) and summarised per measure with Monte Carlo standard errors; with an output
folder the per-trial columns go to ``trials.npz``, the transcript and the map are of trial 0.

Every file is written whole or not at all; the same seed gives byte-identical files.
"""

from __future__ import annotations

import io
import json
import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from stereoplotter.errors import ConfigError, did_you_mean
from stereoplotter.instrument.sc1_complex import SC1Options
from stereoplotter.io.errors_file import load_error_model
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.io.trial_store import TrialStore
from stereoplotter.io.yaml_files import atomic_write_bytes, load_yaml_mapping
from stereoplotter.plotting.figures import plot_residual_y_parallax
from stereoplotter.procedure.operator import OperatorModel
from stereoplotter.procedure.simulate import SimulationResult, prepare_run, run_trials_chunk
from stereoplotter.procedure.trials import (
    DEFAULT_MEMORY_BUDGET_MB,
    chunk_trials_for,
    iter_trial_chunks,
    run_info,
    summarise_columns,
    summarise_result,
    trial_columns,
)

__all__ = [
    "SimulationOutcome",
    "load_operator_model",
    "run_simulation_command",
    "simulation_markdown",
    "write_simulation",
]

log = logging.getLogger(__name__)


def _plain(v: Any) -> Any:
    if isinstance(v, np.ndarray):
        return v.tolist()
    if isinstance(v, np.generic):
        return v.item()
    return str(v)


def json_ready(data: Any) -> Any:
    """Plain lists, floats and strings only."""
    return json.loads(json.dumps(data, default=_plain))


def _yaml(data: Any) -> str:
    import yaml

    return yaml.safe_dump(json_ready(data), sort_keys=False, allow_unicode=True)


def _g(v: Any) -> str:
    return "—" if v is None else f"{v:.4g}"


def _stat(s: dict[str, Any] | None, key: str = "mean") -> str:
    """``mean ± SE`` of a value summary (or the plain value of a single run)."""
    if s is None:
        return "—"
    if not isinstance(s, dict):
        return _g(s)
    if "constant" in s:
        return _g(s["constant"])
    v, se = s.get(key), s.get(f"{key}_se")
    if v is None:
        return "—"
    return _g(v) if se is None else f"{v:.4g} ± {se:.2g}"


def _p95(s: dict[str, Any] | None) -> str:
    if isinstance(s, dict) and "constant" in s:
        return _g(s["constant"])
    if not isinstance(s, dict) or "quantiles" not in s:
        return "—"
    return _g(s["quantiles"]["p95"]["value"])


def tolerance_note(s: dict[str, Any]) -> str:
    """One honest sentence for a single run's summary: inside the book's tolerances, or why not
    (the figures of ``docs/procedure.md``, pass rates over 10 000 trials)."""
    failed = [n for n, c in s.get("checks", {}).items() if c.get("passed") is False]
    if not failed:
        return "The model is inside the book's tolerances (every check passed)."
    return (
        f"Outside the book's tolerances ({'; '.join(failed)}): with the assumed operator "
        "(σ_q = 10 µm, judged at each of six points) the ¼-mark y-parallax check (12.5 µm with "
        "the assumed 0.05 mm mark) passes in about 38 % of 10 000 pair60/SC-1 runs even with the "
        "remedies (σ_q = 5 µm: 99 %, or a 0.08 mm mark: 95 %); H/3000 at the control heights "
        "is met after the levelling remedy R3 in 99 % of pair60 runs but in 56 % of pair80 "
        "runs, where one height reading's σ_p·H/b ≈ 0.39 m nearly fills the 0.47 m "
        "(docs/procedure.md)."
    )


def _remedy_lines(s: dict[str, Any], single: bool) -> list[str]:
    """The remedies table (operator practice): how often each was applied and whether its
    check then passed."""
    practice = s.get("practice", "book")
    rem = s.get("remedies") or {}
    if practice == "book" or not rem:
        return ["", f"Practice: {practice} (no remedy after a failed check, §27 task 1)."]
    lines = ["", f"Practice: {practice} (the book's remedies after a failed check).", ""]
    if single:
        lines += ["| remedy | applied | rounds | check passed after |", "|---|---|---|---|"]
        for name, r in rem.items():
            lines.append(
                f"| {name} | {r['applied']} | {r['rounds']} | "
                f"{r['passed_after'] if r['applied'] else '—'} |"
            )
        return lines
    lines += [
        "| remedy | applied (rate ± SE) | rounds mean | check passed after (rate ± SE) |",
        "|---|---|---|---|",
    ]
    for name, r in rem.items():
        a = r["applied_rate"]
        p = r.get("passed_after_rate")
        after = "—" if not p else f"{p['rate']:.3f} ± {p['rate_se']:.3f}"
        lines.append(
            f"| {name} | {a['rate']:.3f} ± {a['rate_se']:.3f} | {_stat(r.get('rounds'))} | "
            f"{after} |"
        )
    return lines


def simulation_markdown(s: dict[str, Any]) -> str:
    """The Markdown summary of a run (one procedure, or statistics over trials)."""
    trials = s.get("trials")
    lines = [
        f"# Simulated {s['method']} procedure: {s['scenario']} on {s['instrument']}",
        "",
    ]
    if trials is None:
        lines += [
            f"back-end {s['backend']}, seed {s['seed']}, one procedure; operator judgment "
            "errors are assumed values.",
            "",
            "| check | residual | tolerance | passed | iterations |",
            "|---|---|---|---|---|",
        ]
        for name, c in s["checks"].items():
            label = name.replace("|", "\\|")
            lines.append(
                f"| {label} | {_g(c['residual'])} {c['unit']} | {_g(c.get('tolerance'))} | "
                f"{c.get('passed', '—')} | {_g(c.get('iterations'))} |"
            )
        lines += _remedy_lines(s, single=True)
        q = s["residual_y_parallax_um"]
        lines += [
            "",
            f"Residual y-parallax of the built model (truth): max {_g(q['standard_points_max'])} "
            f"µm at the six standard points; over the grid max {_g(q['grid_max'])} µm, "
            f"RMS {_g(q['grid_rms'])} µm.",
            "",
            "Iterations per stage: "
            + ", ".join(f"{k}: {_g(v)}" for k, v in s["iterations"].items()),
            "",
        ]
        return "\n".join(lines)
    chunks = s.get("chunks", {})
    lines += [
        f"back-end {s['backend']}, seed {s['seed']}, {trials} trials"
        + (f" in {chunks['count']} chunk(s) of ≤ {chunks['trials']}" if chunks else "")
        + "; operator judgment errors are assumed values. Figures: mean ± Monte Carlo standard "
        "error; p95 the 95th percentile over the trials.",
        "",
        "| check | passed (rate ± SE) | residual mean | residual p95 | tolerance | iterations |",
        "|---|---|---|---|---|---|",
    ]
    for name, c in s["checks"].items():
        label = name.replace("|", "\\|")
        rate = c.get("pass_rate")
        passed = "—" if rate is None else f"{rate['rate']:.3f} ± {rate['rate_se']:.3f}"
        lines.append(
            f"| {label} | {passed} | {_stat(c.get('residual'))} {c['unit']} | "
            f"{_p95(c.get('residual'))} | {_stat(c.get('tolerance'))} | "
            f"{_stat(c.get('iterations'))} |"
        )
    lines += _remedy_lines(s, single=False)
    q = s["residual_y_parallax"]
    lines += [
        "",
        "Residual y-parallax of the built model (truth), µm: grid RMS "
        f"{_stat(q['grid_rms_um'])} (p95 {_p95(q['grid_rms_um'])}); grid max "
        f"{_stat(q['grid_max_um'])}; six standard points max {_stat(q['standard_points_max_um'])}.",
        "",
    ]
    ev = s.get("evaluation") or {}
    rows = []
    for set_name in ("control", "check", "grid"):
        e = ev.get(set_name) or {}
        h = e.get("height_error_rms_permille")
        p = e.get("plan_error_rms_map_mm")
        if h or p:
            rows.append(
                f"| {set_name} ({e.get('n_points')}) | {_stat(h)} | {_p95(h)} | {_stat(p)} | "
                f"{_p95(p)} |"
            )
    if rows:
        lines += [
            "| points | height RMS, ‰ H | p95 | plan RMS, mm on the map | p95 |",
            "|---|---|---|---|---|",
            *rows,
            "",
        ]
    return "\n".join(lines)


def _parallax_png(result: SimulationResult) -> bytes:
    """The true residual y-parallax over the working-area grid (trial 0) as a PNG."""

    fig = plot_residual_y_parallax(result)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, metadata={"Software": None})
    import matplotlib.pyplot as plt

    plt.close(fig)
    return buf.getvalue()


#: What a real operator does when a check still fails after the simulated operator's remedies
#: (keyed by a word of the check's name); the book's practice of §26–§27 where it says one.
OPERATOR_ADVICE = {
    "|L − L′|": "measure both spans again; if they stay off, recompute f_пр, n and L on the "
    "sheet ((6.3)–(6.5)) before turning ΔZ or Δb_z further",
    "mark 4": "fit k_ω on mark 3 again and re-check mark 4; a misfit that stays means y⁰₃, y⁰₄ "
    "or n on the sheet ((6.2), (6.12)) need checking",
    "residual y-parallax": "clear the y-parallax once more by the relative orientation at the "
    "six standard points (§27, conventional method), then go on and note the residual",
    "control heights": "refine scaling (b_x) and levelling on control once more; a single "
    "point that stays out is checked for its identification and height and left out if a "
    "blunder",
    "levelling": "level again on the levelling points, then re-read the control heights",
    "corner": "place the sheet again over two corners and re-check the others (6.16)–(6.18)",
    "plan control": "re-check the scaling (b_x) and the sheet's placement, then the points' "
    "identification",
}


def _advice(check: str) -> str:
    for word, text in OPERATOR_ADVICE.items():
        if word in check:
            return text
    return "repeat the step and its check; look for a sheet or reading error before going on"


def _at(value: Any, trial: int) -> float:
    v = np.ravel(np.asarray(value, float))
    return float(v[trial] if v.size > 1 else v[0])


def _small(value: float, unit: str) -> str:
    return f"{value:.3f} m" if unit == "m" else f"{value * 1e3:.1f} µm"


def closing_summary(result: SimulationResult) -> str:
    """The transcript's closing summary for trial ``transcript.shown``: every check passed or
    failed with its worst residual and tolerance, the remedies applied, what went wrong and what
    a real operator would do next (:data:`OPERATOR_ADVICE`)."""
    t = result.transcript.shown
    rows, failed = [], []
    for name, c in result.checks.items():
        if c.tolerance is None or c.passed is None:
            rows.append(f"- (reported) {name}: {_small(abs(_at(c.residual, t)), c.unit)}")
            continue
        ok = bool(_at(c.passed, t))
        rows.append(
            f"- {'pass' if ok else 'FAIL'} {name}: worst {_small(abs(_at(c.residual, t)), c.unit)}"
            f", tolerance {_small(_at(c.tolerance, t), c.unit)}"
        )
        if not ok:
            failed.append(name)
    judged = [c for c in result.checks.values() if c.tolerance is not None and c.passed is not None]
    lines = [
        "## Closing summary",
        "",
        f"Checks: {len(judged) - len(failed)} passed, {len(failed)} failed of {len(judged)}.",
        *rows,
    ]
    applied = [(n, r) for n, r in result.remedies.items() if bool(_at(r.applied, t))]
    lines += ["", "Remedies applied: " + (", ".join(
        f"{n} ({int(_at(r.rounds, t))} rounds, check "
        f"{'passed' if bool(_at(r.passed, t)) else 'still failed'} after)" for n, r in applied
    ) if applied else "none") + "."]  # fmt: skip
    if not failed:
        lines += ["", "What went wrong: nothing outside tolerance at the end."]
    else:
        lines += ["", "What went wrong, and what a real operator would do:"]
        for name in failed:
            tried = [n for n, r in applied if r.check == name]
            after = f" after {', '.join(tried)}" if tried else " (no remedy in this practice)"
            lines.append(f"- {name}: still outside tolerance{after} → {_advice(name)}.")
    return "\n".join(lines) + "\n"


def transcript_text(result: SimulationResult) -> str:
    """The learner's transcript: the numbered records, then :func:`closing_summary`."""
    return result.transcript.to_text() + "\n" + closing_summary(result)


def _trial0_files(result: SimulationResult) -> dict[str, bytes]:
    return {
        "transcript.txt": transcript_text(result).encode("utf-8"),
        "transcript.jsonl": result.transcript.to_jsonl().encode("utf-8"),
        "parallax.png": _parallax_png(result),
    }


def write_simulation(result: SimulationResult, out_dir: str | Path) -> dict[str, Path]:
    """Write one run's transcript.txt, transcript.jsonl, evaluation.yaml, evaluation.md,
    parallax.png (a vectorised result: the summary over its trials, trial 0's transcript)."""
    s = summarise_result(result)
    files = _trial0_files(result)
    files["evaluation.yaml"] = _yaml(s).encode("utf-8")
    files["evaluation.md"] = simulation_markdown(s).encode("utf-8")
    return _write_all(Path(out_dir), files)


def _write_all(out: Path, files: dict[str, bytes]) -> dict[str, Path]:
    paths = {}
    for name, data in files.items():
        atomic_write_bytes(out / name, data)
        paths[name] = out / name
    log.info("wrote %s in %s", ", ".join(sorted(files)), out)
    return paths


_OPERATOR_FIELDS: dict[str, tuple[str, Any]] = {
    "monocular_sigma_mm": ("a number ≥ 0 [mm]", float),
    "stereo_sigma_mm": ("a number ≥ 0 [mm]", float),
    "y_parallax_sigma_mm": ("a number ≥ 0 [mm]", float),
    "reading_sigma_lc": ("a number ≥ 0 [least counts]", float),
    "setting_sigma_lc": ("a number ≥ 0 [least counts]", float),
    "quantise": ("true or false", bool),
    "finish_side": ("below, above or null", str),
    "max_iterations": ("an integer 1 … 100", int),
}


def load_operator_model(value: str | Path | OperatorModel | None) -> OperatorModel | None:
    """The operator an ``--operator`` value names: None (the defaults), "zero" (no judgment,
    reading or setting error, no quantisation: ``OperatorModel().zero()``) or a YAML file of
    :class:`OperatorModel` fields (the others keep their defaults); a bad entry is one
    :class:`ConfigError` naming the file and the field."""
    if value is None or isinstance(value, OperatorModel):
        return value
    if str(value) == "zero":
        return OperatorModel().zero()

    data, source = load_yaml_mapping(value)
    fields: dict[str, Any] = {}
    for key, v in data.items():
        if key not in _OPERATOR_FIELDS:
            raise ConfigError(
                source,
                str(key),
                "a field of OperatorModel",
                key,
                did_you_mean(str(key), sorted(_OPERATOR_FIELDS)),
            )
        expected, kind = _OPERATOR_FIELDS[key]
        ok = {
            float: isinstance(v, int | float) and not isinstance(v, bool) and 0 <= v < float("inf"),
            bool: isinstance(v, bool),
            int: isinstance(v, int) and not isinstance(v, bool) and 1 <= v <= 100,
            str: v is None or v in ("below", "above"),
        }[kind]
        if not ok:
            raise ConfigError(source, str(key), expected, v)
        fields[key] = float(v) if kind is float else v
    return OperatorModel(**fields)


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
    """
    scenario = load_scenario(scenario_path)
    spec = load_instrument(instrument)
    fitted = SC1Options.from_names(spec, options)
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
    )
    out = None if output is None else Path(output)
    if trials is None:
        result = run_trials_chunk(prep, 0, None)
        summary = json_ready(summarise_result(result))
        files = {} if out is None else write_simulation(result, out)
        if progress is not None:
            progress(1)
    else:
        chunk = chunk_trials_for(memory_mb, method)
        log.info("%d trials in chunks of %d (memory budget %g MB)", trials, chunk, memory_mb)
        info = None
        with TrialStore() as store:
            for result in iter_trial_chunks(prep, trials, chunk, progress=progress):
                if info is None:  # the first chunk: trial 0's transcript and map
                    info = run_info(result, trials)
                    trial0 = _trial0_files(result) if out is not None else {}
                store.append(trial_columns(result))
            extra = {"chunks": {"trials": chunk, "count": -(-trials // chunk)}}
            summary = json_ready(summarise_columns(info, store.columns(), extra))
            files = {}
            if out is not None:
                trial0["evaluation.yaml"] = _yaml(summary).encode("utf-8")
                trial0["evaluation.md"] = simulation_markdown(summary).encode("utf-8")
                files = _write_all(out, trial0)
                store.write_npz(out / "trials.npz")
                files["trials.npz"] = out / "trials.npz"
    text = simulation_markdown(summary)
    if files:
        text += f"\nwritten: {', '.join(sorted(files))} in {out}\n"
    return SimulationOutcome(summary, text, files)
