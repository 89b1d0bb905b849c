"""The transcript of a simulated procedure: one record per operator action.

A record carries what a trainee must see (``procedure.md`` §What a run returns): stage, step,
control, value before and after, the reading, the judgment error drawn, the residual seen, the
tolerance, pass/fail and the iteration. Vectorised runs record trial ``shown`` only (default 0);
the arrays of all trials live in the result, not in the transcript.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

__all__ = ["Record", "Transcript"]


def _f(value: Any, trial: int) -> float | None:
    if value is None:
        return None
    v = np.asarray(value, float)
    v = v.reshape(-1)[trial] if v.size > 1 else v.reshape(-1)[0]
    return None if math.isnan(float(v)) else float(v)


@dataclass(frozen=True, slots=True)
class Record:
    """One operator action.

    Attributes
    ----------
    number : int
        Running number (1, 2, …).
    stage : str
        "1" … "5" (setup-data method) or "C1" … "C4" (conventional method).
    step : str
        What the operator does, in words.
    control : str
        The control turned or the scale read ("" for a look).
    before, after : float or None
        Value of the control before and after (reading units: mm, m, rad). [unit]
    reading : float or None
        The value the operator reads or sets. [unit]
    unit : str
    judgment_error : float or None
        The judgment error drawn for this act (pointing, y-parallax, reading, setting). [unit]
    residual : float or None
        The residual the operator sees after the act (e.g. |L − L′|, q, misclosure). [mm or m]
    tolerance : float or None
        The tolerance the residual is checked against. [same unit as residual]
    passed : bool or None
        residual ≤ tolerance, where a tolerance applies.
    iteration : int
        Iteration of the enclosing tolerance loop (1 for a single pass).
    equation : str
        The book equation or design decision behind the act.
    remedy : str
        The remedy this act belongs to (``--practice operator``, after a failed check), or "".
    true : float or None
        The true value of what was seen (the y-parallax at the point, the height of the control
        point, …) where the simulation knows it: shown beside the seen one. [residual's unit]
    reading_unit : str
        The unit of ``reading`` where it differs from ``unit`` (a counter reading in mm while a
        knob turns in tan). "" = ``unit``.
    residual_unit : str
        The unit of ``residual``, ``tolerance``, ``judgment_error`` and ``true``: "mm" or "m".
    condition : str
        The name of the condition of a conditional step (a step taken only where it holds:
        :data:`stereoplotter.procedure.step_values.CONDITIONS`), "" for a step every run takes.
        Not written by :meth:`Transcript.to_jsonl` (a reader of the records has it).
    """

    number: int
    stage: str
    step: str
    control: str
    before: float | None
    after: float | None
    reading: float | None
    unit: str
    judgment_error: float | None
    residual: float | None
    tolerance: float | None
    passed: bool | None
    iteration: int
    equation: str
    remedy: str = ""
    true: float | None = None
    reading_unit: str = ""
    residual_unit: str = "mm"
    condition: str = ""


class Transcript:
    """Ordered records of one procedure run (trial ``shown`` of a vectorised run)."""

    def __init__(self, shown: int = 0, enabled: bool = True):
        self.shown = shown
        self.enabled = enabled
        self.records: list[Record] = []

    def add(
        self,
        stage: str,
        step: str,
        control: str = "",
        *,
        before: Any = None,
        after: Any = None,
        reading: Any = None,
        unit: str = "mm",
        judgment_error: Any = None,
        residual: Any = None,
        tolerance: Any = None,
        passed: Any = None,
        iteration: int = 1,
        equation: str = "",
        remedy: str = "",
        when: Any = None,
        true: Any = None,
        reading_unit: str = "",
        residual_unit: str = "",
        condition: str = "",
    ) -> None:
        """Append a record (array arguments are taken at trial ``shown``); ``when`` (a mask
        over the trials) skips the record where trial ``shown`` did not do the act."""
        if not self.enabled:
            return
        t = self.shown
        if when is not None:
            w = np.asarray(when).reshape(-1)
            if not bool(w[t] if w.size > 1 else w[0]):
                return
        ok = None
        if passed is not None:
            p = np.asarray(passed).reshape(-1)
            ok = bool(p[t] if p.size > 1 else p[0])
        self.records.append(
            Record(
                len(self.records) + 1,
                str(stage),
                step,
                control,
                _f(before, t),
                _f(after, t),
                _f(reading, t),
                unit,
                _f(judgment_error, t),
                _f(residual, t),
                _f(tolerance, t),
                ok,
                int(iteration),
                equation,
                remedy,
                _f(true, t),
                reading_unit,
                residual_unit or ("m" if unit == "m" else "mm"),
                condition,
            )
        )

    def to_jsonl(self) -> str:
        """JSON lines, one record per line (keys as in :class:`Record`)."""
        return "".join(
            json.dumps(_written(r), ensure_ascii=False, sort_keys=False) + "\n"
            for r in self.records
        )

    def to_text(self) -> str:
        """Numbered steps for a trainee: what to set, what was read and seen, pass/fail.

        Examples
        --------
        >>> t = Transcript()
        >>> t.add("1", "set f_пр", "f_instrument", reading=109.375, equation="item 1")
        >>> print(t.to_text().splitlines()[-1])
        1. [stage 1] set f_пр — f_instrument: 109.3750 mm  (item 1)
        """
        lines = []
        stage = None
        for r in self.records:
            if r.stage != stage:
                stage = r.stage
                lines.append(f"## Stage {stage}")
            parts = [f"{r.number}. [stage {r.stage}]"]
            if r.remedy:
                parts.append(f"REMEDY ({r.remedy}):")
            if r.iteration > 1:
                parts.append(f"(iteration {r.iteration})")
            parts.append(r.step)
            text = " ".join(parts)
            if r.control:
                text += f" — {r.control}"
                if r.reading is not None:
                    text += f": {_num(r.reading, r.reading_unit or r.unit)}"
                if r.before is not None and r.after is not None:
                    text += f" (from {_num(r.before, r.unit)} to {_num(r.after, r.unit)})"
            elif r.reading is not None:
                text += f" — read {_num(r.reading, r.reading_unit or r.unit)}"
            text += _seen(r)
            if r.equation:
                text += f"  ({r.equation})"
            lines.append(text)
        return "\n".join(lines) + "\n"


def _written(record: Record) -> dict[str, Any]:
    """The fields of a record the JSON lines carry (all but ``condition``)."""
    out = asdict(record)
    del out["condition"]
    return out


def _small(value: float, unit: str, sign: str = "+") -> str:
    """A residual, error or tolerance: µm for model mm (like the judgment errors), m to the
    millimetre for ground heights."""
    if unit == "m":
        return f"{value:{sign}.3f} m"
    return f"{value * 1e3:{sign}.1f} µm"


def _seen(r: Record) -> str:
    """``; judgment error …; seen … (true …; tolerance …: pass)`` where known."""
    text = ""
    u = r.residual_unit
    if r.judgment_error is not None and r.judgment_error != 0.0:
        text += f"; judgment error {_small(r.judgment_error, u)}"
    if r.residual is not None:
        text += f"; seen {_small(r.residual, u)}"
        extra = []
        if r.true is not None:
            extra.append(f"true {_small(r.true, u)}")
        if r.tolerance is not None:
            extra.append(
                f"tolerance {_small(r.tolerance, u, '')}: {'pass' if r.passed else 'FAIL'}"
            )
        if extra:
            text += f" ({'; '.join(extra)})"
    return text


def _num(value: float, unit: str) -> str:
    if unit == "rad":
        return f"{math.degrees(value) * 60:+.2f}′"
    if unit == "m":
        return f"{value:.2f} m"
    if unit == "tan":
        return f"tan {value:+.6f}"
    if unit == "—":
        return f"{value:.6f}"
    return f"{value:.4f} {unit}"
