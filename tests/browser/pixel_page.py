"""The pixel robot's hands and eyes on the instrument page (``tests/browser/pixel_robot.py``
decides): the go-to buttons, turns typed into the keyboard box, the magnification box, and the
two eyepiece canvases as the page draws them (read back as PNG). Nothing else of the page is
read: no parallax read-out (an exam has none), no state, no core. For the shipped exam e12
also the setup sheet panel (C1's values, :func:`interior`), the counters' *read*, the gear and
record forms, and the overview's standard points and its list of unusable ones.
"""

from __future__ import annotations

import base64
import io
import time

import numpy as np
from PIL import Image

_CANVASES = "() => ['left', 'right'].map((s) => document.getElementById('eye-' + s).toDataURL())"
#: A wheel's shown value once the frames asked for so far are drawn (a frame asked for now runs
#: after them).
_WHEEL = ("(sel) => new Promise((r) => requestAnimationFrame(() => "
          "r(document.querySelector(sel).textContent)))")


class PageEyes:
    """:class:`tests.browser.pixel_robot.Eyes` on an open instrument page; counts the actions
    it causes (:attr:`sent`), the looks, the seconds spent waiting for the photos
    (:attr:`wait_s`), reading the canvases back (:attr:`read_s`) and acting (:attr:`act_s`:
    the turns, settings and go-tos until answered)."""

    def __init__(self, page):
        self.page = page
        self.sent = 0
        self.looks = 0
        self.mag: int | None = None
        self.wait_s = 0.0
        self.read_s = 0.0
        self.act_s = 0.0

    def settle(self) -> None:
        """Every action sent answered (a refused one too: a turn past a stop is refused and not
        counted, so the count is the server's)."""
        self.page.wait_for_function("() => window.trainer.idle()", timeout=60_000)
        self.sent = self.page.evaluate("() => window.__n")

    def _type(self, text: str) -> None:
        t0 = time.monotonic()
        self.page.fill("#command", text)
        self.page.press("#command", "Enter")
        self.settle()
        self.act_s += time.monotonic() - t0

    def go_to(self, point: int) -> None:
        t0 = time.monotonic()
        before = self.sent
        self.page.click(f"#goto button[data-point='{point}']")
        # the page fetches the settings, then sends X and Y
        self.page.wait_for_function(f"() => window.__n >= {before + 2}", timeout=60_000)
        self.settle()
        self.act_s += time.monotonic() - t0

    def turn(self, control: str, delta: float) -> None:
        self._type(f"turn {control} {float(delta)!r}")

    def set(self, control: str, value: float) -> None:
        self._type(f"{control} {float(value)!r}")

    def wheel(self, control: str) -> float:
        """The value the wheel shows, read after the page's next animation frame: the page
        redraws its wheels in a frame after a state arrives, so a wheel read as soon as the
        action is answered can still show the value before it (seen: Z set 2 mm down read as
        its old value in 3 of 30 sessions)."""
        text = self.page.evaluate(_WHEEL, f".wheel[data-control='{control}'] .value")
        return float(text.split()[0].replace("−", "-"))

    def gear(self, value: int) -> None:
        """Gear the height counter (the gear form)."""
        t0 = time.monotonic()
        self.page.fill("#act-gear-value", str(int(value)))
        self.page.click("#act-gear")
        self.page.wait_for_function(f"() => window.__n >= {self.sent + 1}", timeout=60_000)
        self.settle()
        self.act_s += time.monotonic() - t0

    def read(self, counter: str) -> float:
        """A counter read by its *read* button: the value the result line shows."""
        import re

        t0 = time.monotonic()
        self.page.click(f"#counters tr[data-counter='{counter}'] .read")
        self.page.wait_for_function(f"() => window.__n >= {self.sent + 1}", timeout=60_000)
        self.settle()
        self.act_s += time.monotonic() - t0
        return float(re.search(r"reads (-?[\d.]+)", self.page.inner_text("#result")).group(1))

    def record(self, name: str, value: str) -> None:
        """Write a value on the sheet (the record form): e.g. ``substitute 3``, ``"x, y"``."""
        self.page.fill("#act-record-name", name)
        self.page.fill("#act-record-value", value)
        self.page.click("#act-record")
        self.page.wait_for_function(f"() => window.__n >= {self.sent + 1}", timeout=60_000)
        self.settle()

    def standard_points(self) -> dict[int, tuple[float, float]]:
        """The standard points where the overview draws them on the left photo. [mm]"""
        out = {}
        for g in self.page.locator("#overview-svg g.ov-standard[data-left-xy]").all():
            x, y = (float(v) for v in g.get_attribute("data-left-xy").split(","))
            out[int(g.get_attribute("data-point"))] = (x, y)
        return out

    def unusable(self) -> list[int]:
        """The standard points the overview calls unusable (its substitute list)."""
        return [int(v) for v in self.page.locator("#substitute-for option").all_inner_texts()]

    def claim(self) -> None:
        before = self.sent
        self.page.click("#claim")
        self.page.wait_for_function(f"() => window.__n >= {before + 1}", timeout=60_000)
        self.settle()

    def look(self, magnification: int) -> tuple[np.ndarray, np.ndarray]:
        if self.mag != magnification:
            self.page.fill("#mag", str(magnification))
            self.page.dispatch_event("#mag", "change")
            self.mag = magnification
        t0 = time.monotonic()
        # the page asks a patch once the mark has rested 120 ms: wait past it, then for the
        # sharp patches of this magnification under both marks
        self.page.wait_for_timeout(150)
        self.page.wait_for_function(
            "(m) => window.trainer.photosReady()"
            " && window.trainer.patchMags().every((v) => v === m)",
            arg=magnification, timeout=60_000,
        )
        self.page.evaluate("() => new Promise((r) => requestAnimationFrame(() => setTimeout(r)))")
        t1 = time.monotonic()
        self.wait_s += t1 - t0
        urls = self.page.evaluate(_CANVASES)
        self.looks += 1
        out = []
        for url in urls:
            png = base64.b64decode(url.split(",", 1)[1])
            out.append(np.asarray(Image.open(io.BytesIO(png)).convert("RGB")))
        self.read_s += time.monotonic() - t1
        return out[0], out[1]


def exercise_text(name: str, mode: str = "exam", seed: str = "per-trainee") -> str:
    """C2 of the shipped e05 (SC-1, hilly pair, injected errors) by eye: C1 preset, errors
    hidden, no read-out, no undo, no hints; as an exam (per-trainee seed drawn by the server)
    or as practice with a fixed ``seed`` (the same instrument every run, the page as in the
    exam: the read-out hidden, the marks drawn at the counters' least count)."""
    return f"""format: stereoplotter-exercise/1
name: {name}
title: "Relative orientation by eye (C2, conventional method)"
level: 9
description: >-
  C1 preset. Clear the y-parallax at the six standard points by eye; no read-out.
instrument: sc1
scenario: pair60
method: conventional
stages: "C2"
terrain: hilly
model: complete
errors: "hidden"
tilt: small
assists: {{parallax_readout: false, undo: false, hints: false}}
mode: {mode}
seed: {seed}
"""


#: The conventional exam of relative orientation the robot sits (:func:`exercise_text`),
#: uploaded by the instructor.
EXAM_NAME = "c2-exam-pixel"
EXAM = exercise_text(EXAM_NAME)


def upload_exam(page, server: str, token: str, text: str = EXAM) -> None:
    """Upload :data:`EXAM` (or another exercise ``text``) as the instructor (a second upload of
    the same name is refused 409: already there)."""
    r = page.request.post(f"{server}/api/instructor/exercises?token={token}", data=text)
    assert r.status in (200, 409), r.text()


def start(page, server: str, trainee: str, name: str = EXAM_NAME) -> str:
    """Open the exam (or the exercise ``name``) for ``trainee`` from the exercises page; the
    session id."""
    page.goto(server + "/")
    page.fill("#trainee", trainee)
    page.click(f"button[data-exercise='{name}']")
    page.wait_for_url("**/s/*")
    page.wait_for_selector("body[data-ready='1']")
    page.wait_for_selector("body[data-overview='1']")
    return page.url.rsplit("/", 1)[1]


#: The shipped conventional exam (SD-3, mountains, C1–C4, standard point 3 unusable).
E12_NAME = "e12-conventional-exam"
#: The places of zero of the counters a C1 sets from (the instrument's own, known to its
#: operator: b_x 0, b_y and b_z′ 50, the decentrations 20 mm; the decentration counter's
#: caption on the page says so for dx, dy). [mm]
ZERO_PLACES = {"bx": 0.0, "by": 50.0, "bz": 50.0, "dx_left": 20.0, "dy_left": 20.0,
               "dx_right": 20.0, "dy_right": 20.0}


def sheet_values(page) -> dict[str, float]:
    """The numeric rows of the setup sheet panel (``f instrument mm`` → 111.987527, …)."""
    page.click("#sheet-btn")
    page.wait_for_function("() => /f instrument/.test(document.querySelector('#sheet-body')"
                           ".innerText)", timeout=60_000)
    out = {}
    for line in page.inner_text("#sheet-body").splitlines():
        parts = line.split("\t")
        if len(parts) == 2:
            try:
                out[parts[0].strip()] = float(parts[1])
            except ValueError:
                pass
    page.click("#sheet-close")
    return out


def interior(eyes: PageEyes, sheet: dict[str, float]) -> None:
    """C1 of the conventional method from the setup sheet, as its steps name it: the height
    counter geared to 1:M_в, f_пр, the cassettes at κ = 0, the correction knobs at 0 and the
    decentrations at their places of zero, b_x = MO_bx + b_x (MO_bx read at the place of
    zero), b_z′ = 0, D = n_л·f_пр (Z, to its upper stop where beyond). MO_by, MO_X, MO_Y need
    the cassette centres, which the exam's page does not caption: b_y is left at its place of
    zero (the relative orientation takes up a common y-shift with the two κ)."""
    eyes.gear(int(sheet["scale vertical"]))
    f = sheet["f instrument mm"]
    eyes.set("f_instrument", f)
    for control in ("kappa_left", "kappa_right", "k_alpha_left", "k_omega_left",
                    "k_alpha_right", "k_omega_right"):
        eyes.set(control, 0.0)
    for control in ("dx_left", "dy_left", "dx_right", "dy_right", "by"):
        eyes.set(control, ZERO_PLACES[control])
    eyes.set("bx", ZERO_PLACES["bx"])
    mo_bx = eyes.read("bx")
    eyes.set("bx", round(mo_bx + sheet["b x mm"], 3))
    eyes.set("bz", ZERO_PLACES["bz"])
    d = sheet["n left"] * f
    for below in Z_BACK_OFF:  # a setting past the stop is refused: a little lower each time
        eyes.set("Z", round(d - below, 3))
        if abs(eyes.wheel("Z") - (d - below)) < 0.011:
            break


#: How far under D = n_л·f_пр C1 tries Z where the setting is refused (past the stop). [mm]
Z_BACK_OFF = (0.0, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0)


def grade_after_claim(page, server: str, sid: str) -> dict:
    """The grade, read with the session's own key once the stage is claimed (the robot never
    reads it before)."""
    secret = page.evaluate(f"localStorage.getItem('stereoplotter-key-{sid}')")
    r = page.request.get(f"{server}/api/sessions/{sid}/grade",
                         headers={"Authorization": f"Bearer {secret}"}, timeout=300_000)
    assert r.ok, r.text()
    body = r.json()
    return body.get("grade", body)


def tolerance_um(page) -> float:
    """The y-parallax tolerance the page's checks name (``0.0125 mm``). [µm]"""
    import re

    text = page.inner_text("#checks")
    m = re.search(r"y-parallax[^:]*:[^\d]*([\d.]+) mm", text)
    assert m, text
    return float(m.group(1)) * 1000.0
