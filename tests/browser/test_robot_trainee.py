"""A robot trainee completes every shipped exercise through the instrument page's controls
alone, and the page's grade is the core's grade of the same log.

The robot's actions are the core's :func:`~stereoplotter.trainer.robot.robot_script` for the
exercise (the simulated operator's settings that pass it), each made as a gesture
(:mod:`tests.browser.robot`): a typed value and Enter, a click. The test never opens a
WebSocket; it reads the log over HTTP with the session's own key and grades it with
the core, independently of the server. Parametrized over the shipped exercise files: a new file
is covered with no new code.
"""

from __future__ import annotations

import json
import time
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context

import pytest
from playwright.sync_api import Error as PlaywrightError

from stereoplotter.io.exercise_file import exercise_from_mapping, load_exercise, shipped_exercises
from stereoplotter.trainer.grading import grade
from stereoplotter.trainer.robot import robot_script
from stereoplotter.trainer.session import Session
from stereoplotter.web.core import GRADE_POPULATION
from tests.browser.conftest import TOKEN
from tests.browser.robot import Hands, script_for

SHIPPED = shipped_exercises()
TRAINEE = "robot"


def _get(page, url: str, secret: str) -> str:
    """GET with the session's key; once more if the server closed an idle kept-alive
    connection just as it was reused (uvicorn closes them after 5 s: ECONNRESET)."""
    for attempt in range(2):
        try:
            r = page.request.get(url, headers={"Authorization": f"Bearer {secret}"})
            assert r.ok, r.text()
            return r.text()
        except PlaywrightError:
            if attempt:
                raise
    raise AssertionError("unreachable")


def _as_javascript_numbers(value):
    """``value`` with every integer beyond 2⁵³ (a per-trainee seed) as the double the page holds
    (JavaScript numbers are doubles; Playwright hands it back as the double's shortest
    decimal digits)."""
    if isinstance(value, dict):
        return {k: _as_javascript_numbers(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_as_javascript_numbers(v) for v in value]
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) > 2**53:
        return float(value)
    return value


@pytest.fixture(scope="module")
def scripts(request):
    """The robot script of each exercise selected, made ahead in a worker process (in the
    tests' order) while the browser works."""
    chosen = [
        item.callspec.params["path"]
        for item in request.session.items
        if getattr(item, "module", None) is request.module and hasattr(item, "callspec")
    ]
    pool = ProcessPoolExecutor(max_workers=1, mp_context=get_context("spawn"))
    yield {p: pool.submit(script_for, str(p), TRAINEE) for p in chosen}
    pool.shutdown(wait=True, cancel_futures=True)


@pytest.fixture(scope="module")
def robot_page(browser):
    """One tab for the whole walk (a new session per exercise loads the page afresh)."""
    p = browser.new_page()
    yield p
    p.close()


@pytest.mark.slow  # a few minutes on the shared machine: still in the README's test command
@pytest.mark.parametrize("path", SHIPPED, ids=[p.stem for p in SHIPPED])
def test_robot_trainee_completes_the_exercise_through_the_page(
    robot_page, process_server, scripts, path, record_property
):
    page, t0, server = robot_page, time.perf_counter(), process_server
    ex = load_exercise(path)
    script = scripts[path].result(timeout=600)
    page.goto(server + "/")
    page.fill("#trainee", TRAINEE)
    page.click(f"button[data-exercise='{ex.name}']")
    page.wait_for_url("**/s/*")
    page.wait_for_selector("body[data-ready='1']")
    page.wait_for_selector("body[data-overview='1']")
    sid = page.url.rsplit("/", 1)[1]
    if ex.mode == "exam":  # the seed is the server's own: the instructor reads it in the log
        head = json.loads(_get(page, f"{server}/api/sessions/{sid}/log.jsonl?token={TOKEN}",
                               TOKEN).splitlines()[0])
        script = robot_script(Session.start(ex, trainee=TRAINEE, seed=head["seed"]))
    hands = Hands(page)
    for action in script:
        hands.do(action)
    hands.settle()
    page.wait_for_selector("#done:not([hidden])")
    assert page.evaluate("window.trainer.state().done")

    secret = page.evaluate(f"localStorage.getItem('stereoplotter-key-{sid}')")
    log = [json.loads(line) for line in _get(page, f"{server}/api/sessions/{sid}/log.jsonl",
                                             secret).splitlines()]
    assert [rec["action"]["kind"] for rec in log[1:]] == [a["kind"] for a in script]
    assert not [rec for rec in log[1:] if rec.get("refused")]

    page.click("#grade-link")
    page.wait_for_selector("body[data-ready='1']")
    shown = page.evaluate("window.__grade")
    core = json.loads(json.dumps(
        grade(log, population=GRADE_POPULATION, read_exercise=exercise_from_mapping)))
    for g in (shown, core):  # the wall-clock time of the grading run itself
        g["population"].pop("seconds")
    assert _as_javascript_numbers(shown) == _as_javascript_numbers(core)
    assert shown["overall"]["passed"], shown["overall"]
    record_property("robot_seconds", round(time.perf_counter() - t0, 2))
    record_property("robot_actions", len(script))
