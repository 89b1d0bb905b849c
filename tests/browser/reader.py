"""The reader robot: a trainee that uses only what the instrument page shows — the step texts,
the setup sheet panel, the parallax read-out, the counters and the mark captions — and the
page's controls (handwheel boxes, the go-to buttons, the overview, *read*, *claim*). No core
call, no simulated operator, no hint.
"""

from __future__ import annotations

import re

_Q = re.compile(r"parallax at standard point (\d): q = (-?[\d.]+) µm, p = (-?[\d.]+) µm")


class Reader:
    """Gestures and readings on an open instrument page."""

    def __init__(self, page):
        self.page = page
        self.sent = 0

    # --- acting ----------------------------------------------------------------------------
    def settle(self) -> None:
        self.page.wait_for_function(f"() => window.__n >= {self.sent}", timeout=60_000)

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
    read-out), cycle until every standard point reads within ``tolerance_um`` / 2; returns the
    last |q| read at the six points. [µm]"""
    pairs = []
    for text in r.steps():
        m = _ELEMENT.search(text)
        if m:
            pairs.append((int(m.group(1)), _NAMES.get(m.group(2), m.group(2))))
    assert pairs, "no step names an element to clear the y-parallax with"
    last: list[float] = []
    typed: dict[str, float] = {}
    for _ in range(cycles):
        for point, label in pairs:
            r.go_to(point)
            if abs(r.q_um()[1]) < tolerance_um / 4:
                continue
            if label in typed:  # what the robot typed last (the wheel shows it rounded)
                a = typed[label]
            else:  # as the wheel shows it: set it so, then read q there
                a = r.wheel_value(label)
                r.set(label, a)
            qa = r.q_um()[1]
            b = a + PROBE
            r.set(label, b)
            qb = r.q_um()[1]
            for _ in range(6):  # the secant on the read-out
                if abs(qb) < tolerance_um / 6 or qb == qa:
                    break
                a, qa, b = b, qb, b - qb * (b - a) / (qb - qa)
                r.set(label, b)
                qb = r.q_um()[1]
            typed[label] = b
        r.cycles = getattr(r, "cycles", 0) + 1
        last = []
        for point in range(1, 7):
            r.go_to(point)
            last.append(abs(r.q_um()[1]))
        if max(last) < tolerance_um / 2:
            break
    return last
