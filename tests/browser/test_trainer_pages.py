"""Issue 14 acceptance in a real browser (headless Debian chromium through Playwright).

Two independent paths to one state: the page drives the server by clicks, keys and wheel
events; the core :class:`Session`, fed the action log the server recorded, must reach the same
counters, and the core's ``grade`` of that log must equal the grade the page shows.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np

from stereoplotter.io.exercise_file import load_exercise
from stereoplotter.trainer.grading import grade
from stereoplotter.trainer.session import Session
from stereoplotter.web.core import GRADE_POPULATION

TOKEN = "test-token"  # conftest.TOKEN

DOCS_IMG = Path(__file__).resolve().parents[2] / "docs" / "img"
FIRST = "e01-setup-stage1"
EXAM = "e11-setup-exam"

#: Values the scripted trainee types (mm); rounded from the simulated operator's own settings
#: for e01 (Session.operator_script), so the claim is near the tolerance, not a wild one.
TYPED = {"f_instrument": "109.34", "bx": "115.21", "bz": "51.27", "Z": "184.96"}


def _start(page, server, exercise, trainee="browser"):
    page.goto(server + "/")
    page.fill("#trainee", trainee)
    page.click(f"button[data-exercise='{exercise}']")
    page.wait_for_url("**/s/*")
    page.wait_for_selector("body[data-ready='1']")
    return page.url.rsplit("/", 1)[1]


def _settle(page, n):
    """Wait until the server has answered n actions."""
    page.wait_for_function(f"window.__n >= {n}")


def _wheel(page, control, notches, shift=False):
    box = page.locator(f".wheel[data-control='{control}'] svg")
    box.hover()
    if shift:
        page.keyboard.down("Shift")
    for _ in range(abs(notches)):
        page.mouse.wheel(0, -100 if notches > 0 else 100)
    if shift:
        page.keyboard.up("Shift")


def test_browser_trainee_completes_stage1_like_the_core_session(page, server, artefacts):
    sid = _start(page, server, FIRST)
    n = 0
    page.click("#gear-btn")  # gear the height counter 1 : 8000 (the exercise's map)
    n += 1
    for control, value in TYPED.items():  # type a value into the knob's box, Enter
        page.fill(f".wheel[data-control='{control}'] input", value)
        page.press(f".wheel[data-control='{control}'] input", "Enter")
        n += 1
        _settle(page, n)
    _wheel(page, "X", 3)
    _wheel(page, "by", -2, shift=True)
    page.locator(".wheel[data-control='Y']").focus()
    page.keyboard.press("ArrowUp")
    n += 3 + 2 + 1
    page.click("tr[data-counter='X'] button.read")
    n += 1
    _settle(page, n)
    page.screenshot(path=str(artefacts / "instrument.png"), full_page=True)
    page.click("#claim")
    n += 1
    _settle(page, n)
    page.wait_for_selector("#done:not([hidden])")
    shown = page.evaluate("window.trainer.state()")
    assert shown["done"]
    dom = {
        row.get_attribute("data-counter"): float(row.locator("td.num").inner_text())
        for row in page.locator("#counters tbody tr").all()
    }

    log = [json.loads(line) for line in
           page.request.get(f"{server}/api/sessions/{sid}/log.jsonl").text().splitlines()]
    assert len(log) == n + 1  # header + every click, key and wheel notch as one action
    kinds = [r["action"]["kind"] for r in log[1:]]
    assert kinds.count("turn") == 6 and kinds.count("set") == 4 and kinds[-1] == "claim"

    # the core session fed the same actions (at the logged times) from a fresh start
    head = log[0]
    core = Session.start(load_exercise(FIRST), trainee=head["trainee"], seed=head["seed"])
    for rec in log[1:]:
        core.act(dict(rec["action"], t=rec["t"]))
    mine = core.state()
    for name, c in mine["counters"].items():
        assert shown["counters"][name]["value"] == c["value"], name
        lc = c["least_count"]
        assert abs(dom[name] - c["value"]) <= lc / 2 + 1e-9, name  # shown to its least count
    # the page's grade is the core's grade of that log
    page.click("#grade-link")
    page.wait_for_selector("body[data-ready='1']")
    page_grade = page.evaluate("window.__grade")
    core_grade = json.loads(json.dumps(grade(log, population=GRADE_POPULATION)))
    for g in (page_grade, core_grade):  # wall-clock time of the grading run itself
        g["population"].pop("seconds")
    assert page_grade == core_grade
    page.screenshot(path=str(artefacts / "grade.png"), full_page=True)
    md = page.request.get(f"{server}/api/sessions/{sid}/grade.md").text()
    assert md.startswith("#") and FIRST in md


def test_anaglyph_shows_the_marks_y_offset(page, server, artefacts):
    """A y-difference planted between the marks (left decentration dy turned, Eq.-free: the
    page draws each photo's graticule about its own mark) appears in the anaglyph pixels as a
    vertical shift of the red against the cyan lines of (y_left − y_right) × px/mm."""
    _start(page, server, FIRST, trainee="anaglyph")
    page.fill(".wheel[data-control='f_instrument'] input", "109.34")
    page.press(".wheel[data-control='f_instrument'] input", "Enter")
    _settle(page, 1)
    page.select_option("#view", "anaglyph")
    page.fill("#mag", "10")
    page.dispatch_event("#mag", "change")
    page.locator(".wheel[data-control='dy_left']").focus()
    for _ in range(3):
        page.keyboard.press("Shift+ArrowUp")  # 3 × 10 steps of 0.01 mm
    _settle(page, 4)
    page.wait_for_timeout(50)
    marks = page.evaluate("window.trainer.state().marks")
    dy = marks["left"]["y_mm"] - marks["right"]["y_mm"]
    assert 0.2 < abs(dy) < 0.45, marks  # planted; under half the 1 mm graticule period
    px_per_mm = 4 * 10  # eyepiece.js PX_PER_MM_AT_1X × magnification
    cols = page.evaluate("""() => {
        const c = document.getElementById('eye-stereo'); const d = c.getContext('2d')
            .getImageData(0, 0, c.width, c.height).data;
        const red = [], cyan = [];
        for (let y = 0; y < c.height; y++) { let r = 0, g = 0;
            for (let x = 20; x < 60; x++) { const i = (y * c.width + x) * 4; r += d[i]; g += d[i + 1]; }
            red.push(r); cyan.push(g); }
        return [red, cyan]; }""")
    red, cyan = (np.asarray(v, float) - np.mean(v) for v in cols)
    lags = np.arange(-19, 20)  # within half a period (40 px) of the graticule
    corr = [np.dot(np.roll(cyan, k), red) for k in lags]
    shift = lags[int(np.argmax(corr))]
    # photo y up, rows down: a left mark higher on its photo draws the left lines lower
    assert abs(shift - dy * px_per_mm) <= 1.5, (shift, dy * px_per_mm)
    page.screenshot(path=str(artefacts / "anaglyph.png"), full_page=True)


def test_exam_hides_hints_and_undo(page, server, artefacts):
    _start(page, server, EXAM, trainee="examinee")
    assert page.locator("#mode").inner_text() == "exam"
    assert page.locator("#hints").is_hidden()
    assert page.locator("#undo").is_disabled() or page.locator("#undo").is_hidden()
    page.screenshot(path=str(artefacts / "exam.png"), full_page=True)
    _start(page, server, FIRST, trainee="practising")
    assert page.locator("#hints").is_visible()
    page.click("#hints button[data-level='1']")
    _settle(page, 1)
    assert page.locator("#message").inner_text().strip() != ""


def test_instructor_page_lists_sessions_and_replays(page, server, artefacts):
    page.goto(f"{server}/instructor?token=wrong")
    page.wait_for_selector("section.fail")
    _start(page, server, FIRST, trainee="replayed")
    page.click("#gear-btn")
    _settle(page, 1)
    page.goto(f"{server}/instructor?token={TOKEN}")
    page.wait_for_selector("body[data-ready='1']")
    rows = page.locator("#sessions tbody tr")
    assert rows.count() >= 1
    page.locator("#sessions tbody tr", has_text="replayed").locator("button").click()
    page.wait_for_selector("#replay:not([hidden])")
    assert "gear" in page.locator("#replay-action").inner_text()
    csv = page.request.get(f"{server}/api/instructor/results.csv?token={TOKEN}").text()
    assert csv.splitlines()[0].startswith("id,trainee,exercise")
    assert page.request.get(f"{server}/api/instructor/results.csv?token=x").status == 403
    page.screenshot(path=str(artefacts / "instructor.png"), full_page=True)


def test_exercise_picker_and_docs_screenshots(page, server, artefacts):
    page.goto(server + "/")
    page.wait_for_selector("button[data-exercise]")
    assert page.locator("button[data-exercise]").count() >= 12
    page.screenshot(path=str(artefacts / "exercises.png"), full_page=True)
    DOCS_IMG.mkdir(parents=True, exist_ok=True)
    for name in ("instrument.png", "grade.png", "instructor.png"):
        if (artefacts / name).exists():
            shutil.copyfile(artefacts / name, DOCS_IMG / f"trainer-{name}")
