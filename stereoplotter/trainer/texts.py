"""Readable text for what the session answers: hint lines, claim results, announced errors.

The structured data stays (the page may build tables from it); these are the lines a page shows
as they are (plain text, never markup). Units as shown: y-parallax in µm, heights in m, plan
errors in mm on the map, angles in mrad or degrees.
"""

from __future__ import annotations

import math
from typing import Any

from stereoplotter.instrument.virtual import CONTROL_INFO
from stereoplotter.trainer.step_words import CONTROL_NAMES

__all__ = ["ERROR_TERMS", "announced_row", "claim_text", "hint_lines", "measure_line"]

#: An injected error's term (before the dot) → (what it is, its unit in the text, factor from
#: the internal unit: mm, rad or relative).
ERROR_TERMS: dict[str, tuple[str, str, float]] = {
    "zero_reading": ("zero-reading error of the counter", "mm", 1.0),
    "counter_scale": ("scale error of the counter", "ppm", 1e6),
    "backlash": ("backlash of the screw", "mm", 1.0),
    "setting": ("setting error of the scale", "", 1.0),
    "coordinatograph": ("coordinatograph", "", 1.0),
}
_SETTING_UNITS = {
    "f_instrument": ("mm", 1.0),
    "bx": ("mm", 1.0),
    "by": ("mm", 1.0),
    "bz": ("mm", 1.0),
    "kappa": ("mrad", 1e3),
    "correction": ("mrad", 1e3),
    "dx": ("mm", 1.0),
    "dy": ("mm", 1.0),
}
_CG_UNITS = {
    "nonorthogonality": ("non-orthogonality of the axes", "mrad", 1e3),
    "pen_play": ("play of the pencil", "mm", 1.0),
    "sheet_placement_x": ("sheet placement error x", "mm", 1.0),
    "sheet_placement_y": ("sheet placement error y", "mm", 1.0),
}


def announced_row(name: str, value: float) -> dict[str, Any]:
    """An announced injected error as ``{"name", "value", "unit", "text"}`` (value in the
    text's unit)."""
    term, _, what = name.partition(".")
    label, unit, factor = ERROR_TERMS.get(term, (term, "", 1.0))
    if term == "setting":
        unit, factor = next(
            (u for key, u in _SETTING_UNITS.items() if what.startswith(key)), ("", 1.0)
        )
        label = f"setting error of {what}"
    elif term == "coordinatograph":
        label, unit, factor = _CG_UNITS.get(what, (what, "", 1.0))
    else:
        label = f"{label} {what}"
    shown = float(value) * factor
    return {
        "name": name,
        "value": shown,
        "unit": unit,
        "text": f"{label}: {shown:+.4g} {unit}".rstrip(),
    }


def measure_line(row: dict[str, Any]) -> str:
    """One measure as text: name, value against tolerance in a readable unit, passed or not."""
    value, tol, unit = row["value"], row["tolerance"], row["unit"]
    name = row["name"]
    if unit == "mm" and "y-parallax" in name:
        value, tol, unit = value * 1000.0, tol * 1000.0, "µm"
    mark = "passed" if row["passed"] else "NOT passed"
    if unit == "—":
        return f"{name}: {'yes' if value > 0.5 else 'no'} ({mark})"
    shown = "∞" if value is None or not math.isfinite(value) else f"{value:.4g}"
    return f"{name}: {shown} {unit} against {tol:.4g} {unit} ({mark})"


def claim_text(step: str, measures: list[dict[str, Any]]) -> str:
    """The result of a practice claim as lines of text."""
    lines = [f"stage {step} claimed"]
    lines += [f"- {measure_line(m)}" for m in measures]
    return "\n".join(lines)


def hint_lines(hint: dict[str, Any]) -> list[str]:
    """A hint as lines: its text; level 1 points to the stage's checklist rather than repeating
    it; level 2 the controls in the order the operator first uses them, by the names the page
    gives them (a control that appears only later says when); level 3 the actions applied."""
    lines = [str(hint["text"])]
    level = hint.get("level")
    if level == 1 and hint.get("steps"):
        lines.append(
            "The steps of the stage are the checklist beside this text, in order; each names "
            "its control and the sheet row its value comes from."
        )
    if hint.get("controls"):
        names = [_control_name(c) for c in hint["controls"]]
        lines.append("Controls, in order: " + ", ".join(names))
    if "applied" in hint:
        lines.append(f"The simulated operator took {hint['applied']} actions on your instrument.")
    return lines


def _control_name(control: str) -> str:
    """A control (or action kind) as the page names it, with where to find it."""
    name = CONTROL_NAMES.get(control, control)
    if control == "H":
        return f"{name} (its wheel appears once the height counter is geared)"
    if control in ("gear", "slip", "connect", "needle", "record"):
        return f"{control} (a form under 'Instrument and sheet actions')"
    if control in CONTROL_INFO:  # every control but the height scale has its wheel
        return f"{name} (wheel)"
    return name
