"""The parts of a grade that teach: per-point tables, the y-parallax map, the hint cost, the
process per stage.

:func:`point_tables` ``(session)`` → (JSON; on the instrument as it stood at the claim of the
exercise's last stage, else as it stands)

.. code-block:: text

    {"y_parallax": {"unit": "µm", "tolerance": 12.5, "stage": "2",
                    "rows": [{"id": "1", "value": 1.3, "usable": true, "passed": true}, …]}
                   | null,                                   # stages 2, 3, C2, C3 and later
     "heights": {"unit": "m", "tolerance": 0.46,
                 "rows": [{"id": "1", "error": -0.12, "passed": true}, …]} | null,   # 3, C3 on
     "plan": {"unit": "m", "tolerance": 3.0, "map_unit": "mm", "map_tolerance": 0.3,
              "rows": [{"id": "1", "dx": 0.4, "dy": -0.2, "error": 0.45, "fitted_error": 0.2,
                        "map_error": 0.02, "passed": true}, …]} | null,   # 4, 5, C4
     "y_parallax_map": {"unit": "µm", "shape": [9, 9],
                        "points": [{"id": "g0", "x_m": …, "y_m": …, "value": 2.1}, …]} | null}

Errors are built − true: heights in m on the ground (read on the slipped metre scale), plan in
m on the ground (``dx``, ``dy``, ``error``: the built model before the sheet is fitted;
``fitted_error``: after the best rotation and shift, as the outcome measure) and on the map
(``map_error``, fitted, mm), y-parallax in µm at photo scale.

:func:`hint_cost` — the documented rule (``docs/trainer.md``, "Hints cost points"): the
exercise is worth :data:`FULL_POINTS`, shared equally among its stages; in each stage the
highest hint level asked costs :data:`HINT_COST` of that stage's share (levels do not add up;
asking the same level again costs nothing more). The outcome gives the points:
:data:`FULL_POINTS` while every measure is within its tolerance (score ≤ 1), falling linearly to
0 at twice the tolerance (score 2). The exercise is passed when every stage is claimed, the
score is ≤ 1 and the points after the hint cost are at least :data:`PASS_POINTS`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from stereoplotter.trainer.outcome import (
    PARALLAX_STAGES,
    model_evaluation,
    rigid_residuals_m,
    standard_q,
)

__all__ = [
    "FULL_POINTS",
    "HINT_COST",
    "PASS_POINTS",
    "hint_cost",
    "outcome_points",
    "point_tables",
    "stage_process",
]

FULL_POINTS = 100.0
#: Share of a stage's points a hint level costs (the highest level asked in the stage counts):
#: 1 what to do, 2 which control, 3 show me (the simulated operator does the stage). [—]
HINT_COST = {1: 0.10, 2: 0.25, 3: 0.75}
#: Points needed to pass (and every measure within its tolerance). [points]
PASS_POINTS = 60.0
_HEIGHTS = ("3", "C3", "4", "5", "C4")
_PLAN = ("4", "5", "C4")


def outcome_points(score: float) -> float:
    """Points of the outcome: full at score ≤ 1, linear to 0 at score 2. [points]"""
    if not np.isfinite(score):
        return 0.0
    return float(FULL_POINTS * np.clip(2.0 - score, 0.0, 1.0))


def hint_cost(stages: tuple[str, ...], log: list[dict[str, Any]]) -> dict[str, Any]:
    """The hint cost of a session log: per stage the highest level asked and its cost. [points]

    Returns ``{"total": points, "stages": {stage: {"level": n | None, "cost": points}}}``."""
    share = FULL_POINTS / max(len(stages), 1)
    highest: dict[str, int] = {}
    for rec in log:
        action = rec.get("action", rec)
        if action.get("kind") != "hint" or rec.get("refused") is not None:
            continue
        stage = rec.get("stage")
        level = int(action["level"])
        if stage is not None and level > highest.get(stage, 0):
            highest[stage] = level
    out = {
        s: {
            "level": highest.get(s),
            "cost": round(share * HINT_COST[highest[s]], 3) if s in highest else 0.0,
        }
        for s in stages
    }
    return {"total": round(sum(v["cost"] for v in out.values()), 3), "stages": out}


def _last_stage_instrument(session: Any) -> tuple[Any, str]:
    last = session.stages[-1]
    return session.at_claim.get(last, session.inst), last


def _parallax_table(session: Any, inst: Any, last: str) -> dict[str, Any]:
    q = np.asarray(standard_q(inst, session.prep), float).reshape(-1) * 1000.0
    tq = float(session.prep.sheet.tolerances["residual_y_parallax_mm"]) * 1000.0
    unusable = session.exercise.unusable_points
    return {
        "unit": "µm",
        "tolerance": tq,
        "stage": last,
        "rows": [
            {
                "id": str(n),
                "value": float(q[n - 1]),
                "usable": n not in unusable,
                "passed": bool(abs(q[n - 1]) <= tq) or n in unusable,
            }
            for n in range(1, 7)
        ],
    }


def _map(grid: Any) -> dict[str, Any]:
    return {
        "unit": "µm",
        "shape": [9, 9],
        "points": [
            {"id": pid, "x_m": float(g[0]), "y_m": float(g[1]), "value": float(v) * 1000.0}
            for pid, g, v in zip(
                grid.ids, np.asarray(grid.ground_m), np.asarray(grid.y_parallax_mm), strict=True
            )
        ],
    }


def _heights_table(control: Any, th: float) -> dict[str, Any]:
    return {
        "unit": "m",
        "tolerance": th,
        "rows": [
            {"id": pid, "error": float(e), "passed": bool(abs(float(e)) <= th)}
            for pid, e in zip(control.ids, np.asarray(control.height_error_m), strict=True)
        ],
    }


def _plan_table(control: Any, m_map: float, tmap: float) -> dict[str, Any]:
    rows = []
    fitted = np.asarray(rigid_residuals_m(control), float).reshape(-1)
    for pid, dx, dy, e in zip(
        control.ids,
        np.asarray(control.x_error_m),
        np.asarray(control.y_error_m),
        fitted,
        strict=True,
    ):
        rows.append(
            {
                "id": pid,
                "dx": float(dx),
                "dy": float(dy),
                "error": float(np.hypot(dx, dy)),
                "fitted_error": float(e),
                "map_error": float(e) * 1000.0 / m_map,
                "passed": bool(float(e) * 1000.0 / m_map <= tmap),
            }
        )
    return {
        "unit": "m",
        "tolerance": tmap * m_map / 1000.0,
        "map_unit": "mm",
        "map_tolerance": tmap,
        "rows": rows,
    }


def point_tables(session: Any) -> dict[str, Any]:
    """The per-point tables and the y-parallax map (see the module docstring)."""
    inst, last = _last_stage_instrument(session)
    prep = session.prep
    tol = prep.sheet.tolerances
    out: dict[str, Any] = {"y_parallax": None, "heights": None, "plan": None}
    out["y_parallax_map"] = None
    if "f_instrument" not in session.commanded or last not in (*PARALLAX_STAGES, *_HEIGHTS):
        return out
    out["y_parallax"] = _parallax_table(session, inst, last)
    ev = model_evaluation(inst, prep)
    out["y_parallax_map"] = _map(ev.grid)
    if last in _HEIGHTS:
        out["heights"] = _heights_table(ev.control, float(tol["control_height_m"]))
    if last in _PLAN:
        m_map = ev.map_scale_denominator or prep.sheet.horizontal_scale_denominator
        out["plan"] = _plan_table(ev.control, float(m_map), float(tol["corner_mm"]))
    return out


def stage_process(
    log: list[dict[str, Any]], stages: tuple[str, ...], measures: Any, controls: dict[str, set[str]]
) -> dict[str, Any]:
    """Process measures per stage (``measures``: :func:`~stereoplotter.trainer.grading.
    process_measures`), time counted from the stage's first action to its last (its claim)."""
    out = {}
    for stage in stages:
        records = [r for r in log if r.get("stage") == stage]
        out[stage] = measures(records, controls) if records else None
    return out
