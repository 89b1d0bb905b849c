"""The words around a step of the stage checklist: the page's names of its controls, the rows of
the setup sheet its values come from, a note where the step's number differs from the sheet's
(and why), the condition of a step taken only when a check fails; and the symbols' glossary as
the page marks them (:data:`stereoplotter.glossary.SYMBOLS`).

Plain JSON data; no markup. Control names are the page's (the handwheels, the counters table,
the steps and the sheet panel use the same ones).
"""

from __future__ import annotations

import re
from typing import Any

from stereoplotter.glossary import SYMBOLS

__all__ = [
    "CONTROL_NAMES",
    "SHEET_NAMES",
    "SHEET_ROWS",
    "SYMBOL_PATTERNS",
    "glossary",
    "step_words",
]

#: Each control (as the core names it) → the name the page shows on its wheel, counter, steps.
CONTROL_NAMES: dict[str, str] = {
    "X": "X",
    "Y": "Y",
    "Z": "Z (foot)",
    "H": "H (height scale)",
    "bx": "b_x",
    "by": "b_y",
    "bz": "b_z",
    "f_instrument": "f_пр",
    "kappa_left": "κ left",
    "kappa_right": "κ right",
    "k_alpha_left": "k_α left",
    "k_omega_left": "k_ω left",
    "k_alpha_right": "k_α right",
    "k_omega_right": "k_ω right",
    "dx_left": "dx left",
    "dy_left": "dy left",
    "dx_right": "dx right",
    "dy_right": "dy right",
    "gear": "gear (action)",
    "slip": "slip (action)",
    "connect": "connect (action)",
    "needle": "needle (action)",
}

#: A key of the setup sheet's data → the name the sheet panel shows (the control's where the
#: value is set on one).
SHEET_NAMES: dict[str, str] = {
    "f_instrument_mm": "f_пр (instrument principal distance) [mm]",
    "scale_horizontal": "M_г (horizontal scale 1:M_г)",
    "scale_vertical": "M_в (vertical scale 1:M_в: gear)",
    "scale_map": "M_map (map scale 1:M_map)",
    "n_left": "n_л (scale coefficient, left)",
    "n_right": "n_п (scale coefficient, right)",
    "b_x_mm": "b_x [mm]",
    "base_mm": "b_x, b_y, b_z [mm]",
    "L_mm": "L_л, L_п (span of marks 3–4, (6.5)) [mm]",
    "decentrations_mm": "dx, dy (decentrations from their place of zero) [mm]",
    "correction_inclinations_deg": "k_α, k_ω (photo-carrier tilts) [deg]",
    "focal_length_corrected_mm": "f′ (corrected focal length) [mm]",
    "control_heights_model_mm": "model heights of the control points [mm]",
}

#: Control → (sheet part, key path, how the value is used): where a step's value comes from.
SHEET_ROWS: dict[str, tuple[str, str, str]] = {
    "f_instrument": ("interior", "f_instrument_mm", "set f_пр to it"),
    "gear": ("interior", "scale_vertical", "gear the height counter for 1:M_в"),
    "bx": ("interior", "b_x_mm", "O_bx = MO_bx + b_x"),
    "by": ("table24", "base_mm.by", "O_by = MO_by + b_y"),
    "bz": ("table24", "base_mm.bz", "O_bz = MO_bz + b_z"),
    "Z": ("interior", "n_left", "O_Z = n_л · f_пр"),
    "dx_left": ("table24", "decentrations_mm.left.x", "MO_dx + dx"),
    "dy_left": ("table24", "decentrations_mm.left.y", "MO_dy + dy"),
    "dx_right": ("table24", "decentrations_mm.right.x", "MO_dx + dx"),
    "dy_right": ("table24", "decentrations_mm.right.y", "MO_dy + dy"),
    "k_alpha_left": ("table24", "correction_inclinations_deg.left.alpha", "tan of it"),
    "k_omega_left": ("table24", "correction_inclinations_deg.left.omega", "tan of it"),
    "k_alpha_right": ("table24", "correction_inclinations_deg.right.alpha", "tan of it"),
    "k_omega_right": ("table24", "correction_inclinations_deg.right.omega", "tan of it"),
    "connect": ("interior", "scale_map", "ratio M_г/M_map"),
}

#: A sheet row is named for a control only where the step sets that control to the sheet's
#: value, as its text says (a step to the places of zero, or one finding a place of zero by
#: looking, takes nothing from the sheet).
_MENTION: dict[str, str] = {
    "f_instrument": r"f_пр",
    "gear": r"M_в",
    "bx": r"O_bx|b_x of the sheet",
    "by": r"O_by",
    "bz": r"O_bz|O′_bz",
    "Z": r"= n_л·f_пр",
    "connect": r"coordinatograph",
    **{c: rf"\({c}\)" for c in ("dx_left", "dy_left", "dx_right", "dy_right")},
    **{c: rf"\({c}\)" for c in ("k_alpha_left", "k_omega_left", "k_alpha_right", "k_omega_right")},
}
_NO_SHEET = re.compile(r"zero place|^MO_")

_W = r"(?<![\w\u0400-\u04FF])"  # not inside a longer word (Latin or Cyrillic)
_E = r"(?![\w\u0400-\u04FF])"
#: Symbol of :data:`SYMBOLS` → the pattern (JavaScript and Python alike) the page finds it by.
SYMBOL_PATTERNS: dict[str, str] = {
    "MO": _W + r"MO(_[A-Za-z]+(,[лп])?)?" + _E,
    "O_": _W + r"O′?_[A-Za-z]+\d?(,[лп])?" + _E,
    "M_в": _W + r"M_в",
    "M_г": _W + r"M_г",
    "n_л": _W + r"n_л",
    "n_п": _W + r"n_п",
    "f_пр": _W + r"f′?_пр",
    "f′": _W + r"f′(?!_)",
    "D": _W + r"D(_п)?" + _E,
    "L-check": _W + r"L-check",
    "L′": _W + r"L′(_[лп])?",
    "L_л": _W + r"L_[лп]",
    "ΔZ": r"ΔZ",
    "Δb_z": r"Δb_z",
    "b_x": _W + r"b_x" + _E,
    "b_y": _W + r"b_y" + _E,
    "b_z": _W + r"b_z′?" + _E,
    "κ": r"κ(_[лп]|′[₁₂])?",
    "k_α": r"k_α",
    "k_ω": r"k_ω",
    "decentration": _W + r"decentrations?",
    "y-parallax": _W + r"y-parallax",
    "x-parallax": _W + r"x-parallax",
    "standard point": _W + r"standard points?",
    "least count": _W + r"least count",
    "decision": _W + r"decision D\d+",
    "(6.": r"\(6\.\d+\)",
    "C1": _W + r"C1" + _E,
    "C2": _W + r"C2" + _E,
    "C3": _W + r"C3" + _E,
    "C4": _W + r"C4" + _E,
}

_COMPARE_L = re.compile(r"compare with L_([лп]) = (-?\d+(?:\.\d+)?) mm")


def glossary() -> list[dict[str, str]]:
    """The symbols for the page: ``[{"symbol", "pattern", "en", "ru"}, …]``, longest pattern
    first (the page tries them in order)."""
    out = [
        {"symbol": k, "pattern": SYMBOL_PATTERNS[k], "en": v["en"], "ru": v["ru"]}
        for k, v in SYMBOLS.items()
    ]
    return sorted(out, key=lambda e: -len(e["symbol"]))


def _l_note(session: Any, text: str) -> str | None:
    """Where a step compares with an L that is not the sheet's: both numbers and why."""
    m = _COMPARE_L.search(text)
    if m is None:
        return None
    side, shown = m.group(1), float(m.group(2))
    photo = session.prep.sheet.photos[0 if side == "л" else 1]
    sheet_l = float(photo.mark_span_mm)
    if abs(sheet_l - shown) < 0.0005:
        return f"L_{side} = {shown:.3f} mm is the sheet's L_{side} (Table 24, (6.5))."
    return (
        f"The sheet's L_{side} is {sheet_l:.3f} mm ((6.5) with the transformed marks, for "
        f"the photos tilted as in the model); this step compares with {shown:.3f} mm = "
        f"n_{side}·(y₃ − y₄) of the measured marks, because the correction units still stand at "
        f"zero (decision D5). Use {shown:.3f} mm here; the difference "
        f"{sheet_l - shown:+.3f} mm is that of the photo tilts, not an error."
    )


def step_words(session: Any, entry: dict[str, Any], given: list[str]) -> dict[str, Any]:
    """The words of one step (an entry of :func:`~stereoplotter.trainer.panel.step_rules`):
    ``{"control_names": [...], "sheet_rows": [{"control", "part", "key", "use"}],
    "note": text | None, "condition": text | None}``; a sheet row only where the exercise's
    sheet gives that part (``given``: the parts the exercise's sheet gives)."""
    names = [CONTROL_NAMES.get(c, c) for c in entry["controls"]]
    rows = []
    text = entry["text"]
    for c in [*entry["needs"], *entry["targets"]]:
        if _NO_SHEET.search(text) or not re.search(_MENTION.get(c, "^$"), text):
            continue
        if c in SHEET_ROWS and SHEET_ROWS[c][0] in given:
            part, key, use = SHEET_ROWS[c]
            row = {"control": CONTROL_NAMES.get(c, c), "part": part, "key": key, "use": use}
            if row not in rows:
                rows.append(row)
    condition = None
    if entry["conditional"]:
        tol = float(session.prep.sheet.tolerances["mark_span_mm"])
        condition = (
            f"only when the L-check fails (|L − L′| above {tol:.4f} mm): a correction, not a "
            "step to do otherwise"
        )
    return {
        "control_names": names,
        "sheet_rows": rows,
        "note": _l_note(session, entry["text"]),
        "condition": condition,
    }
