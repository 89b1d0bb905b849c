"""A newcomer on the instrument page: words one tap away, a tour, ticks that mean done, costs
said before hint 3 runs, a stage checked with its likely wrong setting, going to a point, the
zoom-out advice and the stereo-acuity test — in a real browser, with no console errors."""

from __future__ import annotations

import random

from tests.browser.test_trainer_pages import TOKEN, _settle, _start


def _errors(page):
    seen = []
    page.on("console", lambda m: m.type == "error" and seen.append(m.text))
    page.on("pageerror", lambda e: seen.append(str(e)))
    return seen


def test_the_tour_and_the_glossary_guide_a_newcomer(page, server, artefacts):
    errors = _errors(page)
    _start(page, server, "e00-first-look", trainee="newcomer")
    page.wait_for_selector("#tour:not([hidden])")
    assert "eyepieces" in page.inner_text("#tour").lower()
    page.click("#tour-next")
    page.fill("#mag", "2")
    page.dispatch_event("#mag", "change")
    page.wait_for_function("() => document.querySelector('#tour').dataset.card === '2'")
    box = ".wheel[data-control='f_instrument'] input"
    page.fill(box, "109.3748")
    page.press(box, "Enter")
    page.wait_for_function("() => document.querySelector('#tour').dataset.card === '3'")
    _settle(page, 1)
    # the f_пр step is ticked by its target, the gear step (not yet geared) is not
    f_step = page.locator("#checklist li", has_text="set the instrument principal distance")
    assert f_step.get_attribute("data-done") == "1"
    gear = page.locator("#checklist li", has_text="gear the height counter")
    assert gear.get_attribute("data-done") == "0"
    assert "M_в (vertical scale 1:M_в: gear) = 8000" in gear.inner_text()
    # a symbol tapped: its explanation in both languages
    page.locator("#checklist .term[data-symbol='M_в']").first.click()
    text = page.inner_text("#term-box")
    assert "vertical scale of the model" in text and "вертикальный масштаб" in text
    page.screenshot(path=str(artefacts / "newcomer-e00.png"), full_page=True)
    assert errors == []


def test_hint_3_says_what_it_does_and_costs_then_ticks_the_stage(page, server):
    _start(page, server, "e01-setup-stage1", trainee="helped")
    page.wait_for_function(
        "() => document.querySelector('#hints button[data-level=\"3\"]').title.includes('75')"
    )
    page.click("#hints button[data-level='3']")
    text = page.inner_text("#confirm")
    assert "does the whole of stage 1" in text and "75 of the exercise's 100 points" in text
    page.click("#confirm-no")
    assert page.evaluate("window.__n") == 0  # nothing sent
    page.click("#hints button[data-level='3']")
    page.click("#confirm-yes")
    _settle(page, 1)
    page.wait_for_function(
        "() => /^([1-9]\\d*) \\/ \\1$/.test(document.querySelector('#checklist-count').textContent)"
    )


def test_a_stage_checked_names_the_check_and_the_likely_wrong_setting(page, server):
    _start(page, server, "e01-setup-stage1", trainee="wrong gear")
    page.fill("#act-gear-value", "12500")  # M_г in place of M_в
    page.click("#act-gear")
    _settle(page, 1)
    page.click("#check")
    page.wait_for_selector("#feedback:not([hidden])")
    text = page.inner_text("#feedback")
    assert "Check failed: height counter not geared for M_в" in text
    assert "gear (action) is 12500; the stage needs 8000" in text
    assert "M_г in place of M_в" in text


def test_go_to_a_standard_point_and_the_zoom_out_advice(page, server):
    errors = _errors(page)
    _start(page, server, "e05-conventional-c2", trainee="navigator")
    page.wait_for_selector("body[data-overview='1']")
    page.click("#goto button[data-point='1']")
    _settle(page, 2)
    mark = page.evaluate("window.trainer.state().marks.left")
    ov = page.evaluate(
        "fetch(location.pathname.replace('/s/', '/api/sessions/') + '/overview', {headers: "
        "{Authorization: 'Bearer ' + localStorage.getItem('stereoplotter-key-' + "
        "location.pathname.split('/').pop())}}).then(r => r.json())"
    )
    p1 = ov["photos"]["left"]["standard_points"][0]
    assert abs(mark["x_mm"] - p1["x_mm"]) < 0.01 and abs(mark["y_mm"] - p1["y_mm"]) < 0.01
    # C2 starts with millimetres of y-parallax: the matching detail is outside the ×6 field
    page.wait_for_selector("#zoom-note:not([hidden])")
    assert "Zoom out to ×2" in page.inner_text("#zoom-note")
    assert errors == []


def test_the_acuity_test_recovers_a_simulated_eye_and_the_instructor_sees_it(page, server):
    sid = _start(page, server, "e05-conventional-c2", trainee="eyes")
    page.click("#acuity-open")
    page.click("#acuity-start-y")
    rng, sigma, n = random.Random(5), 15.0, 0
    while page.is_visible("#acuity-ask") and n < 120:  # an observer right with Φ(s/σ)
        truth = page.get_attribute("#acuity-canvas", "data-truth")
        level = float(page.evaluate("window.acuityTest.run.level"))
        right = level / sigma + rng.gauss(0.0, 1.0) > 0.0
        page.click("#acuity-a" if (truth == "0") == right else "#acuity-b")
        n += 1
    _settle(page, 1)
    value = page.evaluate("window.trainer.state().records['stereo acuity y (arcsec)']")
    assert 15.0 / 3 < value < 15.0 * 3  # one run: ± 0.44 in log σ (test_acuity), 2.5 SD
    assert "µm of photo through the instrument" in page.inner_text("#acuity-result-y")
    page.goto(f"{server}/instructor?token={TOKEN}")
    row = page.locator(f"#acuities tr[data-id='{sid}']")
    row.wait_for()
    assert row.locator("td").nth(3).inner_text() == f"{value:.1f}"
