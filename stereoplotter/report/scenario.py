"""The text summary of a scenario (``scenario check``, the head of ``demo``)."""

from __future__ import annotations

from typing import Any

__all__ = ["format_summary"]


def format_summary(s: dict[str, Any]) -> str:
    """The text of :func:`~stereoplotter.scenario.summarize_scenario`'s summary."""
    lines = [f"scenario {s['name']} ({s['file']}): valid", f"  {s['description']}".rstrip(), ""]
    cam = s["camera"]
    lines.append(
        f"camera: f = {cam['focal_length_mm']} mm, format {cam['format_mm']} mm, "
        f"principal point {cam['principal_point_mm']} mm, fiducials given as "
        f"{cam['fiducials_given_as']}"
    )
    lines.append(f"frame: {s['frame']}")
    for p in s["photos"]:
        lines.append(
            f"photo {p['name']}: S = {p['projection_centre_m']} m, α = {p['alpha_deg']}°, "
            f"ω = {p['omega_deg']}°, κ = {p['kappa_deg']}° ({p['exterior_source']}); "
            f"H = {p['flying_height_m']} m, photo scale 1:{p['photo_scale_denominator']:.0f}; "
            f"{p['points_imaged']} points imaged"
        )
    if "base" in s:
        b = s["base"]
        lines.append(
            f"base: B = {b['horizontal_m']} m (components {b['components_m']} m), "
            f"B/H = {b['base_to_height']}, overlap {b['overlap_percent']} %"
        )
    r = s["relief"]
    lines.append(
        f"relief: {r['working_area_min_m']} … {r['working_area_max_m']} m over the "
        f"working area ({r['working_area_range_m']} m = "
        f"{r['range_over_flying_height'] * 100:.1f} % of H); points "
        f"{r['points_min_m']} … {r['points_max_m']} m"
    )
    pts = s["points"]
    lines.append(
        "points: control "
        + ", ".join(f"{v} {k}" for k, v in pts["control"].items())
        + "; check "
        + str(sum(pts["check"].values()))
    )
    if "map_sheet" in s:
        m = s["map_sheet"]
        lines.append(
            f"map sheet: 1:{m['scale_denominator']}"
            + (f" {m['nomenclature']}" if m["nomenclature"] else " (corners given)")
        )
    return "\n".join(lines) + "\n"
