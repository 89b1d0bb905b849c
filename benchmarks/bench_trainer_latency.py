"""Turn-to-frame latency of the browser trainer, measured in headless Debian chromium.

A turn of a handwheel is sent by the page (WebSocket), the server answers with the new state
(counters, marks), and the page redraws both eyepieces from the photo patches it holds; the time
is from the send to the next animation frame after the redraw (``window.trainer.actAndFrame``).
Target: median ≤ 50 ms.

    python -m benchmarks.bench_trainer_latency [--turns 200]   (from the checkout)
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import threading
import time

import uvicorn
from playwright.sync_api import sync_playwright

from stereoplotter.web.app import create_app
from stereoplotter.web.browser_setup import chromium_path

FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--turns", type=int, default=200)
    ap.add_argument("--port", type=int, default=8791)
    args = ap.parse_args()
    srv = uvicorn.Server(uvicorn.Config(create_app("bench"), port=args.port, log_level="warning"))
    threading.Thread(target=srv.run, daemon=True).start()
    while not srv.started:
        time.sleep(0.02)
    base = f"http://127.0.0.1:{args.port}"
    with sync_playwright() as pw, tempfile.TemporaryDirectory() as profile:
        ctx = pw.chromium.launch_persistent_context(
            profile, executable_path=chromium_path(), headless=True, args=FLAGS,
            viewport={"width": 1440, "height": 900})
        page = ctx.new_page()
        page.goto(base + "/")
        page.click("button[data-exercise='e01-setup-stage1']")
        page.wait_for_url("**/s/*")  # the exercises page is ready too
        page.wait_for_selector("body[data-ready='1']")
        page.evaluate("window.trainer.actAndFrame({kind: 'set', control: 'f_instrument', "
                      "value: 109.34})")
        page.wait_for_function("() => window.trainer.photosReady()", timeout=120_000)
        results = {}
        for view in ("split", "anaglyph"):
            page.select_option("#view", view)
            ms = page.evaluate(
                """async (n) => { const out = [];
                   for (let i = 0; i < n; i++) out.push(await window.trainer.actAndFrame(
                       {kind: 'turn', control: 'X', delta: (i % 2 ? -1 : 1) * 0.05}));
                   return out; }""", args.turns)
            ms.sort()
            results[view] = (statistics.median(ms), ms[int(0.95 * (len(ms) - 1))])
        ctx.close()
    srv.should_exit = True
    for view, (med, p95) in results.items():
        print(f"turn-to-frame {view:9s} n={args.turns}: median {med:.1f} ms, p95 {p95:.1f} ms")


if __name__ == "__main__":
    main()
