"""The conventional method's map sheet: the model scaled on the plotted plan control (C3) and
the sheet laid on it (C4), as the book's conventional method does; or the setup sheet's corners
(stages 4–5 of the setup-data method, ``sheet_on="corners"``).

The plotted points are the plan control points' instrument coordinates (6.7), computed from
their SK-42 coordinates by the sheet's similarity. Units: mm (model, table, sheet).
"""

from __future__ import annotations

from dataclasses import replace
from typing import cast

import numpy as np
from numpy.typing import NDArray

from stereoplotter.constants import MM_PER_M
from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.virtual import NOMINAL_ZERO
from stereoplotter.procedure.arrays import Mask
from stereoplotter.procedure.noise_key import KeyLike, NoiseKey, as_key
from stereoplotter.procedure.records import SheetPose
from stereoplotter.procedure.run import Run
from stereoplotter.procedure.sheet_stages import (
    PLAN_CHECK,
    check_plan_control,
    needle_against_plotted,
    plotted_mm,
    sheet_needle,
    sheet_table,
    stage4_orient_sheet,
    stage5_check,
)
from stereoplotter.procedure.step_values import Line
from stereoplotter.procedure.steps import control_point_m, fuse_and_read

__all__ = [
    "SHEET_OPTIONS",
    "c4_sheet",
    "connect_coordinatograph",
    "plan_control_check",
    "plotted_control",
    "scale_on_plotted_control",
    "sheet_on_control",
]

#: How the model meets the map sheet: "control" — C3 scales the model on the plotted plan
#: control (all its points) and C4 turns and shifts the sheet onto them (the book's conventional
#: method); "corners" — C3 scales on two points' ground distance and C4 lays the sheet on the
#: setup sheet's corners (stage 4 of the setup-data method).
SHEET_OPTIONS = ("control", "corners")

#: The identity of C4's laying of the sheet on the plan control (the needles, the placement).
_PLACE = NoiseKey("4").at("place")


#: C3: the model scaled on the plotted plan control.
_SCALE_ON_PLOTTED = Line(
    "C3",
    "scale: fuse on the {n} plan control points, counters' spread against the plotted points' "
    "{spread:.3f} mm; turn b_x in proportion",
    "conventional method: the model to the scale of the plotted control",
)
#: C4: the sheet laid on the plan control's needle positions.
_LAY_SHEET = Line(
    "4",
    "lay the sheet on the needle positions of the plan control points (least squares: "
    "centroid on centroid, turned onto them)",
    "conventional method: the sheet on the plotted control",
)


def plotted_control(run: Run) -> dict[str, NDArray[np.float64]] | None:
    """The plan control points as plotted on the sheet, id → instrument coordinates (6.7)
    [mm]; None where the sheet has fewer than two (then C3 scales on two points' ground
    distance)."""
    sheet = run.sheet
    ids = tuple(sheet.similarity_point_ids)
    if sheet.similarity is None or len(ids) < 2:
        return None
    return {pid: plotted_mm(run, pid) for pid in ids}


def scale_on_plotted_control(
    run: Run, plotted: dict[str, NDArray[np.float64]], key: KeyLike, active: Mask, it: int
) -> None:
    """C3's scale on the plotted plan control (``sheet_on="control"``): fuse on every plan
    control point, read X, Y, compare the spread of the counters about their centroid (RMS
    distance) with the spread of the plotted points (6.7) — the scale of the least-squares
    similarity between them — and turn b_x in proportion, O′_bx = MO_bx + b_x·ratio. [mm]"""
    op = run.op
    key = as_key(key)
    pts = np.stack(list(plotted.values()))
    spread_plot = float(np.sqrt(((pts - pts.mean(axis=0)) ** 2).sum(axis=-1).mean()))
    points = []
    for pid in plotted:
        r = fuse_and_read(run, control_point_m(run, pid), key.at("scale", pid), active, ("X", "Y"))
        points.append(np.stack([r["X"], r["Y"]], axis=-1))
    xy = np.stack(points, axis=-2)
    d = xy - xy.mean(axis=-2, keepdims=True)
    spread = np.sqrt((d**2).sum(axis=-1).mean(axis=-1))
    with np.errstate(divide="ignore", invalid="ignore"):  # trials at rest may read d = 0
        ratio = np.where(active, spread_plot / spread, 1.0)
    bx = op.read("bx", key.at("bx"))
    new = NOMINAL_ZERO["bx"] + (bx - NOMINAL_ZERO["bx"]) * ratio
    op.set("bx", new, key.at("setbx"), active)
    _SCALE_ON_PLOTTED.log(
        op, "bx", {"n": len(plotted), "spread": spread_plot},
        before=bx, after=new, reading=new, residual=spread - spread_plot, iteration=it,
    )  # fmt: skip


def connect_coordinatograph(run: Run) -> None:
    """The coordinatograph connected at the sheet's ratio M_г/M_map (and, with the SC
    complex's automatic coordinatograph, its photo → map enlargement), as stage 4 does."""
    op, sheet = run.op, run.sheet
    map_scale = cast(int, sheet.map_scale_denominator)  # a sheet on plan control has its scale
    ratio = sheet.horizontal_scale_denominator / map_scale
    enlargement = None
    if op.inst.options.automatic_coordinatograph:
        scene = run.scene
        photo_scale = MM_PER_M * scene.flying_height_m / float(scene.camera.focal_length_mm)
        enlargement = photo_scale / map_scale
    op.inst.connect_coordinatograph(ratio, enlargement=enlargement)


def _needles_on(run: Run, ids: tuple[str, ...], key: NoiseKey) -> NDArray[np.float64]:
    """Fuse on each plan control point and put the needle down: table positions (T, n, 2)."""
    out = []
    for pid in ids:
        fuse_and_read(run, control_point_m(run, pid), key.at(pid), None, ())
        out.append(sheet_needle(run, key.at(pid)))
    return np.stack(out, axis=-2)


def sheet_on_control(run: Run) -> None:
    """C4 (``sheet_on="control"``): the map sheet laid on its plotted plan control points, as
    the conventional method does (the model was brought to the scale of the plotted control in
    C3, :func:`scale_on_plotted_control`): fuse on each plan control point, put the needle down,
    and lay the sheet so that the plotted points lie on the needle positions in the
    least-squares sense (rigid: centroid on centroid, the rotation of the closed-form 2-D fit),
    with the sheet placement error (injected) and the operator's monocular σ at the centroid and
    across the points' spread. Units: mm on the table.
    """
    op, sheet = run.op, run.sheet
    ids = tuple(sheet.similarity_point_ids)
    if sheet.similarity is None or len(ids) < 2:
        stage4_orient_sheet(run)
        return
    connect_coordinatograph(run)
    plotted = np.stack([sheet_table(run, plotted_mm(run, pid)) for pid in ids])  # (n, 2)
    centre = plotted.mean(axis=0)
    d_plot = plotted - centre
    needles = _needles_on(run, ids, _PLACE)
    n_centre = needles.mean(axis=-2)
    d_needle = needles - n_centre[..., None, :]
    cross = (d_plot[..., 0] * d_needle[..., 1] - d_plot[..., 1] * d_needle[..., 0]).sum(-1)
    dot = (d_plot[..., 0] * d_needle[..., 0] + d_plot[..., 1] * d_needle[..., 1]).sum(-1)
    inj = op.inst.injected
    place = np.stack(
        [
            op.v(inj["coordinatograph.sheet_placement_x"]),
            op.v(inj["coordinatograph.sheet_placement_y"]),
        ],
        axis=-1,
    )
    sigma = op.model.monocular_sigma_mm
    e = np.stack([op.noise.draw(_PLACE.at(a).by("mono"), sigma) for a in "xy"], axis=-1)
    spread_plot = float(np.sqrt((d_plot**2).sum(axis=-1).mean()))
    e_turn = op.noise.draw(_PLACE.at("turn").by("mono"), sigma) / spread_plot
    angle = np.arctan2(cross, dot) + e_turn
    run.sheet_pose = SheetPose(angle, centre + place + e, n_centre)
    _LAY_SHEET.log(op)
    run.record_stage("4", op.v(2).astype(int))


def plan_control_check(run: Run) -> None:
    """The check of a sheet laid on its plan control: fuse on each plan control point, the
    needle against the plotted point; the largest distance against the corner tolerance (the
    same comparison as stage 5's, its tolerance 0.3 mm). Corner 4 is not checked: its counter
    readings are those of the setup-data model, which the conventional method does not build.
    """
    op, sheet = run.op, run.sheet
    pose = run.sheet_pose
    if pose is None or sheet.similarity is None:
        return
    errs = []
    for pid in sheet.similarity_point_ids:
        fuse_and_read(run, control_point_m(run, pid), PLAN_CHECK.at(pid), None, ())
        errs.append(needle_against_plotted(run, pose, pid, plotted_mm(run, pid)))
    check_plan_control(run, errs)
    run.record_stage("5", op.v(1).astype(int))


def c4_sheet(run: Run, sheet_on: str = "control") -> None:
    """C4: the sheet on the coordinatograph — on its plotted plan control points
    (:func:`sheet_on_control`, default) or on the setup sheet's corners (stage 4 of the
    setup-data method) — then corner 4 and the plotted plan control (stage 5)."""
    if sheet_on not in SHEET_OPTIONS:
        raise StereoplotterError(
            f"sheet_on: expected one of {', '.join(SHEET_OPTIONS)}, found {sheet_on!r}"
        )
    log = run.op.log
    start = len(log.records)
    if sheet_on == "control":
        sheet_on_control(run)
        plan_control_check(run)
    else:
        stage4_orient_sheet(run)
        stage5_check(run)
    log.records[start:] = [replace(r, stage="C4") for r in log.records[start:]]
    for old, new in (("4", "C4"), ("5", "C4/check")):
        if old in run.stages:
            run.record_stage(new, run.stages.pop(old).iterations)
