"""What ``stereoplotter demo`` prints and writes: its summary text and the measurements CSV."""

from __future__ import annotations

import csv
import io
from typing import Any

from stereoplotter.report.scenario import format_summary

__all__ = ["format_demo", "measurements_csv"]


def measurements_csv(scenario: Any, measurements: Any) -> str:
    """Every simulated measurement of the demo: fiducials, points and grid, true and measured
    [mm], one row each."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["photo", "kind", "id", "x_true_mm", "y_true_mm", "x_mm", "y_mm"])
    for pm in measurements.photos:
        for name, t, m in zip(
            ("1", "2", "3", "4"), pm.fiducials_true_mm, pm.fiducials_mm, strict=True
        ):
            writer.writerow([pm.photo, "fiducial", name, *(f"{v:.6f}" for v in (*t, *m))])
        for pid, t, m, ok in zip(
            measurements.point_ids, pm.points_true_mm, pm.points_mm, pm.points_imaged, strict=True
        ):
            if ok:
                role = scenario.points[measurements.point_ids.index(pid)].role
                writer.writerow([pm.photo, role, pid, *(f"{v:.6f}" for v in (*t, *m))])
        for i, (t, m) in enumerate(zip(pm.grid_true_mm, pm.grid_mm, strict=True)):
            writer.writerow([pm.photo, "grid", f"G{i + 1}", *(f"{v:.6f}" for v in (*t, *m))])
    return out.getvalue()


def format_demo(result: dict[str, Any]) -> str:
    """The demo's Markdown summary of :func:`~stereoplotter.scenario.foundation.run_foundation`."""
    s = result["summary"]
    lines = [
        f"# stereoplotter demo: {s['name']}",
        "",
        format_summary(s).rstrip(),
        "",
        f"f′ of the pair from the measured fiducials: "
        f"{result['focal_length_corrected_mm']} mm "
        f"(per photo {result['focal_length_corrected_per_photo_mm']} mm)",
        "",
    ]
    for e in result["exterior"]:
        lines.append(
            f"photo {e['photo']}: exterior orientation {e['source']}; error against "
            f"the truth: angles {e['error_angles_arcsec']}″, centre "
            f"{e['error_centre_m']} m"
        )
    inter = result.get("intersection")
    if inter:
        lines += [
            "",
            "space intersection of the measured points (error = intersected − true):",
            "",
            "| point | role | dX m | dY m | dZ m | dZ ‰H | ray miss m |",
            "|---|---|---|---|---|---|---|",
        ]
        for row in inter["points"]:
            dx, dy, dz = row["error_m"]
            lines.append(
                f"| {row['id']} | {row['role']} | {dx:+.3f} | {dy:+.3f} | {dz:+.3f} | "
                f"{row['error_height_permille_H']:+.3f} | {row['ray_miss_m']:.3f} |"
            )
        lines.append("")
        for role, st in inter["statistics"].items():
            lines.append(
                f"{role} points ({st['count']}): RMS plan {st['rms_plan_m']} m, "
                f"RMS height {st['rms_height_m']} m, max |dZ| {st['max_abs_height_m']} m"
            )
    sim = result.get("similarity")
    if sim:
        lines += [
            "",
            f"similarity (6.8) Gauss–Krüger → photogrammetric: a = {sim['a']:.4e}, "
            f"b = {sim['b']:.9f}, c_X = {sim['cx_m']:.3f} m, c_Y = {sim['cy_m']:.3f} m, "
            f"det = {sim['determinant']:.9f}; RMS residual {sim['rms_m']} m",
        ]
    return "\n".join(lines) + "\n"
