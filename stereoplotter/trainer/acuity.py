"""The trainee's own stereo acuity: an adaptive staircase on x-parallax (depth: which of two marks
is nearer) and on visible y-parallax (which way the right image is offset across the base).

The page shows the stimulus, the trainee answers; the staircase sets the next disparity. The
rule (Kaernbach's weighted up-down): after a right answer the disparity is divided by
:data:`STEP`, after a wrong one multiplied by ``STEP**3``: it settles where right answers are
three in four (P = 0.75). The judgement is taken as eye.py reads the textbook's acuity: a
sign judgement with Gaussian error, P(right | s) = Φ(s/σ), the acuity the σ (the 84 % point);
so σ = s₇₅ / Φ⁻¹(0.75). The estimate is the geometric mean of the disparities at the
reversals after the first :data:`DISCARD`; its standard error (relative) the standard deviation
of their logarithms over √(reversals/4): neighbouring reversals are not independent, and the
divisor is the one that makes the stated error the spread of the estimate over runs of a
simulated observer (``tests/trainer/test_acuity.py``: about 39 trials a run, ±44 % in σ).

A disparity on the screen is an angle at the eye: s_px · pixel pitch / viewing distance; the
result in µm of photo at a magnification V is ``procedure.eye.angle_to_photo_mm`` (eye 1,
referred to 250 mm). Pure numpy; the page runs the same rule (``static/acuity.js``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from stereoplotter.procedure.eye import (
    ACUITY_FIRST_KIND_ARCSEC,
    ACUITY_SECOND_KIND_ARCSEC,
    DEFAULT_VIEWING_DISTANCE_MM,
    Eye,
    ObservationSystem,
    angle_to_photo_mm,
)

__all__ = [
    "ACUITY_RECORDS",
    "DISCARD",
    "MAGNIFICATIONS",
    "PLAUSIBLE",
    "REVERSALS",
    "STEP",
    "Z75",
    "Staircase",
    "acuity_note",
    "photo_um",
    "simulated_observer",
    "trainee_acuity",
    "with_acuity",
]

#: Down step (a ratio) after a right answer; a wrong answer goes up by STEP³. [—]
STEP = 1.25
#: Reversals that end a run, and the first ones left out of the estimate (the approach).
REVERSALS = 12
DISCARD = 3
#: Trials at most (a run that does not settle ends here). [—]
MAX_TRIALS = 100
#: Φ⁻¹(0.75): the 75 % point of Φ(s/σ) in σ. [—]
Z75 = 0.6744897501960817
#: Magnifications the result is given at (the page's eyepiece ×2 … ×20). [×]
MAGNIFICATIONS = (2.0, 6.0, 20.0)
#: A recorded acuity outside this range is taken as not measured (assumed: human stereo
#: acuities run from about 2″ to a few arc-minutes; the value comes from the trainee's page and
#: is not trusted beyond that). [″]
PLAUSIBLE = (2.0, 600.0)
#: Session-log record names the page writes the result under → the instructor's column.
ACUITY_RECORDS = {
    "stereo acuity x (arcsec)": "x_arcsec",
    "stereo acuity y (arcsec)": "y_arcsec",
}


@dataclass
class Staircase:
    """One run: ``level`` the disparity to show next [″]; :meth:`answer` the trainee's answer."""

    start: float
    floor: float = 0.5
    ceiling: float = 3600.0
    level: float = field(init=False)
    trials: int = field(default=0, init=False)
    reversal_levels: list[float] = field(default_factory=list, init=False)
    _last: int = field(default=0, init=False)  # +1 going up, −1 going down

    def __post_init__(self) -> None:
        self.level = float(self.start)

    @property
    def done(self) -> bool:
        return len(self.reversal_levels) >= REVERSALS or self.trials >= MAX_TRIALS

    def answer(self, right: bool) -> None:
        self.trials += 1
        move = -1 if right else 1
        if self._last and move != self._last:
            self.reversal_levels.append(self.level)
        self._last = move
        self.level *= STEP ** -1 if right else STEP**3
        self.level = min(max(self.level, self.floor), self.ceiling)

    def estimate(self) -> tuple[float, float]:
        """(σ [″], its relative standard error): see the module docstring."""
        used = np.log(np.asarray(self.reversal_levels[DISCARD:], float))
        if used.size < 2:
            return math.nan, math.nan
        s75 = float(np.exp(used.mean()))
        se = float(used.std(ddof=1) / math.sqrt(used.size / 4.0))
        return s75 / Z75, se


def simulated_observer(sigma: float, rng: np.random.Generator):
    """An observer whose judgement at disparity s is right with probability Φ(s/σ)."""

    def judge(level: float) -> bool:
        return bool(level / sigma + rng.standard_normal() > 0.0)

    return judge


def photo_um(
    arcsec: float, magnifications=MAGNIFICATIONS, viewing_distance_mm=DEFAULT_VIEWING_DISTANCE_MM
) -> dict[str, float]:
    """An acuity at the eye as µm on the photo at each magnification (eye 1). [µm]"""
    return {
        f"{m:g}": angle_to_photo_mm(arcsec, m, viewing_distance_mm) * 1000.0
        for m in magnifications
    }


def trainee_acuity(records: dict[str, Any]) -> dict[str, float] | None:
    """The acuity the page's test recorded in a session (``{"x_arcsec", "y_arcsec"}``), or None
    when not measured (or a value is not a number within :data:`PLAUSIBLE`). [″]"""
    out = {}
    for name, key in ACUITY_RECORDS.items():
        v = records.get(name)
        number = isinstance(v, (int, float)) and not isinstance(v, bool)
        if not number or not PLAUSIBLE[0] <= v <= PLAUSIBLE[1]:
            return None
        out[key] = float(v)
    return out


def with_acuity(prep: Any, acuity: dict[str, float]) -> Any:
    """The prepared run with its simulated operators given the trainee's acuity: the x-parallax
    (depth) threshold as the first kind (σ_p, the fused mark), the y-parallax one as the second
    kind (σ_q), through the instrument's observation system (procedure.eye, (eye 1))."""
    system = prep.operator.observation or ObservationSystem.from_spec(prep.spec)
    eye = Eye(system, acuity["x_arcsec"], acuity["y_arcsec"])
    operator = replace(
        prep.operator,
        stereo_sigma_mm=eye.stereo_sigma_mm,
        y_parallax_sigma_mm=eye.y_parallax_sigma_mm,
        observation=system,
    )
    return replace(prep, operator=operator)


def acuity_note(acuity: dict[str, float] | None, prep: Any) -> dict[str, Any]:
    """What the grade's population was given for the eye, said in one line (``text``)."""
    op = prep.operator
    if acuity is None:
        x, y, whose = ACUITY_FIRST_KIND_ARCSEC, ACUITY_SECOND_KIND_ARCSEC, "the textbook's"
    else:
        x, y, whose = acuity["x_arcsec"], acuity["y_arcsec"], "your measured"
    system = op.observation or ObservationSystem.from_spec(prep.spec)
    eye = Eye(system, x, y)
    text = (
        f"Compared with simulated operators of {whose} stereo acuity: {x:.1f}″ in depth "
        f"(σ_p {eye.stereo_sigma_mm * 1000:.2f} µm) and {y:.1f}″ across the base (σ_q "
        f"{eye.y_parallax_sigma_mm * 1000:.2f} µm) through the instrument's ×"
        f"{system.magnification:g}"
    )
    if acuity is None:
        text += " (your own was not measured: the page's acuity test measures it)"
    return {"measured": acuity is not None, "x_arcsec": x, "y_arcsec": y,
            "stereo_sigma_um": eye.stereo_sigma_mm * 1000, "y_parallax_sigma_um":
            eye.y_parallax_sigma_mm * 1000, "text": text}
