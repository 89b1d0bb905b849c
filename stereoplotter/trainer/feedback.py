"""What a stage's check says to a trainee: which check fails, measured against allowed, and the
most likely wrong setting, before or after a claim (practice only).

:func:`stage_feedback` ``(session, stage, instrument)`` →

.. code-block:: text

    {"stage": "1", "passed": false,
     "failed": [{"name": "scale coefficient |L − L′| (true)", "value": 2.011,
                 "tolerance": 0.0177, "unit": "mm"}],
     "settings": [{"control": "f_пр", "value": 109.30, "target": 109.3748, "unit": "mm",
                   "least_counts": 7.5, "mistake": "f′ (the camera's) in place of f_пр"}],
     "lines": ["…", …]}

The likely wrong setting: each control the stage's steps set from the sheet (the checklist's
``target`` steps, :func:`~stereoplotter.trainer.panel.step_rules`) compared with the simulated
operator's value, the furthest off in least counts first (a value the L-check's corrections
change may differ by three times the operator's own correction); where the setup sheet checker
knows a mistake that gives the trainee's value (:func:`stereoplotter.setup.sheet_check.check_sheet`:
f′ in place of f_пр, M_г in place of M_в, a wrong sign, mm versus m …) it is named. A stage
whose settings are found by looking (the y-parallax) names the standard point where the true
|q| is largest and the element the operator clears it with there.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from stereoplotter.instrument.virtual import CONTROL_INFO
from stereoplotter.setup.sheet_check import check_sheet
from stereoplotter.trainer.actions import control_value
from stereoplotter.trainer.outcome import stage_measures, standard_q
from stereoplotter.trainer.panel import least_count
from stereoplotter.trainer.step_words import CONTROL_NAMES

__all__ = ["SHEET_KEYS", "stage_feedback"]

#: Control → the key of the setup sheet checker whose value it is set to directly.
SHEET_KEYS = {"f_instrument": "f_instrument_mm", "gear": "scale_vertical"}


def _f(v: Any) -> float:
    return float(np.asarray(v, float).reshape(-1)[0])


def _settings(session: Any, stage: str, inst: Any) -> list[dict[str, Any]]:
    final = {
        a["control"]: float(a["value"])
        for a in session.par.stage_actions(stage)
        if a["kind"] == "set" and isinstance(a.get("value"), (int, float))
    }
    targets: dict[str, float] = {}
    allowance: dict[str, float] = {}  # a value the L-check's corrections change: their size × 3
    for entry in session.step_rules(stage):
        if entry["rule"] == "target":
            for c, v in entry["targets"].items():
                targets.setdefault(c, v)
                if c in entry["corrected"]:
                    allowance[c] = 3.0 * abs(final.get(c, v) - v)
    out = []
    for control, target in targets.items():
        if control == "gear":
            value = None if inst.height_gear is None else float(inst.height_gear)
            lc, unit = 1.0, ""
        else:
            value = control_value(inst, control, session.commanded)
            lc = least_count(inst.spec, control)
            unit = CONTROL_INFO[control].unit if control in CONTROL_INFO else "mm"
        if value is None or not np.isfinite(value) or control == "gear":
            counts = 0.0 if value == target else float("inf")
        else:
            counts = abs(float(value) - target) / lc
        if counts <= max(1.0, allowance.get(control, 0.0) / lc) + 1e-9:
            continue
        row = {
            "control": CONTROL_NAMES.get(control, control),
            "value": None if value is None else float(value),
            "target": float(target),
            "unit": unit,
            "least_counts": counts if np.isfinite(counts) else None,
            "mistake": "",
        }
        key = SHEET_KEYS.get(control)
        if key is not None and value is not None:
            check = check_sheet(session.prep.sheet, inst.spec, {key: float(value)})
            item = next((i for i in check.items if i.expected.key == key), None)
            if item is not None and item.mistake:
                row["mistake"] = item.mistake
        out.append(row)
    return sorted(out, key=lambda r: -(r["least_counts"] or np.inf))


def _parallax_hint(session: Any, stage: str, inst: Any) -> str | None:
    q = np.asarray(standard_q(inst, session.prep), float).reshape(-1) * 1000.0
    usable = [n for n in range(1, 7) if n not in session.exercise.unusable_points]
    worst = max(usable, key=lambda n: abs(q[n - 1]) if np.isfinite(q[n - 1]) else np.inf)
    element = next(
        (e["needs"][0] for e in session.step_rules(stage) if e.get("clears_point") == worst),
        None,
    )
    text = f"the y-parallax is largest at standard point {worst}: q = {q[worst - 1]:+.1f} µm"
    if element is not None:
        text += f"; the operator clears it there with {CONTROL_NAMES.get(element, element)}"
    return text


def stage_feedback(session: Any, stage: str, inst: Any) -> dict[str, Any]:
    """The stage's checks on ``inst`` and the likely wrong setting (see the module docstring)."""
    failed = []
    for m in stage_measures(inst, session.prep, stage, session.exercise.unusable_points):
        value = _f(m.value)
        if not value <= m.tolerance:
            failed.append(
                {"name": m.name, "value": value, "tolerance": float(m.tolerance), "unit": m.unit}
            )
    settings = _settings(session, stage, inst) if failed else []
    lines = []
    for m in failed:
        if m["unit"] == "—":
            lines.append(f"Check failed: {m['name']}.")
        else:
            scale, unit = (1000.0, "µm") if "y-parallax" in m["name"] else (1.0, m["unit"])
            lines.append(
                f"Check failed: {m['name']}: measured {m['value'] * scale:.4g} {unit}, "
                f"allowed {m['tolerance'] * scale:.4g} {unit}."
            )
    for s in settings[:5]:
        shown = "not set" if s["value"] is None else f"{s['value']:.5g} {s['unit']}".rstrip()
        line = (
            f"Likely wrong setting: {s['control']} is {shown}; the stage needs "
            f"{s['target']:.5g} {s['unit']}".rstrip()
        )
        if s["least_counts"] is not None:
            line += f" ({s['least_counts']:.0f} least counts off)"
        if s["mistake"]:
            line += f"; the sheet's likely mistake: {s['mistake']}"
        lines.append(line + ".")
    if failed and not settings:
        names = " ".join(m["name"] for m in failed)
        if "y-parallax" in names:
            lines.append(_parallax_hint(session, stage, inst) + ".")
        elif "L − L′" in names:
            lines.append(
                "The settings from the sheet are in place: the L-check itself fails. Measure L′ "
                "on marks 3 and 4 and correct Z by ΔZ (6.9) and b_z by Δb_z (6.10)."
            )
    return {"stage": stage, "passed": not failed, "failed": failed, "settings": settings,
            "lines": lines}
