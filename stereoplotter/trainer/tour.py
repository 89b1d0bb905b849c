"""A newcomer's tour of the instrument page: cards that introduce one part at a time, in plain
words (no book notation), for the exercises that ask for it (:data:`TOURS`).

Each card: ``{"target": an element id of the page, "title", "text", "try": what to do, "done":
a condition the page checks}``; conditions: ``{"kind": "mag", "value": 2}`` (the magnification
chosen), ``{"kind": "set", "control": "f_instrument"}`` (a control set or turned),
``{"kind": "read"}`` (a counter read), ``{"kind": "goto"}`` (the mark driven to a point),
``{"kind": "next"}`` (the Next button only).
"""

from __future__ import annotations

from typing import Any

__all__ = ["FIRST_LOOK", "TOURS", "tour_of"]

FIRST_LOOK: list[dict[str, Any]] = [
    {
        "target": "eyepieces",
        "title": "1. The two eyepieces",
        "text": "A stereoplotter shows you two photos of the same ground, taken from two places "
        "in the air: the left photo in the left eyepiece, the right photo in the right one. In "
        "the middle of each is a small measuring mark. They stay grey until the instrument is "
        "set to look at the photos (card 3).",
        "try": "Look at the two circles; then press Next.",
        "done": {"kind": "next"},
    },
    {
        "target": "mag",
        "title": "2. Magnification",
        "text": "The eyepieces magnify the photo. ×2 shows a wide field to find things in; ×6 "
        "and ×20 show detail to measure on.",
        "try": "Choose ×2 in the box beside the view selector.",
        "done": {"kind": "mag", "value": 2},
    },
    {
        "target": "wheels",
        "title": "3. Handwheels",
        "text": "Each round wheel turns one part of the instrument. Turn one with the mouse "
        "wheel or by dragging it, or type a number in the box under it and press Enter. The "
        "wheel labelled f_пр is the distance between the lens and the photo; the instrument "
        "needs it before it can show the photos.",
        "try": "Type 109.37 in the box under the wheel f_пр and press Enter.",
        "done": {"kind": "set", "control": "f_instrument"},
    },
    {
        "target": "counters",
        "title": "4. Counters",
        "text": "The counters show where each part stands, to 0.01 mm. Reading a counter writes "
        "the number into your record, as an operator writes it on the sheet.",
        "try": "Press read in the row X.",
        "done": {"kind": "read"},
    },
    {
        "target": "overview",
        "title": "5. Where the marks are",
        "text": "The overview shows both photos whole. The red circle is what you see in the "
        "eyepiece. The numbered circles are the six places where the two photos are compared "
        "later. The X and Y wheels move the marks across the photos.",
        "try": "Press the button 1 after 'go to standard point': X and Y turn to take you there.",
        "done": {"kind": "goto"},
    },
    {
        "target": "checklist",
        "title": "6. The steps of the stage",
        "text": "Here are the steps of the stage, in order. Each says which wheel it uses and "
        "where its number comes from; it is ticked when its target is met. Underlined symbols "
        "explain themselves when you hover over them or tap them.",
        "try": "Work down the list; then press Claim stage done. In this exercise you see how "
        "well you did, and Undo lets you try again.",
        "done": {"kind": "next"},
    },
    {
        "target": "hints",
        "title": "7. Help",
        "text": "Hint 1 says what the stage does, hint 2 which wheels to use. Hint 3 and Show "
        "me let the simulated operator do the stage for you; the page says what each costs "
        "before it runs.",
        "try": "Press Close; 'First steps' at the top opens the cards again.",
        "done": {"kind": "next"},
    },
]

#: Exercise name → its tour.
TOURS: dict[str, list[dict[str, Any]]] = {"e00-first-look": FIRST_LOOK}


def tour_of(exercise_name: str) -> list[dict[str, Any]]:
    """The exercise's tour (empty for an exercise without one)."""
    return [dict(card) for card in TOURS.get(exercise_name, [])]
