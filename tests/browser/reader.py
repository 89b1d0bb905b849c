"""The reader robot: a trainee that uses only what the instrument page shows — the step texts,
the setup sheet panel, the parallax read-out, the counters and the mark captions — and the
page's controls (handwheel boxes, the go-to buttons, the overview, *read*, *claim*). No core
call, no simulated operator, no hint.
"""

from __future__ import annotations

import re

import numpy as np

_Q = re.compile(r"parallax at standard point (\d): q = (-?[\d.]+) µm, p = (-?[\d.]+) µm")


class Reader:
    """Gestures and readings on an open instrument page."""

    def __init__(self, page):
        self.page = page
        self.sent = 0

    # --- acting ----------------------------------------------------------------------------
    def settle(self) -> None:
        """Wait for the server's answer to every action sent, and for the page to draw it."""
        self.page.wait_for_function(f"() => window.__n >= {self.sent}", timeout=60_000)
        self.page.evaluate("() => new Promise((r) => requestAnimationFrame(() => setTimeout(r)))")

    def set(self, label: str, value: float) -> None:
        """Set the control of the wheel labelled ``label``: typed into the keyboard box by the
        control's name (the step texts write it), Enter."""
        self.page.fill("#command", f"{CONTROLS.get(label, label)} {float(value)!r}")
        self.page.press("#command", "Enter")
        self.sent += 1
        self.settle()

    def go_to(self, point: int) -> None:
        self.page.click(f"#goto button[data-point='{point}']")
        self.sent += 2
        self.settle()

    def claim(self) -> None:
        self.page.click("#claim")
        self.sent += 1
        self.settle()

    # --- reading ---------------------------------------------------------------------------
    def steps(self) -> list[str]:
        return self.page.locator("#checklist > li").all_inner_texts()

    def q_um(self) -> tuple[int, float]:
        """The read-out's standard point and its y-parallax. [µm]"""
        m = _Q.search(self.page.inner_text("#parallax"))
        if m is None:
            raise AssertionError("no parallax read-out on the page")
        return int(m.group(1)), float(m.group(2))

    def wheel_value(self, label: str) -> float:
        text = self.page.locator(".wheel", has=self.page.locator(".label", has_text=re.compile(
            rf"^{re.escape(label)}$"))).locator(".value").inner_text()
        return float(text.split()[0].replace("−", "-"))


#: The wheel's label of an element a step names (the step writes the core's name or the page's).
_ELEMENT = re.compile(r"standard point (\d): clear the y-parallax with (\S+)")
_NAMES = {
    "kappa_right": "κ right", "kappa_left": "κ left", "k_alpha_left": "k_α left",
    "k_alpha_right": "k_α right", "k_omega_left": "k_ω left", "k_omega_right": "k_ω right",
}
#: A wheel's label → the control's name the keyboard box takes.
CONTROLS = {v: k for k, v in _NAMES.items()}
#: A first turn of an element to learn its effect on q (its wheel's scale: rad or tan). [—]
PROBE = 2e-4


def relative_orientation(r: Reader, tolerance_um: float, cycles: int = 8) -> list[float]:
    """Clear the y-parallax point by point with the elements the steps name (secant on the
    read-out), cycle until a cycle changes nothing and every standard point then reads within
    ``tolerance_um`` / 2; returns the last |q| read at the six points. [µm]"""
    pairs = []
    for text in r.steps():
        m = _ELEMENT.search(text)
        if m:
            pairs.append((int(m.group(1)), _NAMES.get(m.group(2), m.group(2))))
    assert pairs, "no step names an element to clear the y-parallax with"
    last: list[float] = []
    typed: dict[str, float] = {}
    slope: dict[str, float] = {}  # µm of q per unit of the element, learnt by a probe turn
    for _ in range(cycles):
        moved = False
        for point, label in pairs:
            r.go_to(point)
            q = r.q_um()[1]
            if abs(q) < tolerance_um / 4:
                continue
            moved = True
            if label in typed:  # what the robot typed last (the wheel shows it rounded)
                a = typed[label]
            else:  # as the wheel shows it: set it so, then read q there
                a = r.wheel_value(label)
                r.set(label, a)
                q = r.q_um()[1]
            if label not in slope:
                r.set(label, a + PROBE)
                slope[label] = (r.q_um()[1] - q) / PROBE
                if slope[label] == 0:
                    continue
            for _ in range(4):  # Newton on the read-out, the slope refined by each step
                b = a - q / slope[label]
                r.set(label, b)
                qb = r.q_um()[1]
                if qb != q and b != a:
                    slope[label] = (qb - q) / (b - a)
                a, q = b, qb
                if abs(q) < tolerance_um / 6:
                    break
            typed[label] = a
        r.cycles = getattr(r, "cycles", 0) + 1
        if moved:  # the six points are looked at once a cycle changes nothing
            continue
        last = []
        for point in range(1, 7):
            r.go_to(point)
            last.append(abs(r.q_um()[1]))
        if max(last) < tolerance_um / 2:
            break
    if not last:  # every cycle still changed something: what the six points read now
        for point in range(1, 7):
            r.go_to(point)
            last.append(abs(r.q_um()[1]))
    return last


# --- stage 1 of the setup-data method, from the steps and the sheet rows they name ---------------

_ROW = re.compile(r"sheet: .*? = (-?[\d.]+) — ")
_CAP = re.compile(r"x (-?[\d.]+)\s+y (-?[\d.]+) mm")
_READ = re.compile(r"reads (-?[\d.]+)")
_L = re.compile(r"compare with L_[лп] = ([\d.]+) mm")
_FID = re.compile(r"M(-?[\d.e-]+),(-?[\d.e-]+)h10M(-?[\d.e-]+),(-?[\d.e-]+)v10")
#: The overview's drawing: px of one photo, between them, above (overview.js). [px]
SIDE, GAP, TOP = 260, 40, 24


class SetupReader(Reader):
    """The stage-1 reader: values from the sheet rows the steps name, pointings by the mark
    captions, readings from the counters' *read*."""

    def step(self, start: str) -> str:
        return next(t for t in self.steps() if t.lstrip("☐☑ ").startswith(start))

    def row_value(self, start: str) -> float:
        return float(_ROW.search(self.step(start)).group(1))

    def set_name(self, name: str, value: float) -> None:
        """Type ``name value`` (to the µm: a handwheel's setting) into the keyboard box."""
        self.page.fill("#command", f"{name} {round(float(value), 4)!r}")
        self.page.press("#command", "Enter")
        self.sent += 1
        self.settle()
        error = self.page.inner_text("#message")
        assert "refused" not in error, error

    def read(self, counter: str) -> float:
        self.page.click(f"#counters tr[data-counter='{counter}'] .read")
        self.sent += 1
        self.settle()
        return float(_READ.search(self.page.inner_text("#result")).group(1))

    def counter(self, name: str) -> float:
        cell = self.page.locator(f"#counters tr[data-counter='{name}'] td.num")
        return float(cell.inner_text())

    def caption(self, side: str) -> tuple[float, float]:
        m = _CAP.search(self.page.inner_text(f"#cap-{side}"))
        return float(m.group(1)), float(m.group(2))

    def fiducials(self, format_mm: float) -> dict[str, list[tuple[float, float]]]:
        """The fiducial crosses the overview draws, back in photo mm (1–4 on each photo)."""
        k = SIDE / format_mm
        out: dict[str, list[tuple[float, float]]] = {"left": [], "right": []}
        paths = self.page.locator("#overview-svg path.ov-fiducial")
        for i in range(paths.count()):
            m = _FID.search(paths.nth(i).get_attribute("d"))
            px, py = float(m.group(3)), float(m.group(2))
            side = "left" if px < SIDE + GAP / 2 else "right"
            x0 = 0 if side == "left" else SIDE + GAP
            out[side].append(((px - x0 - SIDE / 2) / k, (TOP + SIDE / 2 - py) / k))
        return out

    def point(self, side: str, target: tuple[float, float], screws=("X", "Y")) -> None:
        """Put the ``side`` mark on ``target`` (photo mm) by the two ``screws``: Newton steps on
        the caption, the 2×2 effect of the screws learnt once by a probe turn each."""
        key = (side, screws)
        jac = getattr(self, "_jac", {})
        self._jac = jac
        start = {s: self.counter(s) for s in screws}
        here = np.array(self.caption(side))
        if key not in jac:
            cols = []
            for s in screws:
                self.set_name(s, start[s] + 1.0)
                moved = np.array(self.caption(side))
                cols.append(moved - here)
                self.set_name(s, start[s])
            jac[key] = np.array(cols).T  # photo mm per screw mm
            here = np.array(self.caption(side))
        setting = np.array([start[s] for s in screws])
        for _ in range(4):
            miss = np.asarray(target) - here
            if np.max(np.abs(miss)) < 0.0015:
                break
            setting = setting + np.linalg.solve(jac[key], miss)
            for s, v in zip(screws, setting, strict=True):
                self.set_name(s, round(float(v), 4))
            here = np.array(self.caption(side))

    def span(self, side: str, fid: dict[str, list[tuple[float, float]]]) -> float:
        """L′: the mark on fiducial 3, then 4 of the ``side`` photo, Y read at each. [mm]"""
        ys = []
        for mark in (2, 3):  # fiducials 3, 4
            self.point(side, fid[side][mark])
            ys.append(self.read("Y"))
        return ys[0] - ys[1]


def stage1(r: SetupReader, z_max: float, tolerance: float, format_mm: float) -> list[float]:
    """Stage 1 from the steps: gear, f_пр, O_bx, O_Z, MO_by, O_by, the L-check with its
    corrections, MO_Z; returns the last L − L′ of each photo. [mm]"""
    gear = r.row_value("gear the height counter")
    r.page.fill("#act-gear-value", str(int(gear)))
    r.page.click("#act-gear")
    r.sent += 1
    r.settle()
    f = r.row_value("set the instrument principal distance")
    r.set_name("f_instrument", f)
    mo_bx = r.read("bx")  # O_bx = MO_bx + b_x: the base carriage at its zero reads MO_bx
    r.set_name("bx", mo_bx + r.row_value("base carriage: O_bx"))
    n_left = r.row_value("lower the carriage")  # O_Z = n_л·f_пр
    r.set_name("Z", min(n_left * f, z_max))
    mo_bz = r.read("bz")
    r.point("right", (0.0, 0.0), screws=("X", "by"))  # MO_by: right mark on the cassette centre
    mo_by = r.read("by")
    r.set_name("by", mo_by + r.row_value("base carriage: O_by"))  # O_by = MO_by + b_y
    fid = r.fiducials(format_mm)
    l_left = float(_L.search(r.step("measure L′_л")).group(1))
    l_right = float(_L.search(r.step("measure L′_п")).group(1))
    diffs = [np.inf, np.inf]
    for _ in range(6):
        span_l, span_r = r.span("left", fid), r.span("right", fid)
        diffs = [l_left - span_l, l_right - span_r]
        if max(abs(d) for d in diffs) <= 0.6 * tolerance:
            break
        d = r.counter("Z")  # D: the Z counter counts the projection distance
        b_z = r.counter("bz") - mo_bz
        scale = 1.0
        if abs(diffs[0]) > 0.6 * tolerance:  # n = D/f_пр: L′ grows with D, falls with f_пр
            want = d * l_left / span_l
            if want <= z_max:
                r.set_name("Z", want)
                scale = (want + b_z) / (d + b_z)  # the right photo's D_п = D + b_z moves too
            else:  # the step: "reached by f_пр instead, f′_пр = f_пр·D/(D + ΔD)"
                f_new = f * d / want
                r.set_name("f_instrument", f_new)
                scale, f = f / f_new, f_new
        d_right = r.counter("Z") + b_z
        span_r *= scale
        if abs(l_right - span_r) > 0.6 * tolerance:  # Δb_z (6.10): D_п = D + b_z, ratio form
            r.set_name("bz", r.counter("bz") + d_right * (l_right / span_r - 1.0))
    r.read("Z")  # record MO_Z on the height scale
    r.read("bz")  # record MO_bz
    return diffs
