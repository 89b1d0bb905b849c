"""Make the trainer screenshots of docs/trainer.md (issue 24): the setup sheet panel, the photo
overview, a frame of an animated "show me", and the grade's per-point tables.

Run from the checkout (the robot trainee's gestures live in ``tests/browser/robot.py``)::

    PYTHONPATH=. python3 docs/make_trainer_screenshots.py [--out docs/img]

It starts the trainer server in this process and drives Debian's ``/usr/bin/chromium``
headless through Playwright, as the browser tests do (``python3 -m
stereoplotter.web.browser_setup`` installs it). Writes ``trainer-sheet.png``,
``trainer-overview.png``, ``trainer-showme.png`` and ``trainer-grade-points.png``.
"""

from __future__ import annotations

import argparse
import socket
import sys
import threading
import time
from pathlib import Path

import uvicorn
from playwright.sync_api import sync_playwright

from stereoplotter.io.exercise_file import load_exercise
from stereoplotter.trainer.robot import robot_script
from stereoplotter.trainer.session import Session
from stereoplotter.web.app import create_app
from stereoplotter.web.browser_setup import chromium_path
from tests.browser.robot import Hands

#: Exercises shown: an incomplete model (sheet, overview with unusable points), a practice stage
#: for "show me", the full setup method for the grade's tables.
SHEET = "e07-setup-stage2-incomplete"
SHOW_ME = "e03-setup-stage2"
GRADE = "e08-setup-full"


def _server():
    app = create_app("docs-token", message_limit=(2000.0, 4000))
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    srv = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning"))
    threading.Thread(target=srv.run, daemon=True).start()
    while not srv.started:
        time.sleep(0.05)
    return srv, f"http://127.0.0.1:{port}"


def _start(page, base: str, exercise: str, trainee: str = "robot") -> None:
    page.goto(base + "/")
    page.fill("#trainee", trainee)
    page.click(f"button[data-exercise='{exercise}']")
    page.wait_for_selector("body[data-ready='1']")
    page.wait_for_selector("body[data-overview='1']")


def _robot(page, exercise: str, upto: int | None = None) -> None:
    script = robot_script(Session.start(load_exercise(exercise), trainee="robot"))
    hands = Hands(page)
    for action in script[:upto]:
        hands.do(action)
    hands.settle()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="docs/img", help="folder of the PNG files")
    out = Path(parser.parse_args(argv).out)
    out.mkdir(parents=True, exist_ok=True)
    exe = chromium_path()
    if exe is None:
        print("error: chromium not found: run python3 -m stereoplotter.web.browser_setup",
              file=sys.stderr)
        return 1
    srv, base = _server()
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=exe, headless=True, args=["--no-sandbox"])
        page = browser.new_page(viewport={"width": 1440, "height": 900})
        _start(page, base, SHEET)
        _robot(page, SHEET, upto=12)  # f_пр set: the marks stand on the photos
        page.click("#sheet-btn")
        page.wait_for_selector("body[data-sheet='1']")
        page.evaluate("document.getElementById('sheet').classList.add('full')")  # all of it
        page.locator("#sheet").screenshot(path=str(out / "trainer-sheet.png"))
        page.evaluate("document.getElementById('sheet').classList.remove('full')")
        page.click("#sheet-close")
        page.locator("#overview").screenshot(path=str(out / "trainer-overview.png"))

        _start(page, base, SHOW_ME)
        page.select_option("#demo-speed", "8")
        page.click("#show-me")
        page.wait_for_function("() => /show me (2[0-9]|[3-9][0-9]) \\//.test("
                               "document.getElementById('show-me-count').textContent)",
                               timeout=60_000)
        page.wait_for_function("() => window.trainer.photosReady()", timeout=60_000)
        page.evaluate("window.scrollTo(0, 0)")
        page.screenshot(path=str(out / "trainer-showme.png"))
        page.click("#show-me")  # stop

        _start(page, base, GRADE)
        _robot(page, GRADE)
        page.click("#grade-link")
        page.wait_for_selector("body[data-ready='1']")
        page.screenshot(path=str(out / "trainer-grade-points.png"), full_page=True)
        browser.close()
    srv.should_exit = True
    for name in ("sheet", "overview", "showme", "grade-points"):
        print(out / f"trainer-{name}.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
