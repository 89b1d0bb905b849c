"""The reader robot (``tests/browser/reader.py``): only what the page shows and its controls —
no core call, no simulated operator, no hint — completes a C2 exercise."""

from __future__ import annotations

from tests.browser.reader import Reader, relative_orientation
from tests.browser.test_trainer_pages import _start


def test_the_reader_robot_clears_the_y_parallax_of_c2_from_the_page(page, server, artefacts):
    _start(page, server, "e05-conventional-c2", trainee="reader")
    page.wait_for_selector("body[data-overview='1']")
    r = Reader(page)
    tol = 12.5  # µm: the page's "Checks and tolerances" (0.0125 mm)
    assert "0.0125 mm" in page.inner_text("#checks")
    q = relative_orientation(r, tol)
    assert max(q) < tol / 2, q
    r.claim()
    page.wait_for_selector("#result table")
    row = page.locator("#result tr", has_text="residual y-parallax")
    assert "within" in row.inner_text()
    assert page.evaluate("window.trainer.state().done")
    print(f"reader robot on e05: {r.sent} actions, worst |q| {max(q):.2f} µm at the claim")
    page.screenshot(path=str(artefacts / "reader-c2.png"), full_page=True)
