"""The L-check of stages 1 and 2: the span L′ of fiducial marks 3, 4 measured on each photo
against the sheet's L (6.5), corrected by ΔZ (6.9) and Δb_z (6.10), set as O′ = O + Δ (6.11),
until |L − L′| ≤ 0.03/n_л for both photos.

Units: mm on the instrument and photo, m on the height counter (ΔZ as shown).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from stereoplotter.instrument.virtual import NOMINAL_ZERO, Side
from stereoplotter.procedure.arrays import Active, Floats, Mask, Value
from stereoplotter.procedure.compaction import compacted
from stereoplotter.procedure.noise_key import KeyLike, NoiseKey, as_key, pointing
from stereoplotter.procedure.operator import Operator
from stereoplotter.procedure.run import Run
from stereoplotter.procedure.step_values import BOTTOM_STOP, L_CHECK_FAILED, Line
from stereoplotter.setup.equations import base_z_correction, height_correction

__all__ = ["fiducial_mm", "span_loop"]

_SIDE: dict[Side, str] = {"left": "л", "right": "п"}

#: The lines of the L-check, declared for stage "1" (a loop of stage 2 writes them as its own).
#: The measurement of L′ of a photo against the sheet's L.
MEASURE_SPAN = Line(
    "1", "measure L′_{side} (marks 3, 4), compare with L_{side} = {span:.3f} mm", "(6.5)"
)
#: The correction ΔZ (6.9), where the check failed.
DELTA_Z = Line(
    "1",
    "ΔZ = {dz:+.3f} m (6.9): {direction} the carriage, O′_Z = O_Z + ΔZ",
    "(6.9), (6.11)",
    condition=L_CHECK_FAILED,
)
#: The correction Δb_z (6.10), where the check failed.
DELTA_BZ = Line(
    "1",
    "Δb_z (6.10), ratio form with D_п = D + b_z and L′_п (decision D9): O′_bz = O_bz {sign} Δb_z",
    "(6.10), (6.11)",
    condition=L_CHECK_FAILED,
)
#: f_пр changed where the ΔZ meets the carriage's bottom stop.
AT_BOTTOM_STOP = Line(
    "1",
    "n = D/f_пр at the carriage's bottom stop (D_max): f′_пр = f_пр·D/(D + ΔD), "
    "shortened for a deeper carriage, lengthened back (to the sheet's f_пр at most) "
    "for a shallower one",
    "(6.3), (6.9), (6.11)",
    condition=BOTTOM_STOP,
)
#: The L-check's conditional steps.
CONDITIONAL_LINES = (DELTA_Z, DELTA_BZ, AT_BOTTOM_STOP)


def _measure_line(stage: str, units_at_zero: bool) -> Line:
    return MEASURE_SPAN.in_stage(stage, "(6.5), decision D5" if units_at_zero else None)


def fiducial_mm(run: Run, side: str, mark: str) -> NDArray[np.float64]:
    """The true position of fiducial ``mark`` on the ``side`` photo. [mm]"""
    position: NDArray[np.float64] = run.scene.fiducials_mm[side][int(mark) - 1]
    return position


def _measure_span(run: Run, side: Side, key: NoiseKey, active: Active, pointings: int = 1) -> Value:
    """L′: the mark on fiducial 3 then 4 of ``side``, Y read at each (the mean of
    ``pointings`` pointings and readings per mark, remedy R1)."""
    op = run.op
    ys = []
    for mark in ("3", "4"):
        y: Value = 0.0
        for j in range(pointings):
            k = key.at(side, mark, *pointing(j))
            op.mark_on(side, fiducial_mm(run, side, mark), k, active)
            y = y + op.read("Y", k)
        ys.append(y / pointings)
    return ys[0] - ys[1]


def _spans(run: Run, units_at_zero: bool) -> tuple[float, float]:
    """The L to compare with, as the sheet prints it: L⁰_л, L⁰_п with the correction units at
    zero (stage 1: n·(y₃ − y₄) of the measured marks, decision D5), else L_л, L_п of (6.5)."""
    name = "L⁰" if units_at_zero else "L"
    return run.readings[f"{name}_л"].value, run.readings[f"{name}_п"].value


def span_loop(
    run: Run,
    stage: str,
    key: KeyLike,
    units_at_zero: bool = False,
    active: Active = None,
    pointings: int = 1,
    remedy: str = "",
) -> tuple[NDArray[np.int_], Mask, Floats]:
    """The L-check loop (6.9)–(6.11) until |L − L′| ≤ 0.03/n_л for both photos."""
    op, sheet = run.op, run.sheet
    tol = sheet.tolerances["mark_span_mm"]
    span_l, span_r = _spans(run, units_at_zero)
    active = op.all() if active is None else active.copy()
    its = np.zeros(np.shape(active), int)
    dl = dr = op.v(np.nan)
    for it in range(1, op.model.max_iterations + 1):
        its = np.where(active, it, its)
        with compacted(run, active) as cut:  # the trials still outside the tolerance only
            dl_s, dr_s = _span_round(
                cut.run, stage, as_key(key).at(it), it, cut.active, (span_l, span_r),
                (cut.take(dl), cut.take(dr)), units_at_zero, pointings, remedy,
            )  # fmt: skip
        dl, dr = cut.put(dl, dl_s), cut.put(dr, dr_s)
        ok = (np.abs(dl) <= tol) & (np.abs(dr) <= tol)
        active = active & ~ok
        if not np.any(active):
            break
    ok = (np.abs(dl) <= tol) & (np.abs(dr) <= tol)
    return its, ok, np.maximum(np.abs(dl), np.abs(dr))


def _span_round(
    run: Run, stage: str, k: NoiseKey, it: int, active: Mask, spans: tuple[float, float],
    diffs: tuple[Floats, Floats], units_at_zero: bool, pointings: int, remedy: str,
) -> tuple[Floats, Floats]:  # fmt: skip
    """One pass of the L-check on ``active``: measure L′ of both photos, log, and correct the
    trials outside the tolerance; the differences L − L′ (kept where not ``active``). [mm]"""
    op = run.op
    tol = run.sheet.tolerances["mark_span_mm"]
    span_l, span_r = spans
    meas_l = _measure_span(run, "left", k, active, pointings)
    meas_r = _measure_span(run, "right", k, active, pointings)
    dl = np.where(active, span_l - meas_l, diffs[0])
    dr = np.where(active, span_r - meas_r, diffs[1])
    ok = (np.abs(dl) <= tol) & (np.abs(dr) <= tol)
    line = _measure_line(stage, units_at_zero)
    sides: tuple[tuple[Side, Floats, Value, float], ...] = (
        ("left", dl, meas_l, span_l),
        ("right", dr, meas_r, span_r),
    )
    for side, d, meas, span in sides:
        line.log(
            op, "Y", {"side": _SIDE[side], "span": span},
            reading=meas, residual=d, tolerance=tol, passed=np.abs(d) <= tol, iteration=it,
            remedy=remedy, when=active if remedy else None,
        )  # fmt: skip
    going = active & ~ok
    if np.any(going):
        _correct_span(run, stage, k, it, going, (dl, dr), spans, remedy)
    return dl, dr


def _log_delta_z(
    op: Operator,
    stage: str,
    dz_shown: float,
    depth: Value,
    dz_mm: Value,
    it: int,
    remedy: str,
    active: Mask,
) -> None:
    """Log the ΔZ (6.9) setting; the word follows the sign: the Z counter counts the projection
    distance D, so ΔZ > 0 (a larger D) lowers the carriage and ΔZ < 0 raises it. [m, mm]"""
    direction = "lower" if dz_shown > 0 else "raise" if dz_shown < 0 else "leave"
    DELTA_Z.in_stage(stage).log(
        op, "Z", {"dz": dz_shown, "direction": direction},
        before=depth, after=depth + dz_mm, reading=depth + dz_mm, iteration=it,
        remedy=remedy, when=active if remedy else None,
    )  # fmt: skip


def _past_bottom_stop(
    run: Run,
    stage: str,
    k: NoiseKey,
    it: int,
    active: Mask,
    depth: Value,
    dz_mm: Value,
    remedy: str,
) -> tuple[Mask, Value, Value]:
    """The carriage at its bottom stop D_max (switch ``bottom_stop``,
    :mod:`~stereoplotter.procedure.fidelity`).

    "both_ways" (the book's (6.11), O′_Z = O_Z + ΔZ either way): a correction that asks for a
    deeper carriage than the stop lowers it to the stop and reaches the rest of n = D/f_пр by
    shortening f_пр in the ratio D_stop/(D + ΔD); one that asks for a shallower carriage while
    f_пр is short of the sheet's value first lengthens f_пр back (at most to the sheet's
    value), and the rest raises the carriage. "one_way": a correction past the stop is taken
    whole by f_пр, f_пр·D/(D + ΔD), wherever the carriage is, and f_пр is never lengthened.
    "free": no stop, every ΔZ on Z (f_пр stays at the sheet's value).

    Returns the trials whose f_пр changed, f′_пр/f_пр of this correction (1 elsewhere) and ΔZ
    left to set on Z. [—, —, mm]
    """
    op = run.op
    mode = run.fidelity.bottom_stop
    f_ratio = op.v(1.0)
    if mode == "free":
        return np.zeros(np.shape(active), bool), f_ratio, dz_mm
    stop = op.v(op.inst.reading_of("Z", op.inst.travel_mm("Z")[1]))
    f_set = op.commanded["f_instrument"]
    beyond = active & (depth + dz_mm > stop)
    # the n this correction asks for, n′ = (D + ΔD)/f_пр, reached with D at the stop: "both_ways"
    # lowers the carriage to the stop and takes the rest by f_пр; "one_way" takes all of it by
    # f_пр wherever the carriage is
    floor = stop if mode == "both_ways" else depth
    f_new = np.where(beyond, f_set * floor / (depth + dz_mm), f_set)
    rest = np.where(beyond, floor - depth, dz_mm)  # "both_ways": down to the stop first
    if mode == "both_ways":
        f_sheet = run.target("f_пр")
        back = active & ~beyond & (dz_mm < 0.0) & (f_set < f_sheet)
        # lengthen f_пр towards the sheet's value; what it cannot take raises the carriage
        f_back = np.minimum(f_sheet, f_set * depth / (depth + dz_mm))
        f_new = np.where(back, f_back, f_new)
        whole = (depth + dz_mm) * f_sheet / f_set - depth  # ΔZ left once f_пр is the sheet's
        rest = np.where(back, np.where(f_back < f_sheet, 0.0, whole), rest)
        beyond = beyond | back
    if np.any(beyond):
        f_ratio = np.where(beyond, f_new / f_set, 1.0)
        op.set("f_instrument", f_new, k.at("setf"), beyond)
        AT_BOTTOM_STOP.in_stage(stage).log(
            op, "f_instrument", before=f_set, after=f_new, reading=f_new, iteration=it,
            remedy=remedy, when=beyond if remedy else None,
        )  # fmt: skip
    return beyond, f_ratio, rest


def _correct_span(
    run: Run,
    stage: str,
    k: NoiseKey,
    it: int,
    active: Mask,
    diffs: tuple[Floats, Floats],
    spans: tuple[float, float],
    remedy: str = "",
) -> None:
    """One correction of the L-check: ΔZ (6.9) from the left photo (or f_пр at the bottom
    stop), Δb_z (6.10) from the right, set as O′ = O + Δ (6.11).

    Decision D9 (``docs/procedure.md``, "The error-free floor"): (6.9) and (6.10) are applied
    in their ratio form, which is exact for the span of a photo (L′ = n·(y₃ − y₄), n = D/f_пр):
    ΔD = D·ΔL/L′ with the *measured* L′ in the denominator, and for the right photo its own
    projection distance D_п = D + b_z, less the change ΔZ (or the f_пр change) that the left
    correction makes to it. The printed first-order form D·ΔL_п/L_п under-corrects by the
    factor L′_п/L_п ≈ D/(D + b_z′): with b_z at zero in stage 1 it leaves b_z′²/(D + b_z′) —
    8.4 µm of b_z for pair60 (b_z′ = 1.25 mm), which the loop accepts (0.03/n_л mm of L is
    11 µm of b_z) and which shows as 6 µm of y-parallax at the standard points.
    """
    op, sheet = run.op, run.sheet
    dl, dr = diffs
    span_l, span_r = spans
    meas_l, meas_r = span_l - dl, span_r - dr  # L′ as measured
    sense = sheet.options.bz_scale_sense
    depth = op.read("Z", k.at("Z"))
    dz_m = height_correction(depth, dl, meas_l, sheet.vertical_scale_denominator)
    dz_mm = dz_m * 1000.0 / sheet.vertical_scale_denominator
    _, f_ratio, dz_mm = _past_bottom_stop(run, stage, k, it, active, depth, dz_mm, remedy)
    op.set("Z", depth + dz_mm, k.at("setZ"), active & (dz_mm != 0.0))
    shown = op.log.shown if np.ndim(dz_mm) else 0
    # logged where the ΔZ set is one the counter shows (not the carriage's last least count
    # down to the stop)
    if abs(np.ravel(dz_mm)[shown if np.size(dz_mm) > 1 else 0]) >= op.least_count("Z"):
        set_m = dz_mm * sheet.vertical_scale_denominator / 1000.0  # ΔZ set on Z [m]
        _log_delta_z(
            op,
            stage,
            float(np.ravel(set_m)[shown if np.size(set_m) > 1 else 0]),
            depth,
            dz_mm,
            it,
            remedy,
            active,
        )
    bz = op.read("bz", k.at("bz"))
    # D_п as the operator knows it: D + b_z from the b_z scale's nominal place of zero; scaled
    # by f_пр/f′_пр where f_пр was changed, less the ΔZ just set (both move the right photo)
    depth_r = (depth + sense * (bz - NOMINAL_ZERO["bz"])) * f_ratio
    dbz = (
        depth_r
        + base_z_correction(depth_r, dr, meas_r)
        - (depth + dz_mm)
        - (sense * (bz - NOMINAL_ZERO["bz"]))
    )
    op.set("bz", bz + sense * dbz, k.at("setbz"), active)
    DELTA_BZ.in_stage(stage).log(
        op, "bz", {"sign": "+" if sense > 0 else "−"},
        before=bz, after=bz + sense * dbz, reading=bz + sense * dbz, iteration=it,
        remedy=remedy, when=active if remedy else None,
    )  # fmt: skip
