r"""The conventional method: relative orientation by the six standard points (ch. 5, §22).

The procedure on a virtual instrument (:func:`run_conventional_method`, stages C1–C4,
``docs/procedure.md``, "The conventional method"); its pure equations — the first-order
y-parallax equation (5.10), its solution (5.11) for the six standard points of Fig. 39 and the
over-correction factor — are :mod:`~stereoplotter.procedure.relative_equations`:

* C1 interior orientation as in stage 1 of the setup-data method, without computed data;
* C2 relative orientation at the six standard points, element by element with over-correction
  (``relative="elements"``) or by the six measured q and (5.11) (``relative="equations"``);
* C3 absolute orientation by control points: scale with b_x (on the plotted plan control, or on
  two points' ground distance with ``sheet_on="corners"``), levelling by a common tilt;
* C4 the sheet on the coordinatograph, oriented on its plotted plan control points (the book's
  conventional method, ``sheet_on="control"``, default) or on the setup sheet's corners
  (stage 4 of the setup-data method, ``sheet_on="corners"``), and the checks of stage 5
  (:mod:`~stereoplotter.procedure.conventional_sheet`).

The mapping between the book's dependent elements α′₁, α′₂, ω′₂, κ′₁, κ′₂ and the instrument's
controls is found numerically (:func:`calibrate`), never by hand.

Reference
---------
.. [1] Kushtin I. F. & Lyskov G. A., *Фотограмметрия снимка и стереоскопических моделей*,
   Moscow: Nedra, 1984, ch. 5, §22, Eqs. (5.10)–(5.11), Fig. 39 (OCR L2928–3010); ch. 6, §26
   (stage 1, stage 3 H/3000, stages 4–5, OCR L3753–3826).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import cast

import numpy as np
from numpy.typing import NDArray

from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.virtual import (
    HEIGHT_SCALE,
    NOMINAL_ZERO,
    CassetteName,
    KnobName,
    control_kind,
)
from stereoplotter.procedure.arrays import Active, Floats, Mask, Value, max_abs_last
from stereoplotter.procedure.compaction import compacted
from stereoplotter.procedure.conventional_calibration import (
    ELEMENTS,
    Calibration,
    calibrate,
    control_sensitivity,
)
from stereoplotter.procedure.conventional_sheet import (
    SHEET_OPTIONS,
    c4_sheet,
    plotted_control,
    scale_on_plotted_control,
)
from stereoplotter.procedure.noise_key import KeyLike, NoiseKey, as_key
from stereoplotter.procedure.operator import DrivenControl, Operator, Scene, solve_1d
from stereoplotter.procedure.relative_equations import (
    overcorrection_factor,
    relative_orientation_from_standard_points,
)
from stereoplotter.procedure.run import Run
from stereoplotter.procedure.step_values import (
    KNOB_AT_STOP,
    Act,
    Line,
    SetStep,
    Step,
    perform_all,
    turn_common_tilt,
)
from stereoplotter.procedure.steps import (
    REPEAT_POINTINGS,
    control_point_m,
    fixed_order_sum,
    fuse_and_read,
    height_mean,
    interior_steps,
    judge_standard_points,
    scale_by_two_points,
    scale_pair,
    slip_height_scale_on_mean,
    zero_base_y,
)
from stereoplotter.setup.sheet import SetupSheet

__all__ = [
    "C1_STEPS",
    "ELEMENTS",
    "RELATIVE_OPTIONS",
    "SHEET_OPTIONS",
    "Calibration",
    "c4_sheet",
    "calibrate",
    "control_sensitivity",
    "conventional_steps",
    "run_conventional_method",
]

#: A way of relative orientation (:func:`c2_relative_by_elements`,
#: :func:`c2_relative_by_equations`): its iterations and the worst |q| seen last, per trial.
Relative = Callable[..., tuple[NDArray[np.int_], Floats]]

#: The two ways of relative orientation offered (``procedure.md``, the conventional method).
RELATIVE_OPTIONS = ("elements", "equations")

#: Unit of a control's line in the transcript of a common tilt (the cassettes' turns: none).
_TRANSFER_UNIT = {"screw": "mm", "knob": "tan"}


def _transfer_unit(control: str) -> str:
    """The unit a common tilt's record of ``control`` shows (:data:`_TRANSFER_UNIT`)."""
    return _TRANSFER_UNIT.get(control_kind(control) or "", "—")


#: C2's common tilt at a knob's stop, per control turned.
_TRANSFER_LINE = Line(
    "C2",
    "a knob of axis {axis} at its stop: common tilt Δ{axis} = {phi_mrad:+.4f} mrad centres "
    "the pair; turn {control}",
    "common tilt (q-neutral)",
    condition=KNOB_AT_STOP,
)
#: C2's stopping rule after a pass's six looks.
_C2_STOP = Line("C2", "pass {pass}: RMS of the six looks {rms_um:.1f} µm — {what}", "stopping rule")
#: C2 (a): a standard point's y-parallax cleared with the control of its element.
_CLEAR_ELEMENT = Line(
    "C2", "standard point {point}: clear the y-parallax with {control} ({element})", "(5.10)"
)
#: … with ω′₂, over-corrected by ½(f′²/c² − 1).
_CLEAR_OVERCORRECTED = Line(
    "C2",
    "standard point {point}: clear the y-parallax with {control} ({element}) and over-correct "
    "by {over:+.4f} of the turn",
    "(5.10), ½(f²/c² − 1)",
)
#: C2 (b): a control turned by the element (5.11) gives.
_TURN_BY_511 = Line(
    "C2", "{element} = {mrad:+.4f} mrad (5.11): turn {control} by −m·{element}", "(5.11)"
)
#: C3: the height scale slipped on the first levelling point.
_C3_SLIP = Line("C3", "fuse on {id}{times}, slip the height scale to H = {height:.2f} m", "stage 3")
#: C3: a control height read against its known height.
_C3_HEIGHT = Line("C3", "control point {id}: fuse, read the height{times}", "H/3000")
#: C3: a levelling point's height error against the first.
_C3_LEVEL_POINT = Line(
    "C3", "level: control point {id}, height error against point {first}", "H/3000"
)
#: C3 (``sheet_on="corners"``): the scale on two points' ground distance.
_C3_SCALE = Line(
    "C3",
    "scale: fuse on {a} and {b}, model distance against {d:.3f} mm; turn b_x in proportion",
    "scale by b_x",
)
#: C3's levelling turn of a control by its rate × the common tilt φ.
_LEVEL_LINE = Line(
    "C3", "common tilt Δ{axis} = {phi_mrad:+.4f} mrad: turn {control}", "levelling (assumption)"
)


# --------------------------------------------------------------------------------------------
# The procedure
# --------------------------------------------------------------------------------------------

_SIDE = {"left": "л", "right": "п"}
#: The identities of the conventional stages' draws (each act's own below its stage).
C1, C3 = NoiseKey("C1"), NoiseKey("C3")
_BOOK = {"alpha1": "α′₁", "alpha2": "α′₂", "omega2": "ω′₂", "kappa1": "κ′₁", "kappa2": "κ′₂"}


#: How the conventional operator's judgment at a standard point reads in the transcript.
_SIX_Q = "standard point {i}: fuse, judge the y-parallax"


def _worst(values: Sequence[Value]) -> NDArray[np.float64]:
    return max_abs_last(np.asarray(np.stack(values, axis=-1), float))


def _rms(values: Sequence[Value]) -> NDArray[np.float64]:
    rms: Floats = np.sqrt(np.mean(np.square(np.stack(values, axis=-1)), axis=-1))
    return rms


#: C2 stopping rule: a pass whose RMS of the six looks is above this fraction of the previous
#: pass's RMS has stopped decreasing (``procedure.md``, "When C2 stops"). Error-free passes
#: shrink the RMS by ≈ 0.1 each (pair60/pair80, both ways of C2), so ½ never stops a converging
#: orientation; at the operator's judgment floor the ratio of two passes is ≈ 1 ± 0.4.
DECREASE_RATIO = 0.5


#: The conventional loops (C2 passes, C3 iterations) are bounded by this multiple of the
#: operator's ``max_iterations``: without setup data the orientation starts from the knobs'
#: zero places, and a knob at its stop costs passes (mountain60 error-free: C2 needs 8 (by
#: elements) / 10 (by (5.11)) passes and C3 7 iterations; pair60/pair80 ≤ 7 and ≤ 4).
BOUND_FACTOR = 2


def _bound(op: Operator) -> int:
    """The bound of a conventional loop (:data:`BOUND_FACTOR` × ``max_iterations``)."""
    return BOUND_FACTOR * op.model.max_iterations


def _c2_stop(
    run: Run, stage: str, it: int, seen: Sequence[Value], prev_rms: Value, active: Mask
) -> tuple[Floats, Mask]:
    """The operator's judgment after the six looks of pass ``it``: go on while the residual
    y-parallax still decreases (RMS of the six looks ≤ :data:`DECREASE_RATIO` × the previous
    pass's), stop when it no longer does — further passes would chase the judgment error or the
    mechanism's own approximation. Bounded (:func:`_bound`); logged. Returns the RMS and the
    trials that stop now."""
    op = run.op
    rms = _rms(seen)
    if prev_rms is None:
        done = np.zeros(np.shape(rms), bool)
        ratio = op.v(np.nan)
    else:
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = rms / prev_rms
        done = ratio > DECREASE_RATIO  # nan (no comparable previous pass): go on
    bound = it == _bound(op)
    r0, q0 = float(np.ravel(ratio)[0]), float(np.ravel(rms)[0]) * 1e3
    if prev_rms is None:
        what = "first pass: orient again"
    elif not np.isfinite(r0):
        what = "after a common tilt: orient again"
    elif bool(np.ravel(done)[0]):
        what = f"ratio {r0:.2f} > {DECREASE_RATIO}: no longer decreasing, stop"
    else:
        what = f"ratio {r0:.2f} ≤ {DECREASE_RATIO}: still decreasing"
    if bound and not bool(np.ravel(done)[0]):
        what += f"; bound of {it} passes reached, stop"
    _C2_STOP.in_stage(stage).log(
        op, "", {"pass": it, "rms_um": q0, "what": what}, residual=rms, iteration=it
    )
    return rms, done & active


def _transfer_common_tilt(run: Run, cal: Calibration, active: Mask, stage: str, it: int) -> Mask:
    """A correction knob at its stop: move the model by a common tilt
    (:class:`Calibration` ``common_alpha`` / ``common_omega``, q-neutral to first order) that
    centres the pair of knobs of that axis, so the relative orientation has room again.

    The relative elements of the basis system (ω′₁ = 0, b_z′ = 0 until C3) can exceed one knob's
    range although each photo's own tilt is inside it: mountain60 needs ω′₂ ≈ ω₂ − ω₁ = 5.1° and
    α′₂ ≈ α₂ − ν = −4.0° (ν = 1.1° the base inclination) against the ±2.94° stops.
    Returns the trials moved (their next pass is not compared with this one).
    """
    op = run.op
    hi = 0.98 * float(np.tan(op.inst.spec.tilt_max))
    moved = np.zeros(np.shape(active), bool)
    if stage != "C2":  # in C3 the knobs hold the levelling: a common tilt would undo it
        return moved
    axes: tuple[tuple[str, dict[str, float], tuple[KnobName, KnobName]], ...] = (
        ("α", cal.common_alpha, ("k_alpha_left", "k_alpha_right")),
        ("ω", cal.common_omega, ("k_omega_left", "k_omega_right")),
    )
    for name, combo, pair in axes:
        now = [op.physical(c) for c in pair]
        near = active & ((np.abs(now[0]) >= 0.999 * hi) | (np.abs(now[1]) >= 0.999 * hi))
        if not np.any(near):
            continue
        moved = moved | near
        key = NoiseKey(stage).at(it, f"transfer{name}")
        phi = np.where(near, -(now[0] + now[1]) / (combo[pair[0]] + combo[pair[1]]), 0.0)
        fields = {"axis": name, "phi_mrad": float(np.ravel(phi)[0]) * 1e3}
        turn_common_tilt(
            run, combo, phi, key, near, _TRANSFER_LINE, fields=fields,
            turn=_turner(op), unit_of=_transfer_unit,
            iteration=it,
        )  # fmt: skip
    return moved


def _c1_left_zero(run: Run, key: NoiseKey) -> None:
    """MO_X, MO_Y: the left mark on the left cassette centre (units at zero), read."""
    op = run.op
    e = op.mark_on("left", np.zeros(2), key)
    run.zero["MO_X"] = op.read("X", key.at("X"))
    run.zero["MO_Y"] = op.read("Y", key.at("Y"))
    _C1_MO_X.log(op, "X", reading=run.zero["MO_X"], judgment_error=e[..., 0])
    _C1_MO_Y.log(op, "Y", reading=run.zero["MO_Y"], judgment_error=e[..., 1])


_C1_MO_X = Line("C1", "left mark on the left cassette centre → MO_X", "decision D6")
_C1_MO_Y = Line("C1", "… and MO_Y", "decision D6")


def _c1_base_y(run: Run, key: NoiseKey) -> None:
    """MO_by found as in stage 1, then b_y of the sheet set from it."""
    op = run.op
    mo_by = zero_base_y(run, "C1", key.at("MOby"))
    by = mo_by + run.sheet.base_mm[1]
    op.set("by", by, key.at("by"))
    _C1_BY.log(op, "by", reading=by)


_C1_BY = Line("C1", "base carriage: O_by = MO_by + b_y", "stage 1")

#: C1: interior orientation as in stage 1, without computed setup data. f_пр, M_в (the
#: height-counter gear) and b_x, b_y are those of the setup sheet (one instrument and scenario
#: for the comparison); cassettes parallel (κ = 0), correction knobs and decentrations at their
#: zero places, b_z′ = 0 (decision: the conventional operator does not know the exterior
#: orientation; the levelling in C3 finds b_z′), D = n_л·f_пр, MO_b_y by the right mark on the
#: right cassette centre as in stage 1, MO_X, MO_Y with the left mark on the left cassette
#: centre (units at zero).
C1_STEPS: tuple[Step, ...] = (
    *interior_steps("C1"),
    SetStep(
        "bx",
        lambda run: NOMINAL_ZERO["bx"] + run.sheet.base_mm[0],
        C1.at("bx"),
        Line("C1", "base carriage: b_x of the sheet", "stage 1"),
    ),
    SetStep(
        "bz",
        lambda run: NOMINAL_ZERO["bz"],
        C1.at("bz"),
        Line("C1", "b_z′ = 0 (found by the levelling, C3)", "assumption"),
    ),
    SetStep(
        "Z",
        lambda run: NOMINAL_ZERO["Z"] + run.sheet.n_left * run.sheet.f_instrument_mm,
        C1.at("Z"),
        Line("C1", "lower the carriage to D = n_л·f_пр", "(6.3)"),
    ),
    Act("MO_by, then b_y", C1, _c1_base_y),
    Act("MO_X, MO_Y", C1.at("MO"), _c1_left_zero),
)


def c1_interior(run: Run) -> None:
    """C1: :data:`C1_STEPS`."""
    perform_all(run, C1_STEPS)


def _turn(op: Operator, control: DrivenControl, target: Value, active: Mask) -> None:
    """Turn a knob or cassette while looking, no further than its stop (2 % short of the
    tilt limit, 1 % of the κ range): a trial that needed more is flagged in ``op.stopped``."""
    spec = op.inst.spec
    if control_kind(control) == "cassette":
        lo, hi = spec.kappa_range
        lo, hi = lo + 0.01 * (hi - lo), hi - 0.01 * (hi - lo)
    else:
        hi = 0.98 * float(np.tan(spec.tilt_max))
        lo = -hi
    target = op.v(target)
    beyond = (target < lo) | (target > hi)
    if np.any(beyond & active):
        op.stopped[control] = op.stopped.get(control, np.zeros_like(beyond)) | (beyond & active)
    op.drive(control, np.clip(target, lo, hi), active)


def _turner(op: Operator) -> Callable[[str, Floats, Mask], None]:
    """:func:`_turn` on ``op``: a common tilt's turn of a knob or cassette, no further than
    its stop."""
    return lambda control, target, on: _turn(op, cast(DrivenControl, control), target, on)


#: The classic sequence (``instruments.md`` §6.1): point index, control, book element.
_SEQUENCE: tuple[tuple[int, CassetteName | KnobName, str], ...] = (
    (0, "kappa_right", "kappa2"),
    (1, "kappa_left", "kappa1"),
    (3, "k_alpha_left", "alpha1"),
    (2, "k_alpha_right", "alpha2"),
    (4, "k_omega_right", "omega2"),
)


def c2_relative_by_elements(
    run: Run, cal: Calibration | None = None, stage: str = "C2", key0: KeyLike = "C2"
) -> tuple[NDArray[np.int_], Floats]:
    """C2 (a): element by element — point 1 → κ_п, 2 → κ_л, 4 → α_л, 3 → α_п, 5 → ω_п with the
    over-correction ½(f′²/c² − 1); repeat while the residual y-parallax of the six looks still
    decreases (:func:`_c2_stop`, bounded); a knob at its stop hands its tilt to a common tilt
    (:func:`_transfer_common_tilt`, when ``cal`` is given). The ¼-mark check is the caller's.

    Returns the iterations and the worst |q| seen at the last check, arrays over the trials.
    """

    op, sheet = run.op, run.sheet
    over = float(overcorrection_factor(sheet.focal_length_corrected_mm, run.scene.c_mm))
    active = op.all()
    its = np.zeros(np.shape(active), int)
    worst = op.v(np.nan)
    prev_rms = None
    for it in range(1, _bound(op) + 1):
        its = np.where(active, it, its)
        with compacted(run, active) as cut:  # the trials still orienting only
            on = cut.active
            ahead = None if prev_rms is None else cut.take(prev_rms)
            seen, rms, done = _c2_pass(cut.run, stage, as_key(key0), it, on, ahead, over)
            going = on & ~done
            moved = np.zeros(np.shape(on), bool)
            if cal is not None and np.any(going):
                moved = _transfer_common_tilt(cut.run, cal, going, stage, it)
        worst = cut.put(worst, _worst(seen))
        prev_rms = cut.put_all(op.v(np.nan), rms) if prev_rms is None else cut.put(prev_rms, rms)
        active = active & ~cut.put(np.zeros(np.shape(active), bool), done)
        prev_rms = np.where(cut.put(np.zeros(np.shape(active), bool), moved), np.nan, prev_rms)
        if not np.any(active):
            break
    return its, worst


def _c2_pass(
    run: Run, stage: str, key0: NoiseKey, it: int, active: Mask, prev_rms: Value, over: float
) -> tuple[list[Floats], Floats, Mask]:
    """Pass ``it`` of C2 (a) on ``active``: the five points cleared element by element, then the
    six looks and the stopping rule. Returns the six q seen, their RMS and the trials that stop
    (:func:`_c2_stop`)."""
    op = run.op
    tol = run.sheet.tolerances["residual_y_parallax_mm"]
    pts = run.scene.standard_points_m
    imgs = run.scene.standard  # the standard points' true images, computed once
    for idx, control, element in _SEQUENCE:
        key = key0.at("a", it, idx + 1)
        img = (imgs[0][idx], imgs[1][idx])
        q_seen, q_true = op.fuse(pts[idx], img, key, active)
        target = op.noise.draw(key.at("clear").by("q"), op.model.y_parallax_sigma_mm)
        before = op.physical(control)
        clear = solve_1d(op.q_turning(control, img), before, target, 4, 1e-6)
        line = _CLEAR_ELEMENT
        if element == "omega2":
            clear = before + (1.0 + over) * (clear - before)
            line = _CLEAR_OVERCORRECTED
        _turn(op, control, clear, active)
        line.in_stage(stage).log(
            op, control,
            {"point": idx + 1, "control": control, "element": _BOOK[element], "over": over},
            before=before, after=op.physical(control), judgment_error=target, residual=q_seen,
            true=q_true, tolerance=tol, passed=np.abs(q_seen) <= tol, iteration=it,
        )  # fmt: skip
    seen = judge_standard_points(
        run, stage, key0.at("a", it, "check"), active, iteration=it, text=_SIX_Q
    )
    rms, done = _c2_stop(run, stage, it, seen, prev_rms, active)
    return seen, rms, done


def c2_relative_by_equations(
    run: Run,
    cal: Calibration,
    stage: str = "C2",
    key0: KeyLike = "C2",
    passes: int | None = None,
) -> tuple[NDArray[np.int_], Floats]:
    """C2 (b): measure the six q, solve (5.11), turn the five controls by the result through the
    numerical mapping; repeat while the residual still decreases (:func:`_c2_stop`, bounded); a
    knob at its stop hands its tilt to a common tilt (:func:`_transfer_common_tilt`).

    ``passes``: exactly this many measurements, no stopping rule (the fixed passes of the
    (5.54) Monte Carlo, ``verification.relative_orientation_mc``).

    Returns the iterations and the worst |q| seen at the last measurement, arrays over the trials.
    """
    op, sheet = run.op, run.sheet
    bound = _bound(op) if passes is None else int(passes)
    imgs = run.scene.standard
    x11, x12 = imgs[0][0, 0], imgs[0][1, 0]
    x21, x22 = imgs[1][0, 0], imgs[1][1, 0]
    active = op.all()
    its = np.zeros(np.shape(active), int)
    worst = op.v(np.nan)
    prev_rms: Value = None
    for it in range(1, bound + 1):
        its = np.where(active, it, its)
        seen = judge_standard_points(
            run, stage, as_key(key0).at("b", it), active, iteration=it, text=_SIX_Q
        )
        worst = np.where(active, _worst(seen), worst)
        if passes is None:
            rms, done = _c2_stop(run, stage, it, seen, prev_rms, active)
            prev_rms = rms if prev_rms is None else np.where(active, rms, prev_rms)
            active = active & ~done
        if not np.any(active) or it == bound:
            break
        el = relative_orientation_from_standard_points(
            np.stack(seen, axis=-1),
            x11,
            x12,
            x21,
            x22,
            run.scene.c_mm,
            sheet.focal_length_corrected_mm,
        )
        for element, control in ELEMENTS.items():
            before = op.physical(control)
            _turn(op, control, before - cal.mapping[element] * el[element], active)
            fields = {
                "element": _BOOK[element],
                "mrad": float(np.ravel(el[element])[0]) * 1e3,
                "control": control,
            }
            _TURN_BY_511.in_stage(stage).log(
                op, control, fields, before=before, after=op.physical(control), iteration=it
            )
        moved = _transfer_common_tilt(run, cal, active, stage, it)
        prev_rms = np.where(moved, np.nan, prev_rms)
    return its, worst


def _height_points(run: Run, ids: Sequence[str]) -> list[tuple[str, NDArray[np.float64]]]:
    return [(i, control_point_m(run, i)) for i in ids]


def levelling_points(scene: Scene, sheet: SetupSheet) -> tuple[str, ...]:
    """The height control points of the ``sheet`` nearest (in plan) to the ``scene``'s standard
    points 3, 4, 5, 6, distinct."""
    rows = [(h["id"], np.asarray(scene.point(h["id"]).local_m, float))
            for h in sheet.control_heights]
    out: list[str] = []
    for std in scene.standard_points_m[2:6]:
        free = [(float(np.hypot(*(p[:2] - std[:2]))), i) for i, p in rows if i not in out]
        if free:
            out.append(min(free)[1])
    return tuple(out)


def _pointings(run: Run) -> int:
    """Fusings per height reading in C3: the setup method's ``REPEAT_POINTINGS`` with the
    operator's practice (remedy CR1), one with the book's."""
    return REPEAT_POINTINGS if getattr(run, "remedial", False) else 1


#: Remedy names of the conventional method (operator practice), as recorded in ``run.remedies``.
CR1 = "CR1 C3: read the control heights as the mean of several fusings"
CR2 = "CR2 C3: refine the relative orientation only where q fails, then check the heights again"


def _slip_and_read_heights(
    run: Run,
    rows: Sequence[tuple[str, Floats]],
    heights: Sequence[tuple[str, Floats]],
    key: NoiseKey,
    active: Active,
    pointings: int,
    remedy: str = "",
) -> list[Value]:
    """Fuse on the first levelling point, slip the height scale there (on the mean of
    ``pointings`` readings where ``pointings`` > 1), then read every other control height (the
    mean of ``pointings``) and log it against H/3000. Trials not ``active`` keep their scale.

    Returns the errors read − truth of the other control points. [m]
    """
    op = run.op
    tol = run.sheet.tolerances["control_height_m"]
    pid0, p0 = rows[0]
    if pointings == 1:
        fuse_and_read(run, p0, key.at("slip", pid0), active, ())
        op.inst.slip_height_scale(p0[2])
    else:
        slip_height_scale_on_mean(run, p0, key.at("slip", pid0), active, pointings)
    times = f" ({pointings} times, mean)" if pointings > 1 else ""
    _C3_SLIP.log(
        op, HEIGHT_SCALE, {"id": pid0, "times": times, "height": p0[2]},
        reading=p0[2], remedy=remedy, when=active,
    )  # fmt: skip
    errs = []
    for pid, p in heights:
        if pid == pid0:
            continue
        read = height_mean(run, p, key.at("h", pid), active, pointings)
        errs.append(read - p[2])
        _C3_HEIGHT.log(
            op, HEIGHT_SCALE, {"id": pid, "times": times},
            reading=read, residual=read - p[2], tolerance=tol, passed=np.abs(read - p[2]) <= tol,
            remedy=remedy, when=active,
        )  # fmt: skip
    return errs


def _level(
    run: Run,
    cal: Calibration,
    rows: Sequence[tuple[str, Floats]],
    key: NoiseKey,
    active: Mask,
    pointings: int,
    it: int,
    remedy: str = "",
) -> list[Value]:
    """Read the levelling points' heights (each the mean of ``pointings`` fusings), log them
    against the first, fit offset + common tilts φ_α, φ_ω (``cal.level_weights``) and turn the
    common tilts by −φ for the ``active`` trials. Returns the heights against the first. [m]"""
    op = run.op
    tol = run.sheet.tolerances["control_height_m"]
    when = active if remedy else None  # the book's loop logs every iteration as before
    errs = [height_mean(run, p, key.at("level", pid), active, pointings) - p[2] for pid, p in rows]
    resid = [e - errs[0] for e in errs]
    for (pid, _), r, e in zip(rows, resid, errs, strict=True):
        _C3_LEVEL_POINT.log(
            op, HEIGHT_SCALE, {"id": pid, "first": rows[0][0]},
            reading=e, residual=r, tolerance=tol, passed=np.abs(r) <= tol, iteration=it,
            remedy=remedy, when=when,
        )  # fmt: skip
    w = cal.level_weights
    phi_a = -fixed_order_sum(w[1, i] * e for i, e in enumerate(errs))
    phi_o = -fixed_order_sum(w[2, i] * e for i, e in enumerate(errs))
    for name, phi, combo in (("α", phi_a, cal.common_alpha), ("ω", phi_o, cal.common_omega)):
        fields = {"axis": name, "phi_mrad": float(np.ravel(phi)[0]) * 1e3}
        turn_common_tilt(
            run, combo, phi, key.at(name), active, _LEVEL_LINE, fields=fields,
            turn=_turner(op), unit_of=_transfer_unit,
            iteration=it, remedy=remedy, when=when,
        )  # fmt: skip
    return resid


# long: the book's items of absolute orientation (scale, levelling, repeated relative orientation,
# final levelling) in their order, one bounded loop; split, the loop state would pass through each.
def _scale_on_two_points(
    run: Run, a: tuple[str, Floats], b: tuple[str, Floats], d_true: float, active: Mask, it: int
) -> None:
    """C3's scale with ``sheet_on="corners"``: the two plan control points farthest apart,
    their counter distance against the ground distance/M_г, b_x in proportion. [mm]"""
    bx, new, d_model = scale_by_two_points(run, a, b, d_true, C3.at(it), active)
    _C3_SCALE.log(
        run.op, "bx", {"a": a[0], "b": b[0], "d": d_true},
        before=bx, after=new, reading=new, residual=d_model - d_true, iteration=it,
    )  # fmt: skip


def c3_absolute(
    run: Run,
    cal: Calibration,
    level_ids: tuple[str, ...],
    relative_fn: Relative | None = None,
    sheet_on: str = "control",
) -> None:
    """C3: absolute orientation by control points, iterated until the levelling points agree in
    height within H/3000 with the first of them (where the height scale is slipped); then slip
    the height scale there and check all control heights, and the six standard points again.
    The levelling of the last iteration is always made (the least-squares plane on the four
    heights, read with σ_p), with no relative orientation after it: the model is levelled last,
    as (5.54)/(5.55) assume (before, a model inside H/3000 was accepted unlevelled).

    Each iteration: (1) scale — fuse on the two plan control points farthest apart, compare the
    model distance from the X, Y counters with the ground distance/M_г, turn b_x in proportion;
    (2) level — fuse on the four control points nearest standard points 3–6, read the heights,
    fit offset + common tilts φ_α, φ_ω (:class:`Calibration` ``level_design``) and turn the
    knobs of both photos, the cassettes and b_z′ by −φ (assumption: the common tilt of
    ``instruments.md`` §6.1); (3) clear the y-parallax the common tilt leaves (the relative
    orientation of C2 again, bounded): on this instrument the common tilt is q-neutral only to
    a few per cent.
    """
    # Long (119 lines of code): one bounded loop whose masks (active, its, ro_its, worst) are
    # updated together per iteration, then the slip and the checks on the same state. Kept whole
    # so the vectorised masks stay in one place; a split is left for the next redesign step.
    op, sheet = run.op, run.sheet
    tol = sheet.tolerances["control_height_m"]
    tol_q = sheet.tolerances["residual_y_parallax_mm"]
    mg = sheet.horizontal_scale_denominator
    a_id, b_id = scale_pair(run, ties="last")
    (_, pa), (_, pb) = _height_points(run, (a_id, b_id))
    d_true = float(np.hypot(*(pa[:2] - pb[:2]))) * 1000.0 / mg
    rows = _height_points(run, level_ids)
    active = op.all()
    its = np.zeros(np.shape(active), int)
    ro_its = np.zeros(np.shape(active), int)
    worst = op.v(np.nan)
    plotted = plotted_control(run) if sheet_on == "control" else None
    for it in range(1, _bound(op) + 1):
        its = np.where(active, it, its)
        if plotted is not None:
            scale_on_plotted_control(run, plotted, C3.at(it), active, it)
        else:
            _scale_on_two_points(run, (a_id, pa), (b_id, pb), d_true, active, it)
        resid = _level(run, cal, rows, C3.at(it), active, 1, it)
        worst = np.where(active, _worst(resid), worst)
        # every trial still iterating levels on these heights (the least-squares plane of the
        # four points, as (5.54)/(5.55) assume); those inside H/3000 (or at the bound) stop after
        # it without a further relative orientation, so the model is always levelled last
        going = active & ~(worst <= tol) & (it < _bound(op))
        active = going
        if not np.any(active):
            break
        if relative_fn is not None:
            r_its, _ = _masked(run, active, relative_fn, cal, C3.at(it, "ro"))
            ro_its = ro_its + np.where(active, r_its, 0)
    run.record_stage("C3", its)
    run.record_stage("C3/relative", ro_its)
    run.check("C3: levelling points (against the first)", worst, tol, unit="m", iterations=its)
    heights = _height_points(run, [h["id"] for h in sheet.control_heights])
    if not run.remedial:  # the book: single readings, nothing after a failed check
        errs = _slip_and_read_heights(run, rows, heights, C3, None, 1)
        run.check("C3: control heights", _worst(errs) if errs else op.v(0.0), tol, unit="m")
        seen = judge_standard_points(run, "C3", C3.at("std"), text=_SIX_Q)
        run.check("C3: residual y-parallax (6 points)", _worst(seen), tol_q)
        return
    _c3_operator_checks(run, cal, rows, heights, relative_fn, _pointings(run))


def _c3_operator_checks(
    run: Run,
    cal: Calibration,
    rows: Sequence[tuple[str, Floats]],
    heights: Sequence[tuple[str, Floats]],
    relative_fn: Relative | None,
    pointings: int,
) -> None:
    """The end of C3 with the operator's practice. The control heights are first read once, as
    the book does; where one misses H/3000 the operator slips and reads them all again, each the
    mean of ``pointings`` fusings (CR1: one reading has σ_p·H/b = 0.19 m at pair60, 0.39 m at
    pair80). Then q at the six standard points; where it exceeds ¼ mark, one bounded refinement
    of the relative orientation (the C2 loop, its own bound), a levelling on the levelling points
    (averaged readings) and a final check of the control heights (averaged) (CR2)."""
    op = run.op
    tol = run.sheet.tolerances["control_height_m"]
    tol_q = run.sheet.tolerances["residual_y_parallax_mm"]
    name_h, name_q = "C3: control heights", "C3: residual y-parallax (6 points)"
    errs = _slip_and_read_heights(run, rows, heights, C3, None, 1)
    h_worst = _worst(errs) if errs else op.v(0.0)
    h_failed = h_worst > tol
    if errs and np.any(h_failed):
        with compacted(run, h_failed) as cut:  # CR1 on the trials that failed only
            again = _slip_and_read_heights(
                cut.run, rows, heights, C3.at("CR1"), cut.active, pointings, CR1
            )
        h_worst = cut.put(h_worst, _worst(again))
    seen = judge_standard_points(run, "C3", C3.at("std"), text=_SIX_Q)
    q_worst = _worst(seen)
    q_failed = q_worst > tol_q
    rounds = np.zeros(np.shape(q_failed), int)
    if relative_fn is not None and np.any(q_failed):
        with compacted(run, q_failed) as cut:  # CR2 on the trials that failed only
            sub, on = cut.run, cut.active
            r_its, _ = _masked(sub, on, relative_fn, cal, C3.at("CR2", "ro"))
            seen = judge_standard_points(sub, "C3", C3.at("CR2", "std"), on, text=_SIX_Q)
            _level(sub, cal, rows, C3.at("CR2"), on, pointings, 1, CR2)
            errs = _slip_and_read_heights(sub, rows, heights, C3.at("CR2"), on, pointings, CR2)
        rounds = cut.put(rounds, r_its)
        q_worst = cut.put(q_worst, _worst(seen))
        if errs:
            h_worst = cut.put(h_worst, _worst(errs))
    run.check(name_h, h_worst, tol, unit="m")
    run.check(name_q, q_worst, tol_q)
    run.record_remedy(CR1, name_h, h_failed, np.where(h_failed, pointings, 0))
    run.record_remedy(CR2, name_q, q_failed, rounds)


def _masked(
    run: Run, active: Mask, relative_fn: Relative, cal: Calibration, key0: NoiseKey
) -> tuple[NDArray[np.int_], Floats]:
    """The relative orientation for the trials still ``active`` only (the others stay): run on
    those trials alone (:func:`~stereoplotter.procedure.compaction.compacted`), masked within.
    Returns its iterations and worst |q| (0 and NaN where not ``active``)."""
    with compacted(run, active) as cut:
        op = cut.run.op
        saved = op.all
        on = cut.active
        op.all = lambda: on.copy()  # type: ignore[method-assign]  # the masked trials are "all"
        try:
            its, worst = relative_fn(cut.run, cal, stage="C3", key0=key0)
        finally:
            op.all = saved  # type: ignore[method-assign]
    return cut.put(np.zeros(np.shape(active), int), its), cut.put(run.op.v(np.nan), worst)


def run_conventional_method(run: Run, relative: str = "elements", sheet_on: str = "control") -> Run:
    """The conventional method on a virtual instrument: C1–C4 in order.

    Parameters
    ----------
    run : stereoplotter.procedure.run.Run
        Instrument, sheet, operator and scene; receives results, iterations, zero readings.
    relative : {"elements", "equations"}
        Relative orientation element by element with over-correction, or by the six measured
        q and (5.11).
    sheet_on : {"control", "corners"}
        C3 scales the model on the plotted plan control and C4 lays the sheet on it (the
        book's conventional method), or C3 scales on two points' ground distance and C4 lays
        the sheet on the setup sheet's corners (:data:`SHEET_OPTIONS`).

    Returns
    -------
    Run
    """
    if relative not in RELATIVE_OPTIONS:
        raise StereoplotterError(
            f"relative: expected one of {', '.join(RELATIVE_OPTIONS)}, found {relative!r}"
        )
    perform_all(run, conventional_steps(relative, sheet_on))
    return run


def _calibration(run: Run) -> Calibration:
    """The run's calibration (:func:`conventional_steps` finds it after C1)."""
    cal: Calibration = run.calibration
    return cal


def _calibrate(run: Run, key: NoiseKey) -> None:
    """What the operator knows of the instrument's response (no draws): :func:`calibrate` at
    the levelling points."""
    run.calibration = calibrate(run, levelling_points(run.scene, run.sheet))


def _relative_orientation(run: Run, key: NoiseKey, relative_fn: Relative) -> None:
    """C2: the relative orientation (``relative_fn``) and its ¼-mark check."""
    its, worst = relative_fn(run, _calibration(run), key0=key)
    run.record_stage("C2", its)
    tol = run.sheet.tolerances["residual_y_parallax_mm"]
    run.check("C2: residual y-parallax (6 points)", worst, tol, iterations=its)


def conventional_steps(relative: str = "elements", sheet_on: str = "control") -> tuple[Step, ...]:
    """The conventional method as declared steps: C1 (:data:`C1_STEPS`), the calibration, C2
    by ``relative`` (:data:`RELATIVE_OPTIONS`), C3 and C4 with the sheet ``sheet_on``
    (:data:`SHEET_OPTIONS`)."""
    relative_fn = c2_relative_by_elements if relative == "elements" else c2_relative_by_equations

    def absolute(run: Run, key: NoiseKey) -> None:
        levels = levelling_points(run.scene, run.sheet)
        c3_absolute(run, _calibration(run), levels, relative_fn, sheet_on)

    return (
        *C1_STEPS,
        Act("calibrate the instrument's response (no draws)", C1.at("calibration"), _calibrate),
        Act(
            "C2: relative orientation",
            NoiseKey("C2"),
            lambda run, key: _relative_orientation(run, key, relative_fn),
        ),
        Act("C3: absolute orientation", C3, absolute),
        Act("C4: the sheet", NoiseKey("4"), lambda run, key: c4_sheet(run, sheet_on)),
    )
