"""The browser tests: the trainer server in a thread, Debian's chromium driven by Playwright.

Chromium is ``/usr/bin/chromium`` (``python3 -m stereoplotter.web.browser_setup`` installs it);
a missing browser fails these tests with one line, never skips them. Screenshots of each page go
to ``tmp/artefacts/`` of the checkout (kept as test artefacts).
"""

from __future__ import annotations

import multiprocessing
import socket
import threading
import time
from pathlib import Path

import pytest
import uvicorn
from playwright.sync_api import sync_playwright

from stereoplotter.web.app import create_app
from stereoplotter.web.browser_setup import chromium_path

ARTEFACTS = Path(__file__).resolve().parents[2] / "tmp" / "artefacts"
TOKEN = "test-token"
FLAGS = [
    "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
]


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="session")
def server():
    """The base URL of a trainer server running in this process (stopped at the end)."""
    # the robot trainee's page sends as fast as the server takes: a high message rate (the
    # page paces itself by the rate the server tells it; the classroom default is 60/s)
    app = create_app(TOKEN, message_limit=(2000.0, 4000))
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
    thread.join(5)


def _serve(port: int) -> None:
    """The trainer server alone in a process (the robot trainee's: its actions and grading run
    beside the test's browser driving and core grading, not under one interpreter lock)."""
    app = create_app(TOKEN, message_limit=(2000.0, 4000))
    uvicorn.run(app, host="127.0.0.1", port=port, log_level="warning")


@pytest.fixture(scope="session")
def process_server():
    """The base URL of a trainer server in its own process (terminated at the end)."""
    port = _free_port()
    proc = multiprocessing.get_context("spawn").Process(target=_serve, args=(port,), daemon=True)
    proc.start()
    deadline = time.monotonic() + 60
    while True:
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=0.2):
                break
        except OSError:
            if time.monotonic() > deadline or not proc.is_alive():
                proc.terminate()
                pytest.fail("trainer server process did not start within 60 s")
            time.sleep(0.1)
    yield f"http://127.0.0.1:{port}"
    proc.terminate()
    proc.join(10)


@pytest.fixture(scope="session")
def browser(tmp_path_factory):
    exe = chromium_path()
    if exe is None:
        pytest.fail(
            "chromium not found at /usr/bin/chromium: run 'python3 -m "
            "stereoplotter.web.browser_setup' (as root) to install Debian's chromium"
        )
    profile = tmp_path_factory.mktemp("chromium-profile")  # a fresh --user-data-dir
    with sync_playwright() as pw:
        context = pw.chromium.launch_persistent_context(
            str(profile), executable_path=exe, headless=True, args=FLAGS,
            viewport={"width": 1440, "height": 900},
        )
        yield context
        context.close()


@pytest.fixture
def page(browser):
    p = browser.new_page()
    yield p
    p.close()


@pytest.fixture(scope="session")
def artefacts() -> Path:
    ARTEFACTS.mkdir(parents=True, exist_ok=True)
    return ARTEFACTS
