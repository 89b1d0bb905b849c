"""Grading a trainee's session: outcome, process, par and the percentile among simulated operators.

* **Outcome** — for every stage of the exercise,
  :func:`~stereoplotter.trainer.outcome.stage_measures` on the instrument as it stood when
  the trainee claimed the stage (the final state if never claimed), against the book's
  tolerances of the setup sheet.
* **Process** — from the action log (:func:`process_measures`): time, moves, reversals of a
  control's direction, whether every lead screw's last move came from one side, iterations (returns
  to a control after another one was turned), steps out of order (refused claims, controls the
  simulated operator does not touch in that stage), checks skipped (a stage claimed without a
  counter read in it), hints, undos, refused actions.
* **Par** — the simulated operator on the same instrument (same injected errors), the same seed
  of judgments: its outcome at the end of each stage and its process.
* **Percentile** — ``population`` simulated operators on the same instrument, each with its own
  judgment errors (trial t of :class:`~stereoplotter.procedure.operator.Noise` of the session's
  seed; trial 0 is the par), run vectorised over the trials in chunks; the percentile of a
  measure is the share of them whose value is no better (≥) than the trainee's, in %.

The overall score is the largest value/tolerance over the exercise's measures. Points: the
outcome's points less the hints' cost (:mod:`~stereoplotter.trainer.grade_tables`); passed when
every stage is claimed, the score is ≤ 1 and the points reach ``PASS_POINTS``. The grade also
carries the per-point tables and the y-parallax map (``tables``), the process per stage with
time from the stage's first action (``process_by_stage``) and the checks skipped by name
(``process.skipped_checks``).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np

from stereoplotter.instrument.virtual import SCREWS
from stereoplotter.procedure.operator import Noise
from stereoplotter.procedure.run import PreparedRun, build_run
from stereoplotter.trainer.actions import apply
from stereoplotter.trainer.acuity import acuity_note, trainee_acuity, with_acuity
from stereoplotter.trainer.exercise import Exercise
from stereoplotter.trainer.grade_tables import (
    PASS_POINTS,
    hint_cost,
    outcome_points,
    point_tables,
    stage_process,
)
from stereoplotter.trainer.operator_steps import new_instrument, stage_functions
from stereoplotter.trainer.outcome import Measure, stage_measures
from stereoplotter.trainer.session import SUBSTITUTE_STAGES, Session, check_stage, json_finite

__all__ = [
    "GRADE_FORMAT",
    "grade",
    "percentile",
    "population_measures",
    "process_measures",
]

GRADE_FORMAT = "stereoplotter-grade/1"
#: Trials per vectorised chunk of the population (peak memory grows by about 35 MB with 2500,
#: measured by ``benchmarks/bench_trainer.py``).
CHUNK = 2500


def percentile(trainee: float, population: np.ndarray) -> float:
    """Share of the population whose value is no better (≥) than the trainee's. [%]"""
    pop = np.asarray(population, float)
    return float(100.0 * np.mean(pop >= trainee))


def population_measures(
    prep: PreparedRun,
    seed: int,
    stages: tuple[str, ...],
    trials: int,
    injected: dict[str, Any],
    chunk: int = CHUNK,
    progress: Callable[[int], None] | None = None,
    unusable: tuple[int, ...] = (),
) -> dict[str, dict[str, np.ndarray]]:
    """The measures of ``stages`` for ``trials`` simulated operators on one instrument.

    Stage → measure name → its values, an array (trials,). Every trial runs the
    method from stage 1 to the last of ``stages`` (its own presets too), vectorised per chunk.
    """
    out: dict[str, list[dict[str, np.ndarray]]] = {s: [] for s in stages}
    last = stages[-1]
    for first in range(0, trials, chunk):
        n = min(chunk, trials - first)
        # a population is vectorised over its trials: only the closed-form back-end runs that
        run = build_run(
            prep,
            first,
            n,
            injected=injected,
            noise=Noise(seed, n, None, first),
            transcript=False,
            backend="closed-form",
        )
        inst = run.op.inst
        for name, fn in stage_functions(run, prep.method).items():
            fn()
            if name in out:
                measures = stage_measures(inst, prep, name, unusable)
                out[name].append({m.name: np.asarray(m.value, float) for m in measures})
            if name == last:
                break
        if progress is not None:
            progress(n)
    return {
        s: {k: np.concatenate([c[k] for c in chunks]) for k in chunks[0]}
        for s, chunks in out.items()
    }


def _sign(x: float) -> int:
    return 1 if x > 0 else -1 if x < 0 else 0


_Controls = dict[str, set[str]] | None
_Checks = dict[str, list[str]] | None


def process_measures(
    actions: list[dict[str, Any]], stage_controls: _Controls = None, stage_checks: _Checks = None
) -> dict[str, Any]:
    """Process measures of a sequence of log records (or bare actions with a ``stage``).

    The final approach of a lead screw is the side its last move finished from: the ``side`` of
    the action when given, else the direction of the move. ``stage_controls``: stage → the
    controls the simulated operator turns in it (for "out of order"); ``stage_checks``: stage →
    the names of its checks (the skipped ones are named). Moves are ``turn`` and ``set``
    actions; a ``set`` moves by the difference from the control's previous value where the log
    knows it (its own earlier turns and sets).
    """
    moves = reversals = iterations = out_of_order = hints = undos = refused = 0
    last_dir: dict[str, int] = {}
    approach: dict[str, str] = {}
    last_value: dict[str, float] = {}
    touched_last: str | None = None
    seen: set[str] = set()
    reads_in: dict[str, int] = {}
    claimed: list[str] = []
    times = []
    for rec in actions:
        action = rec.get("action", rec)
        stage = rec.get("stage")
        kind = action.get("kind")
        if rec.get("t") is not None:
            times.append(float(rec["t"]))
        if rec.get("refused") is not None:
            refused += 1
            if kind == "claim":
                out_of_order += 1
            continue
        if kind == "hint":
            hints += 1
        elif kind == "undo":
            undos += 1
        elif kind == "read" and stage is not None:
            reads_in[stage] = reads_in.get(stage, 0) + 1
        elif kind == "claim":
            claimed.append(str(action["step"]))
        elif kind in ("turn", "set"):
            control = str(action["control"])
            moves += 1
            if kind == "turn":
                step = float(action["delta"])
                last_value[control] = last_value.get(control, 0.0) + step
            else:
                value = float(action["value"])
                step = value - last_value[control] if control in last_value else 0.0
                last_value[control] = value
            d = _sign(step)
            if d and control in last_dir and last_dir[control] != d:
                reversals += 1
            if d:
                last_dir[control] = d
            if control in SCREWS and (d or action.get("side")):
                # the last stroke: from the side asked for (the screw pre-positions beyond the
                # target, PlayAxis.approach), else the direction of the move
                side = action.get("side") or ("below" if d > 0 else "above")
                approach[control] = f"from {side}"
            if control != touched_last and control in seen:
                iterations += 1
            seen.add(control)
            touched_last = control
            if stage_controls and stage in stage_controls and control not in stage_controls[stage]:
                out_of_order += 1
    return {
        "time_s": (max(times) - min(times)) if times else None,
        "moves": moves,
        "reversals": reversals,
        "final_approach_one_side": len(set(approach.values())) <= 1,
        "final_approach": approach,
        "iterations": iterations,
        "steps_out_of_order": out_of_order,
        "checks_skipped": sum(1 for s in claimed if reads_in.get(s, 0) == 0),
        "skipped_checks": _skipped(claimed, reads_in, stage_checks or {}),
        "hints": hints,
        "undos": undos,
        "refused": refused,
    }


def _skipped(
    claimed: list[str], reads_in: dict[str, int], stage_checks: dict[str, list[str]]
) -> list[str]:
    """The names of the checks of each stage claimed without a counter read in it."""
    return [
        name
        for s in claimed
        if reads_in.get(s, 0) == 0
        for name in (stage_checks.get(s) or [f"stage {s}: no counter read"])
    ]


def _measure_row(m: Measure, par: Measure | None, pop: np.ndarray | None) -> dict[str, Any]:
    value = float(np.asarray(m.value, float))
    par_value = None if par is None else float(np.asarray(par.value, float))
    row = {
        "name": m.name,
        "value": value,
        "tolerance": float(m.tolerance),
        "unit": m.unit,
        "passed": bool(value <= m.tolerance),
        "par": par_value,
        "par_passed": None if par_value is None else bool(par_value <= m.tolerance),
    }
    if pop is not None:
        row["percentile"] = percentile(value, pop)
        row["population_median"] = float(np.median(pop))
    return row


def _par_measures(session: Session) -> dict[str, list[Measure]]:
    """The par's measures at the end of each of the exercise's stages (its recorded actions
    replayed on a fresh instrument: the same state as the operator's, tested)."""
    inst = new_instrument(session.prep, session.seed)
    commanded: dict[str, float] = {}
    out = {}
    for stage in session.exercise.preset_stages + session.stages:
        for a in session.par.stage_actions(stage):
            apply(inst, a, commanded)
        if stage in session.stages:
            out[stage] = stage_measures(inst, session.prep, stage, session.exercise.unusable_points)
    return out


def _outcome(
    session: Session, par: dict[str, list[Measure]], pop: dict[str, dict[str, np.ndarray]]
) -> tuple[dict[str, Any], list[float], list[float], np.ndarray | None]:
    """Rows per stage (matched by measure name), the trainee's and the par's value/tolerance
    ratios, and the population's largest ratio per operator."""
    ex = session.exercise
    stages_out = {}
    ratios: list[float] = []
    par_ratios = [float(np.asarray(p.ratio)) for s in ex.stages for p in par[s]]
    pop_ratio = None
    for stage in ex.stages:
        par_by_name = {p.name: p for p in par[stage]}
        pop_by_name = pop.get(stage, {})
        for p in par[stage]:
            if p.name in pop_by_name:
                r = pop_by_name[p.name] / p.tolerance
                pop_ratio = r if pop_ratio is None else np.maximum(pop_ratio, r)
        inst = session.at_claim.get(stage, session.inst)
        rows = []
        for m in stage_measures(inst, session.prep, stage, ex.unusable_points):
            rows.append(_measure_row(m, par_by_name.get(m.name), pop_by_name.get(m.name)))
            ratios.append(rows[-1]["value"] / m.tolerance)
        if stage in SUBSTITUTE_STAGES:
            for n in ex.unusable_points:
                row = _substitute_row(session, n)
                rows.append(row)
                ratios.append(row["value"] / row["tolerance"])
        stages_out[stage] = {"claimed": stage in session.claimed, "measures": rows}
    return stages_out, ratios, par_ratios, pop_ratio


def grade(
    session_or_log: Session | list[dict[str, Any]],
    *,
    population: int = 10_000,
    progress: Callable[[int], None] | None = None,
    read_exercise: Callable[[dict[str, Any]], Exercise] | None = None,
) -> dict[str, Any]:
    """The grade of a session (or of a session log's records, replayed first) as a dict (JSON).

    ``population`` 0 skips the percentile; ``read_exercise`` reads a log's exercise
    (:meth:`Session.replay`).
    """
    session = (
        session_or_log
        if isinstance(session_or_log, Session)
        else Session.replay(session_or_log, read_exercise=read_exercise)
    )
    ex = session.exercise
    par = _par_measures(session)
    t0 = time.perf_counter()
    acuity = trainee_acuity(session.records)
    pop_prep = with_acuity(session.prep, acuity) if acuity else session.prep
    pop = _population(session, pop_prep, population, progress)
    pop_seconds = time.perf_counter() - t0
    stages_out, ratios, par_ratios, pop_ratio = _outcome(session, par, pop)
    score = max(ratios) if ratios else float("inf")
    controls = {
        s: {a["control"] for a in session.par.stage_actions(s) if "control" in a} for s in ex.stages
    }
    script = _par_script(session)
    checks = stage_check_names(session)
    hints = hint_cost(ex.stages, session.log)
    overall = _overall(score, stages_out, par_ratios, hints["total"])
    if pop_ratio is not None:
        overall.update(_percentile(score, pop_ratio))
    return json_finite(
        {
            "format": GRADE_FORMAT,
            "exercise": ex.name,
            "title": ex.title,
            "trainee": session.trainee,
            "seed": session.seed,
            "instrument": ex.spec.key,
            "method": ex.method,
            "mode": ex.mode,
            "errors": ex.errors,
            "stages": stages_out,
            "overall": overall,
            "process": process_measures(session.log, controls, checks),
            "par_process": process_measures(script, controls, checks),
            "process_by_stage": stage_process(
                session.log,
                ex.stages,
                lambda records, c: process_measures(records, c, checks),
                controls,
            ),
            "hints": hints,
            "tables": point_tables(session),
            "population": {
                "operators": population,
                "seconds": round(pop_seconds, 3),
                "same_instrument": True,
                "acuity": acuity_note(acuity, pop_prep),
            },
        }
    )


def _population(
    session: Session,
    pop_prep: Any,
    population: int,
    progress: Callable[[int], None] | None,
) -> dict[str, Any]:
    """The measures of ``population`` simulated operators on the session's instrument (with
    the trainee's acuity in ``pop_prep``); empty when ``population`` is 0."""
    if not population:
        return {}
    ex = session.exercise
    return population_measures(
        pop_prep,
        session.seed,
        ex.stages,
        population,
        session.inst.injected,
        progress=progress,
        unusable=ex.unusable_points,
    )


def _percentile(score: float, pop_ratio: Any) -> dict[str, float]:
    """The score's percentile among the operators [%] with its binomial standard error (of a
    share estimated from N operators) [%]."""
    pct = percentile(score, pop_ratio)
    se = 100.0 * float(np.sqrt(pct / 100.0 * (1.0 - pct / 100.0) / len(pop_ratio)))
    return {"percentile": pct, "percentile_se": se}


#: A substitute for a standard point may lie this fraction of c from it (assumed: the relative
#: orientation stays well determined while the six points keep roughly their pattern). [—]
SUBSTITUTE_FRACTION = 0.2


def _substitute_row(session: Session, n: int) -> dict[str, Any]:
    """The distance of the recorded substitute from standard point n on the left photo. [mm]"""
    il = session.prep.scene.standard[0]
    value = session.records.get(f"substitute {n}")
    tol = SUBSTITUTE_FRACTION * session.prep.scene.c_mm
    d = float(np.hypot(*(np.asarray(value, float) - il[n - 1]))) if value else float("inf")
    return {
        "name": f"substitute {n}: distance from the standard point (left photo)",
        "value": d,
        "tolerance": tol,
        "unit": "mm",
        "passed": d <= tol,
        "par": 0.0,
        "par_passed": True,
    }


def _overall(
    score: float, stages_out: dict[str, Any], par_ratios: list[float], hint_total: float
) -> dict[str, Any]:
    """Score, points after the hints' cost and the verdict (``grade_tables``' rule)."""
    earned = outcome_points(score)
    points = max(0.0, earned - hint_total)
    return {
        "score": score,
        "passed": bool(
            score <= 1.0
            and all(s["claimed"] for s in stages_out.values())
            and points >= PASS_POINTS
        ),
        "par_score": max(par_ratios) if par_ratios else None,
        "outcome_points": earned,
        "hint_cost": hint_total,
        "points": round(points, 3),
        "pass_points": PASS_POINTS,
        "within_tolerance": bool(score <= 1.0),
    }


def stage_check_names(session: Session) -> dict[str, list[str]]:
    """Stage → the names of the procedure's checks in it (the simulated operator's run)."""
    out: dict[str, list[str]] = {}
    for name, check in session.par.run.results.items():
        stage = check_stage(name)
        if stage == "5" and session.exercise.method == "conventional":
            stage = "C4"  # the conventional method's sheet checks are named "stage 5"
        if stage is not None and check.tolerance is not None:
            out.setdefault(stage, []).append(name)
    return out


def _par_script(session: Session) -> list[dict[str, Any]]:
    out = []
    for stage in session.stages:
        out.extend(session.par.stage_actions(stage))
        out.append({"kind": "claim", "step": stage, "stage": stage})
    return out
