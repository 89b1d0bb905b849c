"""User text is text, in a real browser: a trainee name with markup stays text on the
instructor's page (its script never runs, the token is not read), the Content-Security-Policy
blocks inline script, and a dropped socket is reopened and the session resumes."""

from __future__ import annotations

from tests.browser.test_trainer_pages import FIRST, TOKEN, _settle, _start

MARKUP = '<img src=x onerror="window.__pwned=document.location.href">'


def test_a_name_with_markup_is_text_on_the_instructor_page(page, server):
    r = page.request.post(f"{server}/api/sessions", data={"exercise": FIRST, "trainee": MARKUP})
    assert r.ok
    page.goto(f"{server}/instructor?token={TOKEN}")
    page.wait_for_selector("body[data-ready='1']")
    cell = page.locator("#sessions tbody td", has_text="onerror").first
    assert cell.inner_text() == MARKUP  # shown as the text it is
    assert page.locator("#sessions img").count() == 0
    page.wait_for_timeout(200)
    assert page.evaluate("window.__pwned") is None


def test_inline_script_is_blocked_by_the_policy(page, server):
    page.goto(server + "/")
    page.wait_for_selector("button[data-exercise]")  # the page's own module has run
    csp = page.request.get(server + "/").headers["content-security-policy"]
    assert "script-src 'self'" in csp and "unsafe-inline" not in csp
    page.evaluate("""() => { const s = document.createElement('script');
        s.textContent = 'window.__inline = 1'; document.body.append(s); }""")
    page.wait_for_timeout(100)
    assert page.evaluate("window.__inline") is None


def test_a_dropped_socket_reconnects_and_the_session_resumes(page, server):
    _start(page, server, FIRST, trainee="dropped")
    page.evaluate("window.trainer.actAndFrame({kind: 'read', counter: 'X'})")
    _settle(page, 1)
    page.evaluate("window.trainer.drop()")
    page.wait_for_selector("#link.lost", timeout=5_000)  # the page says so
    page.wait_for_function("() => !document.querySelector('#link.lost')", timeout=10_000)
    page.evaluate("window.trainer.actAndFrame({kind: 'read', counter: 'Y'})")
    _settle(page, 2)  # the second action joined the same session's log
