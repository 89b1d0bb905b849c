"""Rendering of a trainee-sheet check (:mod:`stereoplotter.setup.sheet_check`) as text and data."""

from __future__ import annotations

import math
from typing import Any

from stereoplotter.setup.sheet_check import ItemResult, SheetCheck

__all__ = ["check_dict", "check_text"]


def _digits(tolerance: float) -> int:
    """Decimals that show a value to a tenth of its tolerance (at most 6)."""
    if tolerance <= 0:
        return 0
    return max(0, min(6, 1 - math.floor(math.log10(tolerance))))


def _line(item: ItemResult) -> str:
    e = item.expected
    d = _digits(e.tolerance)
    diff = round(item.difference, d) + 0.0 if item.trainee is not None else math.nan
    unit = "" if e.unit == "—" else f" {e.unit}"
    if item.status == "missing":
        return f"MISSING {e.key}: no value; expected {e.value:.{d}f}{unit} ({e.equation})"
    verdict = "ok     " if item.status == "ok" else "WRONG  "
    text = (
        f"{verdict}{e.key} = {item.trainee:.{d}f}{unit}; program {e.value:.{d}f}{unit}, "
        f"difference {diff:+.{d}f}{unit}, tolerance ±{e.tolerance:.{d}f}{unit} "
        f"({e.tolerance_basis}); {e.equation}"
    )
    if item.status == "wrong":
        text += f"; likely mistake: {item.mistake}" if item.mistake else "; no known mistake fits"
    return text


def check_text(check: SheetCheck) -> str:
    """One line per value, then the totals."""
    lines = [f"Setup sheet check — {check.scenario} on {check.instrument}", ""]
    lines += [_line(i) for i in check.items]
    lines += [
        "",
        f"{check.count('ok')} ok, {check.count('wrong')} wrong, {check.count('missing')} missing"
        f" of {len(check.items)} values: {'PASSED' if check.passed else 'NOT PASSED'}",
    ]
    if check.unknown_keys:
        lines.append(
            "not compared (the program's sheet has no such value): " + ", ".join(check.unknown_keys)
        )
    return "\n".join(lines) + "\n"


def check_dict(check: SheetCheck) -> dict[str, Any]:
    """The check as plain data (``--json``)."""
    return {
        "scenario": check.scenario,
        "instrument": check.instrument,
        "passed": check.passed,
        "counts": {s: check.count(s) for s in ("ok", "wrong", "missing")},
        "items": [
            {
                "key": i.expected.key,
                "status": i.status,
                "trainee": i.trainee,
                "program": i.expected.value,
                "unit": i.expected.unit,
                "equation": i.expected.equation,
                "tolerance": i.expected.tolerance,
                "tolerance_basis": i.expected.tolerance_basis,
                "likely_mistake": i.mistake or None,
            }
            for i in check.items
        ],
        "not_compared": list(check.unknown_keys),
    }
