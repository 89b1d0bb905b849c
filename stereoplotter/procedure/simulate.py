"""Run a whole procedure on a virtual instrument and write what it produced.

:func:`simulate` builds the setup sheet, the instrument (with injected errors drawn from the
seed), the operator and the scene, runs the setup-data method (stages 1–5) or the conventional
method, vectorised over ``trials`` on the closed-form back-end, and evaluates the model.
:func:`simulate_per_trial` is the test oracle: the same procedure one trial at a time.
:func:`write_simulation` writes the transcript, the evaluation and a parallax-error map.
"""

from __future__ import annotations

import io
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.error_model import ErrorModel, error_model_from_spec
from stereoplotter.instrument.spec import InstrumentSpec
from stereoplotter.instrument.virtual import Instrument
from stereoplotter.procedure.operator import Noise, Operator, OperatorModel, Scene
from stereoplotter.procedure.setup_method import Run, run_setup_method
from stereoplotter.procedure.transcript import Transcript
from stereoplotter.scenario.model import Scenario
from stereoplotter.setup_sheet import SetupSheet, compute_setup_sheet
from stereoplotter.yamlio import atomic_write_bytes

__all__ = ["METHODS", "SimulationResult", "simulate", "simulate_per_trial", "write_simulation"]

METHODS = ("setup", "conventional")


@dataclass
class SimulationResult:
    """What a simulated run returns.

    Attributes
    ----------
    method, backend : str
    seed : int
    trials : int or None
    sheet : SetupSheet
    transcript : Transcript
        Trial 0 of the run.
    checks : dict
        Every tolerance check: residual, tolerance, passed, iterations (arrays over trials).
    iterations : dict
        Stage → iterations used (arrays).
    zero_readings : dict
        The zero readings the operator determined.
    q_standard_mm, q_grid_mm : ndarray
        True residual y-parallax at the six standard points and over the working-area grid
        of the final model, shape (T, 6) / (T, g) or (6,) / (g,). [mm]
    evaluation : dict or None
        ``stereoplotter.evaluation.evaluate_model`` output, when that module is available.
    instrument : Instrument
    scene : Scene
    operator_model : OperatorModel
    """

    method: str
    backend: str
    seed: int
    trials: int | None
    sheet: SetupSheet
    transcript: Transcript
    checks: dict[str, dict[str, Any]]
    iterations: dict[str, Any]
    zero_readings: dict[str, Any]
    q_standard_mm: np.ndarray
    q_grid_mm: np.ndarray
    evaluation: dict[str, Any] | None
    instrument: Instrument
    scene: Scene
    operator_model: OperatorModel
    sheet_pose: dict[str, Any] = field(default_factory=dict)

    def summary(self) -> dict[str, Any]:
        """JSON-ready figures (trial statistics when vectorised)."""
        return _summary(self)


def _errors(spec: InstrumentSpec, errors: ErrorModel | str | None) -> ErrorModel:
    if errors is None:
        return error_model_from_spec(spec)
    if isinstance(errors, ErrorModel):
        return errors
    if errors == "zero":
        return error_model_from_spec(spec).zero()
    from stereoplotter.yamlio import load_yaml_mapping

    data, source = load_yaml_mapping(errors)
    return error_model_from_spec(spec).with_overrides(data, source)


def _prepare(scenario, spec, errors, seed, trials, backend, ideal_mechanics, operator):
    if backend == "pymunk" and trials is not None:
        raise StereoplotterError(
            "the pymunk back-end runs single procedures; use --backend closed-form for --trials"
        )
    sheet = compute_setup_sheet(scenario, spec, rng=np.random.default_rng(scenario.seed))
    model = _errors(spec, errors)
    if operator is None:
        operator = OperatorModel()
    scene = Scene.build(
        scenario, sheet.frame_origin_m, sheet.frame_rotation, spec.standard_points_c_mm
    )
    injected = model.draw(np.random.default_rng(seed), trials)
    return sheet, model, operator, scene, injected


def _run_one(
    scenario,
    spec,
    sheet,
    model,
    operator,
    scene,
    injected,
    seed,
    trials,
    trial,
    backend,
    ideal_mechanics,
    method,
    variant,
    transcript=True,
    noise_trials=None,
    relative="elements",
):
    inst = Instrument(
        spec,
        sheet.focal_length_corrected_mm,
        errors=model,
        injected=injected,
        variant=variant,
        backend=backend,
        trials=trials,
        ideal_mechanics=ideal_mechanics,
    )
    noise = Noise(seed, trials if trial is None else noise_trials, trial)
    op = Operator(inst, operator, noise, Transcript(enabled=transcript))
    run = Run(op, sheet, scene)
    if method == "setup":
        run_setup_method(run)
    elif method == "conventional":
        from stereoplotter.procedure.conventional import run_conventional_method

        run_conventional_method(run, relative)
    else:
        raise StereoplotterError(f"method: expected one of {', '.join(METHODS)}, found {method!r}")
    q_std = op.y_parallax(scene.standard_points_m, scene.images(scene.standard_points_m))
    grid = _grid(scenario)
    q_grid = op.y_parallax(grid, scene.images(grid))
    return run, q_std, q_grid


def _grid(scenario: Scenario) -> np.ndarray:
    from stereoplotter.scenario.synthetic import working_area_grid_m

    return working_area_grid_m(scenario, (9, 9))


def simulate(
    scenario: Scenario,
    spec: InstrumentSpec,
    method: str = "setup",
    errors: ErrorModel | str | None = None,
    seed: int = 0,
    trials: int | None = None,
    backend: str = "closed-form",
    *,
    operator: OperatorModel | None = None,
    ideal_mechanics: bool = False,
    variant: str = "L",
    evaluate: bool = True,
    relative: str = "elements",
) -> SimulationResult:
    """Run the setup-data or the conventional method on a virtual instrument.

    Parameters
    ----------
    scenario : Scenario
    spec : InstrumentSpec
    method : {"setup", "conventional"}
    errors : ErrorModel, "zero", path of an errors YAML, or None
        Injected instrument errors; None: the instrument's defaults; "zero": none.
    seed : int
        Seeds the injected errors and every judgment of the operator.
    trials : int, optional
        T independent instruments and operators at once (closed-form back-end).
    backend : {"closed-form", "pymunk"}
    operator : OperatorModel, optional
        Default: :class:`OperatorModel` defaults (assumed).
    ideal_mechanics : bool
        Rigid screws without backlash.
    variant : str
        Decentration linkage variant of the instrument ("L" canonical).
    evaluate : bool
        Call ``stereoplotter.evaluation.evaluate_model`` (if the module exists).
    relative : {"elements", "equations"}
        Conventional method only: relative orientation element by element with over-correction,
        or by the six measured q and (5.11).

    Returns
    -------
    SimulationResult
    """
    sheet, model, operator, scene, injected = _prepare(
        scenario, spec, errors, seed, trials, backend, ideal_mechanics, operator
    )
    run, q_std, q_grid = _run_one(
        scenario,
        spec,
        sheet,
        model,
        operator,
        scene,
        injected,
        seed,
        trials,
        None,
        backend,
        ideal_mechanics,
        method,
        variant,
        relative=relative,
    )
    evaluation = _evaluate(scenario, sheet, run) if evaluate else None
    return SimulationResult(
        method,
        backend,
        seed,
        trials,
        sheet,
        run.op.log,
        run.results,
        run.iterations,
        run.zero,
        q_std,
        q_grid,
        evaluation,
        run.op.inst,
        scene,
        operator,
        run.sheet_pose,
    )


def simulate_per_trial(
    scenario: Scenario,
    spec: InstrumentSpec,
    method: str = "setup",
    errors: ErrorModel | str | None = None,
    seed: int = 0,
    trials: int = 2,
    *,
    operator: OperatorModel | None = None,
    ideal_mechanics: bool = False,
    variant: str = "L",
    relative: str = "elements",
) -> dict[str, Any]:
    """The test oracle: trial t of ``simulate(..., trials=T)`` run alone, for t = 0 … T−1.

    Returns the checks, iterations, zero readings and q arrays stacked over the trials, in the
    layout of :class:`SimulationResult` (no evaluation, no transcript).
    """
    sheet, model, operator, scene, injected = _prepare(
        scenario, spec, errors, seed, trials, "closed-form", ideal_mechanics, operator
    )
    rows = []
    for t in range(trials):
        one = {k: (v[t] if np.ndim(v) else v) for k, v in injected.items()}
        one = {k: float(v) for k, v in one.items()}
        run, q_std, q_grid = _run_one(
            scenario,
            spec,
            sheet,
            model,
            operator,
            scene,
            one,
            seed,
            None,
            t,
            "closed-form",
            ideal_mechanics,
            method,
            variant,
            transcript=False,
            noise_trials=trials,
            relative=relative,
        )
        rows.append((run, q_std, q_grid))
    # the noise of a per-trial run must see T: rebuilt with trial index (see _run_one)
    out: dict[str, Any] = {"checks": {}, "iterations": {}, "zero_readings": {}}
    first = rows[0][0]
    for name, c in first.results.items():
        out["checks"][name] = {
            k: (None if c[k] is None else np.array([r[0].results[name][k] for r in rows]))
            for k in ("residual", "tolerance", "passed", "iterations")
        }
    for name in first.iterations:
        out["iterations"][name] = np.array([r[0].iterations[name] for r in rows])
    for name in first.zero:
        out["zero_readings"][name] = np.array([r[0].zero[name] for r in rows])
    out["q_standard_mm"] = np.array([r[1] for r in rows])
    out["q_grid_mm"] = np.array([r[2] for r in rows])
    return out


def _evaluate(scenario, sheet, run: Run) -> dict[str, Any] | None:
    try:
        from stereoplotter.evaluation import evaluate_model
    except ImportError:  # pragma: no cover - the module is written alongside
        return None
    inst = run.op.inst
    units = inst.state()["units"]
    # the metre height scale as the operator slipped it, at D = 0 [m]
    zero = (
        np.asarray(inst.read("H", exact=True))
        + np.asarray(inst.state()["carriages_mm"]["Z"]) * sheet.vertical_scale_denominator / 1000.0
    )
    corner = run.results.get("stage 5: corner 4")
    ev = evaluate_model(
        scenario,
        sheet,
        inst.setting,
        units["left"],
        units["right"],
        height_zero=zero,
        standard_points_c_mm=inst.spec.standard_points_c_mm,
        corner4_misclosure_mm=None if corner is None else corner["residual"],
    )
    return ev.to_dict()


# --- summary and files -----------------------------------------------------------------------


def _stat(v) -> Any:
    a = np.asarray(v, float)
    if a.ndim == 0 or a.size == 1:
        x = float(a.reshape(-1)[0])
        return None if math.isnan(x) else x
    return {"mean": float(np.nanmean(a)), "max": float(np.nanmax(a)), "min": float(np.nanmin(a))}


def _summary(r: SimulationResult) -> dict[str, Any]:
    checks = {}
    for name, c in r.checks.items():
        entry = {"residual": _stat(c["residual"]), "unit": c["unit"]}
        if c["tolerance"] is not None:
            entry["tolerance"] = _stat(c["tolerance"])
            p = np.asarray(c["passed"])
            entry["passed"] = bool(p.all()) if p.size == 1 else float(p.mean())
        if c["iterations"] is not None:
            entry["iterations"] = _stat(c["iterations"])
        checks[name] = entry
    q_std = np.abs(np.asarray(r.q_standard_mm))
    q_grid = np.asarray(r.q_grid_mm)
    return {
        "method": r.method,
        "backend": r.backend,
        "seed": r.seed,
        "trials": r.trials,
        "scenario": r.sheet.scenario,
        "instrument": r.sheet.instrument,
        "operator": r.operator_model.to_dict(),
        "iterations": {k: _stat(v) for k, v in r.iterations.items()},
        "checks": checks,
        "residual_y_parallax_um": {
            "standard_points_max": _stat(np.max(q_std, axis=-1) * 1e3),
            "grid_max": _stat(np.max(np.abs(q_grid), axis=-1) * 1e3),
            "grid_rms": _stat(np.sqrt(np.mean(q_grid**2, axis=-1)) * 1e3),
        },
        "evaluation": r.evaluation,
    }


def _yaml(data: Any) -> str:
    try:
        import yaml
    except ImportError:  # pragma: no cover
        return json.dumps(data, indent=2, ensure_ascii=False, default=_plain) + "\n"
    return yaml.safe_dump(
        json.loads(json.dumps(data, default=_plain)), sort_keys=False, allow_unicode=True
    )


def _plain(v: Any) -> Any:
    if isinstance(v, np.ndarray):
        return v.tolist()
    if isinstance(v, np.generic):
        return v.item()
    return str(v)


def _markdown(s: dict[str, Any]) -> str:
    lines = [
        f"# Simulated {s['method']} procedure: {s['scenario']} on {s['instrument']}",
        "",
        f"back-end {s['backend']}, seed {s['seed']}, trials {s['trials'] or 1}; operator "
        "judgment errors are assumed values.",
        "",
        "| check | residual | tolerance | passed | iterations |",
        "|---|---|---|---|---|",
    ]
    for name, c in s["checks"].items():
        label = name.replace("|", "\\|")
        lines.append(
            f"| {label} | {_md(c['residual'])} {c['unit']} | {_md(c.get('tolerance'))} | "
            f"{c.get('passed', '—')} | {_md(c.get('iterations'))} |"
        )
    q = s["residual_y_parallax_um"]
    lines += [
        "",
        f"Residual y-parallax of the built model (truth): max {_md(q['standard_points_max'])} µm "
        f"at the six standard points; over the grid max {_md(q['grid_max'])} µm, "
        f"RMS {_md(q['grid_rms'])} µm.",
        "",
        "Iterations per stage: " + ", ".join(f"{k}: {_md(v)}" for k, v in s["iterations"].items()),
        "",
    ]
    if s.get("evaluation") is None:
        lines.append("(stereoplotter.evaluation not available: no height/plan evaluation)")
        lines.append("")
    return "\n".join(lines)


def _md(v: Any) -> str:
    if v is None:
        return "—"
    if isinstance(v, dict):
        return f"{v['mean']:.4g} (max {v['max']:.4g})"
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def _figure(r: SimulationResult) -> bytes:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    grid = _grid(r.scene.scenario)
    q = np.asarray(r.q_grid_mm)
    q = q[0] if q.ndim > 1 else q
    fig, ax = plt.subplots(figsize=(6, 5))
    sc = ax.scatter(grid[:, 0], grid[:, 1], c=q * 1e3, cmap="RdBu_r", s=80)
    std = r.scene.standard_points_m
    ax.plot(std[:, 0], std[:, 1], "k+", ms=10)
    for i, p in enumerate(std):
        ax.annotate(str(i + 1), p[:2], textcoords="offset points", xytext=(4, 4))
    fig.colorbar(sc, ax=ax, label="residual y-parallax q [µm, photo]")
    ax.set_xlabel("X [m]")
    ax.set_ylabel("Y [m]")
    ax.set_title(f"{r.method} method, {r.sheet.instrument}, seed {r.seed} (trial 0)")
    ax.set_aspect("equal")
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, metadata={"Software": None})
    plt.close(fig)
    return buf.getvalue()


def write_simulation(result: SimulationResult, out_dir: str | Path) -> dict[str, Path]:
    """Write transcript.txt, transcript.jsonl, evaluation.yaml, evaluation.md, parallax.png.

    Each file is written whole or not at all; the same seed gives byte-identical files.
    """
    out = Path(out_dir)
    s = result.summary()
    plot = None
    try:
        from stereoplotter import evaluation as ev  # type: ignore[attr-defined]

        plot = getattr(ev, "plot_parallax_errors", None)
    except ImportError:
        pass
    png = _figure(result) if plot is None or result.evaluation is None else None
    if png is None:
        fig = plot(result.evaluation)
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=100, metadata={"Software": None})
        png = buf.getvalue()
    files = {
        "transcript.txt": result.transcript.to_text().encode("utf-8"),
        "transcript.jsonl": result.transcript.to_jsonl().encode("utf-8"),
        "evaluation.yaml": _yaml(s).encode("utf-8"),
        "evaluation.md": _markdown(s).encode("utf-8"),
        "parallax.png": png,
    }
    paths = {}
    for name, data in files.items():
        atomic_write_bytes(out / name, data)
        paths[name] = out / name
    return paths


def run_simulation_command(
    scenario_path: str | Path,
    instrument: str = "sc1",
    method: str = "setup",
    errors: str | None = None,
    seed: int | None = None,
    trials: int | None = None,
    backend: str = "closed-form",
    output: str | Path = "stereoplotter-simulate",
) -> tuple[str, dict[str, Any]]:
    """What ``stereoplotter simulate`` does: run, write the files, return (text, summary).

    ``seed`` defaults to the scenario's seed; ``errors`` is None (instrument defaults),
    "zero" or an errors YAML path. The text is the Markdown evaluation plus the file list; the
    summary is JSON-ready (print it for ``--json``).
    """
    from stereoplotter.instrument.spec import load_instrument
    from stereoplotter.scenario import load_scenario

    scenario = load_scenario(scenario_path)
    spec = load_instrument(instrument)
    seed = scenario.seed if seed is None else seed
    result = simulate(scenario, spec, method, errors, seed, trials, backend)
    paths = write_simulation(result, output)
    summary = json.loads(json.dumps(result.summary(), default=_plain))
    text = _markdown(result.summary()) + f"\nwritten: {', '.join(sorted(paths))} in {output}\n"
    return text, summary
