"""The outputs of ``stereoplotter triangulate``: orientation and residual tables, the report.

Angles are written in degrees (their σ in arc seconds), coordinates in metres: local X, Y, Z of
the block's system of §10 and SK-42 x, ȳ, H of the centres.
"""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from stereoplotter import __version__
from stereoplotter.constants import ARCSEC_PER_RAD
from stereoplotter.triangulation.block import Block, sk42_from_block_local
from stereoplotter.triangulation.bundle import BundleProblem
from stereoplotter.triangulation.reliability import (
    CENTRE_NAMES,
    CONTROL_NAMES,
    Flag,
    ObservationReliability,
    SnoopingResult,
)
from stereoplotter.triangulation.self_calibration import CameraCalibration, camera_calibration
from stereoplotter.triangulation.solution import (
    BlockSolution,
    CatalogueResiduals,
    photo_residuals,
)

__all__ = [
    "catalogue_observations_csv",
    "flagged_csv",
    "observations_csv",
    "orientation_csv",
    "points_csv",
    "report_markdown",
    "residual_csv",
]

_ORIENTATION_COLUMNS = (
    "photo",
    "strip",
    "alpha_deg",
    "omega_deg",
    "kappa_deg",
    "X_m",
    "Y_m",
    "Z_m",
    "north_m",
    "east_m",
    "height_m",
    "s_alpha_arcsec",
    "s_omega_arcsec",
    "s_kappa_arcsec",
    "s_X_m",
    "s_Y_m",
    "s_Z_m",
)


def orientation_csv(block: Block, solution: BlockSolution) -> str:
    """One row per photo: α, ω, κ [°], local X_S, Y_S, Z_S and SK-42 x, ȳ, H [m], their σ
    (empty where the method gives none)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(_ORIENTATION_COLUMNS)
    sk42 = sk42_from_block_local(block, solution.orientations[:, 3:])
    se = solution.standard_errors
    strip = block.strip_of_photo
    for j, p in enumerate(block.photos):
        o = solution.orientations[j]
        angles = [f"{math.degrees(float(v)):.6f}" for v in o[:3]]
        xyz = [f"{v:.3f}" for v in o[3:]]
        geo = [f"{v:.3f}" for v in sk42[j]]
        sig = (
            [f"{v * ARCSEC_PER_RAD:.2f}" for v in se[j, :3]] + [f"{v:.3f}" for v in se[j, 3:]]
            if se is not None
            else [""] * 6
        )
        w.writerow([p, int(strip[j]) + 1, *angles, *xyz, *geo, *sig])
    return buf.getvalue()


def residual_csv(block: Block, residuals: CatalogueResiduals) -> str:
    """One row per catalogue point measured on the photos: triangulated minus catalogue [m];
    a point measured on one photo has no values and the note ``not intersected``."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(("id", "role", "kind", "rays", "vX_m", "vY_m", "vZ_m", "note"))
    for k, i in enumerate(residuals.index):
        c = block.catalogue[i]
        v = residuals.residuals_m[k]
        rays = int(residuals.rays[k])
        if np.all(np.isfinite(v)):
            w.writerow((c.id, c.role, c.kind, rays, *(f"{x:.3f}" for x in v), ""))
        else:
            w.writerow((c.id, c.role, c.kind, rays, "", "", "", f"not intersected ({rays} photo)"))
    return buf.getvalue()


def _point_roles(block: Block) -> list[tuple[str, str]]:
    """(role, kind) of every measured point: the catalogue's, or (tie, '') for the others."""
    cat = {c.id: (c.role, c.kind) for c in block.catalogue}
    return [cat.get(pid, ("tie", "")) for pid in block.point_ids]


def points_csv(block: Block, solution: BlockSolution) -> str:
    """One row per measured point (tie, control, check): the adjusted local X, Y, Z [m] and
    their σ (``s_X_m`` …; empty where the method gives none); a point measured on one photo
    has no values and the note ``not intersected``."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(("point", "role", "kind", "rays", "X_m", "Y_m", "Z_m", "s_X_m", "s_Y_m", "s_Z_m",
                "note"))  # fmt: skip
    rays = np.bincount(block.obs_point, minlength=len(block.point_ids))
    se = solution.point_standard_errors
    for i, (pid, (role, kind)) in enumerate(zip(block.point_ids, _point_roles(block), strict=True)):
        x = solution.points_m[i]
        if not np.all(np.isfinite(x)):
            w.writerow((pid, role, kind, int(rays[i]), "", "", "", "", "", "",
                        f"not intersected ({int(rays[i])} photo)"))  # fmt: skip
            continue
        sig = [f"{v:.4f}" for v in se[i]] if se is not None else ["", "", ""]
        w.writerow((pid, role, kind, int(rays[i]), *(f"{v:.3f}" for v in x), *sig, ""))
    return buf.getvalue()


def flagged_csv(flags: tuple[Flag, ...]) -> str:
    """One row per flagged observation: photo ('' for a catalogue observation), point,
    observation (x_mm, y_mm, X_m, Y_m, height_m), w, MDB (in the observation's unit), and the
    observations it cannot be told from."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(("photo", "point", "observation", "w", "mdb", "inseparable_from"))
    for f in flags:
        w.writerow((f.photo, f.point, f.observation, f"{f.w:.2f}", f"{f.mdb:.4f}",
                    "; ".join(f.inseparable)))  # fmt: skip
    return buf.getvalue()


def catalogue_observations_csv(problem: BundleProblem, rel: ObservationReliability) -> str:
    """One row per catalogue coordinate of a control point and per coordinate of a measured
    projection centre: residual v = measured − adjusted [m], w, r, MDB [m] and (control) the
    MDB's effect on the point [m]; the photo empty for a control point, the point for a centre."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(("photo", "point", "observation", "v_m", "w", "r", "mdb_m", "effect_m"))
    for j in range(problem.control_point.size):
        for c, name in enumerate(CONTROL_NAMES):
            if problem.control_weight[j, c] <= 0:
                continue
            w.writerow((
                "", problem.point_ids[problem.control_point[j]], name,
                f"{rel.control_v[j, c]:.4f}", f"{rel.control_w[j, c]:.2f}",
                f"{rel.control_r[j, c]:.3f}", f"{rel.control_mdb[j, c]:.3f}",
                f"{rel.control_effect[j, c]:.3f}",
            ))  # fmt: skip
    for g in range(problem.centre_photo.size):
        for c, name in enumerate(CENTRE_NAMES):
            if problem.centre_weight[g, c] <= 0:
                continue
            w.writerow((
                problem.photo_ids[problem.centre_photo[g]], "", name,
                f"{rel.centre_v[g, c]:.4f}", f"{rel.centre_w[g, c]:.2f}",
                f"{rel.centre_r[g, c]:.3f}", f"{rel.centre_mdb[g, c]:.3f}", "",
            ))  # fmt: skip
    return buf.getvalue()


def observations_csv(block: Block, problem: BundleProblem, rel: ObservationReliability) -> str:
    """One row per photo measurement of the adjustment (tie points included): residual v =
    measured − computed [µm], standardized residual w, redundancy number r, MDB [µm] and the
    MDB's effect on the point [m], for x and y."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(("photo", "point", "role", "v_x_um", "v_y_um", "w_x", "w_y", "r_x", "r_y",
                "mdb_x_um", "mdb_y_um", "effect_x_m", "effect_y_m"))  # fmt: skip
    roles = _point_roles(block)
    for o in range(problem.obs_photo.size):
        i = int(problem.obs_point[o])
        w.writerow((
            problem.photo_ids[problem.obs_photo[o]], block.point_ids[i], roles[i][0],
            *(f"{v * 1000:.2f}" for v in rel.photo_v[o]), *(f"{v:.2f}" for v in rel.photo_w[o]),
            *(f"{v:.3f}" for v in rel.photo_r[o]), *(f"{v * 1000:.1f}" for v in rel.photo_mdb[o]),
            *(f"{v:.3f}" for v in rel.photo_effect[o]),
        ))  # fmt: skip
    return buf.getvalue()


def _num(x: float, fmt: str) -> str:
    """A number, or a dash where there is none (no NaN in a report)."""
    return format(x, fmt) if np.isfinite(x) else "—"


def _rms_row(block: Block, residuals: CatalogueResiduals, role: str) -> str:
    n = sum(1 for i in residuals.index if block.catalogue[i].role == role)
    rms = residuals.rms(block, role)
    return f"| {role} | {n} | " + " | ".join(_num(float(v), ".3f") for v in rms) + " |"


def _photo_rms(block: Block, v: NDArray) -> tuple[NDArray, NDArray]:
    """Per photo: number of measurements with a residual and RMS of x and y [mm] (NaN: none)."""
    ok = np.all(np.isfinite(v), axis=1)
    n = np.bincount(block.obs_photo[ok], minlength=len(block.photos))
    ss = np.zeros((len(block.photos), 2))
    np.add.at(ss, block.obs_photo[ok], v[ok] ** 2)
    with np.errstate(invalid="ignore", divide="ignore"):
        return n, np.sqrt(ss / n[:, None])


def _snooping_lines(block: Block, sn: SnoopingResult, reject: bool) -> list[str]:
    """The section "Tests after Baarda": global test, data snooping, flags and reliability."""
    rel = sn.reliability if reject else sn.reliability_first
    prob = sn.problem_last if reject else sn.problem_first
    return [
        *_test_lines(sn, reject),
        *_flag_lines(sn, reject),
        *_reliability_table_lines(rel),
        *_reliability_note_lines(block, prob, rel),
    ]


def _test_lines(sn: SnoopingResult, reject: bool) -> list[str]:
    """The global test of σ₀ and how data snooping (or robust re-weighting) went."""
    rel = sn.reliability if reject else sn.reliability_first
    g = sn.global_test if reject else sn.global_test_first
    verdict = (
        "accepted"
        if g.passed
        else "**rejected**: the a priori σ do not describe the residuals (a blunder, a wrong σ "
        "or an error the model lacks — e.g. the fiducial marks' error, which moves all points "
        "of a photo together)"
    )
    return [
        "## Tests after Baarda",
        "",
        f"Global test of σ₀ (χ², two-sided, α = 5 %): σ₀ = {g.sigma0:.3f} on a redundancy of "
        f"{g.redundancy}; acceptance interval {g.low:.3f}–{g.high:.3f}, p = {g.p_value:.2g}: "
        f"{verdict}"
        + (
            ("." if not reject else " (after the flagged observations were removed).")
            if sn.method == "snooping"
            else " (after the re-weighting)."
        ),
        "",
        f"Data snooping (w-test, a priori σ₀ = 1) on {rel.n_tests} observations: α₀ = "
        f"{rel.alpha0:.2e} per test (family-wise 5 % by Šidák), critical value k = {rel.k:.2f}; "
        f"β₀ = 80 %, δ₀ = {rel.delta0:.2f}. "
        + (
            "Iterated: the largest |w| above k removed and the block readjusted, until none is "
            "above k."
            if sn.method == "snooping"
            else f"Instead of removing: {sn.method} re-weighting, t = v/(σ·√r) with the a "
            "priori σ, weight × exp(1 − |t|/k) (Danish) or × k/|t| (Huber) beyond k, until the "
            "weights settle; the table lists the down-weighted observations with their t."
        ),
        "",
    ]


def _flag_lines(sn: SnoopingResult, reject: bool) -> list[str]:
    """The flagged observations' table (or "No observation flagged.")."""
    if not sn.flags:
        return ["No observation flagged.", ""]
    lines = [
        "| round | photo | point | observation | w | MDB | cannot be told from |",
        "|---:|---|---|---|---:|---:|---|",
    ]
    for f in sn.flags:
        photo_mm = f.observation.endswith("_mm")
        unit = "µm" if photo_mm else "m"
        mdb = f.mdb * 1000 if photo_mm else f.mdb
        lines.append(
            f"| {f.round} | {f.photo or '(catalogue)'} | {f.point or '(centre)'} | "
            f"{f.observation} | {f.w:.1f} | {mdb:.3g} {unit} | "
            f"{', '.join(f.inseparable) or '—'} |"
        )
    return [
        *lines,
        "",
        "Flagged observations one per line: `flagged.csv`. "
        + (
            "They were removed and the block readjusted (`--reject`): the results below "
            "are without them."
            if reject
            else "The results below still hold them: `--reject` removes them and readjusts."
        ),
        "",
    ]


def _reliability_row(
    name: str, r: NDArray, mdb: NDArray, effect: NDArray, unit: str, k: float
) -> str:
    """One row of the reliability table: n, r min and mean, uncontrolled, median MDB (× k into
    the unit), largest effect of a controlled observation."""
    ok = np.isfinite(r)
    controlled = ok & (r >= 0.01)
    r, mdb, effect = r[ok], mdb[ok], effect[controlled]
    if not r.size:
        return f"| {name} | 0 | — | — | — | — | — |"
    weak = int(np.count_nonzero(r < 0.01))
    return (
        f"| {name} | {r.size} | {r.min():.3f} | {r.mean():.3f} | {weak} | "
        f"{np.median(mdb) * k:.3g} {unit} | "
        + (f"{np.max(effect):.3f} m |" if effect.size else "— |")
    )


def _reliability_table_lines(rel: ObservationReliability) -> list[str]:
    """The reliability table: photo coordinates, control, projection centres (if measured)."""
    lines = [
        "Reliability (of the adjustment the report gives; every measurement in "
        "`observations.csv`):",
        "",
        "| observations | n | r min | r mean | r < 0.01 | median MDB | largest effect (r ≥ 0.01) |",
        "|---|---:|---:|---:|---:|---:|---:|",
        _reliability_row("photo x, y", rel.photo_r, rel.photo_mdb, rel.photo_effect, "µm", 1000.0),
        _reliability_row(
            "control X, Y, height", rel.control_r, rel.control_mdb, rel.control_effect, "m", 1.0
        ),
    ]
    if rel.centre_r.size:
        none = np.full_like(rel.centre_r, np.nan)
        lines.append(
            _reliability_row("projection centres", rel.centre_r, rel.centre_mdb, none, "m", 1.0)
        )
    lines.append("")
    return lines


def _reliability_note_lines(
    block: Block, prob: BundleProblem, rel: ObservationReliability
) -> list[str]:
    """What r, MDB and effect mean, and where the largest effect is."""
    worst = int(np.argmax(rel.photo_effect.max(axis=1))) if rel.photo_r.size else 0
    pr = rel.photo_r
    return [
        "r: redundancy number (share of an error the residual shows); MDB = δ₀·σ/√r the "
        "smallest blunder found with probability β₀; its effect: how far such a blunder, "
        "undetected, moves the point. An observation with r < 0.01 is not controlled (x on a "
        "point of two photos of one strip: a blunder there moves the point without a residual)"
        + (
            f" (largest at photo {prob.photo_ids[prob.obs_photo[worst]]}, "
            f"point {block.point_ids[prob.obs_point[worst]]})."
            if pr.size
            else "."
        ),
        "",
    ]


def _camera_lines(c: CameraCalibration) -> list[str]:
    verdict = "significant" if c.group_significant else "not significant"
    lines = [
        "## Self-calibration of the camera",
        "",
        f"Group test of all {len(c.names)} parameters against the certificate: F = "
        f"{c.f_statistic:.2f}, critical F = {c.f_critical:.2f} (α = {c.alpha:g}), p = "
        f"{c.p_value:.2g}: **{verdict}**. Each alone: |t| against {c.t_critical:.2f} "
        f"(α = {c.alpha:g} shared by the {len(c.names)}, Bonferroni).",
        "",
        "The production job (`job.yaml`) carries the adjusted f and principal point; the "
        "distortion parameters have no place in a job and are given here only.",
        "",
        "| parameter | certificate | adjusted | σ | t | significant |",
        "|---|---:|---:|---:|---:|---|",
    ]
    for k, name in enumerate(c.names):
        lines.append(
            f"| {name} [{c.units[k]}] | {c.certificate[k]:.6g} | {c.values[k]:.6g} | "
            f"{c.sigma[k]:.3g} | {c.t[k]:+.2f} | {'yes' if c.significant[k] else 'no'} |"
        )
    lines += ["", "Correlations:", "", "| | " + " | ".join(c.names) + " |",
              "|---|" + "---:|" * len(c.names)]  # fmt: skip
    for k, name in enumerate(c.names):
        lines.append(f"| {name} | " + " | ".join(f"{v:+.2f}" for v in c.correlation[k]) + " |")
    return [*lines, ""]


def report_markdown(
    block: Block,
    solution: BlockSolution,
    residuals: CatalogueResiduals,
    source: str,
    snooping: SnoopingResult | None = None,
    reject: bool = False,
) -> str:
    """The Markdown report: the block, the method, σ₀, the tests after Baarda and the flagged
    observations (bundle), RMS at control and check points, the largest residuals, the σ of
    the points and orientations, the residuals photo by photo and the figure ``residuals.png``.
    No NaN: a value that does not exist is a dash."""
    v = photo_residuals(block, solution)
    lines = _header_lines(block, solution, source)
    if snooping is not None:
        lines += _snooping_lines(block, snooping, reject)
        prob = snooping.problem_last if reject else snooping.problem_first
        if prob.camera_free:
            adj = snooping.last if reject else snooping.first
            lines += _camera_lines(camera_calibration(prob, adj))
    lines += _catalogue_residual_lines(block, residuals, v)
    lines += _point_precision_lines(block, solution)
    lines += _orientation_precision_lines(solution)
    lines += _largest_residual_lines(block, residuals)
    lines += _photo_residual_lines(block, v)
    lines += _file_lines(snooping is not None)
    return "\n".join(lines)


def _header_lines(block: Block, solution: BlockSolution, source: str) -> list[str]:
    """Title, the block file, the method, iterations, σ₀ and the solution's notes."""
    return [
        f"# Phototriangulation of block {block.name}",
        "",
        f"Block file `{Path(source).name}`: {len(block.strips)} strips, {len(block.photos)} "
        f"photos, {block.obs_photo.size} point measurements, {len(block.catalogue)} catalogue "
        f"points; f = {block.camera.focal_length_mm:g} mm. Method **{solution.method}**, "
        f"{solution.iterations} iterations, σ₀ = {_num(solution.sigma0, '.3f')} (a posteriori, "
        f"in units of the a priori σ = {block.sigmas.photo_mm * 1000:g} µm per photo "
        f"coordinate). Written by stereoplotter {__version__}.",
        "",
        *[f"- {n}" for n in solution.notes],
        "",
    ]


def _catalogue_residual_lines(block: Block, residuals: CatalogueResiduals, v: NDArray) -> list[str]:
    """RMS at control and check points, the vector figure, the RMS photo residual [µm]."""
    ok = np.all(np.isfinite(v), axis=1)
    photo_rms = float(np.sqrt(np.mean(v[ok] ** 2))) if ok.any() else float("nan")
    return [
        "## Residuals at control and check points (triangulated − catalogue) [m]",
        "",
        "| role | points | RMS X | RMS Y | RMS Z |",
        "|---|---:|---:|---:|---:|",
        _rms_row(block, residuals, "control"),
        _rms_row(block, residuals, "check"),
        "",
        "Height points count in Z only, plan points in X and Y only. The vectors over the block:",
        "",
        "![residual vectors](residuals.png)",
        "",
        f"RMS photo residual (measured − computed by (2.53)): {_num(photo_rms * 1000, '.2f')} µm "
        f"over {int(ok.sum())} of {ok.size} measurements"
        + (f" ({ok.size - int(ok.sum())} of points not intersected)." if not ok.all() else "."),
        "",
    ]


def _point_precision_lines(block: Block, solution: BlockSolution) -> list[str]:
    """RMS of the points' σ by role and how the σ were found (none without point σ)."""
    pse = solution.point_standard_errors
    if pse is None:
        return []
    roles = np.array([r for r, _ in _point_roles(block)])
    lines = [
        "## Precision of the points (RMS of the σ; every point in `points.csv`) [m]",
        "",
        "| points | n | σX | σY | σZ |",
        "|---|---:|---:|---:|---:|",
    ]
    for role in ("tie", "control", "check"):
        m = (roles == role) & np.all(np.isfinite(pse), axis=1)
        if m.any():
            rms = np.sqrt(np.mean(pse[m] ** 2, axis=0))
            lines.append(f"| {role} | {int(m.sum())} | " + " | ".join(f"{x:.3f}" for x in rms)
                         + " |")  # fmt: skip
    how = (
        "σ = σ₀·√(diagonal of N⁻¹), from the selected inverse of the normal equations (no "
        "dense inverse)."
        if solution.method == "bundle"
        else "σ propagated through the polynomial adjustment with its a posteriori σ₀ "
        "(model coordinates independent)."
        if solution.method == "strip"
        else "σ by an empirical rule: the RMS residual at the control points, per axis."
    )
    return [*lines, "", f"{how} Plan σ ellipses and σ_Z over the block:", "",
            "![precision of the points](precision.png)", ""]  # fmt: skip


def _orientation_precision_lines(solution: BlockSolution) -> list[str]:
    """RMS over the photos of the orientations' σ (none without them)."""
    se = solution.standard_errors
    if se is None:
        return []
    mean = np.sqrt(np.mean(se**2, axis=0))
    return [
        "## Precision of the orientations (RMS of the σ over the photos)",
        "",
        "| σα ″ | σω ″ | σκ ″ | σX_S m | σY_S m | σZ_S m |",
        "|---:|---:|---:|---:|---:|---:|",
        "| "
        + " | ".join(
            [f"{x * ARCSEC_PER_RAD:.1f}" for x in mean[:3]] + [f"{x:.3f}" for x in mean[3:]]
        )
        + " |",
        "",
    ]


def _largest_residual_lines(block: Block, residuals: CatalogueResiduals) -> list[str]:
    """The ten catalogue points with the largest residual vectors."""
    worst = np.argsort(-np.linalg.norm(np.nan_to_num(residuals.residuals_m), axis=1))[:10]
    lines = [
        "## The ten largest residuals [m]",
        "",
        "| point | role | kind | rays | vX | vY | vZ |",
        "|---|---|---|---:|---:|---:|---:|",
    ]
    for k in worst:
        c = block.catalogue[residuals.index[k]]
        vals = residuals.residuals_m[k]
        cells = (
            " | ".join(f"{x:.3f}" for x in vals)
            if np.all(np.isfinite(vals))
            else "not intersected | | "
        )
        lines.append(f"| {c.id} | {c.role} | {c.kind} | {residuals.rays[k]} | {cells} |")
    return lines


def _photo_residual_lines(block: Block, v: NDArray) -> list[str]:
    """RMS photo residuals photo by photo [µm] with the figure ``photo_residuals.png``."""
    n, rms = _photo_rms(block, v)
    lines = [
        "",
        "## Photo residuals photo by photo (RMS, measured − computed) [µm]",
        "",
        "![photo residuals](photo_residuals.png)",
        "",
        "| photo | strip | points | RMS x | RMS y |",
        "|---|---:|---:|---:|---:|",
    ]
    strip = block.strip_of_photo
    for j, photo in enumerate(block.photos):
        lines.append(
            f"| {photo} | {int(strip[j]) + 1} | {int(n[j])} | {_num(rms[j, 0] * 1000, '.2f')} | "
            f"{_num(rms[j, 1] * 1000, '.2f')} |"
        )
    return lines


def _file_lines(snooped: bool) -> list[str]:
    """Where the tables are: the CSV files written beside the report."""
    return [
        "",
        "Orientations with their σ: `orientations.csv`; points with their σ: `points.csv`; "
        "residuals at catalogue points: `residuals.csv`"
        + (
            "; every observation's residual, w, r and MDB: `observations.csv` (photo "
            "coordinates) and `catalogue_observations.csv` (control and centres); flagged "
            "observations: `flagged.csv`."
            if snooped
            else "."
        ),
        "",
    ]
