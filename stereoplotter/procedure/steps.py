"""Procedure steps both methods share: the interior settings, judging the six standard points,
fusing on a control point and reading its counters, reading and slipping the height scale,
scaling by two plan control points, and the fixed-order sums of the levelling fit.

The setup-data method (:mod:`~stereoplotter.procedure.setup_method`) and the conventional method
(:mod:`~stereoplotter.procedure.conventional`) compose these; neither imports the other. Every
step takes the :class:`~stereoplotter.procedure.run.Run`, the noise key of its judgments (the
keyed streams of :mod:`stereoplotter.random_streams`: the same key gives the same draw in either
method) and the ``active`` trials (None: all). What a step writes in the transcript is the
caller's wording where the methods word it differently.

Units: mm on the instrument, m on the ground (the height scale reads m).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

import numpy as np
from numpy.typing import NDArray

from stereoplotter.instrument.virtual import HEIGHT_SCALE, NOMINAL_ZERO, ScaleName, Side
from stereoplotter.procedure.arrays import Active, Floats, Mask, Value
from stereoplotter.procedure.control_names import CASSETTE, DECENTRATION, KNOB, Tilt
from stereoplotter.procedure.noise_key import KeyLike, NoiseKey, as_key, pointing
from stereoplotter.procedure.run import Run
from stereoplotter.procedure.step_values import (
    Act,
    DriveStep,
    Line,
    Note,
    SetStep,
    Step,
    perform_all,
)

__all__ = [
    "REPEAT_POINTINGS",
    "control_point_m",
    "fixed_order_sum",
    "fuse_and_read",
    "height_mean",
    "interior_orientation",
    "interior_steps",
    "judge_standard_points",
    "scale_by_two_points",
    "scale_pair",
    "slip_height_scale_on_mean",
    "zero_base_y",
]

#: Remedy R1 (stage 1, "otherwise the setting is repeated"): pointings per fiducial mark,
#: averaged, when the L-check loop has ended failed (a choice: 4 halves the pointing σ).
REPEAT_POINTINGS = 4


def interior_steps(stage: str) -> tuple[Step, ...]:
    """The interior settings common to stage 1 and the conventional method's C1, as steps of
    ``stage``: the height-counter gear M_в, f_пр, the cassettes parallel to the axes, the
    correction mechanisms and the decentrations at their zero places (OCR L3755–3759)."""
    key = NoiseKey(stage)
    out: list[Step] = [
        Act("gear the height counter to 1:M_в", key, _gear_height_counter),
        SetStep(
            "f_instrument",
            lambda run: run.target("f_пр"),
            key.at("f"),
            Line(stage, "set the instrument principal distance f_пр", "item 1"),
        ),
    ]
    sides: tuple[Side, ...] = ("left", "right")
    tilts: tuple[Tilt, ...] = ("alpha", "omega")
    for side in sides:
        cassette = Line(
            stage, f"turn the {side} cassette: fiducial lines parallel to the axes", "stage 1"
        )
        out.append(DriveStep(CASSETTE[side], _at_zero, cassette))
        out += [DriveStep(KNOB[tilt, side], _at_zero) for tilt in tilts]
        for d in ("dx", "dy"):
            control = DECENTRATION[d, side]
            out.append(SetStep(control, _nominal_zero(control), key.at(control)))
    out.append(
        Note(Line(stage, "correction mechanisms and decentrations to their zero places", "stage 1"))
    )
    return tuple(out)


def _gear_height_counter(run: Run, key: NoiseKey) -> None:
    run.op.inst.gear_height_counter(run.sheet.vertical_scale_denominator)


def _at_zero(run: Run) -> float:
    return 0.0


def _nominal_zero(control: str) -> Callable[[Run], float]:
    """The scale reading of ``control``'s place of zero."""
    return lambda run: NOMINAL_ZERO[control]


def interior_orientation(run: Run, stage: str) -> None:
    """The interior settings of :func:`interior_steps`, done."""
    perform_all(run, interior_steps(stage))


#: MO_by found by turning b_y (stage 1, C1).
_MO_BY = Line("1", "MO_by: right mark on the right cassette centre (by turning b_y)", "stage 1")


def zero_base_y(run: Run, stage: str, key: NoiseKey | None = None) -> NDArray[np.float64]:
    """MO_by (stage 1 and C1): the left mark on the left cassette centre, then b_y turned until
    the right mark is on the right cassette centre's line (σ_mono across it); recorded in
    ``run.zero``. Returns MO_by. [mm]"""
    op = run.op
    key = NoiseKey(stage).at("MOby") if key is None else key
    op.mark_on("left", np.zeros(2), key.at("left"))
    right_map = op.unit_map("right")  # kinematics.rod_from_photo with the unit's cos κ kept
    car = {c: op.physical(c) for c in ("X", "Y", "Z")}
    e = op.noise.draw(key.by("mono").at("right"), op.model.monocular_sigma_mm)
    eta = right_map.rod_from_photo(np.stack([0.0 * e, e], axis=-1))[..., 1]
    f_instrument: Value = op.inst.setting.f_instrument_mm
    n_r = (car["Z"] + op.physical("bz")) / f_instrument
    op.drive("by", car["Y"] - n_r * eta)
    mo_by = op.read("by", key)
    run.zero["MO_by"] = mo_by
    _MO_BY.in_stage(stage).log(op, "by", reading=mo_by, judgment_error=e)
    return mo_by


def control_point_m(run: Run, pid: str) -> NDArray[np.float64]:
    """The scenario's control point ``pid`` in the local frame (X, Y, Z). [m]"""
    return np.asarray(run.scene.point(pid).local_m, float)


def scale_pair(run: Run, ties: str = "first") -> tuple[str, str]:
    """The two plan control points of the sheet farthest apart (the scale is taken there);
    the sheet's height control points where it has no plan control.

    ``ties``: which of equally distant pairs (the two diagonals of a rectangle of control) —
    "first" in the sheet's order of the points (the setup-data method), "last" the
    lexicographically largest ids (the conventional method; kept so that its figures do not
    change). The book names no rule.
    """
    ids = run.sheet.similarity_point_ids or tuple(h["id"] for h in run.sheet.control_heights)
    pts = {i: control_point_m(run, i) for i in ids}
    pairs = [(a, b) for k, a in enumerate(ids) for b in ids[k + 1 :]]
    if ties == "last":
        best = max((float(np.hypot(*(pts[a][:2] - pts[b][:2]))), a, b) for a, b in pairs)
        return best[1], best[2]
    return max(pairs, key=lambda ab: float(np.hypot(*(pts[ab[0]][:2] - pts[ab[1]][:2]))))


def fuse_and_read(
    run: Run, p: Value, key: KeyLike, active: Active, read: tuple[ScaleName, ...]
) -> dict[str, Floats]:
    """Fuse the floating mark on the ground point ``p`` [m] and read the counters ``read``."""
    op = run.op
    key = as_key(key)
    img = run.scene.images(np.asarray(p, float)[None, :])
    op.fuse_mark(p, (img[0][0], img[1][0]), key, active)
    return {c: op.read(c, key.at(c)) for c in read}


def height_mean(run: Run, p: Value, key: KeyLike, active: Active, pointings: int) -> Floats:
    """The height scale read after ``pointings`` fusings on ``p``, averaged (the first fusing
    has the single reading's noise key, so ``pointings=1`` is the book's single reading). [m]"""
    total: Value = None
    for j in range(pointings):
        k = as_key(key).at(*pointing(j))
        read = fuse_and_read(run, p, k, active, (HEIGHT_SCALE,))[HEIGHT_SCALE]
        total = read if total is None else total + read
    return total / pointings  # type: ignore[no-any-return]


def slip_height_scale_on_mean(
    run: Run, p0: Value, key: KeyLike, active: Active, pointings: int
) -> None:
    """Fuse on the control point ``p0`` [m] ``pointings`` times and slip the height scale so
    that the mean reading shows its known height; trials not ``active`` keep their scale."""
    op = run.op
    seen0 = height_mean(run, p0, key, active, pointings)
    exact = op.v(op.inst.read(HEIGHT_SCALE, exact=True))
    act = op.all() if active is None else active
    op.inst.slip_height_scale(np.where(act, exact + (p0[2] - seen0), exact))


def scale_by_two_points(
    run: Run,
    a: tuple[str, Floats],
    b: tuple[str, Floats],
    distance_mm: float,
    key: KeyLike,
    active: Mask,
) -> tuple[Floats, Floats, Floats]:
    """Scaling: fuse on the ground points ``a``, ``b`` [m], compare the X, Y counters' distance
    with ``distance_mm`` (the model distance the scale asks for) and turn b_x in proportion,
    O′_bx = MO_bx + b_x·ratio. Returns (b_x read before, b_x set, the counters' distance). [mm]
    """
    op = run.op
    key = as_key(key)
    ra = fuse_and_read(run, a[1], key.at("scale", a[0]), active, ("X", "Y"))
    rb = fuse_and_read(run, b[1], key.at("scale", b[0]), active, ("X", "Y"))
    d_model = np.hypot(ra["X"] - rb["X"], ra["Y"] - rb["Y"])
    with np.errstate(divide="ignore", invalid="ignore"):  # trials at rest may read d = 0
        ratio = np.where(active, distance_mm / d_model, 1.0)
    bx = op.read("bx", key.at("bx"))
    new = NOMINAL_ZERO["bx"] + (bx - NOMINAL_ZERO["bx"]) * ratio  # MO_bx + b_x·ratio
    op.set("bx", new, key.at("setbx"), active)
    return bx, new, d_model


def judge_standard_points(
    run: Run,
    stage: str,
    key: KeyLike,
    active: Active = None,
    *,
    text: str = "residual y-parallax at standard point {i}",
    remedy: str = "",
    iteration: int = 1,
) -> list[NDArray[np.float64]]:
    """Fuse on each of the six standard points and judge its y-parallax (σ_q), logging each
    against ¼ mark (``text`` with ``{i}`` the point's number). [mm], one array per point.

    A detection (``procedure.eye``, (eye 2)): where the y-parallax is seen over ¼ mark and the
    operator remeasures (``OperatorModel.remeasure``), the point is fused and judged again
    (key ``…/again``, a new pointing and judgement) and the second look is what counts: a
    point fails only when both looks see it over."""
    op = run.op
    key = as_key(key)
    tol = run.sheet.tolerances["residual_y_parallax_mm"]
    pts = run.scene.standard_points_m
    imgs = run.scene.standard  # the standard points' true images, computed once
    act = op.all() if active is None else op.v(active).astype(bool)
    line = Line(stage, text, "≤ ¼ mark")
    seen = []
    for i in range(6):
        img = (imgs[0][i], imgs[1][i])
        q, q_true = op.fuse(pts[i], img, key.at(i + 1), active)
        again = act & (np.abs(q) > tol) if op.model.remeasure else None
        if again is not None and np.any(again):
            q2, _ = op.fuse(pts[i], img, key.at(i + 1, "again"), again)
            q = np.where(again, q2, q)
        seen.append(q)
        line.log(
            op, "", {"i": i + 1},
            residual=q, true=q_true, judgment_error=q - q_true, tolerance=tol,
            passed=np.abs(q) <= tol, iteration=iteration, remedy=remedy,
            when=active if remedy else None,
        )  # fmt: skip
    return seen


def fixed_order_sum(values: Iterable[Value]) -> Floats:
    """A sum over points in a fixed order (a vectorised run and a per-trial loop agree)."""
    total: Value = None
    for v in values:
        total = v if total is None else total + v
    return total  # type: ignore[no-any-return]
