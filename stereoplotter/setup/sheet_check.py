"""A trainee's setup sheet checked against the program's.

Pure comparison and diagnosis, no file I/O: the trainee's values come as a flat mapping
``key → value or None`` (keys as in ``sheet.yaml``: ``n_right``, ``L_mm.left``,
``base_mm.bx``, ``readings.O_Y4,л`` …; :mod:`stereoplotter.io.trainee_sheet` reads the file).
Every value is compared with :func:`stereoplotter.setup.sheet.compute_setup_sheet` within a
stated tolerance (the least count of the scale it is set on, or the book's tolerance), and a value
outside it is matched against the same value recomputed under each known mistake (sign of (6.4),
n applied twice in (6.5), mm versus m, magnitudes in (6.12)/(6.13), …): the first hypothesis that
reproduces the trainee's value within the tolerance names the likely mistake.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from stereoplotter.constants import MM_PER_M
from stereoplotter.setup.records import SetupSheet
from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = ["Expected", "ItemResult", "SheetCheck", "check_sheet", "expected_values"]

#: A sheet value a trainee writes down more exactly than its scale shows is no error; a mistake
#: hypothesis matches when it reproduces the trainee's value this closely (in tolerances).
MATCH_FACTOR = 1.0


@dataclass(frozen=True, slots=True)
class Expected:
    """One value of the sheet: the program's value, its tolerance and the known mistakes.

    ``mistakes`` holds (name, value the mistake gives) pairs, tried in order.
    """

    key: str
    value: float
    unit: str
    equation: str
    tolerance: float
    tolerance_basis: str
    mistakes: tuple[tuple[str, float], ...] = ()


@dataclass(frozen=True, slots=True)
class ItemResult:
    """The verdict on one value: ``ok``, ``wrong`` or ``missing``; ``mistake`` the likely one."""

    expected: Expected
    trainee: float | None
    status: str
    mistake: str = ""

    @property
    def difference(self) -> float:
        """Trainee minus program, in the value's unit (NaN when missing)."""
        return math.nan if self.trainee is None else self.trainee - self.expected.value


@dataclass(frozen=True, slots=True)
class SheetCheck:
    """All verdicts, in sheet order, and the keys of the trainee sheet nothing was compared to."""

    scenario: str
    instrument: str
    items: tuple[ItemResult, ...]
    unknown_keys: tuple[str, ...] = ()

    def count(self, status: str) -> int:
        return sum(1 for i in self.items if i.status == status)

    @property
    def passed(self) -> bool:
        return self.count("wrong") == 0 and self.count("missing") == 0


def _least(spec: InstrumentSpec, attribute: str, what: str) -> tuple[float, str]:
    key = spec.key_of(attribute)
    status = "assumed" if spec.is_assumed(key) else "documented"
    return getattr(spec, attribute), f"least count of the {what} ({status}, {spec.source}: {key})"


def _generic(value: float, unit: str) -> tuple[tuple[str, float], ...]:
    """Mistakes any value can carry: the sign, and a factor 1000 (mm versus m)."""
    out: list[tuple[str, float]] = [("wrong sign", -value)]
    if unit == "mm":
        out += [("mm versus m: written in metres", value / MM_PER_M)]
        out += [("mm versus m: a factor 1000 too large", value * MM_PER_M)]
    elif unit == "m":
        out += [("mm versus m: written in millimetres", value * MM_PER_M)]
        out += [("mm versus m: a factor 1000 too small", value / MM_PER_M)]
    return tuple(out)


def _scalars(sheet: SetupSheet, spec: InstrumentSpec) -> list[Expected]:
    xy, xy_basis = _least(spec, "xy_least_count_mm", "X, Y counters")
    n_l, n_r, f_pr = sheet.n_left, sheet.n_right, sheet.f_instrument_mm
    f_prime = sheet.focal_length_corrected_mm
    # n: the change of n that moves the largest mark reading (≈ half the format) by one least count
    half = max(abs(v) for p in sheet.photos for v in p.transformed_book_mm.values())
    n_tol = xy / half
    n_basis = f"{xy_basis} over the largest mark coordinate {half:.1f} mm (derived)"
    k = sheet.transformation_coefficient
    bx, by, bz = sheet.base_mm
    out = [
        Expected(
            "f_instrument_mm",
            f_pr,
            "mm",
            "item 1",
            xy,
            xy_basis + "; assumed the same scale",
            (("f′ (the camera's) in place of f_пр", f_prime),),
        ),
        Expected(
            "transformation_coefficient",
            k,
            "—",
            "k = f_пр/f′",
            n_tol,
            n_basis,
            (("inverted: f′/f_пр", 1.0 / k),),
        ),
        Expected(
            "n_left",
            n_l,
            "—",
            "(6.3)",
            n_tol,
            n_basis,
            (("f′ in place of f_пр in (6.3)", n_l * f_pr / f_prime),),
        ),
        Expected(
            "n_right",
            n_r,
            "—",
            "(6.4)",
            n_tol,
            n_basis,
            (
                ("sign of (6.4): Z_Sл − Z_Sп in place of Z_Sп − Z_Sл", 2 * n_l - n_r),
                ("n_п taken equal to n_л ((6.4) not applied)", n_l),
            ),
        ),
    ]
    for name, value in (("bx", bx), ("by", by), ("bz", bz)):
        out.append(
            Expected(
                f"base_mm.{name}",
                value,
                "mm",
                "item 1",
                xy,
                xy_basis,
                (
                    (
                        "ground metres in place of model mm",
                        value * sheet.horizontal_scale_denominator / MM_PER_M,
                    ),
                ),
            )
        )
    return out


def _photos(sheet: SetupSheet, spec: InstrumentSpec) -> list[Expected]:
    xy, xy_basis = _least(spec, "xy_least_count_mm", "X, Y counters")
    f_prime, f_pr = sheet.focal_length_corrected_mm, sheet.f_instrument_mm
    out: list[Expected] = []
    for p in sheet.photos:
        n = p.n
        for key, value in p.transformed_book_mm.items():
            out.append(
                Expected(
                    f"fiducials_transformed_mm.{p.name}.{key}",
                    value,
                    "mm",
                    "(6.1)/(6.2)",
                    xy,
                    xy_basis,
                    (
                        (
                            "n applied in (6.1)/(6.2) (the printed form; this sheet applies n in "
                            "(6.12)/(6.13))",
                            n * value,
                        ),
                    ),
                )
            )
        span_tol = sheet.tolerances["mark_span_mm"]
        y3, y4 = p.transformed_book_mm["y3"], p.transformed_book_mm["y4"]
        out.append(
            Expected(
                f"L_mm.{p.name}",
                p.mark_span_mm,
                "mm",
                "(6.5)",
                span_tol,
                "the book's mark-span tolerance (tolerances.mark_span_mm, §26 stage 1)",
                (
                    ("n applied twice in (6.5)", n * p.mark_span_mm),
                    ("n left out of (6.5)", p.mark_span_mm / n),
                    ("magnitudes in (6.5): n·(|y⁰₃| − |y⁰₄|)", n * (abs(y3) - abs(y4))),
                ),
            )
        )
        for axis, d, angle in (("x", p.decentration_mm[0], "α"), ("y", p.decentration_mm[1], "ω")):
            out.append(
                Expected(
                    f"decentrations_mm.{p.name}.{axis}",
                    d,
                    "mm",
                    f"f′·tan {angle}",
                    xy,
                    xy_basis,
                    (("f_пр in place of f′", d * f_pr / f_prime),),
                )
            )
    return out


def _heights_and_corners(sheet: SetupSheet, spec: InstrumentSpec) -> list[Expected]:
    z, z_basis = _least(spec, "z_least_count_mm", "absolute height counter")
    m_v, m_g = sheet.vertical_scale_denominator, sheet.horizontal_scale_denominator
    out = [
        Expected(
            f"control_heights_model_mm.{h['id']}",
            h["model_height_mm"],
            "mm",
            "(6.6)",
            z,
            z_basis,
            (("M_г in place of M_в in (6.6)", h["model_height_mm"] * m_v / m_g),),
        )
        for h in sheet.control_heights
    ]
    corner_tol = sheet.tolerances["corner_mm"]
    for c in sheet.corners:
        for axis, other in (("x", "y"), ("y", "x")):
            value = c[f"{axis}_mm"]
            mistakes: list[tuple[str, float]] = [("x and y exchanged", c[f"{other}_mm"])]
            if sheet.map_scale_denominator:
                mistakes.append(
                    ("M_map in place of M_г in (6.7)", value * m_g / sheet.map_scale_denominator)
                )
            out.append(
                Expected(
                    f"sheet_corners_mm.{c['corner']}.{axis}",
                    value,
                    "mm",
                    "(6.7)",
                    corner_tol,
                    "the book's corner tolerance (tolerances.corner_mm, §26 stage 4)",
                    tuple(mistakes),
                )
            )
    return out


def _readings(sheet: SetupSheet, spec: InstrumentSpec) -> list[Expected]:
    xy, xy_basis = _least(spec, "xy_least_count_mm", "X, Y counters")
    hs, hs_basis = _least(spec, "height_scale_least_count_m", "height scale")
    out: list[Expected] = []
    for r in sheet.readings:
        if r["equation"] == "stage 2":  # the residual-parallax bound is a tolerance, not a value
            continue
        value, unit = float(r["value"]), r["unit"]
        tol, basis = (hs, hs_basis) if unit == "m" else (xy, xy_basis)
        if "tolerance" in r and unit == "mm":
            tol, basis = r["tolerance"], f"the book's tolerance of this step ({r['equation']})"
        mistakes: list[tuple[str, float]] = []
        if r["equation"] in ("(6.12)", "(6.13)"):
            n = sheet.n_left if r["reading"].endswith("л") else sheet.n_right
            if value < 0:
                mistakes.append(
                    (f"magnitude in place of the signed reading in {r['equation']}", abs(value))
                )
            mistakes += [
                (f"n left out of {r['equation']}", value / n),
                (f"n applied twice in {r['equation']}", value * n),
            ]
            if not r["reading"].endswith("л"):
                mistakes.append(("n_л used for the right photo", value * sheet.n_left / n))
        out.append(
            Expected(
                f"readings.{r['reading']}", value, unit, r["equation"], tol, basis, tuple(mistakes)
            )
        )
    return out


def expected_values(sheet: SetupSheet, spec: InstrumentSpec) -> tuple[Expected, ...]:
    """Every value a trainee computes for the sheet, in sheet order, with tolerance and mistakes.

    The scale denominators are compared exactly (a choice, not a computation: tolerance 0).
    """
    scales = [
        Expected(
            "scale_horizontal",
            float(sheet.horizontal_scale_denominator),
            "—",
            "item 1",
            0.0,
            "a chosen scale: exact",
        ),
        Expected(
            "scale_vertical",
            float(sheet.vertical_scale_denominator),
            "—",
            "item 1",
            0.0,
            "a chosen scale: exact",
            (("M_г in place of M_в", float(sheet.horizontal_scale_denominator)),),
        ),
    ]
    return tuple(
        scales
        + _scalars(sheet, spec)
        + _photos(sheet, spec)
        + _heights_and_corners(sheet, spec)
        + _readings(sheet, spec)
    )


def _diagnose(e: Expected, trainee: float) -> str:
    for name, value in (*e.mistakes, *_generic(e.value, e.unit)):
        if math.isfinite(value) and abs(trainee - value) <= MATCH_FACTOR * max(e.tolerance, 1e-12):
            if abs(value - e.value) > e.tolerance:  # a mistake that changes nothing is no cause
                return name
    return ""


def check_sheet(
    sheet: SetupSheet, spec: InstrumentSpec, trainee: Mapping[str, float | None]
) -> SheetCheck:
    """Compare a trainee's values with the program's sheet and name the likely mistakes.

    Parameters
    ----------
    sheet : SetupSheet
        :func:`stereoplotter.setup.sheet.compute_setup_sheet` of the scenario and instrument.
    spec : InstrumentSpec
        The instrument (its least counts are the tolerances of values set on its scales).
    trainee : mapping
        ``key → value`` as read from the trainee's sheet (None or absent: missing). [units of
        each key, as in ``sheet.yaml``]

    Returns
    -------
    SheetCheck
        A value is ``ok`` when |trainee − program| ≤ tolerance (the tolerance and where it comes
        from are in ``ItemResult.expected``).
    """
    items = []
    expected = expected_values(sheet, spec)
    for e in expected:
        got = trainee.get(e.key)
        if got is None or not math.isfinite(got):
            items.append(ItemResult(e, None, "missing"))
        elif abs(got - e.value) <= e.tolerance + 1e-9 * max(1.0, abs(e.value)):
            items.append(ItemResult(e, got, "ok"))
        else:
            items.append(ItemResult(e, got, "wrong", _diagnose(e, got)))
    known = {e.key for e in expected} | {f"readings.{r['reading']}" for r in sheet.readings}
    unknown = tuple(sorted(k for k in trainee if k not in known))
    return SheetCheck(sheet.scenario, sheet.instrument, tuple(items), unknown)
