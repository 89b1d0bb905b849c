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

from stereoplotter import __version__
from stereoplotter.constants import ARCSEC_PER_RAD
from stereoplotter.triangulation.block import Block, sk42_from_block_local
from stereoplotter.triangulation.solution import (
    BlockSolution,
    CatalogueResiduals,
    photo_residuals,
)

__all__ = ["orientation_csv", "report_markdown", "residual_csv"]

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
    """One row per catalogue point measured on the photos: triangulated minus catalogue [m]."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(("id", "role", "kind", "rays", "vX_m", "vY_m", "vZ_m"))
    for k, i in enumerate(residuals.index):
        c = block.catalogue[i]
        v = residuals.residuals_m[k]
        w.writerow((c.id, c.role, c.kind, int(residuals.rays[k]), *(f"{x:.3f}" for x in v)))
    return buf.getvalue()


def _rms_row(block: Block, residuals: CatalogueResiduals, role: str) -> str:
    n = sum(1 for i in residuals.index if block.catalogue[i].role == role)
    rms = residuals.rms(block, role)
    return f"| {role} | {n} | {rms[0]:.3f} | {rms[1]:.3f} | {rms[2]:.3f} |"


def report_markdown(
    block: Block, solution: BlockSolution, residuals: CatalogueResiduals, source: str
) -> str:
    """The Markdown report: the block, the method, σ₀, RMS at control and check points, the
    largest residuals, the photo residuals and the figure ``residuals.png``."""
    v = photo_residuals(block, solution)
    photo_rms = float(np.sqrt(np.nanmean(v**2)))
    se = solution.standard_errors
    lines = [
        f"# Phototriangulation of block {block.name}",
        "",
        f"Block file `{Path(source).name}`: {len(block.strips)} strips, {len(block.photos)} "
        f"photos, {block.obs_photo.size} point measurements, {len(block.catalogue)} catalogue "
        f"points; f = {block.camera.focal_length_mm:g} mm. Method **{solution.method}**, "
        f"{solution.iterations} iterations, σ₀ = {solution.sigma0:.3f} (a posteriori, in units "
        f"of the a priori σ = {block.sigmas.photo_mm * 1000:g} µm per photo coordinate). "
        f"Written by stereoplotter {__version__}.",
        "",
        *[f"- {n}" for n in solution.notes],
        "",
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
        f"RMS photo residual (measured − computed by (2.53)): {photo_rms * 1000:.2f} µm.",
        "",
    ]
    if se is not None:
        mean = np.sqrt(np.mean(se**2, axis=0))
        lines += [
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
    worst = np.argsort(-np.linalg.norm(np.nan_to_num(residuals.residuals_m), axis=1))[:10]
    lines += [
        "## The ten largest residuals [m]",
        "",
        "| point | role | kind | rays | vX | vY | vZ |",
        "|---|---|---|---:|---:|---:|---:|",
    ]
    for k in worst:
        c = block.catalogue[residuals.index[k]]
        vx, vy, vz = residuals.residuals_m[k]
        lines.append(
            f"| {c.id} | {c.role} | {c.kind} | {residuals.rays[k]} | {vx:.3f} | {vy:.3f} | "
            f"{vz:.3f} |"
        )
    lines += ["", "Orientations with their σ: `orientations.csv`; residuals: `residuals.csv`.", ""]
    return "\n".join(lines)
