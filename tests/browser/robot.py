"""The robot trainee's hands: each action of the core's ``robot_script`` as the gesture a person
makes on the instrument page. Settings and readings, the bulk of a script, are typed into the
page's keyboard box (``X 215.3 below`` Enter, ``read X`` Enter: the box keeps the focus, so a
run of them is keys only — a Playwright click or fill costs 12–37 ms on the shared 2-core
machine, a key press 3.5 ms); ``SLOW_HANDS`` types them into each handwheel's own box instead
(Enter, Shift+Enter: finish from below, Alt+Enter: from above) and clicks *read*. Gear, slip,
connect, needle, record: a value typed into the action's form and its button; a substitute
standard point: a click on it in the photo overview; the stage: *Claim stage done*. No WebSocket
message is sent by the test: the page sends what the gestures ask for, paced at the server's
rate.
"""

from __future__ import annotations

from typing import Any

from stereoplotter.io.exercise_file import load_exercise
from stereoplotter.trainer.robot import robot_script
from stereoplotter.trainer.session import Session

#: Keys that finish a typed value on a handwheel, by the approach side.
ENTER = {None: "Enter", "below": "Shift+Enter", "above": "Alt+Enter"}


def script_for(path: str, trainee: str) -> list[dict[str, Any]]:
    """The core's robot script for an exercise file and trainee (run in a worker process: the
    scripts of the exercises to come are made while the browser works on this one)."""
    return robot_script(Session.start(load_exercise(path), trainee=trainee))


def _number(value: float) -> str:
    """A float as the shortest text that reads back to the same double (Python's repr; the
    page's ``Number()`` parses it to the same value)."""
    return repr(float(value))


class Hands:
    """Gestures on an open instrument page; :attr:`sent` counts the actions they cause."""

    def __init__(self, page, slow: bool = False):
        self.page = page
        self.sent = 0
        self.slow = slow
        self.typing = False  # the keyboard box holds the focus

    def _type(self, text: str) -> None:
        if not self.typing:
            self.page.focus("#command")
            self.typing = True
        self.page.keyboard.insert_text(text)
        self.page.keyboard.press("Enter")

    def settle(self, timeout: float = 60_000) -> None:
        """Wait until the server has answered every action sent (the log holds them)."""
        self.page.wait_for_function(f"() => window.__n >= {self.sent}", timeout=timeout)

    def do(self, action: dict[str, Any]) -> None:
        kind = action["kind"]
        if kind not in ("set", "read", "turn"):
            self.typing = False  # a click elsewhere takes the focus
        getattr(self, f"_{kind}")(action)
        self.sent += 1
        if kind == "claim":  # the next stage's controls follow the claim's answer
            self.settle()

    # --- one gesture per kind -----------------------------------------------------------------

    def _set(self, a: dict[str, Any]) -> None:
        if not self.slow:
            side = f" {a['side']}" if a.get("side") else ""
            self._type(f"{a['control']} {_number(a['value'])}{side}")
            return
        self.typing = False
        box = f".wheel[data-control='{a['control']}'] input"
        self.page.fill(box, _number(a["value"]))  # focuses the box, replaces its text
        self.page.keyboard.press(ENTER[a.get("side")])

    def _turn(self, a: dict[str, Any]) -> None:
        side = f" {a['side']}" if a.get("side") else ""
        self._type(f"turn {a['control']} {_number(a['delta'])}{side}")

    def _read(self, a: dict[str, Any]) -> None:
        if not self.slow:
            self._type(f"read {a['counter']}")
            return
        self.typing = False
        self.page.click(f"tr[data-counter='{a['counter']}'] button.read")

    def _direction(self, a: dict[str, Any]) -> None:
        self.page.click(f"tr[data-counter='{a['counter']}'] button.dir")

    def _lock(self, a: dict[str, Any]) -> None:
        self.page.click(f".wheel[data-control='{a['control']}'] button.lock")

    def _form(self, kind: str, values: dict[str, Any]) -> None:
        for name, value in values.items():
            box = f"#act-{kind}-{name}"
            if self.page.locator(box).evaluate("e => e.tagName") == "SELECT":
                self.page.select_option(box, "" if value is None else str(value))
            else:
                text = ", ".join(map(_number, value)) if isinstance(value, list) else (
                    _number(value) if isinstance(value, float) else str(value))
                self.page.fill(box, text)
        self.page.click(f"#act-{kind}")

    def _gear(self, a):
        self._form("gear", {"value": a["value"]})

    def _slip(self, a):
        self._form("slip", {"value": a["value"]})

    def _connect(self, a):
        self._form("connect", {"value": a["value"], "origin_mm": a.get("origin_mm") or ""})

    def _needle(self, a):
        self._form("needle", {"side": a.get("side")})

    def _record(self, a: dict[str, Any]) -> None:
        name = a["name"]
        if name.startswith("substitute "):  # click the point on the left photo of the overview
            n = name.split()[1]
            self.page.select_option("#substitute-for", n)
            self.page.click(f"#overview-svg g.ov-standard[data-point='{n}'][data-left-xy] circle")
            return
        self._form("record", {"name": name, "value": a["value"]})

    def _claim(self, a: dict[str, Any]) -> None:
        self.settle()  # every action of the stage answered: the page shows the stage in hand
        self.page.click("#claim")

    def _hint(self, a):
        self.page.click(f"#hints button[data-level='{a['level']}']")

    def _undo(self, a):
        self.page.click("#undo")

    def _redo(self, a):
        self.page.click("#redo")
