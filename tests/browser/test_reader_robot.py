"""The reader robot (``tests/browser/reader.py``): only what the page shows and its controls —
no core call, no simulated operator, no hint — completes stage 1 of e01 and the C2 of e05."""

from __future__ import annotations

import re

from tests.browser.reader import Reader, SetupReader, relative_orientation, stage1
from tests.browser.test_trainer_pages import _start


def test_the_reader_robot_clears_the_y_parallax_of_c2_from_the_page(page, server, artefacts):
    _start(page, server, "e05-conventional-c2", trainee="reader")
    page.wait_for_selector("body[data-overview='1']")
    page.wait_for_selector("#checklist li")
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
    print(f"reader robot on e05: {r.sent} actions, {r.cycles} cycles, worst |q| {max(q):.2f} µm")
    page.screenshot(path=str(artefacts / "reader-c2.png"), full_page=True)


def test_the_reader_robot_does_stage_1_of_the_setup_data_method_from_the_page(
    page, server, artefacts
):
    _start(page, server, "e01-setup-stage1", trainee="reader 1")
    page.wait_for_selector("body[data-overview='1']")
    r = SetupReader(page)
    page.wait_for_selector("#checks li")
    page.wait_for_function(  # the steps' sheet rows with their values (the sheet loaded)
        "() => [...document.querySelectorAll('.step-sheet')]"
        ".some((e) => e.textContent.includes(' = '))"
    )
    checks = page.inner_text("#checks")
    tol = float(re.search(r"\|L − L′\|[^:]*: tolerance ([\d.]+) mm", checks).group(1))
    diffs = stage1(r, z_max=185.0, tolerance=tol, format_mm=180.0)
    r.claim()
    page.wait_for_selector("#result table")
    text = page.inner_text("#result")
    print(f"reader robot on e01: {r.sent} actions, last L − L′ {diffs} mm; {text}")
    assert "outside" not in text, text
