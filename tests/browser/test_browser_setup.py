"""browser_setup: installs chromium only when missing; one clear line when it cannot."""

from __future__ import annotations

import subprocess

from stereoplotter.web import browser_setup


def test_nothing_is_installed_when_chromium_is_there(monkeypatch):
    monkeypatch.setattr(browser_setup, "chromium_path", lambda: "/usr/bin/chromium")

    def never(cmd):
        raise AssertionError(cmd)

    monkeypatch.setattr(browser_setup, "run_quietly", never)
    assert browser_setup.main() == 0


def test_a_failed_apt_get_is_one_line(monkeypatch, capsys):
    monkeypatch.setattr(browser_setup, "chromium_path", lambda: None)

    def refuse(cmd):
        raise subprocess.CalledProcessError(100, cmd, stderr="E: Unable to locate package x\n")

    monkeypatch.setattr(browser_setup, "run_quietly", refuse)
    assert browser_setup.main() == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "chromium" in err[0] and "Unable to locate package" in err[0]
