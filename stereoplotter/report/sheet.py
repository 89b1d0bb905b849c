"""The setup sheet as data (JSON/YAML) and as Markdown: Table 24 and the readings of each stage.

Pure formatting of a :class:`~stereoplotter.setup.sheet.SetupSheet`; the figure is in
``plotting.py``. Every value carries its unit, equation and, where it rests on an assumed
instrument parameter, the list of those parameters (shown as ASSUMED).
"""

from __future__ import annotations

import math
from typing import Any

from stereoplotter.setup.sheet import SetupSheet

__all__ = ["sheet_markdown", "sheet_to_dict"]

#: Unit, equation and meaning of each top-level value of the sheet.
ANNOTATIONS: dict[str, tuple[str, str, str]] = {
    "scale_horizontal": ("—", "item 1", "M_г, horizontal model scale denominator"),
    "scale_vertical": ("—", "item 1", "M_в = M_г/k, vertical model scale denominator"),
    "f_instrument_mm": ("mm", "item 1", "f_пр = k·f′, instrument principal distance"),
    "transformation_coefficient": ("—", "item 1", "k = f_пр/f′ = M_г/M_в"),
    "n_left": ("—", "(6.3)", "n_л = D_max/f_пр"),
    "n_right": ("—", "(6.4)", "n_п = n_л + (Z_Sп − Z_Sл)·1000/(f_пр·M_в)"),
    "base_mm": ("mm", "item 1", "b_x, b_y at M_г; b_z′ = k·b_z at M_в"),
    "fiducials_transformed_mm": ("mm", "(6.1)/(6.2)", "x⁰, y⁰ of the marks without n"),
    "fiducials_rigorous_mm": ("mm", "(3.17)", "rigorous x⁰, y⁰ of the marks (κ = 0)"),
    "L_mm": ("mm", "(6.5)", "L = n·(y⁰₃ − y⁰₄)"),
    "decentrations_mm": ("mm", "kinematics §2.4", "d = f′·tan α, f′·tan ω"),
    "correction_inclinations_deg": ("°", "DRO60 (4)", "θ = atan(k·tan α), fitted in stage 2"),
    "control_heights_model_mm": ("mm", "(6.6)", "Z_i = H_Фi·1000/M_в"),
    "sheet_corners_mm": ("mm", "(6.7)", "x′, y′ from the left plumb (MO)"),
    "similarity": ("—, m", "(6.8)", "Gauss–Krüger → photogrammetric, with reflection"),
}


def _round(value: float, digits: int = 6) -> float:
    return round(float(value), digits) + 0.0  # + 0.0 turns −0.0 into 0.0


def sheet_to_dict(sheet: SetupSheet) -> dict[str, Any]:
    """The sheet as plain data: the keys of the ``--json`` output and of ``sheet.yaml``."""
    left, right = sheet.photos
    fiducials = {
        p.name: {k: _round(v) for k, v in p.transformed_book_mm.items()} for p in sheet.photos
    }
    rigorous = {
        p.name: {k: [_round(v[0]), _round(v[1])] for k, v in p.transformed_rigorous_mm.items()}
        for p in sheet.photos
    }
    similarity = None
    if sheet.similarity is not None:
        fit = sheet.similarity
        similarity = {
            "a": fit.a,
            "b": fit.b,
            "cx_m": _round(fit.cx_m, 4),
            "cy_m": _round(fit.cy_m, 4),
            "scale": fit.scale,
            "determinant": fit.determinant,
            "rms_m": _round(fit.rms_m, 4),
            "redundancy": fit.redundancy,
            "residuals_m": {
                pid: [_round(r[0], 4), _round(r[1], 4)]
                for pid, r in zip(sheet.similarity_point_ids, fit.residuals_m, strict=True)
            },
            "frame": "photogrammetric X, Y rotated so that X runs along the base, origin S_л",
        }
    assumed = {key: list(params) for key, params in sheet.assumed.items() if params}
    data: dict[str, Any] = {
        "scenario": sheet.scenario,
        "instrument": sheet.instrument,
        "instrument_title": sheet.instrument_title,
        "scale_horizontal": sheet.horizontal_scale_denominator,
        "scale_vertical": sheet.vertical_scale_denominator,
        "scale_map": sheet.map_scale_denominator,
        "f_instrument_mm": _round(sheet.f_instrument_mm),
        "transformation_coefficient": _round(sheet.transformation_coefficient),
        "focal_length_corrected_mm": _round(sheet.focal_length_corrected_mm),
        "focal_length_corrected_per_photo_mm": [
            _round(v) for v in sheet.focal_length_corrected_per_photo_mm
        ],
        "n_left": _round(sheet.n_left),
        "n_right": _round(sheet.n_right),
        "base_mm": dict(zip(("bx", "by", "bz"), (_round(v) for v in sheet.base_mm), strict=True)),
        "fiducials_transformed_mm": fiducials,
        "fiducials_rigorous_mm": rigorous,
        "L_mm": {"left": _round(left.mark_span_mm), "right": _round(right.mark_span_mm)},
        "decentrations_mm": {
            p.name: {"x": _round(p.decentration_mm[0]), "y": _round(p.decentration_mm[1])}
            for p in sheet.photos
        },
        "correction_inclinations_deg": {
            p.name: {
                "alpha": _round(math.degrees(p.correction_inclination[0])),
                "omega": _round(math.degrees(p.correction_inclination[1])),
            }
            for p in sheet.photos
        },
        "angles_deg": {
            p.name: {
                "alpha": _round(math.degrees(p.alpha), 7),
                "omega": _round(math.degrees(p.omega), 7),
                "kappa": _round(math.degrees(p.kappa), 7),
            }
            for p in sheet.photos
        },
        "control_heights_model_mm": {
            h["id"]: _round(h["model_height_mm"]) for h in sheet.control_heights
        },
        "sheet_corners_mm": {
            c["corner"]: {
                "position": c["position"],
                "x": _round(c["x_mm"]),
                "y": _round(c["y_mm"]),
                "x_book_form": _round(c["x_book_form_mm"]),
                "y_book_form": _round(c["y_book_form_mm"]),
            }
            for c in sheet.corners
        },
        "similarity": similarity,
        "readings": [
            {k: (_round(v) if isinstance(v, float) else v) for k, v in r.items()}
            for r in sheet.readings
        ],
        "tolerances": {k: _round(v) for k, v in sheet.tolerances.items()},
        "frame": {
            "rotation_deg": _round(math.degrees(sheet.frame_rotation), 7),
            "origin_m": [_round(v, 4) for v in sheet.frame_origin_m],
            "note": "the photogrammetric system is moved to S_л and turned about Z by "
            "−rotation so that X runs along the base (docs/setup-data.md)",
        },
        "exterior_orientation": list(sheet.exterior_sources),
        "depth_range_used_mm": [_round(v, 3) for v in sheet.depth_range_used_mm],
        "scale_choice": {
            "chosen": [sheet.horizontal_scale_denominator, sheet.vertical_scale_denominator],
            "feasible": [[c.horizontal, c.vertical] for c in sheet.candidates if c.feasible],
            "refused_larger_scales": _refused_larger_scales(sheet),
        },
        "options": {
            "book_sign_n_right": sheet.options.book_sign_n_right,
            "bz_scale_sense": sheet.options.bz_scale_sense,
        },
        "assumed": assumed,
        "annotations": {
            k: {"unit": u, "equation": e, "meaning": m, "assumed": bool(sheet.assumed.get(k))}
            for k, (u, e, m) in ANNOTATIONS.items()
        },
    }
    return data


def _refused_larger_scales(sheet: SetupSheet) -> list[dict[str, Any]]:
    """For every horizontal scale larger than the chosen one, its closest M_в and why it fails."""
    rows = []
    for mg in sorted({c.horizontal for c in sheet.candidates}):
        if mg >= sheet.horizontal_scale_denominator:
            break
        options = [c for c in sheet.candidates if c.horizontal == mg]
        best = min(options, key=lambda c: (len(c.reasons), c.vertical))
        rows.append(
            {
                "horizontal": mg,
                "closest_vertical": best.vertical,
                "f_instrument_mm": _round(best.f_instrument_mm, 3),
                "fails": list(best.reasons),
            }
        )
    return rows


def _fmt(value: float, digits: int = 3) -> str:
    if abs(value) < 0.5 * 10.0**-digits:
        value = 0.0  # no "−0.000"
    return f"{value:.{digits}f}"


def sheet_markdown(sheet: SetupSheet) -> str:
    """Table 24 and the stage-by-stage list of readings, as Markdown."""
    d = sheet_to_dict(sheet)
    flag = {k: " **(assumed)**" if params else "" for k, params in sheet.assumed.items()}
    left, right = sheet.photos
    lines = [
        f"# Setup sheet — {sheet.scenario} on {sheet.instrument_title}",
        "",
        "Computed by stereoplotter after Kushtin & Lyskov (1984), §26, Table 24. Values marked "
        "**(assumed)** rest on instrument parameters that no source documents "
        "(`docs/instruments.md`).",
        "",
        f"Scale chain: map 1:{sheet.map_scale_denominator} → horizontal model scale "
        f"M_г = 1:{sheet.horizontal_scale_denominator} (coordinatograph ratio "
        f"{sheet.horizontal_scale_denominator / sheet.map_scale_denominator:g}); vertical "
        f"M_в = M_г/k = 1:{sheet.vertical_scale_denominator}; k = f_пр/f′ = "
        f"{sheet.transformation_coefficient:.5f}; n_л = D_max/f_пр = {sheet.n_left:.5f}; "
        f"projection distances of the working area {sheet.depth_range_used_mm[0]:.1f} … "
        f"{sheet.depth_range_used_mm[1]:.1f} mm.",
        "",
        "## Table 24",
        "",
        "| quantity | symbol | value | unit | equation |",
        "|---|---|---|---|---|",
        f"| horizontal scale | M_г | 1:{sheet.horizontal_scale_denominator}"
        f"{flag['scale_horizontal']} | — | item 1 |",
        f"| vertical scale | M_в | 1:{sheet.vertical_scale_denominator}"
        f"{flag['scale_vertical']} | — | item 1 |",
        f"| instrument principal distance | f_пр | {sheet.f_instrument_mm:.3f}"
        f"{flag['f_instrument_mm']} | mm | item 1 |",
        f"| corrected focal length | f′ | {sheet.focal_length_corrected_mm:.4f} | mm | f·l′/l |",
        f"| base components | b_x, b_y, b_z′ | {_fmt(sheet.base_mm[0])}, {_fmt(sheet.base_mm[1])}, "
        f"{_fmt(sheet.base_mm[2])}{flag['base_mm']} | mm | item 1 |",
        f"| counter coefficients | n_л, n_п | {sheet.n_left:.5f}, {sheet.n_right:.5f}"
        f"{flag['n_left']} | — | (6.3), (6.4) |",
        f"| marks, left photo | (x⁰₂)_л, (y⁰₃)_л, (y⁰₄)_л | "
        f"{_fmt(left.transformed_book_mm['x2'])}, {_fmt(left.transformed_book_mm['y3'])}, "
        f"{_fmt(left.transformed_book_mm['y4'])} | mm | (6.1)/(6.2) |",
        f"| marks, right photo | (x⁰₁)_п, (y⁰₃)_п, (y⁰₄)_п | "
        f"{_fmt(right.transformed_book_mm['x1'])}, {_fmt(right.transformed_book_mm['y3'])}, "
        f"{_fmt(right.transformed_book_mm['y4'])} | mm | (6.1)/(6.2) |",
        f"| mark spans | L_л, L_п | {left.mark_span_mm:.3f}, {right.mark_span_mm:.3f}"
        f"{flag['L_mm']} | mm | (6.5) |",
    ]
    for p in sheet.photos:
        lines.append(
            f"| decentrations, {p.name} | d_x, d_y | {_fmt(p.decentration_mm[0])}, "
            f"{_fmt(p.decentration_mm[1])} | mm | f′·tan α, f′·tan ω |"
        )
    for h in sheet.control_heights:
        lines.append(
            f"| model height over point {h['id']} | Z_{h['id']} | "
            f"{h['model_height_mm']:.3f}{flag['control_heights_model_mm']} | mm | (6.6) |"
        )
    for c in sheet.corners:
        lines.append(
            f"| sheet corner {c['corner']} ({c['position']}) | x′, y′ | "
            f"{_fmt(c['x_mm'])}, {_fmt(c['y_mm'])}{flag['sheet_corners_mm']} | mm | "
            "(6.7) |"
        )
    if d["similarity"]:
        s = d["similarity"]
        lines += [
            "",
            f"Similarity (6.8), {len(s['residuals_m'])} control points: "
            f"a = {s['a']:.6e}, b = {s['b']:.9f}, c_X = {s['cx_m']:.3f} m, "
            f"c_Y = {s['cy_m']:.3f} m (det {s['determinant']:.6f} < 0: reflection); "
            f"RMS residual {s['rms_m']:.3f} m; residuals "
            + ", ".join(f"{k}: ({v[0]:+.3f}, {v[1]:+.3f})" for k, v in s["residuals_m"].items())
            + " m.",
        ]
    lines += [
        "",
        "Transformed mark coordinates: the book's single-axis (6.1)/(6.2) against the "
        "rigorous (3.17) (κ = 0):",
        "",
        "| photo | mark | (6.1)/(6.2) mm | (3.17) x⁰, y⁰ mm | difference µm |",
        "|---|---|---|---|---|",
    ]
    for p in sheet.photos:
        for key, value in p.transformed_book_mm.items():
            mark = key[1:]
            rig = p.transformed_rigorous_mm[mark]
            axis = 0 if key[0] == "x" else 1
            lines.append(
                f"| {p.name} | {key} | {value:.4f} | {rig[0]:.4f}, {rig[1]:.4f} | "
                f"{(value - rig[axis]) * 1000:+.2f} |"
            )
    lines += [
        "",
        "## Readings, stage by stage",
        "",
        "Every reading is a zero reading (MO, found on the instrument) plus the signed "
        "value. The right photo's zero readings are MO_X,п = MO_X + b_x, "
        "MO_Y,п = MO_Y + b_y.",
        "",
    ]
    stage = None
    for r in sheet.readings:
        if r["stage"] != stage:
            stage = r["stage"]
            lines += [
                "",
                f"### Stage {stage}",
                "",
                "| step | reading | equation | tolerance |",
                "|---|---|---|---|",
            ]
        tol = f"± {r['tolerance']:.4g} {r['unit']}" if "tolerance" in r else ""
        formula = r["formula"] + (f" (book: {r['book_form']})" if "book_form" in r else "")
        lines.append(f"| {r['step']} | {formula} | {r['equation']} | {tol} |")
    if any(sheet.assumed.values()):
        params = sorted({p for ps in sheet.assumed.values() for p in ps})
        lines += [
            "",
            "## Assumed instrument parameters used",
            "",
            "These values come from no documented source; adjust them in the instrument "
            "YAML if yours differs: " + ", ".join(f"`{p}`" for p in params) + ".",
        ]
    return "\n".join(lines) + "\n"
