"""Make sure the browser tests can run: Debian's chromium, installed with apt-get if missing.

``python3 -m stereoplotter.web.browser_setup`` (README quick start). The tests drive
``/usr/bin/chromium`` headless through Python Playwright (no ``playwright install``: the
machine may have no network beyond the Debian mirror). Exits 1 with one line on failure.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys

__all__ = ["CHROMIUM", "chromium_path", "main", "run_quietly"]

#: Where Debian's chromium package puts the browser.
CHROMIUM = "/usr/bin/chromium"


def chromium_path() -> str | None:
    """The chromium executable the browser tests use, or None."""
    env = os.environ.get("STEREOPLOTTER_CHROMIUM")
    for path in (env, CHROMIUM, shutil.which("chromium")):
        if path and os.access(path, os.X_OK):
            return path
    return None


def run_quietly(cmd: list[str]) -> None:
    """Run ``cmd``, its output discarded; raises ``CalledProcessError`` (with its stderr) when
    it fails."""
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)


def main() -> int:
    """Install chromium with apt-get unless it is there; 0, or 1 with one line on stderr."""
    if chromium_path():
        return 0
    apt = ["apt-get"] if os.geteuid() == 0 else ["sudo", "-n", "apt-get"]
    try:
        run_quietly([*apt, "update", "-q"])
        run_quietly([*apt, "install", "-y", "-q", "chromium"])
    except (OSError, subprocess.CalledProcessError) as exc:
        detail = getattr(exc, "stderr", "") or str(exc)
        last = detail.strip().splitlines()[-1] if detail.strip() else str(exc)
        print(f"browser_setup: could not install chromium with apt-get ({last}); "
              f"install Debian's 'chromium' package as root", file=sys.stderr)
        return 1
    if not chromium_path():
        print(f"browser_setup: apt-get installed chromium but {CHROMIUM} is missing",
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
