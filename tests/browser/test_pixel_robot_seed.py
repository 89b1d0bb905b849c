"""One seed of the pixel robot (``tests/browser/pixel_robot.py``) sits the C2 exam by eye in
Chromium, as ``benchmarks/bench_pixel_robot.py --seeds 1 --first 10 --server-key stereoplotter``
does: the robot reads only the two eyepiece canvases and turns the page's controls; after its
claim the grade's true residual y-parallax at the six standard points must lie within the
tolerance the page's checks name, and the exam must be passed.

The exam's instrument is drawn by the server from its own key and the trainee's name: the
server's key is SHA-256 of ``"stereoplotter"`` (held in its data folder, as the bench's
``--server-key`` sets it) and the trainee is ``"pixel 10"``, so every run meets the same
instrument (docs/trainer.md, "The pixel robot").
"""

from __future__ import annotations

import hashlib
import threading
import time

import pytest
import uvicorn

from stereoplotter.io.session_store import SessionStore
from stereoplotter.web.app import create_app
from stereoplotter.web.registry import SEED_KEY
from tests.browser import pixel_page
from tests.browser.conftest import TOKEN, _free_port
from tests.browser.pixel_robot import relative_orientation

SERVER_KEY = "stereoplotter"
TRAINEE = "pixel 10"


@pytest.fixture
def keyed_server(tmp_path):
    """A trainer server whose exam-seed key is SHA-256 of :data:`SERVER_KEY` (stopped at the
    end)."""
    store = SessionStore(str(tmp_path))
    store.put_value(SEED_KEY, hashlib.sha256(SERVER_KEY.encode()).hexdigest())
    store.close()
    app = create_app(TOKEN, str(tmp_path), message_limit=(2000.0, 4000))
    port = _free_port()
    srv = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning"))
    thread = threading.Thread(target=srv.run, daemon=True)
    thread.start()
    deadline = time.monotonic() + 10
    while not srv.started:
        if time.monotonic() > deadline:
            pytest.fail("trainer server did not start within 10 s")
        time.sleep(0.02)
    yield f"http://127.0.0.1:{port}"
    srv.should_exit = True
    thread.join(10)


@pytest.mark.slow
def test_the_pixel_robot_passes_the_exam_by_eye(keyed_server, page):
    base = keyed_server
    page.goto(base + "/")
    pixel_page.upload_exam(page, base, TOKEN)
    sid = pixel_page.start(page, base, TRAINEE)
    tolerance = pixel_page.tolerance_um(page)
    eyes = pixel_page.PageEyes(page)
    relative_orientation(eyes, tolerance)
    eyes.claim()
    grade = pixel_page.grade_after_claim(page, base, sid)
    table = grade["tables"]["y_parallax"]
    # the page's checks and the grade name the same tolerance: Eq. (5.11)'s 0.0125 mm
    assert table["tolerance"] == pytest.approx(tolerance)
    true_q = {row["id"]: row["value"] for row in table["rows"]}
    assert sorted(true_q) == ["1", "2", "3", "4", "5", "6"]
    assert all(abs(q) <= tolerance for q in true_q.values()), true_q
    assert grade["overall"]["passed"], grade["overall"]
