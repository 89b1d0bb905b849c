"""The operator sets the readings printed on the setup sheet, and computes none (issue, part 4).

A seeded vectorised run of the setup-data method with a recording wrapper around
``Operator.set`` (every value the operator sets on a scale). Each set is classified by its act
key: a reading of the sheet (its name and the zero reading it is added to), or one of the few
settings that are not sheet readings (zero places, the corrections of the L-check loop). A set
that is neither fails the test, so a reading recomputed in the procedure under a new act shows up
here as well as a wrong value.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from stereoplotter.instrument.virtual import NOMINAL_ZERO
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.procedure import simulate
from stereoplotter.procedure.noise_key import as_key
from stereoplotter.procedure.operator import Operator

SIDE = {"left": "л", "right": "п"}
SUFFIX = {"left": "", "right": ",п"}

#: Settings that are not sheet readings: zero places of stage 1 and the L-check corrections
#: O′ = O + Δ (6.9)–(6.11), f′_пр at the bottom stop.
NOT_READINGS = (
    r"1/bz0",
    r"1/d[xy]_(left|right)",
    r"(1/L|1/L/R1|2/L\d+)/\d+/set(Z|bz|f)",  # R1 repeats the L-check corrections
    r"3/R3/\d+/(setbx|(alpha|omega)/setbz)",  # R3: b_x, b_z′ turned from the control heights
)


def _expected(key: str, sheet) -> tuple[str, str | float | None] | None:
    """(sheet reading, its zero: a zero-reading name, a nominal zero place, or None)."""
    first_height = sheet.control_heights[0]["id"]
    fixed = {
        "1/f": ("f_пр", None),
        "1/bx": ("O_bx", "MO_bx"),  # MO_bx from two pointings, (6.38)
        "1/Z": ("O_Z", None),
        "1/by": ("O_by", "MO_by"),
        "2/bz": ("O_bz", "MO_bz"),
        "3/OZ": (f"O_Z{first_height}", "MO_Z"),
    }
    if key in fixed:
        return fixed[key]
    if m := re.fullmatch(r"2/\d+/(left|right)/(omega|m4)/set", key):
        side, act = m.groups()
        mark = "3" if act == "omega" else "4"
        return f"O_Y{mark},{SIDE[side]}", "MO_Y" + SUFFIX[side]
    if m := re.fullmatch(r"2/(left|right)/alpha/set", key):
        side = m.group(1)
        mark = "2" if side == "left" else "1"
        return f"O_X{mark},{SIDE[side]}", "MO_X" + SUFFIX[side]
    if m := re.fullmatch(r"2/(d([xy])_(left|right))", key):
        control, axis, side = m.groups()
        return f"d_{axis},{SIDE[side]}", NOMINAL_ZERO[control]
    if m := re.fullmatch(r"(4/\d|5)/c(\d)/([XY])", key):
        _, corner, axis = m.groups()
        return f"corner {corner}: O_{axis}", "MO_" + axis
    return None


@pytest.fixture(scope="module")
def recorded():
    calls = []
    original = Operator.set

    def recording(self, control, value, key, active=None):
        cmd = original(self, control, value, key, active)
        stopped = np.array(self.stopped.get(control, False))  # trials turned against a stop
        calls.append((control, as_key(key).stream(), self.v(value), np.array(cmd, float), stopped))
        return cmd

    mp = pytest.MonkeyPatch()
    mp.setattr(Operator, "set", recording)
    try:
        sc = load_scenario("scenarios/pair60.yaml")
        result = simulate(sc, load_instrument("sc1"), seed=11, trials=16, evaluate=False)
    finally:
        mp.undo()
    return result, calls


def test_every_value_set_is_a_printed_reading(recorded):
    result, calls = recorded
    sheet = result.sheet
    printed = {r["reading"]: r for r in sheet.readings}
    spec = result.instrument.spec
    used = set()
    for control, key, value, cmd, stopped in calls:
        expected = _expected(key, sheet)
        if expected is None:
            assert any(re.fullmatch(p, key) for p in NOT_READINGS), f"{key}: not a sheet reading"
            continue
        name, zero = expected
        row = printed[name]
        if isinstance(zero, str):
            assert row["zero_reading"] == zero, name
            zero = result.zero_readings[zero]
        want = row["value"] if zero is None else zero + row["value"]
        np.testing.assert_allclose(value, np.broadcast_to(want, value.shape), rtol=0, atol=1e-9)
        used.add(name)
        # what reached the scale: the reading + σ_set (0.2 least count), within one least count,
        # unless the reading lies beyond the stop (O_Z = D_max with a zero-reading error)
        lc = {"H": spec.height_scale_least_count_m, "Z": spec.z_least_count_mm}.get(
            control, spec.xy_least_count_mm
        )
        if control != "f_instrument":
            free = ~np.broadcast_to(stopped, value.shape)
            assert np.all(np.abs(cmd - value)[free] <= lc), name
    corners = {f"corner {c}: O_{a}" for c in "134" for a in "XY"}
    sides = {f"{r},{s}" for s in "лп" for r in ("O_Y3", "O_Y4", "d_x", "d_y")}
    want_used = {"f_пр", "O_bx", "O_by", "O_Z", "O_X2,л", "O_X1,п", "O_bz"} | sides | corners
    assert want_used | {f"O_Z{sheet.control_heights[0]['id']}"} <= used


def test_zero_readings_are_read_to_the_least_count(recorded):
    """The MO the printed values are added to are the operator's rounded readings."""
    result, _ = recorded
    spec = result.instrument.spec
    lcs = {"MO_Z": spec.height_scale_least_count_m}
    for name in ("MO_X", "MO_Y", "MO_X,п", "MO_Y,п", "MO_by", "MO_Z"):
        lc = lcs.get(name, spec.xy_least_count_mm)
        mo = np.asarray(result.zero_readings[name], float)
        np.testing.assert_allclose(mo / lc, np.round(mo / lc), rtol=0, atol=1e-6, err_msg=name)
