"""The setup-data method of §26: stages 1–5 on a virtual instrument (``procedure.md``).

Each stage is a function of a :class:`Run` (instrument, sheet, operator, scene) that changes the
instrument only through the operator and appends to the transcript. Every tolerance loop is
bounded by ``OperatorModel.max_iterations``; its iteration count and its last residual are
returned per trial (never silent). All arithmetic is vectorised over the trials of the run; a
trial whose loop has passed is left alone (``active`` masks), so a vectorised run and a per-trial
loop give the same numbers.

Reference
---------
.. [1] Kushtin I. F. & Lyskov G. A., *Фотограмметрия снимка и стереоскопических моделей*,
   Moscow: Nedra, 1984, ch. 6, §26, Eqs. (6.9)–(6.18) (OCR L3753–3826).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from stereoplotter.instrument.kinematics import rod_from_counters
from stereoplotter.instrument.principles import mark_phrase, sequence_for
from stereoplotter.instrument.virtual import (
    CONTROL_INFO,
    HEIGHT_SCALE,
    NOMINAL_ZERO,
    CassetteName,
    KnobName,
    ScrewName,
    Side,
    control_kind,
)
from stereoplotter.procedure import steps
from stereoplotter.procedure.arrays import Floats, Mask, Value, max_abs_last
from stereoplotter.procedure.compaction import compacted
from stereoplotter.procedure.control_names import CASSETTE, DECENTRATION, KNOB, Tilt
from stereoplotter.procedure.floor import ControlHeights
from stereoplotter.procedure.levelling import LevelDesign
from stereoplotter.procedure.noise_key import NoiseKey
from stereoplotter.procedure.operator import Look, Operator, solve_1d
from stereoplotter.procedure.records import ControlHeight
from stereoplotter.procedure.run import Run
from stereoplotter.procedure.sheet_stages import plotted_mm, stage4_orient_sheet, stage5_check
from stereoplotter.procedure.span_check import fiducial_mm, span_loop
from stereoplotter.procedure.step_values import (
    Act,
    Line,
    ReadStep,
    SetStep,
    Step,
    perform_all,
    turn_common_tilt,
)
from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = [
    "Q_ELEMENTS",
    "STAGE1_STEPS",
    "STAGE2_STEPS",
    "STAGE3_STEPS",
    "check_standard_points",
    "clear_kappa",
    "kappa_from_fiducials",
    "refine_relative_orientation",
    "refine_scale_and_level",
    "run_setup_method",
    "stage1_scale_coefficient",
    "stage2_transform",
    "stage3_scale_model",
]

_SIDE: dict[Side, str] = {"left": "л", "right": "п"}
_SUB = {"1": "₁", "2": "₂", "3": "₃", "4": "₄"}
_TILT = {"alpha": "α", "omega": "ω"}

#: Remedy R2 (after stage 2 and 3, q > ¼ mark): the elements that clear the y-parallax on a
#: setup-data instrument — the five of a dependent-pair relative orientation as this
#: instrument has them. κ_л, κ_п: the book's own ("orientation along the initial direction by
#: κ_л and κ_п", stage 2; "after scaling the orientation along the initial direction is
#: refined", stage 3); k_ω,п: "otherwise refine k_ω" (stage 2), the element with the symmetric
#: pattern at points 3–6 that κ cannot give; k_α,л, k_α,п: the correction knobs carry the
#: photos' α, the xy/f pattern at points 3–6 ("the relative orientation is checked over the
#: whole stereopair", stage 3). Not b_y (a constant q, dependent on κ_л, κ_п at six points),
#: not b_z (it carries n_п, set by the stage-1 L-check, and moves the model's longitudinal
#: tilt).
Q_ELEMENTS: tuple[CassetteName | KnobName, ...] = (
    "kappa_left",
    "kappa_right",
    "k_omega_right",
    "k_alpha_left",
    "k_alpha_right",
)

#: The identities of the stages' draws (each act's own below its stage by its path).
STAGE1, STAGE2, STAGE3 = NoiseKey("1"), NoiseKey("2"), NoiseKey("3")


# --- stage 1 ---------------------------------------------------------------------------------


def _stage1_l_check(run: Run, key: NoiseKey) -> None:
    """The stage-1 L-check loop (units at zero, D5), with R1 where it ends failed (the
    operator's practice): "otherwise the setting is repeated", with averaged pointings."""
    its, ok, res = span_loop(run, "1", key, units_at_zero=True)
    name = "stage 1: |L − L′|"
    if run.remedial:  # R1: "otherwise the setting is repeated", with averaged pointings
        remedy = "R1 repeat the setting"
        failed = ~ok
        with compacted(run, failed) as cut:  # on the trials that failed only
            r_its, _, r_res = span_loop(
                cut.run, "1", key.at("R1"), True, cut.active, steps.REPEAT_POINTINGS, remedy
            )
        r_its = cut.put(np.zeros_like(its), r_its)
        res = cut.put(res, r_res)
        its = its + np.where(failed, r_its, 0)
    run.record_stage("1", its)
    run.check(name, res, run.sheet.tolerances["mark_span_mm"], iterations=its)
    if run.remedial:
        run.record_remedy("R1 stage 1: repeat the setting", name, failed, r_its * failed)


def _record_bx_zero(run: Run, key: NoiseKey) -> None:
    run.zero["MO_bx"] = _bx_zero(run, key)


#: Stage 1 (§26, OCR L3753–3763): interior settings, base, D = n_л f_пр, the L-check loop,
#: MO_Z and MO_bz (D7).
STAGE1_STEPS: tuple[Step, ...] = (
    *steps.interior_steps("1"),
    Act("MO_bx, b_x's place of zero", STAGE1.at("MObx"), _record_bx_zero),
    SetStep(
        "bx",
        lambda run: run.target("O_bx", run.zero["MO_bx"]),
        STAGE1.at("bx"),
        Line("1", "base carriage: O_bx = MO_bx + b_x", "item 1"),
    ),
    SetStep("bz", lambda run: NOMINAL_ZERO["bz"], STAGE1.at("bz0")),
    SetStep(
        "Z",
        lambda run: run.target("O_Z"),  # absolute height counter: D = n_л·f_пр
        STAGE1.at("Z"),
        Line("1", "lower the carriage to O_Z = n_л·f_пр (absolute height counter)", "(6.3)"),
    ),
    Act("MO_by", STAGE1.at("MOby"), lambda run, key: steps.zero_base_y(run, "1", key)),
    SetStep(
        "by",
        lambda run: run.target("O_by"),
        STAGE1.at("by"),
        Line("1", "base carriage: O_by = MO_by + b_y", "item 1"),
    ),
    Act("the L-check (6.9)–(6.11)", STAGE1.at("L"), _stage1_l_check),
    ReadStep(
        HEIGHT_SCALE,
        STAGE1.at("MOZ"),
        "MO_Z",
        Line("1", "record MO_Z on the height scale", "stage 1"),
    ),
    ReadStep("Z", STAGE1.at("MOZ", "D"), "D_MO_Z"),
    ReadStep(
        "bz",
        STAGE1.at("MObz"),
        "MO_bz",
        Line("1", "record MO_bz = (b_z reading) − b_z′", "decision D7"),
        recorded=lambda run, reading: run.target("MO_bz", reading),  # (b_z reading) ∓ b_z′
    ),
)


def stage1_scale_coefficient(run: Run) -> None:
    """Stage 1: :data:`STAGE1_STEPS`."""
    perform_all(run, STAGE1_STEPS)


def _bx_zero(run: Run, key: NoiseKey) -> Floats:
    """MO_bx, b_x's place of zero (switch ``bx_zero``, :mod:`~stereoplotter.procedure.fidelity`):
    "two_pointings" ((6.38), m_bx = √2·m_x/n): found as MO_by is, the left mark monocularly on
    the left cassette centre, the right mark on the right one, each pointing with σ_mono along
    x at photo scale, so MO_bx carries n_л·(e_п − e_л); "exact": the scale's nominal place of
    zero. [mm]"""
    op = run.op
    if run.fidelity.bx_zero == "exact":
        return op.v(NOMINAL_ZERO["bx"])
    sigma = op.model.monocular_sigma_mm
    e = [op.noise.draw(key.at(side).by("mono"), sigma) for side in ("left", "right")]
    zero = NOMINAL_ZERO["bx"] + run.sheet.n_left * (e[1] - e[0])
    _BX_ZERO_LINE.log(op, "bx", reading=zero, judgment_error=e[1] - e[0])
    return zero


_BX_ZERO_LINE = Line(
    "1",
    "MO_bx: the left mark on the left cassette centre, the right mark on the right one "
    "(two monocular pointings along x)",
    "(6.38)",
)


# --- stage 2 ---------------------------------------------------------------------------------


def _zero_readings(run: Run, key: NoiseKey) -> None:
    op = run.op
    zeros: tuple[tuple[Side, tuple[str, str]], ...] = (
        ("left", ("MO_X", "MO_Y")),
        ("right", ("MO_X,п", "MO_Y,п")),
    )
    for side, names in zeros:
        e = op.mark_on(side, np.zeros(2), key.at(side))
        run.zero[names[0]] = op.read("X", key.at(side, "X"))
        run.zero[names[1]] = op.read("Y", key.at(side, "Y"))
        fields = {"side": side, "x": names[0], "y": names[1]}
        _ZERO_X.log(op, "X", fields, reading=run.zero[names[0]], judgment_error=e[..., 0])
        _ZERO_Y.log(op, "Y", fields, reading=run.zero[names[1]], judgment_error=e[..., 1])


#: Stage 2's zero readings MO_X, MO_Y (MO_X,п, MO_Y,п) of a photo.
_ZERO_X = Line("2", "{side} mark on the {side} cassette centre → {x}", "decision D6")
_ZERO_Y = Line("2", "… and {y}", "decision D6")


def _fit_knob(run: Run, side: Side, axis: Tilt, mark: str, key: NoiseKey, active: Mask) -> Floats:
    """Set the counter to MO + n·(x⁰ or y⁰), the other handwheel onto the fiducial line, turn
    the knob until the fiducial is under the mark ((6.12) or (6.13)); the knob's tangent
    after the turn. [—]"""
    op = run.op
    sfx = "" if side == "left" else ",п"
    fid = fiducial_mm(run, side, mark)
    counter: ScrewName
    if axis == "omega":
        counter, free, comp = "Y", "X", 1
    else:
        counter, free, comp = "X", "Y", 0
    value = _fit_target(run, side, f"O_{counter}{mark},{_SIDE[side]}")
    op.set(counter, value, key.at("set"), active)
    op.mark_on(side, fid, key.at("line"), active, free=free)
    e = op.noise.draw(key.at("knob").by("mono"), op.model.monocular_sigma_mm)
    left_u, right_u = op.units()
    unit = left_u if side == "left" else right_u
    rod = rod_from_counters(
        op.physical("X"), op.physical("Y"), op.physical("Z"), op.inst.setting, side
    )
    knob = KNOB[axis, side]
    t = op.knob_for(knob, unit, fid, rod, comp, fid[comp] + e)
    before = op.physical(knob)
    op.drive(knob, t, active)
    coordinate = f"{counter.lower()}⁰{_SUB[mark]}"  # y⁰₃ for k_ω, x⁰₂ / x⁰₁ for k_α
    fields = {
        "side": side,
        "counter": counter,
        "zero": "MO_" + counter + sfx,
        "coordinate": coordinate,
        "value": np.ravel(value)[0],
        "knob": CONTROL_INFO[knob].own_name(op.inst.spec.principle),
        "tilt": _TILT[axis],
        "mark": mark_phrase(op.inst.spec.principle, mark),
    }
    _FIT_KNOB[axis].log(op, knob, fields, before=before, after=op.physical(knob), judgment_error=e)
    return op.physical(knob)


_FIT_TEXT = (
    "{side} photo: counter {counter} at {zero} + n·{coordinate} = {value:.2f} mm, turn {knob} "
    "(tan {tilt}) until {mark}"
)
#: Stage 2's fit of a correction knob: k_ω (6.12), k_α (6.13).
_FIT_KNOB = {"omega": Line("2", _FIT_TEXT, "(6.12)"), "alpha": Line("2", _FIT_TEXT, "(6.13)")}


def _fit_target(run: Run, side: Side, name: str) -> Value:
    """The counter target MO (+ ,п) + n·x⁰ or n·y⁰ of a fit (switch ``fit_scale``): the sheet's
    reading ("as_set"), or its value scaled by n_true/n of the sheet, n_true = D/f_пр of the
    instrument as it is (D + b_z on the right; "exact"). [mm]"""
    value = run.target(name)
    if run.fidelity.fit_scale != "exact":
        return value
    op, sheet = run.op, run.sheet
    depth = op.physical("Z") + (op.physical("bz") if side == "right" else 0.0)
    f_instrument: Value = op.inst.setting.f_instrument_mm
    n_true = depth / f_instrument
    n_sheet = sheet.n_left if side == "left" else sheet.n_right
    reading = run.readings[name]
    return value + reading.value * (n_true / n_sheet - 1.0)


def _fit_omega(run: Run, side: Side, key: NoiseKey, active: Mask) -> None:
    """k_ω of ``side`` (switch ``tilts``): fitted at mark 3 ("knob_fit"), or at marks 3 and 4
    and set to the mean of the two fits ("least_squares", (6.33))."""
    t3 = _fit_knob(run, side, "omega", "3", key, active)
    if run.fidelity.tilts != "least_squares":
        return
    op = run.op
    t4 = _fit_knob(run, side, "omega", "4", key.at("4"), active)
    knob = KNOB["omega", side]
    before = op.physical(knob)
    op.drive(knob, 0.5 * (t3 + t4), active)
    _OMEGA_MEAN.log(op, knob, {"side": side}, before=before, after=op.physical(knob))


_OMEGA_MEAN = Line(
    "2", "{side} photo: k_ω to the mean of its fits at marks 3 and 4 (least squares)", "(6.33)"
)


def _mark4(run: Run, side: Side, key: NoiseKey, active: Mask) -> Floats:
    """Check mark 4 at MO_Y + n·y⁰₄ (6.12): the offset of the mark from fiducial 4 seen."""
    op = run.op
    fid = fiducial_mm(run, side, "4")
    value = run.target(f"O_Y4,{_SIDE[side]}")
    op.set("Y", value, key.at("set"), active)
    op.mark_on(side, fid, key.at("line"), active, free="X")
    off = op.inst.mark_offsets(**{f"{side}_point_mm": fid})[side]
    e = op.noise.draw(key.at("seen").by("mono"), op.model.monocular_sigma_mm)
    seen: Floats = np.abs(np.asarray(off)[..., 1]) + e
    return seen


def _stage2_k_omega(run: Run, key: NoiseKey) -> None:
    """k_ω of both photos with the mark-4 check, iterated with the stage-1 L-check (decision
    D5) until mark 4 is within its tolerance (bounded)."""
    op, sheet = run.op, run.sheet
    tol4 = sheet.tolerances["mark_fit_mm"]
    active = op.all()
    its = np.zeros(np.shape(active), int)
    worst = op.v(np.nan)
    for it in range(1, op.model.max_iterations + 1):
        its = np.where(active, it, its)
        with compacted(run, active) as cut:  # the trials whose mark 4 is still off only
            l_its, new = _stage2_round(cut.run, key, it, cut.active, tol4)
        if it > 1:  # D5: the L-check repeated with the units set
            l_its = cut.put(np.zeros(np.shape(active), int), l_its)
            run.record_stage("1", run.stage_iterations("1") + np.where(active, l_its, 0))
        worst = cut.put(worst, new)
        active = active & ~(worst <= tol4)
        if not np.any(active):
            break
    run.record_stage("2", its)
    run.check("stage 2: mark 4", worst, tol4, iterations=its)


def _stage2_k_alpha(run: Run, key: NoiseKey) -> None:
    """k_α of the left photo at mark 2, of the right at mark 1 ((6.13))."""
    marks: tuple[tuple[Side, str], ...] = (("left", "2"), ("right", "1"))
    for side, mark in marks:
        _fit_knob(run, side, "alpha", mark, key.at(side, "alpha"), run.op.all())


def _stage2_decentrations(run: Run, key: NoiseKey) -> None:
    """The computed decentrations after the fits (variant B2 set them before, ``_stage2_round``)."""
    if not run.op.inst.variant.decentrations_first:
        _set_computed_decentrations(run, key)


def _stage2_kappa(run: Run, key: NoiseKey) -> None:
    """κ (switch ``kappa``): from the fiducials (6.36), or cleared at standard points 1, 2 (D8)."""
    if run.fidelity.kappa == "fiducials":
        kappa_from_fiducials(run, "2")
    else:
        clear_kappa(run, "2")


#: Stage 2 (§26, OCR L3764–3790): zero readings, k_ω with the mark-4 check (iterated with the
#: stage-1 L-check, decision D5), k_α, computed decentrations, O_bz (6.14), κ (D8), the residual
#: y-parallax.
STAGE2_STEPS: tuple[Step, ...] = (
    Act("k_ω with the mark-4 check", STAGE2, _stage2_k_omega),
    Act("k_α", STAGE2, _stage2_k_alpha),
    Act("computed decentrations", STAGE2, _stage2_decentrations),
    SetStep(
        "bz",
        lambda run: run.target("O_bz"),
        STAGE2.at("bz"),
        Line("2", "O_bz = MO_bz + b_z′", "(6.14)"),
    ),
    Act("κ", STAGE2.at("kappa"), _stage2_kappa),
    Act("residual y-parallax", STAGE2.at("std"), lambda run, key: check_standard_points(run, "2")),
)


def stage2_transform(run: Run) -> None:
    """Stage 2: :data:`STAGE2_STEPS`."""
    perform_all(run, STAGE2_STEPS)


def kappa_from_fiducials(run: Run, stage: str) -> None:
    """κ of each photo from its fiducials (switch ``kappa`` "fiducials", (6.36), OCR L3761):
    the x-readings of marks 3 and 4 (at y = ±l) made equal, each a monocular pointing with
    σ_mono along x; κ is the sheet's κ of the photo plus (e₃ − e₄)/(y₃ − y₄), so
    m_κ = m_x/(√2·l·n) at counter scale. No y-parallax is judged. [rad]"""
    op = run.op
    sigma = op.model.monocular_sigma_mm
    key = NoiseKey(stage).at("kappa")
    sides: tuple[Side, Side] = ("left", "right")
    for side, photo in zip(sides, run.sheet.photos, strict=True):
        span = fiducial_mm(run, side, "3")[1] - fiducial_mm(run, side, "4")[1]
        e3, e4 = (op.noise.draw(key.at(side, m).by("mono"), sigma) for m in "34")
        control = CASSETTE[side]
        before = op.physical(control)
        op.drive(control, photo.kappa + (e3 - e4) / span)
        _KAPPA_FIDUCIALS.in_stage(stage).log(
            op, control, {"side": _SIDE[side]},
            before=before, after=op.physical(control), judgment_error=e3 - e4,
        )  # fmt: skip


_KAPPA_FIDUCIALS = Line(
    "2", "κ_{side} from the fiducials: marks 3 and 4 at equal x-readings", "(6.36)"
)


def _set_computed_decentrations(run: Run, key: NoiseKey) -> None:
    """The computed decentrations d = MO_d + f′·tan(tilt) on the scales (stage 2): after the
    k_α, k_ω fits in the book's order, before them under variant B2 (``decentrations_first``)."""
    op = run.op
    sides: tuple[Side, Side] = ("left", "right")
    for side in sides:
        for d in ("dx", "dy"):
            control = DECENTRATION[d, side]
            # MO_dx, MO_dy: the decentration scale's place of zero
            value = run.target(f"d_{d[1]},{_SIDE[side]}", NOMINAL_ZERO[control])
            op.set(control, value, key.at(control))
            fields = {
                "name": CONTROL_INFO[control].own_name(op.inst.spec.principle),
                "d": d,
                "side": _SIDE[side],
                "zero": NOMINAL_ZERO[control],
                "tables": _table_settings(op.inst.spec.principle, d),
            }
            _DECENTRATION[d].log(op, control, fields, reading=value)


def _decentration_line(d: str, tilt: str) -> Line:
    text = (
        "decentration {name} = MO_{d} + f′·tan " + tilt + "_{side} "
        "(place of zero MO_{d} = {zero:g} mm){tables}"
    )
    return Line("2", text, f"f′·tan {tilt} (§2.4)")


#: Stage 2's computed decentration d_x (from α) or d_y (from ω) of a photo.
_DECENTRATION = {"dx": _decentration_line("dx", "α"), "dy": _decentration_line("dy", "ω")}


def _stage2_round(
    run: Run, key: NoiseKey, it: int, active: Mask, tol4: float
) -> tuple[NDArray[np.int_] | None, Floats]:
    """One pass of stage 2's k_ω loop on ``active``: (from the second on) the L-check again
    with the units set (D5), or the zero readings; k_ω fitted and mark 4 checked on both
    photos. Returns the L-check's iterations (None on the first pass) and the worst mark-4
    offset seen. [—, mm]"""
    op = run.op
    l_its = None
    if it > 1:  # D5: repeat the L-check with the units set, then refit k_ω
        l_its, _, _ = span_loop(run, "2", key.at(f"L{it}"), active=active)
    else:  # with the correction units still at zero the cassette centre is on the plumb
        _zero_readings(run, key.at("MO"))
        if op.inst.variant.decentrations_first:  # B2: the decentrations before the fits
            _set_computed_decentrations(run, key)
    seen = []
    for side in ("left", "right"):
        _fit_omega(run, side, key.at(it, side, "omega"), active)
        m4 = _mark4(run, side, key.at(it, side, "m4"), active)
        seen.append(m4)
        _MARK4.log(
            op, "Y", {"sfx": ",п" if side == "right" else "", "side": side},
            residual=m4, tolerance=tol4, passed=np.abs(m4) <= tol4, iteration=it,
        )  # fmt: skip
    return l_its, np.maximum(np.abs(seen[0]), np.abs(seen[1]))


#: Stage 2's check of mark 4 of a photo.
_MARK4 = Line("2", "{side} photo: check mark 4 at MO_Y{sfx} + n·y⁰₄", "(6.12)")
#: D8: the y-parallax at standard point 1 or 2 cleared with a cassette's κ.
_CLEAR_KAPPA = Line(
    "2", "standard point {point}: clear the y-parallax with κ_{side}", "decision D8"
)
#: R2: a turn of an element by the least-squares clearing of the six q.
_R2_TURN = Line(
    "2",
    "turn {control} by the least-squares clearing of the six q seen",
    "§26 stages 2, 3: κ along the initial direction; refine k_ω",
)
#: R3: the height scale slipped on the first control point, on the mean of several fusings.
_R3_SLIP = Line(
    "3",
    "fuse on {id} ({pointings} times), slip the height scale to H = {height:.2f} m",
    "stage 3",
)
#: A control height read against its known height (H/3000).
_CONTROL_HEIGHT = Line("3", "{text}, against the point's known height {truth:.2f} m", "H/3000")
#: Stage 3: b_x turned until the mark fuses on the height control point.
_FUSE_BX = Line("3", "fuse the mark on point {id} by turning b_x", "stage 3")


def _table_settings(principle: str, control: str) -> str:
    """On an instrument with several decentrations per tilt (the SPR-3's photo, correction
    mechanism and follower), the ones this setting stands for (from the tables)."""
    seq = sequence_for(principle)
    if seq is None:
        return ""
    tilt = "alpha" if control == "dx" else "omega"
    kinds = [s for s in seq.settings if s.kind == "derived" and s.tilt == tilt]
    if len(kinds) < 2:
        return ""
    names = ", ".join(f"{s.name} {s.symbol}" for s in kinds)
    return (
        f"; from the tables: {names} all take this value (one pair per photo on the virtual "
        "instrument, decision D2)"
    )


def clear_kappa(run: Run, stage: str) -> None:
    """κ by the initial directions (decision D8): q at standard point 1 with κ_п, at point 2
    with κ_л, repeated until both are within ¼ mark (bounded)."""
    op = run.op
    tol = run.sheet.tolerances["residual_y_parallax_mm"]
    pts = run.scene.standard_points_m
    imgs = run.scene.standard  # the standard points' true images, computed once
    active = op.all()
    its = np.zeros(np.shape(active), int)
    for it in range(1, op.model.max_iterations + 1):
        its = np.where(active, it, its)
        with compacted(run, active) as cut:  # the trials whose q is still beyond ¼ mark only
            ok = _kappa_round(cut.run, stage, it, cut.active, pts, imgs, tol)
        active = active & ~cut.put(np.zeros(np.shape(active), bool), ok)
        if it > 1 and not np.any(active):
            break
    run.record_stage(f"{stage}/kappa", its)


def _kappa_round(
    run: Run,
    stage: str,
    it: int,
    active: Mask,
    pts: Floats,
    imgs: tuple[Floats, Floats],
    tol: float,
) -> Mask:
    """One pass of D8 on ``active``: q at standard point 1 cleared with κ_п, at point 2 with
    κ_л; whether both were within ¼ mark as seen before the turns."""
    op = run.op
    qs = []
    points: tuple[tuple[int, Side], ...] = ((0, "right"), (1, "left"))
    for idx, side in points:
        key = NoiseKey(stage).at("kappa", it, idx + 1)
        img = (imgs[0][idx], imgs[1][idx])
        q_seen, q_true = op.fuse(pts[idx], img, key, active)
        qs.append(q_seen)
        control = CASSETTE[side]
        target = op.noise.draw(key.at("clear").by("q"), op.model.y_parallax_sigma_mm)
        q_of = op.q_turning(control, img)  # q with κ turned, the rest as it is now
        ok_here = np.abs(q_seen) <= tol
        move = active & ~ok_here if it > 1 else active
        kappa = op.physical(control)
        new = _solve_kappa(q_of, kappa, target)
        op.drive(control, new, move)
        _CLEAR_KAPPA.in_stage(stage).log(
            op, control, {"point": idx + 1, "side": _SIDE[side]},
            before=kappa, after=op.physical(control), residual=q_seen, true=q_true,
            judgment_error=q_seen - q_true, tolerance=tol, passed=ok_here, iteration=it,
        )  # fmt: skip
    return (np.abs(qs[0]) <= tol) & (np.abs(qs[1]) <= tol)


def _solve_kappa(q_of: Look, kappa0: Floats, target: Floats) -> Floats:
    kappa: Floats = solve_1d(q_of, kappa0, target, iterations=4, h=1e-6)
    return kappa


def check_standard_points(run: Run, stage: str) -> NDArray[np.float64]:
    """The residual y-parallax at the six standard points, judged by the operator; with the
    operator's practice, remedy R2 where it exceeds ¼ mark."""
    tol = run.sheet.tolerances["residual_y_parallax_mm"]
    seen = np.stack(steps.judge_standard_points(run, stage, NoiseKey(stage).at("std")), axis=-1)
    worst = max_abs_last(seen)
    name = f"stage {stage}: residual y-parallax (6 points)"
    if run.remedial:
        failed = worst > tol
        rounds, worst = refine_relative_orientation(run, stage, seen, failed)
    run.check(name, worst, tol)
    if run.remedial:
        remedy = f"R2 stage {stage}: refine the relative orientation"
        run.record_remedy(remedy, name, failed, rounds)
    return worst


def _q_jacobian(run: Run, imgs: tuple[Floats, Floats]) -> NDArray[np.float64]:
    """∂q/∂element at the six standard points for :data:`Q_ELEMENTS`, the rest of the
    instrument as it is (the operator's knowledge of how each element moves q): (..., 6, 5).

    The six points in one evaluation per turn (points on a leading axis, trials on the last):
    the point-dependent arithmetic is + − × ÷ only, so each value is the one of a point alone.
    """
    op = run.op
    left, right = (np.asarray(im, float) for im in imgs)
    if op.trials:  # (6, 1, 2): the points broadcast against the trials' (T,) state
        left, right = left[:, None, :], right[:, None, :]
    h = 1e-6
    cols = []
    for control in Q_ELEMENTS:
        x0 = op.physical(control)
        q_of = op.q_turning(control, (left, right))
        cols.append(np.moveaxis((q_of(x0 + h) - q_of(x0 - h)) / (2.0 * h), 0, -1))
    return np.stack(cols, axis=-1)


def refine_relative_orientation(
    run: Run, stage: str, seen: NDArray[np.float64], failed: NDArray[np.bool_]
) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Remedy R2: q seen at the six standard points exceeds ¼ mark. The operator clears it
    with κ_л, κ_п, k_ω,п, k_α,л, k_α,п (:data:`Q_ELEMENTS`): the least-squares turns from
    the six q seen (the §22 way with measured q, on the instrument's own sensitivities), then
    judges the six points again; bounded by ``OperatorModel.max_iterations`` rounds.

    Returns the rounds used and the worst |q| seen last (per trial; unchanged where not
    failed).
    """
    op = run.op
    tol = run.sheet.tolerances["residual_y_parallax_mm"]
    remedy = "R2 refine the relative orientation"
    active = op.v(failed).astype(bool)
    rounds = np.zeros(np.shape(active), int)
    worst = max_abs_last(seen)
    for it in range(1, op.model.max_iterations + 1):
        if not np.any(active):
            break
        rounds = np.where(active, it, rounds)
        with compacted(run, active) as cut:  # the round on the trials still failing only
            new = _r2_round(cut.run, stage, it, cut.take(seen), cut.active, remedy)
        seen = cut.put(seen, new)
        worst = cut.put(worst, max_abs_last(new))
        active = active & (worst > tol)
    return rounds, worst


#: Damping ladder of R2's least-squares turns: λ of (JᵀJ + λ·diag JᵀJ) δ = −Jᵀq, tried in
#: order per trial until every element's target lies in its range (Levenberg–Marquardt). λ = 0
#: is the plain least squares, which a well-conditioned pair always takes.
R2_DAMPING = (0.0, 1e-4, 1e-3, 1e-2, 1e-1, 1.0, 10.0, 100.0)
#: Fraction of an element's range R2 may use: the rest is the margin for the knob's or
#: cassette's own setting error, which the stop sees on top of the operator's target. [—]
R2_RANGE_FRACTION = 0.98


def r2_element_bounds(spec: InstrumentSpec) -> dict[str, tuple[float, float]]:
    """Where R2 may drive each of :data:`Q_ELEMENTS`: the instrument's κ range [rad] and its
    correction range ±tilt_max as tan of the tilt [—], each shrunk to
    :data:`R2_RANGE_FRACTION` (the stops are the instrument file's
    ``orientation.kappa_deg`` and ``correction.tilt_max_deg``)."""
    lo_k, hi_k = spec.kappa_range
    mid, half = 0.5 * (lo_k + hi_k), 0.5 * (hi_k - lo_k) * R2_RANGE_FRACTION
    t = float(np.tan(spec.tilt_max * R2_RANGE_FRACTION))
    return {
        name: (mid - half, mid + half) if control_kind(name) == "cassette" else (-t, t)
        for name in Q_ELEMENTS
    }


def r2_turns(
    jac: Floats, seen: Floats, before: Floats, bounds: Sequence[tuple[float, float]]
) -> NDArray[np.float64]:
    """R2's turns δ of :data:`Q_ELEMENTS` from the six q seen (..., 6) and the Jacobian
    (..., 6, 5): the least squares −(JᵀJ)⁻¹Jᵀq where it keeps every element inside ``bounds``,
    else damped (Levenberg–Marquardt, the first λ of :data:`R2_DAMPING` that keeps them
    inside), else the most damped step clipped to the bounds. ``before``: the elements now
    (..., 5). Near-collinear elements (the two k_α at a narrow base) are what the damping
    tames: the plain solution turns them far apart in opposite senses.

    Examples
    --------
    >>> jac = np.array([[1.0, 1.0 + 1e-9]] * 3)          # two collinear elements
    >>> r2_turns(jac, np.array([0.1, 0.1, 0.1]), np.zeros(2), [(-1, 1), (-1, 1)]).round(3)
    array([-0.05, -0.05])
    """
    jt = np.swapaxes(jac, -1, -2)
    a = jt @ jac
    g = (jt @ seen[..., None])[..., 0]
    lo = np.array([b[0] for b in bounds])
    hi = np.array([b[1] for b in bounds])
    diag = np.einsum("...ii->...i", a)
    out: Value = None
    done: Value = None
    for lam in R2_DAMPING:
        m = a + lam * (diag[..., :, None] * np.eye(a.shape[-1]))
        with np.errstate(all="ignore"):
            try:
                delta = -np.linalg.solve(m, g[..., None])[..., 0]
            except np.linalg.LinAlgError:
                delta = -(np.linalg.pinv(m) @ g[..., None])[..., 0]
        target = before + delta
        inside = np.all(np.isfinite(target) & (target >= lo) & (target <= hi), axis=-1)
        if out is None:
            out, done = delta, inside
        else:
            out = np.where(done[..., None], out, delta)
            done = done | inside
        if np.all(done):
            return cast(Floats, out)
    # the most damped step, clipped where still outside: the element stops at its range
    clipped: Floats = np.where(done[..., None], out, np.clip(before + out, lo, hi) - before)
    return clipped


def _r2_round(
    run: Run, stage: str, it: int, seen: Floats, active: Mask, remedy: str
) -> NDArray[np.float64]:
    """One round of R2 on ``active``: the bounded least-squares turns (:func:`r2_turns`) from
    the six q seen, then the six points judged again; the q seen, (..., 6). [mm]"""
    op = run.op
    jac = _q_jacobian(run, run.scene.standard)
    bounds = r2_element_bounds(op.inst.spec)
    before = np.stack([op.physical(c) for c in Q_ELEMENTS], axis=-1)
    delta = r2_turns(jac, seen, before, [bounds[c] for c in Q_ELEMENTS])
    for j, control in enumerate(Q_ELEMENTS):
        before = op.physical(control)
        op.drive(control, before + delta[..., j], active)
        _R2_TURN.in_stage(stage).log(
            op, control, {"control": control},
            before=before, after=op.physical(control), iteration=it, remedy=remedy, when=active,
        )  # fmt: skip
    return np.stack(
        steps.judge_standard_points(
            run, stage, NoiseKey(stage).at("R2", it), active, remedy=remedy, iteration=it
        ),
        axis=-1,
    )


# --- stage 3 ---------------------------------------------------------------------------------


def _refine_scale(run: Run, it: int, active: Mask, remedy: str) -> None:
    """R3 (1): fuse on the two plan control points farthest apart, compare the distance of the
    X, Y counters with that of their sheet coordinates (6.7), turn b_x in proportion."""
    op, sheet = run.op, run.sheet
    if sheet.similarity is None:
        return
    a_id, b_id = steps.scale_pair(run)
    d_sheet = float(np.hypot(*(plotted_mm(run, a_id) - plotted_mm(run, b_id))))
    bx, new, d_model = steps.scale_by_two_points(
        run,
        (a_id, steps.control_point_m(run, a_id)),
        (b_id, steps.control_point_m(run, b_id)),
        d_sheet,
        STAGE3.at("R3", it),
        active,
    )
    _R3_SCALE.log(
        op, "bx", {"a": a_id, "b": b_id, "d": d_sheet},
        before=bx, after=new, reading=new, residual=d_model - d_sheet, iteration=it,
        remedy=remedy, when=active,
    )  # fmt: skip


_R3_SCALE = Line(
    "3",
    "scale: fuse on {a} and {b}, counter distance against the sheet's {d:.3f} mm (6.7); "
    "turn b_x in proportion",
    "§26 stage 3: scaling refined (b_x)",
)


#: R3's turn of a control by its rate × the common tilt φ.
_LEVEL_LINE = Line(
    "3",
    "level: common tilt Δφ_{axis} = {phi_mrad:+.4f} mrad, turn {control}",
    "levelling on control (assumption, q-neutral common tilt)",
)


def _level(
    run: Run, design: LevelDesign, errs: Sequence[Value], it: int, active: Mask, remedy: str
) -> None:
    """R3 (2): fit offset + common tilts φ_α, φ_ω to the control-height errors and turn the
    q-neutral common tilts (:class:`LevelDesign`) by −φ."""
    op = run.op
    sense = run.sheet.options.bz_scale_sense
    w = np.linalg.pinv(design.design)
    for row, name in ((1, "alpha"), (2, "omega")):
        phi = np.where(
            active, -steps.fixed_order_sum(w[row, i] * e for i, e in enumerate(errs)), 0.0
        )
        fields = {"axis": name[0], "phi_mrad": _shown(op, phi) * 1e3}
        key = STAGE3.at("R3", it, name)
        turn_common_tilt(
            run, design.combos[name], phi, key, active, _LEVEL_LINE, fields=fields,
            scale_sense=sense, iteration=it, remedy=remedy, when=active,
        )  # fmt: skip


def _shown(op: Operator, value: Value) -> float:
    """The value of the trial the transcript shows."""
    flat = np.ravel(value)
    return float(flat[op.log.shown if flat.size > 1 else 0])


def _read_control_heights(
    run: Run,
    rows: Sequence[ControlHeight],
    key: NoiseKey,
    active: Mask,
    remedy: str,
    it: int,
    pointings: int = steps.REPEAT_POINTINGS,
) -> list[NDArray[np.float64]]:
    """Slip the height scale on control point 0 (the mean of ``pointings`` fusings and readings
    there), then fuse on the others and read their heights (each the mean of ``pointings``):
    the errors (read − truth) of points 1 … n−1. [m]"""
    op, tol = run.op, run.sheet.tolerances["control_height_m"]
    p0 = rows[0].ground_m
    steps.slip_height_scale_on_mean(run, p0, key.at("slip"), active, pointings)
    _R3_SLIP.log(
        op, HEIGHT_SCALE, {"id": rows[0].id, "pointings": pointings, "height": p0[2]},
        reading=p0[2], iteration=it, remedy=remedy, when=active,
    )  # fmt: skip
    return [
        log_control_height(
            op,
            "3",
            f"control point {h.id}: fuse, read the height ({pointings} times, mean)",
            steps.height_mean(run, h.ground_m, key.at(h.id), active, pointings),
            h.ground_m[2],
            tol,
            iteration=it,
            remedy=remedy,
            when=active,
        )
        for h in rows[1:]
    ]


def log_control_height(
    op: Operator, stage: str, text: str, read: Value, truth_m: float, tol: float, **extra: Any
) -> Value:
    """Log one control-point height read on the height scale against its truth and H/3000;
    return the error read − truth. [m]"""
    _CONTROL_HEIGHT.in_stage(stage).log(
        op, HEIGHT_SCALE, {"text": text, "truth": truth_m},
        reading=read, residual=read - truth_m, tolerance=tol,
        passed=np.abs(read - truth_m) <= tol, **extra,
    )  # fmt: skip
    return read - truth_m


def refine_scale_and_level(
    run: Run, rows: Sequence[ControlHeight], errs: Sequence[Value], failed: NDArray[np.bool_]
) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Remedy R3: a control height misses H/3000 after stage 3. Each round: (1) the scale by
    b_x on the two plan control points farthest apart; (2) the levelling: read the control
    heights, fit offset + φ_α, φ_ω (the run's :class:`LevelDesign`, prepared once per run) and
    turn the q-neutral common tilts by −φ; (3) slip the height scale again on the first control
    point and check all control heights. Bounded by ``OperatorModel.max_iterations`` rounds.

    Returns the rounds used and the worst |height error| last (per trial). [m]
    """
    op = run.op
    tol = run.sheet.tolerances["control_height_m"]
    remedy = "R3 refine scaling and levelling on control"
    design = cast(LevelDesign, run.level)  # prepared with the run
    active = op.v(failed).astype(bool)
    rounds = np.zeros(np.shape(active), int)
    worst = np.max(np.abs(np.stack(errs, axis=-1)), axis=-1)
    for it in range(1, op.model.max_iterations + 1):
        if not np.any(active):
            break
        rounds = np.where(active, it, rounds)
        with compacted(run, active) as cut:  # the round on the trials still failing only
            sub, on = cut.run, cut.active
            _refine_scale(sub, it, on, remedy)
            level = _read_control_heights(sub, rows, STAGE3.at("R3", it, "level"), on, remedy, it)
            _level(sub, design, [sub.op.v(0.0) * 0.0, *level], it, on, remedy)
            errs = _read_control_heights(sub, rows, STAGE3.at("R3", it, "check"), on, remedy, it)
            new = np.max(np.abs(np.stack(errs, axis=-1)), axis=-1)
        worst = cut.put(worst, new)
        active = active & (worst > tol)
    return rounds, worst


def _fuse_bx(run: Run, pid: str, left_img: Floats, right_img: Floats) -> None:
    """Stage 3's scaling (switch ``stage3``): the mark fused on the height control point ``pid``
    by turning b_x, then ("fuse") κ cleared again (D10)."""
    op = run.op
    op.mark_on("left", left_img, STAGE3.at("left"))
    e = op.noise.draw(STAGE3.at("bx").by("stereo"), op.model.stereo_sigma_mm)
    right_map = op.unit_map("right")
    xi_r = right_map.rod_from_photo(right_img + np.stack([e, 0.0 * e], axis=-1))[..., 0]
    f_instrument: Value = op.inst.setting.f_instrument_mm
    n_r = (op.physical("Z") + op.physical("bz")) / f_instrument
    before = op.read("bx", STAGE3.at("bx", "before"))
    op.drive("bx", op.physical("X") - n_r * xi_r)
    after = op.read("bx", STAGE3.at("bx", "after"))
    _FUSE_BX.log(op, "bx", {"id": pid}, before=before, after=after, reading=after, judgment_error=e)
    # Decision D10 (docs/procedure.md): the b_x change moves the rods' meeting depth and with it
    # q where η_л ≠ η_п, so κ is cleared again (D8) *before* the heights are read: they are then
    # read on the model that is kept. Read before it (pair80: b_x 57.6 mm, κ absorbing f·ω/b),
    # they differed from the final model's by 0.14 m of the 0.465 m tolerance. κ from the
    # fiducials (switch ``kappa``) is not refined: the fiducials do not move with b_x.
    if run.fidelity.kappa != "fiducials" and run.fidelity.stage3 == "fuse":
        clear_kappa(run, "3")


def _heights(run: Run) -> ControlHeights:
    """The run's height control points (prepared with the run)."""
    return cast(ControlHeights, run.heights)


def _stage3_fuse(run: Run, key: NoiseKey) -> None:
    """b_x until the mark fuses on the first height control point (switch ``stage3``), the
    mark fused there again and the height scale slipped to its height."""
    op = run.op
    h0 = _heights(run).rows[0]
    p0 = h0.ground_m
    pl, pr = run.scene.images(p0[None, :])
    if run.fidelity.stage3 != "none":
        _fuse_bx(run, h0.id, pl[0], pr[0])
    op.fuse_mark(p0, (pl[0], pr[0]), key.at("refuse"))
    op.inst.slip_height_scale(p0[2])
    _SLIP_LINE.log(op, HEIGHT_SCALE, {"height": p0[2]}, reading=p0[2])


_SLIP_LINE = Line("3", "slip the height scale to H = {height:.2f} m", "stage 3")


def _stage3_heights(run: Run, key: NoiseKey) -> None:
    """The other control heights read against H/3000; R3 where one misses it (the operator's
    practice)."""
    op, sheet = run.op, run.sheet
    rows = _heights(run).rows  # the sheet's height control points, prepared once per run
    tol = sheet.tolerances["control_height_m"]
    errs = []
    for h in rows[1:]:
        p = h.ground_m
        img = run.scene.images(p[None, :])
        op.fuse_mark(p, (img[0][0], img[1][0]), key.at(h.id))
        read = op.read(HEIGHT_SCALE, key.at(h.id))
        text = f"control point {h.id}: fuse, read the height"
        errs.append(log_control_height(op, "3", text, read, p[2], tol))
    worst = np.max(np.abs(np.stack(errs, axis=-1)), axis=-1) if errs else op.v(0.0)
    name = "stage 3: control heights"
    remedial = run.remedial and bool(errs)
    if remedial:  # R3: scaling refined "by the heights of control points", and levelling
        failed = worst > tol
        rounds, worst = refine_scale_and_level(run, rows, errs, failed)
    run.check(name, worst, tol, unit="m")
    if remedial:
        remedy = "R3 stage 3: refine scaling and levelling on control"
        run.record_remedy(remedy, name, failed, rounds)


#: Stage 3 (§26, OCR L3791–3805): (6.15) at a height control point, b_x until the mark fuses,
#: slip the height scale, check the other control heights (H/3000), re-check κ and the residual
#: y-parallax.
STAGE3_STEPS: tuple[Step, ...] = (
    SetStep(
        HEIGHT_SCALE,
        lambda run: run.target(f"O_Z{_heights(run).rows[0].id}"),  # MO_Z + (6.15)
        STAGE3.at("OZ"),
        Line("3", "height scale to O_Z{id} for control point {id}", "(6.15)"),
        fields=lambda run: {"id": _heights(run).rows[0].id},
    ),
    Act("fuse on the control point, slip the height scale", STAGE3, _stage3_fuse),
    Act("control heights", STAGE3.at("h"), _stage3_heights),
    Act("residual y-parallax", STAGE3.at("std"), lambda run, key: check_standard_points(run, "3")),
)


def stage3_scale_model(run: Run) -> None:
    """Stage 3: :data:`STAGE3_STEPS`."""
    perform_all(run, STAGE3_STEPS)


def run_setup_method(run: Run) -> Run:
    """Stages 1–5 in order."""
    stage1_scale_coefficient(run)
    stage2_transform(run)
    stage3_scale_model(run)
    stage4_orient_sheet(run)
    stage5_check(run)
    return run
