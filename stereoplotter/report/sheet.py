"""The setup sheet as data (JSON/YAML) and as Markdown: Table 24 and the readings of each stage.

Pure formatting. :func:`setup_dict` is the one serialiser of a setup sheet, for the single-pair
:class:`~stereoplotter.setup.sheet.SetupSheet` (:func:`sheet_to_dict`) and for a model of a block
(:func:`stereoplotter.report.block.model_sheet`): the same keys, the block model holding None where
it cannot have a value. The figure is in ``plotting/figures.py``. Every value carries its unit,
equation and, where it rests on an assumed instrument parameter, the list of those parameters
(shown as ASSUMED).
"""

from __future__ import annotations

import math
from typing import Any

from stereoplotter.glossary import (
    check_language,
    instrument_name,
    localize,
    parameter_name,
    term,
    translate,
)
from stereoplotter.instrument.controls import CONTROL_INFO
from stereoplotter.instrument.principles import (
    mark_phrase,
    sequence_for,
    setting_values,
)
from stereoplotter.report.form_fields import step_text, value_to_set
from stereoplotter.setup.sheet import SetupSheet, assumed_parameters
from stereoplotter.setup.table24 import X_MARK_NAME, BlockResult, candidates_of

__all__ = [
    "NOT_IN_BLOCK_MODE",
    "instrument_settings",
    "setup_dict",
    "sheet_markdown",
    "sheet_to_dict",
    "signed_m",
]

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


def _num(value: float, digits: int = 6) -> float | None:
    v = float(value)
    return None if math.isnan(v) else round(v, digits) + 0.0  # + 0.0 turns −0.0 into 0.0


def _int(value: float) -> int | None:
    v = float(value)
    return None if math.isnan(v) else round(v)


#: What a block model cannot have, and why (the keys are present, with the value None).
NOT_IN_BLOCK_MODE = {
    "scenario": "a block model is named by block and model",
    "focal_length_corrected_per_photo_mm": "a block file has no measured fiducial spans",
    "sheet_corners_mm": "(6.7) needs the map sheet and plan control of the model",
    "similarity": "(6.8) needs the plan control of the model",
    "readings": "the stage readings need the corners and the tolerances of a single-pair sheet",
    "tolerances": "the control-height tolerance needs the working area of a single-pair sheet",
    "exterior_orientation": "given in the block file",
    "options.bz_scale_sense": "a single-pair option",
    "model X, Y travel": "a block file gives no plan extent of the working area",
}


def _marks_dict(table: BlockResult, i: int) -> dict[str, Any]:
    """The marks' settings of pair ``i``: transformed and rigorous fiducials, L, decentrations."""
    photos = ("left", "right")
    fid, rig = table.fiducials_transformed_mm[i], table.fiducials_rigorous_mm[i]
    return {
        "fiducials_transformed_mm": {
            p: {f"x{X_MARK_NAME[j]}": _num(fid[j, 0]), "y3": _num(fid[j, 1]), "y4": _num(fid[j, 2])}
            for j, p in enumerate(photos)
        },
        "fiducials_rigorous_mm": {
            p: {
                key: [_num(rig[j, m, 0]), _num(rig[j, m, 1])]
                for m, key in enumerate((X_MARK_NAME[j], "3", "4"))
            }
            for j, p in enumerate(photos)
        },
        "L_mm": dict(zip(photos, map(_num, table.mark_span_mm[i]), strict=True)),
        "decentrations_mm": {
            p: dict(zip("xy", map(_num, table.decentration_mm[i, j]), strict=True))
            for j, p in enumerate(photos)
        },
    }


def _angles_dict(table: BlockResult, i: int) -> dict[str, Any]:
    """The correction mechanism's inclinations and the photos' angles of pair ``i`` [°]."""
    photos = ("left", "right")
    return {
        "correction_inclinations_deg": {
            p: dict(
                zip(
                    ("alpha", "omega"),
                    (_num(math.degrees(v)) for v in table.correction_inclination[i, j]),
                    strict=True,
                )
            )
            for j, p in enumerate(photos)
        },
        "angles_deg": {
            p: {
                a: _num(math.degrees(table.angles[i, j, m]), 7)
                for m, a in enumerate(("alpha", "omega", "kappa"))
            }
            for j, p in enumerate(photos)
        },
    }


def setup_dict(table: BlockResult, i: int, sheet: SetupSheet | None = None) -> dict[str, Any]:
    """Pair ``i`` of a Table 24 computation as plain data: the one serialiser of setup sheets.

    Parameters
    ----------
    table : BlockResult
        :func:`stereoplotter.setup.table24.compute_table24` of a block, or the block of one of a
        single-pair sheet (``sheet.table24``).
    i : int
        The pair.
    sheet : SetupSheet, optional
        The single-pair sheet, for what only a sheet has (corners, similarity, readings,
        tolerances, …); without it those keys hold None and ``not_in_block_mode`` says why.

    Returns
    -------
    dict
        The keys of ``sheet.yaml`` and of the ``--json`` output, the same for both. [mm, —, °]
    """
    ok = bool(table.accepted[i])
    assumed = sheet.assumed if sheet is not None else assumed_parameters(table.spec)
    data: dict[str, Any] = {
        "scenario": sheet.scenario if sheet is not None else None,
        "block": None if sheet is not None else table.name,
        "model": None if sheet is not None else table.model_names[i],
        "instrument": table.instrument,
        "instrument_title": table.spec.title,
        "status": "ok" if ok else "refused",
        "reason": table.reason(i),
        "reason_code": int(table.reason_code[i]),
        "scale_horizontal": _int(table.horizontal_scale_denominator[i]),
        "scale_vertical": _int(table.vertical_scale_denominator[i]),
        "scale_map": table.map_scale_denominator,
        "f_instrument_mm": _num(table.f_instrument_mm[i]),
        "transformation_coefficient": _num(table.transformation_coefficient[i]),
        "focal_length_corrected_mm": _num(table.focal_length_of(i)),
        "focal_length_corrected_per_photo_mm": None
        if sheet is None
        else [_num(v) for v in sheet.focal_length_corrected_per_photo_mm],
        "n_left": _num(table.n_left[i]),
        "n_right": _num(table.n_right[i]),
        "base_mm": dict(zip(("bx", "by", "bz"), map(_num, table.base_mm[i]), strict=True)),
        **_marks_dict(table, i),
        "instrument_settings": instrument_settings(table, i),
        **_angles_dict(table, i),
        "control_heights_model_mm": {
            pid: _num(table.control_heights_model_mm[i, j])
            for j, pid in enumerate(table.height_point_ids[i])
        },
        **_single_pair_only(sheet),
        "frame": {
            "rotation_deg": _num(math.degrees(table.frame_rotation[i]), 7),
            "origin_m": [_num(v, 4) for v in table.frame_origin_m[i]],
            "note": "the photogrammetric system is moved to S_л and turned about Z by "
            "−rotation so that X runs along the base (docs/setup-data.md)",
        },
        "exterior_orientation": None if sheet is None else list(sheet.exterior_sources),
        "depth_range_used_mm": [_num(v, 3) for v in table.depth_range_mm[i]],
        "scale_choice": _scale_choice(table, i),
        "options": {
            "book_sign_n_right": table.book_sign,
            "bz_scale_sense": None if sheet is None else sheet.options.bz_scale_sense,
        },
        "assumed": {key: list(params) for key, params in assumed.items() if params},
        "annotations": {
            k: {"unit": u, "equation": e, "meaning": m, "assumed": bool(assumed.get(k))}
            for k, (u, e, m) in ANNOTATIONS.items()
        },
        "not_in_block_mode": {} if sheet is not None else dict(NOT_IN_BLOCK_MODE),
    }
    return data


def instrument_settings(table: BlockResult, i: int) -> dict[str, Any] | None:
    """The instrument's own φ, ω-dependent settings of pair ``i`` with their formulas
    (:mod:`stereoplotter.instrument.principles`); None for an instrument file whose
    ``principle`` is none of the three."""
    seq = sequence_for(table.spec.principle)
    if seq is None:
        return None
    f, k = table.focal_length_of(i), float(table.transformation_coefficient[i])
    values = {
        p: setting_values(seq, f, k, float(table.angles[i, j, 0]), float(table.angles[i, j, 1]))
        for j, p in enumerate(("left", "right"))
    }
    return {
        "phi_omega_dependent": seq.phi_omega_dependent,
        "counted": seq.counted,
        "count_status": seq.count_status,
        "count_basis": seq.count_basis,
        "sequence": list(seq.sequence),
        "settings": [
            {
                "key": s.key,
                "name": s.name,
                "symbol": s.symbol,
                "unit": s.unit,
                "formula": s.formula,
                "kind": s.kind,
                "left": _num(values["left"][m]),
                "right": _num(values["right"][m]),
            }
            for m, s in enumerate(seq.settings)
        ],
    }


def _single_pair_only(sheet: SetupSheet | None) -> dict[str, Any]:
    """Corners (6.7), similarity (6.8), readings and tolerances: None for a block model."""
    if sheet is None:
        return dict.fromkeys(("sheet_corners_mm", "similarity", "readings", "tolerances"))
    similarity = None
    if sheet.similarity is not None:
        fit = sheet.similarity
        similarity = {
            "a": fit.a,
            "b": fit.b,
            "cx_m": _num(fit.cx_m, 4),
            "cy_m": _num(fit.cy_m, 4),
            "scale": fit.scale,
            "determinant": fit.determinant,
            "rms_m": _num(fit.rms_m, 4),
            "redundancy": fit.redundancy,
            "residuals_m": {
                pid: [_num(r[0], 4), _num(r[1], 4)]
                for pid, r in zip(sheet.similarity_point_ids, fit.residuals_m, strict=True)
            },
            "frame": "photogrammetric X, Y rotated so that X runs along the base, origin S_л",
        }
    return {
        "sheet_corners_mm": {
            c["corner"]: {
                "position": c["position"],
                "x": _num(c["x_mm"]),
                "y": _num(c["y_mm"]),
                "x_book_form": _num(c["x_book_form_mm"]),
                "y_book_form": _num(c["y_book_form_mm"]),
            }
            for c in sheet.corners
        },
        "similarity": similarity,
        "readings": [
            {k: (_num(v) if isinstance(v, float) else v) for k, v in r.items()}
            for r in sheet.readings
        ],
        "tolerances": {k: _num(v) for k, v in sheet.tolerances.items()},
    }


def sheet_to_dict(sheet: SetupSheet) -> dict[str, Any]:
    """The sheet as plain data: the keys of the ``--json`` output and of ``sheet.yaml``
    (:func:`setup_dict` of its block of one)."""
    if sheet.table24 is None:
        raise ValueError("sheet_to_dict: expected a sheet from compute_setup_sheet")
    return setup_dict(sheet.table24, 0, sheet)


def _scale_choice(table: BlockResult, i: int) -> dict[str, Any]:
    """The chosen (M_г, M_в), the feasible ones, and for every horizontal scale larger than the
    chosen one (every one, for a refused pair) its closest M_в and why it fails."""
    candidates = candidates_of(table, i)
    chosen = [
        _int(table.horizontal_scale_denominator[i]),
        _int(table.vertical_scale_denominator[i]),
    ]
    limit = chosen[0] if chosen[0] is not None else math.inf
    rows = []
    for mg in sorted({c.horizontal for c in candidates}):
        if mg >= limit:
            break
        same = [c for c in candidates if c.horizontal == mg]
        best = min(same, key=lambda c: (len(c.reasons), c.vertical))
        rows.append(
            {
                "horizontal": mg,
                "closest_vertical": best.vertical,
                "f_instrument_mm": _num(best.f_instrument_mm, 3),
                "fails": list(best.reasons),
            }
        )
    return {
        "chosen": chosen,
        "feasible": [[c.horizontal, c.vertical] for c in candidates if c.feasible],
        "refused_larger_scales": rows,
    }


def _fmt(value: float, digits: int = 3) -> str:
    if abs(value) < 0.5 * 10.0**-digits:
        value = 0.0  # no "−0.000"
    return f"{value:.{digits}f}"


def signed_m(value: float) -> str:
    """A signed value to 1 mm; one that rounds to zero is +0.000 (never -0.000). [m]"""
    return f"{round(value, 3) + 0.0:+.3f}"


def _controls_rows(sheet: SetupSheet, lang: str = "en") -> list[str]:
    """The instrument's own names of the correction controls, one row per photo (in Russian the
    names translated, each control's identifier kept)."""
    principle = sheet.instrument_principle
    rows = []
    for p in sheet.photos:
        names = [
            info.own_name(principle)
            for kind in ("knob", "decentration")  # k_α, k_ω, then dx, dy
            for info in CONTROL_INFO.values()
            if info.kind == kind and info.side == p.name
        ]
        how = mark_phrase(principle, "N")
        if lang == "en":
            rows.append(f"| controls, {p.name} | — | {', '.join(names)} | — | stage 2: {how} |")
            continue
        own = []
        for n in names:
            text, sep, ident = n.rpartition(" (")
            own.append(f"{translate(text, lang)} ({ident}" if sep else n)
        rows.append(f"| {term('md_controls', lang)}, {term(p.name, lang)} | — | {', '.join(own)} "
                    f"| — | {term('stage', lang)} 2: {translate(how, lang)} |")  # fmt: skip
    return rows


def _settings_lines(
    settings: dict[str, Any] | None, title: str, lang: str = "en"
) -> list[str]:
    """The instrument's own settings as a Markdown section (in ``lang``)."""
    if settings is None:
        return []
    t = lambda key: term(key, lang)  # noqa: E731 - a local shorthand for the many labels
    tr = lambda text: translate(str(text), lang)  # noqa: E731 - the same
    status = t("md_documented") if settings["count_status"] == "documented" else t(
        "md_assumed_upper")  # fmt: skip
    lines = [
        "",
        f"## {t('md_settings_of')} {title}" if lang == "en" else f"## {t('md_settings_of')}: "
        f"{title}",
        "",
        f"{settings['phi_omega_dependent']} {t('md_settings_depend')} "
        f"({tr(settings['counted'])}; {status}: {tr(settings['count_basis'])}). {t('md_order')}:",
        "",
    ]
    lines += [f"{n}. {tr(step)}" for n, step in enumerate(settings["sequence"], 1)]
    lines += ["", t("md_settings_header"), "|---|---|---|---|---|---|---|"]
    for s in settings["settings"]:
        digits = 4 if s["unit"] == "deg" else 3
        lines.append(
            f"| {tr(s['name'])} | {s['symbol']} | {tr(s['kind'])} | {s['formula']} | "
            f"{_fmt(s['left'], digits)} | {_fmt(s['right'], digits)} | "
            f"{'°' if s['unit'] == 'deg' else 'mm'} |"
        )
    return lines


def sheet_markdown(sheet: SetupSheet, lang: str = "en", sides: tuple[str, ...] = ()) -> str:
    """Table 24 and the stage-by-stage list of readings, as Markdown in ``lang`` (``"ru"`` uses
    the book's terms, :mod:`stereoplotter.glossary`)."""
    check_language(lang)
    d = sheet_to_dict(sheet)
    lines = _intro_lines(sheet, lang) + _table24_lines(sheet, lang) + _similarity_lines(d, lang)
    lines += _mark_comparison_lines(sheet, lang)
    title = instrument_name(sheet.instrument, sheet.instrument_title, lang)
    lines += _settings_lines(d["instrument_settings"], title, lang)
    lines += _readings_lines(sheet, lang, sides)
    if lang == "en":
        return "\n".join(lines) + "\n"
    return "\n".join(localize(line, lang) for line in lines) + "\n"  # units, corners, МО, tg


def _intro_lines(sheet: SetupSheet, lang: str = "en") -> list[str]:
    """The title, the source and the scale chain."""
    t = lambda key: term(key, lang)  # noqa: E731 - a local shorthand for the many labels
    m_map = sheet.map_scale_denominator
    chain = (  # no map sheet: the horizontal scale was forced, there is no coordinatograph ratio
        f"{t('md_no_map')} → {t('scale_horizontal')} M_г = 1:{sheet.horizontal_scale_denominator} "
        f"({t('md_forced')})" if m_map is None else
        f"{t('md_map')} 1:{m_map} → {t('scale_horizontal')} M_г = "
        f"1:{sheet.horizontal_scale_denominator} "
        f"({t('md_ratio')} {sheet.horizontal_scale_denominator / m_map:g})"
    )  # fmt: skip
    return [
        f"# {t('md_title')} — {sheet.scenario} {t('md_on')} {sheet.instrument_title}"
        if lang == "en" else f"# {t('md_title')} — {sheet.scenario}, "
        f"{instrument_name(sheet.instrument, sheet.instrument_title, lang)}",
        "",
        t("md_computed"),
        "",
        f"{t('md_chain')}: {chain}; {t('md_vertical')} "
        f"M_в = M_г/k = 1:{sheet.vertical_scale_denominator}; k = f_пр/f′ = "
        f"{sheet.transformation_coefficient:.5f}; n_л = D_max/f_пр = {sheet.n_left:.5f}; "
        f"{t('md_depths')} {sheet.depth_range_used_mm[0]:.1f} … "
        f"{sheet.depth_range_used_mm[1]:.1f} mm.",
        "",
    ]


def _table24_lines(sheet: SetupSheet, lang: str = "en") -> list[str]:
    """Table 24: scales, f_пр, f′, base, n, marks, spans, decentrations, controls, heights,
    sheet corners; an assumed value flagged."""
    t = lambda key: term(key, lang)  # noqa: E731 - a local shorthand for the many labels
    star = f" **({t('md_assumed_flag')})**"
    flag = {k: star if params else "" for k, params in sheet.assumed.items()}
    left, right = sheet.photos
    item = t("item1")
    scale_h = "horizontal scale" if lang == "en" else t("scale_horizontal")
    scale_v = "vertical scale" if lang == "en" else t("scale_vertical")
    lines = [
        f"## {t('table24')}",
        "",
        t("md_table24_header"),
        "|---|---|---|---|---|",
        f"| {scale_h} | M_г | 1:{sheet.horizontal_scale_denominator}"
        f"{flag['scale_horizontal']} | — | {item} |",
        f"| {scale_v} | M_в | 1:{sheet.vertical_scale_denominator}"
        f"{flag['scale_vertical']} | — | {item} |",
        f"| {t('f_instrument')} | f_пр | {sheet.f_instrument_mm:.3f}"
        f"{flag['f_instrument_mm']} | mm | {item} |",
        f"| {t('focal_corrected')} | f′ | {sheet.focal_length_corrected_mm:.4f} | mm | f·l′/l |",
        f"| {t('base_components')} | b_x, b_y, b_z′ | {_fmt(sheet.base_mm[0])}, "
        f"{_fmt(sheet.base_mm[1])}, {_fmt(sheet.base_mm[2])}{flag['base_mm']} | mm | {item} |",
        f"| {t('counter_coefficients')} | n_л, n_п | {sheet.n_left:.5f}, {sheet.n_right:.5f}"
        f"{flag['n_left']} | — | (6.3), (6.4) |",
        f"| {t('marks_left')} | (x⁰₂)_л, (y⁰₃)_л, (y⁰₄)_л | "
        f"{_fmt(left.transformed_book_mm['x2'])}, {_fmt(left.transformed_book_mm['y3'])}, "
        f"{_fmt(left.transformed_book_mm['y4'])} | mm | (6.1)/(6.2) |",
        f"| {t('marks_right')} | (x⁰₁)_п, (y⁰₃)_п, (y⁰₄)_п | "
        f"{_fmt(right.transformed_book_mm['x1'])}, {_fmt(right.transformed_book_mm['y3'])}, "
        f"{_fmt(right.transformed_book_mm['y4'])} | mm | (6.1)/(6.2) |",
        f"| {'mark spans' if lang == 'en' else t('mark_spans')} | L_л, L_п | "
        f"{left.mark_span_mm:.3f}, {right.mark_span_mm:.3f}{flag['L_mm']} | mm | (6.5) |",
    ]
    for p in sheet.photos:
        side = p.name if lang == "en" else t(p.name)
        lines.append(
            f"| {t('md_decentrations')}, {side} | d_x, d_y | {_fmt(p.decentration_mm[0])}, "
            f"{_fmt(p.decentration_mm[1])} | mm | f′·tan α, f′·tan ω |"
        )
    lines += _controls_rows(sheet, lang)
    for h in sheet.control_heights:
        lines.append(
            f"| {t('md_model_height')} {h['id']} | Z_{h['id']} | "
            f"{h['model_height_mm']:.3f}{flag['control_heights_model_mm']} | mm | (6.6) |"
        )
    for c in sheet.corners:
        lines.append(
            f"| {t('md_sheet_corner')} {c['corner']} ({c['position']}) | x′, y′ | "
            f"{_fmt(c['x_mm'])}, {_fmt(c['y_mm'])}{flag['sheet_corners_mm']} | mm | "
            "(6.7) |"
        )
    return lines


def _similarity_lines(d: dict[str, Any], lang: str = "en") -> list[str]:
    """The similarity (6.8) on the control points, if the sheet has a map."""
    t = lambda key: term(key, lang)  # noqa: E731 - a local shorthand for the many labels
    lines: list[str] = []
    if d["similarity"]:
        s = d["similarity"]
        lines += [
            "",
            f"{t('md_similarity')}, {len(s['residuals_m'])} {t('md_control_points')}: "
            f"a = {s['a']:.6e}, b = {s['b']:.9f}, c_X = {s['cx_m']:.3f} m, "
            f"c_Y = {s['cy_m']:.3f} m (det {s['determinant']:.6f} < 0: {t('md_reflection')}); "
            f"{t('md_rms_residual')} {s['rms_m']:.3f} m; {t('md_residuals')} "
            + ", ".join(
                f"{k}: ({signed_m(v[0])}, {signed_m(v[1])})" for k, v in s["residuals_m"].items()
            )
            + " m.",
        ]
    return lines


def _mark_comparison_lines(sheet: SetupSheet, lang: str = "en") -> list[str]:
    """The book's single-axis (6.1)/(6.2) marks against the rigorous (3.17)."""
    lines = ["", term("md_marks_intro", lang), "", term("md_marks_header", lang),
             "|---|---|---|---|---|"]  # fmt: skip
    for p in sheet.photos:
        for key, value in p.transformed_book_mm.items():
            mark = key[1:]
            rig = p.transformed_rigorous_mm[mark]
            axis = 0 if key[0] == "x" else 1
            lines.append(
                f"| {p.name if lang == 'en' else term(p.name, lang)} | {key} | {value:.4f} | "
                f"{rig[0]:.4f}, {rig[1]:.4f} | "
                f"{(value - rig[axis]) * 1000:+.2f} |"
            )
    return lines


def _readings_lines(sheet: SetupSheet, lang: str = "en", sides: tuple[str, ...] = ()) -> list[str]:
    """Every reading stage by stage, and the assumed parameters used. The mark targets and span
    of a photo in ``sides`` are the rigorous (3.17) ones, the book's beside them (the values a
    job's form gives to set, :func:`~stereoplotter.report.form_fields.rigorous_sides`)."""
    t = lambda key: term(key, lang)  # noqa: E731 - a local shorthand for the many labels
    lines = ["", f"## {t('md_readings')}", "", t("md_readings_intro"), ""]
    if sides:
        lines += [t("limit_choice_mixed"), ""]
    stage = None
    for r in sheet.readings:
        if r["stage"] != stage:
            stage = r["stage"]
            lines += ["", f"### {t('md_stage')} {stage}", "", t("md_readings_header"),
                      "|---|---|---|---|"]  # fmt: skip
        tol = f"± {r['tolerance']:.4g} {r['unit']}" if "tolerance" in r else ""
        book = f" ({t('md_book')}: {r['book_form']})" if "book_form" in r else ""
        formula = r["formula"] + book
        value, book_value = value_to_set(sheet, r, sides)
        if book_value is not None:  # the rigorous value to set, the book's beside it
            sign = "−" if value < 0 else "+"
            formula = (f"{r['reading']} = {r['zero_reading']} {sign} {abs(value):.3f} {r['unit']}"
                       if r["zero_reading"] else f"{r['reading']} = {value:.3f} {r['unit']}")
            formula += f" ({t('md_book')}: {book_value:.3f})"
        if lang != "en":
            formula = formula.replace("corner", t("corner")).replace("residual q",
                                                                      t("residual_q"))  # fmt: skip
        equation = r["equation"] if lang == "en" else translate(str(r["equation"]), lang)
        equation = "(3.17)" if book_value is not None else equation
        lines.append(f"| {step_text(r, lang)} | {formula} | {equation} | {tol} |")
    if any(sheet.assumed.values()):
        params = sorted({p for ps in sheet.assumed.values() for p in ps})
        shown = [f"`{p}`" if lang == "en" else f"{parameter_name(p, lang)} (`{p}`)"
                 for p in params]  # fmt: skip
        lines += [
            "",
            f"## {t('md_assumed_params')}",
            "",
            f"{t('md_assumed_params_text')}: " + ", ".join(shown) + ".",
        ]
    return lines
