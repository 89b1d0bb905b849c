"""The grade of a trainee's session as Markdown and JSON (``trainer.grading.grade``).

:func:`grade_markdown` formats the grade dict, :func:`grade_json` its JSON; the ``grade``
command writes both (:mod:`stereoplotter.commands.grade`).
"""

from __future__ import annotations

import json
from typing import Any

__all__ = ["grade_json", "grade_markdown"]


def _num(value: Any, unit: str = "") -> str:
    if value is None:
        return "—"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        if value == float("inf"):
            return "not set"
        text = f"{value:.4g}"
    else:
        text = str(value)
    return f"{text} {unit}".strip() if unit and unit != "—" else text


def _mark(passed: bool) -> str:
    return "pass" if passed else "**fail**"


def grade_json(grade: dict[str, Any]) -> str:
    """The grade as indented JSON (UTF-8 text, one final newline)."""
    return json.dumps(grade, indent=2, ensure_ascii=False, allow_nan=False) + "\n"


def grade_markdown(grade: dict[str, Any]) -> str:
    """The grade as a Markdown report: outcome per stage, overall, process against par."""
    overall = grade["overall"]
    lines = [
        f"# Grade: {grade['title']}",
        "",
        f"Exercise `{grade['exercise']}` · trainee **{grade['trainee']}** · instrument "
        f"{grade['instrument']} · {grade['method']} method · {grade['mode']} · injected errors "
        f"{grade['errors']} · seed {grade['seed']}",
        "",
        f"**Overall: {'passed' if overall['passed'] else 'not passed'}** — score "
        f"{_num(overall['score'])} (largest value/tolerance, ≤ 1 passes); par "
        f"{_num(overall['par_score'])}"
        + (
            f"; better than or equal to {overall['percentile']:.1f} % "
            f"(± {overall['percentile_se']:.1f} %) of "
            f"{grade['population']['operators']} simulated operators on the same instrument"
            if "percentile" in overall
            else ""
        ),
        "",
        "## Outcome against the ground truth",
        "",
        "| stage | measure | yours | tolerance | | par | percentile |",
        "|---|---|---:|---:|---|---:|---:|",
    ]
    for stage, body in grade["stages"].items():
        label = stage if body["claimed"] else f"{stage} (not claimed)"
        for m in body["measures"]:
            pct = f"{m['percentile']:.1f} %" if "percentile" in m else "—"
            lines.append(
                f"| {label} | {m['name'].replace('|', chr(92) + '|')} | "
                f"{_num(m['value'], m['unit'])} | "
                f"{_num(m['tolerance'], m['unit'])} | {_mark(m['passed'])} | "
                f"{_num(m['par'], m['unit'])} | {pct} |"
            )
    lines += ["", "## Process", "", "| measure | yours | par |", "|---|---:|---:|"]
    mine, par = grade["process"], grade["par_process"]
    for key in mine:
        if key == "final_approach":
            continue
        lines.append(f"| {key.replace('_', ' ')} | {_num(mine[key])} | {_num(par.get(key))} |")
    pop = grade["population"]
    lines += [
        "",
        f"Population: {pop['operators']} simulated operators in {pop['seconds']:.1f} s "
        "(vectorised trials; trial 0 is the par).",
        "",
    ]
    return "\n".join(lines)
