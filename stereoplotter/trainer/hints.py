"""Hints to a trainee: level 1 what to do, level 2 which control (the session lists the
controls the simulated operator turns in the stage), level 3 show me (the session lets the
simulated operator do the stage). Every level also lists the steps of the simulated operator's
transcript in the stage, each once, in the order first taken.

The texts follow the stages of ``docs/procedure.md`` (the book's §27 for the setup-data method,
§26 for the conventional method).
"""

from __future__ import annotations

__all__ = ["WHAT_TO_DO", "hint_text"]

#: Level 1: what the stage does, in the book's order.
WHAT_TO_DO = {
    "1": "Stage 1: set f_пр, put the photos on their fiducials, determine the zero readings "
    "(MO) of the counters and gear the height counter for M_в.",
    "2": "Stage 2: set the decentrations, κ and the correction knobs k_α, k_ω from the sheet, "
    "fit the knobs on the fiducials, then clear the y-parallax at the six standard points.",
    "3": "Stage 3: set the base b_x = B/M, check the scale on the control points and the "
    "heights, slip the metre height scale and level the model if the heights disagree.",
    "4": "Stage 4: connect the coordinatograph at M_г/M_map and orient the map sheet on the "
    "control points.",
    "5": "Stage 5: check the sheet's fourth corner and the check points.",
    "C1": "C1: interior orientation: f_пр, photos on their fiducials, zero the correction "
    "elements.",
    "C2": "C2: relative orientation element by element: clear the y-parallax at the six "
    "standard points, over-correcting at point 5 or 6.",
    "C3": "C3: absolute orientation: scale on two control points with b_x, level with the "
    "tilt elements on the control heights.",
    "C4": "C4: connect the coordinatograph and put the sheet on the control points.",
}

_LEVEL = {1: "what to do", 2: "which control", 3: "show me"}


def hint_text(method: str, stage: str, level: int) -> str:
    """The hint's text for a stage at a level (1–3)."""
    text = WHAT_TO_DO.get(stage, f"stage {stage}")
    if level == 1:
        return text
    if level == 2:
        return f"{text} The controls the operator turns, in order, are listed."
    return f"{text} The simulated operator does the stage on your instrument ({_LEVEL[3]})."
