"""The texts of ``stereoplotter simulate``: the Markdown summary of a run (one procedure, or
statistics over trials), the learner's transcript with its closing summary and the operator's
advice. The command itself (load, run, write) is :mod:`stereoplotter.commands.simulate`.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from stereoplotter.glossary import check_language, localize, term, translate
from stereoplotter.procedure.eye import look_probability
from stereoplotter.procedure.simulate import SimulationResult
from stereoplotter.procedure.transcript import Record

__all__ = [
    "OPERATOR_ADVICE",
    "OPERATOR_ADVICE_RU",
    "closing_summary",
    "eye_lines",
    "judgement",
    "simulation_markdown",
    "tolerance_note",
    "transcript_text",
    "trial0_texts",
]


def _g(v: Any) -> str:
    return "—" if v is None else f"{v:.4g}"


def _stat(s: dict[str, Any] | None, key: str = "mean") -> str:
    """``mean ± SE`` of a value summary (or the plain value of a single run)."""
    if s is None:
        return "—"
    if not isinstance(s, dict):
        return _g(s)
    if "constant" in s:
        return _g(s["constant"])
    v, se = s.get(key), s.get(f"{key}_se")
    if v is None:
        return "—"
    return _g(v) if se is None else f"{v:.4g} ± {se:.2g}"


def _p95(s: dict[str, Any] | None) -> str:
    if isinstance(s, dict) and "constant" in s:
        return _g(s["constant"])
    if not isinstance(s, dict) or "quantiles" not in s:
        return "—"
    return _g(s["quantiles"]["p95"]["value"])


def _eye(s: dict[str, Any]) -> dict[str, Any] | None:
    return (s.get("operator") or {}).get("eye_figures")


def judgement(check: str, operator: dict[str, Any] | None) -> str:
    """How the operator judged a check (the σ of the act that decides it), photo scale. [µm]"""
    if not operator:
        return "—"
    um = {
        k: (operator.get(k) or 0.0) * 1000.0
        for k in ("y_parallax_sigma_mm", "stereo_sigma_mm", "monocular_sigma_mm")
    }
    eye = operator.get("eye_figures")
    if "y-parallax" in check:
        looks = eye["looks_before_failure"] if eye and operator.get("remeasure") else 1
        how = "10″·d/V, " if eye else ""
        return f"σ_q {um['y_parallax_sigma_mm']:.2f} µm ({how}{looks} look{'s' * (looks > 1)})"
    if "heights" in check:
        how = " (30″·d/V)" if eye else ""
        return f"σ_p {um['stereo_sigma_mm']:.2f} µm{how}"
    if "plan control" in check:
        return f"σ_p {um['stereo_sigma_mm']:.2f}, σ_mono {um['monocular_sigma_mm']:.2f} µm"
    return f"σ_mono {um['monocular_sigma_mm']:.2f} µm (assumed)"


def eye_lines(s: dict[str, Any]) -> list[str]:
    """The operator's eye: the derived judgement figures with the status of their inputs."""
    eye = _eye(s)
    op = s.get("operator") or {}
    if not eye:
        if not op:
            return []
        return [
            "",
            f"Operator: free σ (eye: {op.get('eye')}), σ_p = "
            f"{(op.get('stereo_sigma_mm') or 0) * 1000:.2f} µm, σ_q = "
            f"{(op.get('y_parallax_sigma_mm') or 0) * 1000:.2f} µm (given, not derived).",
        ]
    return [
        "",
        "Operator's eye (derived, docs/procedure.md): stereo acuity "
        f"{eye['acuity_first_kind_arcsec']:g}″ (first kind: the fused mark) and "
        f"{eye['acuity_second_kind_arcsec']:g}″ (second kind: y-parallax) through the "
        f"observation system V = {eye['magnification']:g}× ({eye['magnification_status']}), "
        f"d = {eye['viewing_distance_mm']:g} mm ({eye['viewing_distance_status']}): "
        f"σ_p = 30″·d/V = {eye['stereo_sigma_um']:.2f} µm, "
        f"σ_q = 10″·d/V = {eye['y_parallax_sigma_um']:.2f} µm; a y-parallax check is a "
        f"detection, a point failed only when {eye['looks_before_failure']} looks see it over "
        "¼ mark.",
    ]


def tolerance_note(s: dict[str, Any]) -> str:
    """One honest sentence for a single run's summary: inside the book's tolerances, or by how
    much and why not, with the operator's derived judgement figures."""
    checks = s.get("checks", {})
    failed = [n for n, c in checks.items() if c.get("passed") is False]
    if not failed:
        return "The model is inside the book's tolerances (every check passed)."
    q_true = (s.get("residual_y_parallax_um") or {}).get("standard_points_max")
    op = s.get("operator") or {}
    sq = (op.get("y_parallax_sigma_mm") or 0.0) * 1000.0
    parts = []
    for name in failed:
        c = checks[name]
        res, tol = c.get("residual"), c.get("tolerance")
        unit = c.get("unit", "")
        if res is None or tol is None:
            parts.append(name)
            continue
        text = f"{name}: {_g(abs(res))} {unit} against {_g(tol)} (over by {_g(abs(res) - tol)})"
        if "y-parallax" in name and q_true is not None and unit == "mm":
            if q_true <= tol * 1000.0:
                p = look_probability(q_true / 1000.0, tol, sq / 1000.0)
                text += (
                    f"; the final model's true residual is within it (max {q_true:.4g} µm at the "
                    f"six points): the operator's judgement σ_q = {sq:.2f} µm sees "
                    f"{q_true:.4g} µm over {tol * 1000:.4g} µm in one look with probability "
                    f"{p:.2g}"
                )
            else:
                text += (
                    f"; the final model's true residual exceeds it (max {q_true:.4g} µm at "
                    "the six points): the remedies did not clear it"
                )
        parts.append(text)
    return "Outside the book's tolerances: " + "; ".join(parts) + "."


def _remedy_lines(s: dict[str, Any], single: bool) -> list[str]:
    """The remedies table (operator practice): how often each was applied and whether its
    check then passed."""
    practice = s.get("practice", "book")
    rem = s.get("remedies") or {}
    if practice == "book" or not rem:
        return ["", f"Practice: {practice} (no remedy after a failed check, §27 task 1)."]
    lines = ["", f"Practice: {practice} (the book's remedies after a failed check).", ""]
    if single:
        lines += ["| remedy | applied | rounds | check passed after |", "|---|---|---|---|"]
        for name, r in rem.items():
            lines.append(
                f"| {name} | {r['applied']} | {r['rounds']} | "
                f"{r['passed_after'] if r['applied'] else '—'} |"
            )
        return lines
    lines += [
        "| remedy | applied (rate ± SE) | rounds mean | check passed after (rate ± SE) |",
        "|---|---|---|---|",
    ]
    for name, r in rem.items():
        a = r["applied_rate"]
        p = r.get("passed_after_rate")
        after = "—" if not p else f"{p['rate']:.3f} ± {p['rate_se']:.3f}"
        lines.append(
            f"| {name} | {a['rate']:.3f} ± {a['rate_se']:.3f} | {_stat(r.get('rounds'))} | "
            f"{after} |"
        )
    return lines


def _single_run_lines(s: dict[str, Any]) -> list[str]:
    """The summary of one procedure: checks, remedies, residual y-parallax, iterations."""
    lines = [
        f"back-end {s['backend']}, seed {s['seed']}, one procedure; operator judgment "
        "errors are assumed values.",
        "",
        "| check | residual | tolerance | passed | iterations | judged with |",
        "|---|---|---|---|---|---|",
    ]
    op = s.get("operator")
    for name, c in s["checks"].items():
        label = name.replace("|", "\\|")
        lines.append(
            f"| {label} | {_g(c['residual'])} {c['unit']} | {_g(c.get('tolerance'))} | "
            f"{c.get('passed', '—')} | {_g(c.get('iterations'))} | {judgement(name, op)} |"
        )
    lines += eye_lines(s)
    lines += _remedy_lines(s, single=True)
    q = s["residual_y_parallax_um"]
    lines += [
        "",
        f"Residual y-parallax of the built model (truth): max {_g(q['standard_points_max'])} "
        f"µm at the six standard points; over the grid max {_g(q['grid_max'])} µm, "
        f"RMS {_g(q['grid_rms'])} µm.",
        "",
        "Iterations per stage: " + ", ".join(f"{k}: {_g(v)}" for k, v in s["iterations"].items()),
        "",
    ]
    return lines


def simulation_markdown(s: dict[str, Any]) -> str:
    """The Markdown summary of a run (one procedure, or statistics over trials)."""
    trials = s.get("trials")
    lines = [
        f"# Simulated {s['method']} procedure: {s['scenario']} on {s['instrument']}",
        "",
    ]
    if trials is None:
        return "\n".join(lines + _single_run_lines(s))
    chunks = s.get("chunks", {})
    lines += [
        f"back-end {s['backend']}, seed {s['seed']}, {trials} trials"
        + (f" in {chunks['count']} chunk(s) of ≤ {chunks['trials']}" if chunks else "")
        + "; operator judgment errors are assumed values. Figures: mean ± Monte Carlo standard "
        "error; p95 the 95th percentile over the trials.",
        "",
        "| check | passed (rate ± SE) | residual mean | residual p95 | tolerance | iterations "
        "| judged with |",
        "|---|---|---|---|---|---|---|",
    ]
    op = s.get("operator")
    for name, c in s["checks"].items():
        label = name.replace("|", "\\|")
        rate = c.get("pass_rate")
        passed = "—" if rate is None else f"{rate['rate']:.3f} ± {rate['rate_se']:.3f}"
        lines.append(
            f"| {label} | {passed} | {_stat(c.get('residual'))} {c['unit']} | "
            f"{_p95(c.get('residual'))} | {_stat(c.get('tolerance'))} | "
            f"{_stat(c.get('iterations'))} | {judgement(name, op)} |"
        )
    lines += eye_lines(s)
    lines += _remedy_lines(s, single=False)
    q = s["residual_y_parallax"]
    lines += [
        "",
        "Residual y-parallax of the built model (truth), µm: grid RMS "
        f"{_stat(q['grid_rms_um'])} (p95 {_p95(q['grid_rms_um'])}); grid max "
        f"{_stat(q['grid_max_um'])}; six standard points max {_stat(q['standard_points_max_um'])}.",
        "",
    ]
    ev = s.get("evaluation") or {}
    rows = []
    for set_name in ("control", "check", "grid"):
        e = ev.get(set_name) or {}
        h = e.get("height_error_rms_permille")
        p = e.get("plan_error_rms_map_mm")
        if h or p:
            rows.append(
                f"| {set_name} ({e.get('n_points')}) | {_stat(h)} | {_p95(h)} | {_stat(p)} | "
                f"{_p95(p)} |"
            )
    if rows:
        lines += [
            "| points | height RMS, ‰ H | p95 | plan RMS, mm on the map | p95 |",
            "|---|---|---|---|---|",
            *rows,
            "",
        ]
    return "\n".join(lines)


#: What a real operator does when a check still fails after the simulated operator's remedies
#: (keyed by a word of the check's name); the book's practice of §26–§27 where it says one.
OPERATOR_ADVICE = {
    "|L − L′|": "measure both spans again; if they stay off, recompute f_пр, n and L on the "
    "sheet ((6.3)–(6.5)) before turning ΔZ or Δb_z further",
    "mark 4": "fit k_ω on mark 3 again and re-check mark 4; a misfit that stays means y⁰₃, y⁰₄ "
    "or n on the sheet ((6.2), (6.12)) need checking",
    "residual y-parallax": "clear the y-parallax once more by the relative orientation at the "
    "six standard points (§27, conventional method), then go on and note the residual",
    "control heights": "refine scaling (b_x) and levelling on control once more; a single "
    "point that stays out is checked for its identification and height and left out if a "
    "blunder",
    "levelling": "level again on the levelling points, then re-read the control heights",
    "corner": "place the sheet again over two corners and re-check the others (6.16)–(6.18)",
    "plan control": "re-check the scaling (b_x) and the sheet's placement, then the points' "
    "identification",
}


#: The same advice in Russian, by the same keys (the transcript's ``--lang ru``).
OPERATOR_ADVICE_RU = {
    "|L − L′|": "измерить оба расстояния ещё раз; если расхождение остаётся, пересчитать f_пр, n "
    "и L в установочных данных ((6.3)–(6.5)), прежде чем снова вводить ΔZ или Δb_z",
    "mark 4": "снова установить k_ω по метке 3 и проверить метку 4; если несовпадение остаётся, "
    "проверить y⁰₃, y⁰₄ или n в установочных данных ((6.2), (6.12))",
    "residual y-parallax": "ещё раз устранить поперечный параллакс взаимным ориентированием по "
    "шести стандартным точкам (§27, обычный способ), затем продолжить и записать остаток",
    "control heights": "ещё раз уточнить масштаб (b_x) и горизонтирование по опорным точкам; "
    "точку, которая остаётся вне допуска, проверить по опознанию и высоте и исключить, если это "
    "грубая ошибка",
    "levelling": "снова горизонтировать по точкам горизонтирования, затем перечитать высоты "
    "опорных точек",
    "corner": "снова совместить лист по двум углам и проверить остальные (6.16)–(6.18)",
    "plan control": "перепроверить масштаб (b_x) и положение листа, затем опознание точек",
}


def _advice(check: str, lang: str = "en") -> str:
    advice = OPERATOR_ADVICE_RU if lang == "ru" else OPERATOR_ADVICE
    for word, text in advice.items():
        if word in check:
            return text
    return term("cs_default_advice", lang)


def _at(value: Any, trial: int) -> float:
    v = np.ravel(np.asarray(value, float))
    return float(v[trial] if v.size > 1 else v[0])


def _small(value: float, unit: str) -> str:
    return f"{value:.3f} m" if unit == "m" else f"{value * 1e3:.1f} µm"


def closing_summary(result: SimulationResult, lang: str = "en") -> str:
    """The transcript's closing summary for trial ``transcript.shown``: every check passed or
    failed with its worst residual and tolerance, the remedies applied, what went wrong and what
    a real operator would do next (:data:`OPERATOR_ADVICE`), in ``lang``."""
    t = result.transcript.shown
    tr = lambda key: term(key, lang)  # noqa: E731 - a local shorthand for the many labels
    rows, failed = [], []
    for name, c in result.checks.items():
        shown = _stage_words(name, lang)
        if c.tolerance is None or c.passed is None:
            value = _small(abs(_at(c.residual, t)), c.unit)
            rows.append(f"- ({tr('cs_reported')}) {shown}: {value}")
            continue
        ok = bool(_at(c.passed, t))
        rows.append(
            f"- {tr('cs_pass') if ok else tr('cs_fail')} {shown}: {tr('cs_worst')} "
            f"{_small(abs(_at(c.residual, t)), c.unit)}, {tr('tolerance')} "
            f"{_small(_at(c.tolerance, t), c.unit)}"
        )
        if not ok:
            failed.append(name)
    judged = [c for c in result.checks.values() if c.tolerance is not None and c.passed is not None]
    lines = [
        f"## {tr('cs_title')}",
        "",
        tr("cs_checks").format(p=len(judged) - len(failed), f=len(failed), n=len(judged)),
        *rows,
    ]
    applied = [(n, r) for n, r in result.remedies.items() if bool(_at(r.applied, t))]
    lines += ["", f"{tr('cs_remedies')}: " + (", ".join(
        f"{_stage_words(n, lang)} ({int(_at(r.rounds, t))} {tr('cs_rounds')}, "
        f"{tr('cs_passed_after') if bool(_at(r.passed, t)) else tr('cs_failed_after')})"
        for n, r in applied
    ) if applied else tr("none")) + "."]  # fmt: skip
    if not failed:
        lines += ["", tr("cs_nothing")]
    else:
        lines += ["", tr("cs_wrong")]
        for name in failed:
            tried = [n for n, r in applied if r.check == name]
            after = (f" {tr('cs_after')} {', '.join(_stage_words(n, lang) for n in tried)}"
                     if tried else f" {tr('cs_no_remedy')}")  # fmt: skip
            lines.append(
                f"- {_stage_words(name, lang)}: {tr('cs_still_outside')}"
                f"{after} → {_advice(name, lang)}."
            )
    return "\n".join(localize(line, lang) for line in lines) + "\n"


def _stage_words(text: str, lang: str) -> str:
    """A check's or remedy's name in ``lang`` (its template in the glossary, "stage N" too)."""
    if lang == "en":
        return text
    text = translate(text, lang)
    return re.sub(r"\bstage (\w+)", lambda m: f"{term('stage', lang)} {m[1]}", text)


#: The fixed words of a record line after its step (``Transcript.to_text``), in Russian.
_TAIL_RU = (
    (" (from ", " (от "), (" to ", " до "), (" — read ", " — отсчёт "),
    ("; judgment error ", "; ошибка наблюдения "), ("; seen ", "; видно "),
    (" (true ", " (истинное "), ("; tolerance ", "; допуск "), (" (tolerance ", " (допуск "),
    (": pass)", ": в допуске)"), (": FAIL)", ": ВНЕ ДОПУСКА)"),
)  # fmt: skip


def _record_line(line: str, r: Record, lang: str) -> str:
    """One line of ``Transcript.to_text`` in ``lang``: its frame (stage, remedy, iteration,
    the words around the values) from the glossary, the step, the remedy and the equation by
    their templates (:func:`~stereoplotter.glossary.translate`); the values as printed."""
    head = f"{r.number}. [stage {r.stage}]"
    prefix = f"{r.number}. [{term('stage', lang)} {r.stage}]"
    if r.remedy:
        head += f" REMEDY ({r.remedy}):"
        prefix += f" {term('tr_remedy', lang)} ({translate(r.remedy, lang)}):"
    if r.iteration > 1:
        head += f" (iteration {r.iteration})"
        prefix += f" ({term('cs_iteration', lang)} {r.iteration})"
    head += f" {r.step}"
    prefix += f" {translate(r.step, lang)}"
    tail = line[len(head):]
    equation = f"  ({r.equation})" if r.equation else ""
    if equation and tail.endswith(equation):
        tail = tail[: -len(equation)]
        equation = f"  ({translate(r.equation, lang)})"
    for english, russian in _TAIL_RU:
        tail = tail.replace(english, russian)
    return prefix + tail + equation


def _records_text(result: SimulationResult, lang: str) -> str:
    """The numbered records (``Transcript.to_text``); in Russian every line is rendered again
    with its words from the glossary (:func:`_record_line`), the numbers as printed."""
    text = result.transcript.to_text()
    if lang == "en":
        return text
    records = iter(result.transcript.records)
    lines = []
    for line in text.splitlines():
        if line.startswith("## Stage "):
            lines.append(f"## {term('md_stage', lang)} {line.removeprefix('## Stage ')}")
        else:
            lines.append(_record_line(line, next(records), lang))
    return "\n".join(lines) + "\n"


def transcript_text(result: SimulationResult, lang: str = "en") -> str:
    """The learner's transcript: the numbered records, then :func:`closing_summary`."""
    check_language(lang)
    text = _records_text(result, lang) + "\n" + closing_summary(result, lang)
    if lang == "en":
        return text
    # the units, МО and tg in Russian, line by line (a control's identifier is left as it is)
    return "\n".join(localize(line, lang) for line in text.split("\n"))


def trial0_texts(result: SimulationResult, lang: str = "en") -> dict[str, bytes]:
    """``transcript.txt`` (:func:`transcript_text`, in ``lang``) and ``transcript.jsonl`` of
    trial 0."""
    return {
        "transcript.txt": transcript_text(result, lang).encode("utf-8"),
        "transcript.jsonl": result.transcript.to_jsonl().encode("utf-8"),
    }
