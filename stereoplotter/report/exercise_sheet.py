"""An exercise's own setup sheet, as the trainer page's sheet panel and ``stereoplotter exercise
sheet NAME`` show it (one home for both).

:func:`exercise_sheet` ``(exercise or session)`` is the data of the trainer page's sheet panel
(JSON). The sheet is computed for the exercise's *modified* scenario (its terrain and tilt
applied, ``io.exercise_file``) by the project's one setup-sheet computation (the session's
prepared run, ``procedure.run.prepare_pair``) and serialised by ``report.sheet`` (the one
serialiser of setup sheets); which parts are given follows
:func:`stereoplotter.trainer.panel.sheet_parts` (the setup-data method: all; the conventional
method: the camera certificate and the interior part only)::

    {"exercise": "e03-setup-stage2", "method": "setup", "instrument": "sc1",
     "given": ["certificate", "interior", "table24", "readings"], "withheld": {part: reason},
     "certificate": {"focal_length_mm": 70.0, "principal_point_mm": [0.0, 0.0],
                     "format_mm": 180.0, "fiducials_mm": {"1": [-85.0, 0.0], …},
                     "distortion": null, "note": …},
     "interior": {"f_instrument_mm": 109.375, "scale_horizontal": 12500,
                  "scale_vertical": 8000, "scale_map": 10000, "n_left": …, "n_right": …,
                  "b_x_mm": 115.206, "tolerances": {…}},
     "table24": {… report.sheet.sheet_to_dict without "readings" …} | absent,
     "readings": [{"stage": 1, "step": …, "reading": "f_пр", "value": 109.375, "unit": "mm",
                   "formula": …}, …] | absent,
     "markdown": "printable text of the given parts"}

Units as in the setup sheet: mm on the photo and the instrument, m on the ground.
"""

from __future__ import annotations

from typing import Any

from stereoplotter.procedure.run import prepare_pair
from stereoplotter.report.sheet import sheet_markdown, sheet_to_dict
from stereoplotter.trainer.panel import sheet_parts
from stereoplotter.trainer.session import Session

__all__ = ["exercise_sheet"]


def _certificate(exercise: Any) -> dict[str, Any]:
    cam = exercise.scenario.camera
    return {
        "focal_length_mm": float(cam.focal_length_mm),
        "principal_point_mm": [float(v) for v in cam.principal_point_mm],
        "format_mm": float(cam.format_mm),
        "fiducials_mm": {k: [float(v) for v in xy] for k, xy in cam.fiducials_mm.items()},
        "distortion": None,
        "note": "the scenario's camera has no distortion model (an ideal lens)",
    }


def _interior(table: dict[str, Any]) -> dict[str, Any]:
    return {
        "f_instrument_mm": table["f_instrument_mm"],
        "scale_horizontal": table["scale_horizontal"],
        "scale_vertical": table["scale_vertical"],
        "scale_map": table["scale_map"],
        "n_left": table["n_left"],
        "n_right": table["n_right"],
        "b_x_mm": (table["base_mm"] or {}).get("bx"),
        "tolerances": table["tolerances"],
    }


def _markdown(out: dict[str, Any], full: str | None) -> str:
    lines = [f"# Setup sheet — exercise {out['exercise']}", ""]
    cert = out["certificate"]
    lines += [
        "## Camera certificate",
        "",
        f"f = {cert['focal_length_mm']:.3f} mm, principal point "
        f"({cert['principal_point_mm'][0]:.3f}, {cert['principal_point_mm'][1]:.3f}) mm, "
        f"format {cert['format_mm']:.0f} mm; {cert['note']}.",
        "",
        "| fiducial | x (mm) | y (mm) |",
        "|---|---|---|",
        *(f"| {k} | {xy[0]:.3f} | {xy[1]:.3f} |" for k, xy in cert["fiducials_mm"].items()),
        "",
    ]
    if full is not None:
        return "\n".join(lines) + full
    i = out["interior"]
    lines += [
        "## Interior orientation and scales",
        "",
        f"f_пр = {i['f_instrument_mm']:.3f} mm; M_г = 1:{i['scale_horizontal']}, "
        f"M_в = 1:{i['scale_vertical']}, map 1:{i['scale_map']}; n_л = {i['n_left']:.5f}, "
        f"n_п = {i['n_right']:.5f}; b_x = {i['b_x_mm']:.3f} mm.",
        "",
    ]
    for part, why in out["withheld"].items():
        lines.append(f"- {part} withheld: {why}.")
    return "\n".join(lines) + "\n"


def exercise_sheet(exercise_or_session: Any) -> dict[str, Any]:
    """The sheet panel's data for an exercise or a session (see the module docstring)."""
    if isinstance(exercise_or_session, Session):
        exercise, sheet = exercise_or_session.exercise, exercise_or_session.prep.sheet
    else:  # the sheet alone: a session's (prepare_run's) without the operator's run
        exercise = exercise_or_session
        sheet = prepare_pair(exercise.scenario, exercise.spec, exercise.method).sheet
    table = sheet_to_dict(sheet)
    parts = sheet_parts(exercise)
    out: dict[str, Any] = {
        "exercise": exercise.name,
        "method": exercise.method,
        "instrument": exercise.spec.key,
        **parts,
        "certificate": _certificate(exercise),
        "interior": _interior(table),
    }
    full = None
    if "table24" in parts["given"]:
        out["table24"] = {k: v for k, v in table.items() if k != "readings"}
    if "readings" in parts["given"]:
        out["readings"] = table["readings"]
    if "table24" in parts["given"] and "readings" in parts["given"]:
        full = sheet_markdown(sheet)
    out["markdown"] = _markdown(out, full)
    return out
