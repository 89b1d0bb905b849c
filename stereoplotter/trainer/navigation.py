"""Getting to a point as a trainee's handwheels would: the X and Y settings that put the left
mark on a standard point (or on any place of the left photo), the Z where the model height is
given.

:func:`goto_actions` ``(session, point=3)`` or ``(session, left_xy=[x, y])`` → the ``set``
actions of X and Y (and Z) the page sends one by one, logged as the trainee's own. The settings
come from the instrument as it stands (its orientation, its counter errors): the left mark is
put on the place monocularly, as the operator's ``mark_on`` does without judgment error, Z left
where it is (a standard point's model height is not on the sheet: the trainee fuses with Z) —
except where the setup sheet gives the control point's model height, which is a setting O_Z the
sheet prints (stage 3 of the setup-data method). Units: mm on the photo and the counters.
"""

from __future__ import annotations

import copy
from typing import Any

import numpy as np

from stereoplotter.errors import TrainerError
from stereoplotter.procedure.operator import Noise, Operator, OperatorModel
from stereoplotter.procedure.transcript import Transcript
from stereoplotter.trainer.actions import control_value

__all__ = ["DECIMALS", "goto_actions", "point_xy"]

#: Settings are sent to the µm (finer than any counter's least count). [decimals of a mm]
DECIMALS = 3


def point_xy(session: Any, point: str) -> np.ndarray:
    """The left-photo image of a standard point ("1"…"6") or of a control or check point (its
    id). [mm]"""
    scene = session.prep.scene
    if point.isdigit() and 1 <= int(point) <= 6:
        return np.asarray(scene.standard[0][int(point) - 1], float)
    for p in scene.points:
        if p.id == point:
            return np.asarray(scene.images(np.array([p.local_m]))[0][0], float)
    raise TrainerError(f"go to: no point {point!r} (standard points 1–6 or a control point id)")


def goto_actions(
    session: Any, point: str | None = None, left_xy: Any = None
) -> list[dict[str, Any]]:
    """The settings of X, Y that put the left mark on ``point`` or on ``left_xy`` of the left
    photo (see the module docstring)."""
    if "f_instrument" not in session.commanded:
        raise TrainerError("go to: set f_пр first (nothing is projected before it)")
    if point is not None:
        xy = point_xy(session, str(point))
    else:
        xy = np.asarray(left_xy, float).reshape(-1)[:2]
        half = float(session.prep.scene.camera.format_mm) / 2.0
        if xy.size != 2 or not np.all(np.isfinite(xy)) or np.any(np.abs(xy) > half):
            raise TrainerError(f"go to: expected x, y on the left photo within ±{half:g} mm")
    inst = session.inst
    memo = {id(inst.spec): inst.spec, id(inst.errors): inst.errors}
    twin = copy.deepcopy(inst, memo)
    op = Operator(
        twin, OperatorModel().zero(), Noise(0, twin.trials, None, 0), Transcript(enabled=False)
    )
    op.mark_on("left", xy, "goto", free="XY")
    return [
        {"kind": "set", "control": axis, "value": round(control_value(twin, axis, {}), DECIMALS)}
        for axis in ("X", "Y")
    ]
