"""The trainer's pages in a real browser (headless Debian chromium through Playwright).

Two independent paths to one state: the page drives the server by clicks, keys and wheel
events; the core :class:`Session`, fed the action log the server recorded, must reach the same
counters, and the core's ``grade`` of that log must equal the grade the page shows.
"""

from __future__ import annotations

import json

import numpy as np

from stereoplotter.io.exercise_file import exercise_from_mapping, load_exercise
from stereoplotter.trainer.grading import grade
from stereoplotter.trainer.session import Session
from stereoplotter.web.core import GRADE_POPULATION, SCREEN_PIXEL_MM

TOKEN = "test-token"  # conftest.TOKEN

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
    page.wait_for_function(f"() => window.__n >= {n}")  # a function: no eval under the CSP


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
    page.fill("#act-gear-value", "8000")  # gear the height counter 1 : 8000 (the exercise's map)
    page.click("#act-gear")
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
    page.wait_for_function("() => window.trainer.photosReady()", timeout=60_000)  # both photos in
    page.wait_for_timeout(100)
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

    secret = page.evaluate(f"localStorage.getItem('stereoplotter-key-{sid}')")
    key = {"Authorization": f"Bearer {secret}"}  # the session's own key
    log = [json.loads(line) for line in page.request.get(
        f"{server}/api/sessions/{sid}/log.jsonl", headers=key).text().splitlines()]
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
    core = grade(log, population=GRADE_POPULATION, read_exercise=exercise_from_mapping)
    core_grade = json.loads(json.dumps(core))
    for g in (page_grade, core_grade):  # wall-clock time of the grading run itself
        g["population"].pop("seconds")
    assert page_grade == core_grade
    page.screenshot(path=str(artefacts / "grade.png"), full_page=True)
    md = page.request.get(f"{server}/api/sessions/{sid}/grade.md", headers=key).text()
    assert md.startswith("#") and FIRST in md


PROFILE_JS = """() => {
    const c = document.getElementById('eye-stereo'); const d = c.getContext('2d')
        .getImageData(0, 0, c.width, c.height).data;
    const red = [], cyan = [];
    for (let y = 0; y < c.height; y++) {
        let r = 0, g = 0;
        for (let x = 100; x < 140; x++) {
            const i = (y * c.width + x) * 4; r += d[i]; g += d[i + 1];
        }
        red.push(r); cyan.push(g);
    }
    return [red, cyan]; }"""


def _row_shift(before, after, max_lag=40):
    """Rows by which ``after`` is ``before`` moved down (cross-correlation peak)."""
    a, b = (np.asarray(v, float) - np.mean(v) for v in (before, after))
    lags = np.arange(-max_lag, max_lag + 1)
    core = slice(max_lag, len(a) - max_lag)
    corr = [np.dot(np.roll(a, k)[core], b[core]) for k in lags]
    return int(lags[int(np.argmax(corr))])


def test_anaglyph_pixels_show_a_planted_y_parallax(page, server, artefacts):
    """Plant a y-parallax by turning the left decentration dy: in the anaglyph the left photo
    (red) moves vertically by Δy_left × px/mm while the right photo (cyan) stays: the pixels, not
    the state, are compared (page compositing of the server's photo patches)."""
    _start(page, server, FIRST, trainee="anaglyph")
    page.fill(".wheel[data-control='f_instrument'] input", "109.34")
    page.press(".wheel[data-control='f_instrument'] input", "Enter")
    _settle(page, 1)
    page.select_option("#view", "anaglyph")
    page.select_option("#colours", "red,cyan")
    page.fill("#mag", "10")
    page.dispatch_event("#mag", "change")
    page.wait_for_function("() => window.trainer.photosReady() && window.trainer.patchMags()"
                           ".every((m) => m === 10)", timeout=60_000)  # both sides at ×10
    page.wait_for_timeout(100)
    red0, cyan0 = page.evaluate(PROFILE_JS)
    m0 = page.evaluate("window.trainer.state().marks")
    page.locator(".wheel[data-control='dy_left']").focus()
    for _ in range(3):
        page.keyboard.press("Shift+ArrowUp")  # 3 × 10 steps of 0.01 mm
    _settle(page, 4)
    page.wait_for_timeout(100)
    red1, cyan1 = page.evaluate(PROFILE_JS)
    m1 = page.evaluate("window.trainer.state().marks")
    dy_left = m1["left"]["y_mm"] - m0["left"]["y_mm"]
    assert 0.2 < abs(dy_left) < 0.45, (m0, m1)  # planted
    assert m1["right"] == m0["right"]
    px_per_mm = 10 / SCREEN_PIXEL_MM
    # photo y up, rows down: the mark higher on its photo moves the picture down
    assert abs(_row_shift(red0, red1) - dy_left * px_per_mm) <= 1.5
    assert _row_shift(cyan0, cyan1) == 0
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
    shown = page.locator("#result").inner_text()
    assert shown.lower().startswith("hint 1") and '{"' not in shown  # text, not a JSON dump


def test_demonstration_plays_the_operators_actions(page, server):
    page.goto(server + "/")
    page.check("#demo")
    page.click(f"button[data-exercise='{FIRST}']")
    page.wait_for_selector("body[data-ready='1']")
    assert page.locator("#mode").inner_text() == "demonstration"
    assert page.locator("#claim").is_disabled()
    for n in (1, 2, 3):
        page.click("#demo-step")
        _settle(page, n)
    script = Session.start(load_exercise(FIRST)).operator_script()
    assert page.locator("#demo-count").inner_text() == f"3 / {len(script)}"
    # the operator's second action set f_пр: the page's knob shows it
    shown = page.evaluate("window.trainer.state().controls.f_instrument.value")
    assert shown == script[1]["value"]


def test_instructor_page_lists_sessions_and_replays(page, server, artefacts):
    page.goto(f"{server}/instructor?token=wrong")
    page.wait_for_selector("section.fail")
    _start(page, server, FIRST, trainee="replayed")
    page.fill("#act-gear-value", "8000")
    page.click("#act-gear")
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


def test_exercise_picker_lists_the_shipped_exercises(page, server, artefacts):
    page.goto(server + "/")
    page.wait_for_selector("button[data-exercise]")
    assert page.locator("button[data-exercise]").count() >= 12
    page.screenshot(path=str(artefacts / "exercises.png"), full_page=True)
    # docs/img/trainer-*.png are copies of these artefacts, made by hand: a test run never
    # writes into the checkout's docs


def test_an_exam_shows_no_parallax_numbers(page, server):
    """With the q/p read-out off the page shows no parallax number; the
    eyepieces are what the trainee judges from. Practice with the read-out shows one."""
    for exercise, readout in ((EXAM, False), ("e03-setup-stage2", True)):
        _start(page, server, exercise, trainee=f"readout-{readout}")
        page.fill("#command", "f_instrument 109.34")
        page.press("#command", "Enter")
        _settle(page, 1)
        page.wait_for_function("() => window.trainer.state().marks !== null")
        page.wait_for_timeout(50)  # the frame after the state
        text = page.locator("#parallax").inner_text()
        state = page.evaluate("window.trainer.state()")
        if readout:
            assert state["parallax"] is not None and "µm" in text
        else:
            assert state["parallax"] is None
            assert not any(c.isdigit() for c in text) and "eyepieces" in text
