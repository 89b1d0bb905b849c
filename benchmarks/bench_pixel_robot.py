"""The pixel robot (``tests/browser/pixel_robot.py``) on N seeds of the C2 exam, in Chromium.

The robot reads only the two eyepiece canvases the page draws and turns the page's controls
(the go-to buttons, the keyboard box, the magnification); the exam shows no parallax read-out.
Each seed is a trainee name (the exam's seed is per trainee, drawn by the server). After the
claim the grade's true residual y-parallax at the six points is read, for the report only.

    PYTHONPATH=$PWD python -m benchmarks.bench_pixel_robot [--seeds 10]   (from the checkout)

Prints per seed: passed, the true q at the six points [µm] (the grade's sign), the robot's last
reading of q at each point with its magnification (the page's sign: "a detail lower on the right"
is +, the opposite of the grade's), actions, looks, seconds (and how they split: acting, waiting
for the photos, reading the canvases, the rest); then the pass rate. The exam seed
of a trainee is drawn by the server from its own key (HMAC of exercise, trainee, attempt):
``--server-key TEXT`` gives the server the key SHA-256(TEXT) (a data folder in a temporary
directory holds it), so that a run meets the same instruments as another run with the same
TEXT; ``--server-key random`` (the default) a fresh key, other instruments each run.
"""

from __future__ import annotations

import argparse
import hashlib
import tempfile
import threading
import time

import numpy as np
import uvicorn
from playwright.sync_api import sync_playwright

from stereoplotter.io.session_store import SessionStore
from stereoplotter.web.app import create_app
from stereoplotter.web.browser_setup import chromium_path
from stereoplotter.web.registry import SEED_KEY
from tests.browser import pixel_page
from tests.browser.conftest import FLAGS, _free_port
from tests.browser.pixel_robot import relative_orientation, substitute_offset

TOKEN = "bench-token"


def _true_q_um(app, sid: str) -> list[float]:
    """The true y-parallax at the six points now (the grade's sign). [µm]"""
    from stereoplotter.trainer.outcome import standard_q

    session = app.state.registry.live[sid].session
    return [round(float(v) * 1000.0, 1)
            for v in np.asarray(standard_q(session.inst, session.prep)).reshape(-1)]


def _observer(app, sid: str, eyes):
    """Diagnostics after each pass: the robot's readings against the true q, and Z."""

    def show(rec) -> None:
        true = _true_q_um(app, sid)
        seen = {n: f"{-q:.1f}(×{rec.mag[n]})" for n, q in sorted(rec.q_um.items())}
        print(f"  pass {rec.passes}: read (grade's sign) {seen}; true {true}; "
              f"Z {eyes.wheel('Z')}; {eyes.sent} actions", flush=True)

    return show


class _Echo(list):
    """The robot's notes, printed as they are made (``--verbose``)."""

    def append(self, note) -> None:
        print("   ", note, flush=True)
        super().append(note)


def _stage(page) -> str:
    return page.inner_text("#stage")


def _e12(page, base, app, sid, eyes, observer, trainee, t0, verbose) -> None:
    """e12 as far as the robot goes: C1 from the sheet (claimed), the substitute recorded, C2
    by the robot (claimed); prints the stage reached and the true residuals at each claim."""
    from stereoplotter.trainer.outcome import stage_measures

    session = app.state.registry.live[sid].session

    def measures(stage: str) -> str:
        inst = session.at_claim.get(stage, session.inst)
        return "; ".join(f"{m.name} {float(np.max(m.value)):.4g} {m.unit} (tol "
                         f"{m.tolerance:.4g})"
                         for m in stage_measures(inst, session.prep, stage,
                                                 session.exercise.unusable_points))

    sheet = pixel_page.sheet_values(page)
    pixel_page.interior(eyes, sheet)
    eyes.claim()
    print(f"{trainee}: C1 claimed ({eyes.sent} actions): {measures('C1')}; now "
          f"{_stage(page)!r}", flush=True)
    points = eyes.standard_points()
    subs = {n: substitute_offset(points, n) for n in eyes.unusable()}
    for n, (dx, dy) in subs.items():
        x, y = points[n][0] + dx, points[n][1] + dy
        eyes.record(f"substitute {n}", f"{x:.3f}, {y:.3f}")
    print(f"  substitutes (offset from the point, mm): {subs}; true q after C1 "
          f"{_true_q_um(app, sid)} µm", flush=True)
    rec = relative_orientation(eyes, pixel_page.tolerance_um(page), observer=observer,
                               substitutes=subs, wide=True,
                               notes=_Echo() if verbose else None)
    eyes.claim()
    seen = {n: f"{q:.1f} (×{rec.mag[n]})" for n, q in sorted(rec.q_um.items())}
    print(f"{trainee}: C2 claimed; true q {_true_q_um(app, sid)} µm; {measures('C2')}; "
          f"last read q {seen}; passes {rec.passes}; {eyes.sent} actions, {eyes.looks} looks, "
          f"{time.perf_counter() - t0:.0f} s; now {_stage(page)!r} (C3, C4 not attempted)",
          flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--first", type=int, default=1, help="first trainee number")
    ap.add_argument("--practice-seed", type=int, default=None,
                    help="run the fixed-seed practice exercise of "
                    "tests/browser/test_pixel_robot.py with this seed, for its trainee")
    ap.add_argument("--exercise", choices=("c2", "e12"), default="c2",
                    help="c2: C2 of e05 as an exam (the default); e12: the shipped conventional "
                    "exam e12 (SD-3, mountains): C1 from the sheet, C2 with a substitute for "
                    "the unusable point and the search beyond the field; C3 and C4 are not "
                    "attempted")
    ap.add_argument("--verbose", action="store_true",
                    help="diagnostics: the robot's notes, and after each pass the true q and Z "
                    "read from the server's session (never shown to the robot)")
    ap.add_argument("--server-key", default="random",
                    help="the server's exam-seed key is SHA-256 of this text (the same text, "
                    "the same instruments); 'random': a fresh key")
    args = ap.parse_args()
    port = _free_port()
    data = tempfile.TemporaryDirectory()
    data_dir = None
    if args.server_key != "random":
        data_dir = data.name
        store = SessionStore(data_dir)
        store.put_value(SEED_KEY, hashlib.sha256(args.server_key.encode()).hexdigest())
        store.close()
    app = create_app(TOKEN, data_dir, message_limit=(2000.0, 4000))
    srv = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning"))
    threading.Thread(target=srv.run, daemon=True).start()
    while not srv.started:
        time.sleep(0.02)
    base = f"http://127.0.0.1:{port}"
    passed = 0
    actions, secs = [], []
    with sync_playwright() as pw, tempfile.TemporaryDirectory() as profile:
        ctx = pw.chromium.launch_persistent_context(
            profile, executable_path=chromium_path(), headless=True, args=FLAGS,
            viewport={"width": 1440, "height": 900})
        page = ctx.new_page()
        page.goto(base + "/")
        name = pixel_page.EXAM_NAME
        if args.exercise == "e12":
            name = pixel_page.E12_NAME
        elif args.practice_seed is None:
            pixel_page.upload_exam(page, base, TOKEN)
        else:
            name = f"c2-by-eye-{args.practice_seed}"
            pixel_page.upload_exam(page, base, TOKEN,
                                   pixel_page.exercise_text(name, "practice", args.practice_seed))
        for k in range(args.first, args.first + args.seeds):
            t0 = time.perf_counter()
            trainee = f"pixel {k}" if args.practice_seed is None else "pixel robot"
            sid = pixel_page.start(page, base, trainee, name)
            eyes = pixel_page.PageEyes(page)
            observer = _observer(app, sid, eyes) if args.verbose else None
            if args.exercise == "e12":
                _e12(page, base, app, sid, eyes, observer, trainee, t0, args.verbose)
                continue
            rec = relative_orientation(eyes, pixel_page.tolerance_um(page), observer=observer)
            if args.verbose:
                for note in rec.notes:
                    print("   ", note)
            eyes.claim()
            seconds = time.perf_counter() - t0
            g = pixel_page.grade_after_claim(page, base, sid)
            rows = g["tables"]["y_parallax"]["rows"]
            ok = bool(g["overall"]["passed"])
            passed += ok
            true = [round(r["value"], 1) for r in rows]
            seen = {n: f"{q:.1f} (×{rec.mag[n]})" for n, q in sorted(rec.q_um.items())}
            worst = max(abs(v) for v in true)
            actions.append(eyes.sent)
            secs.append(seconds)
            print(f"seed 'pixel {k}': passed {ok}; true q {true} µm (worst {worst}); "
                  f"last read q {seen} µm; "
                  f"{eyes.sent} actions, {eyes.looks} looks, {rec.passes} passes, "
                  f"{seconds:.0f} s (acting {eyes.act_s:.0f}, waiting for the photos "
                  f"{eyes.wait_s:.0f}, reading them {eyes.read_s:.0f}, the rest — the "
                  f"robot's judgement, the session's start and the claim — "
                  f"{seconds - eyes.act_s - eyes.wait_s - eyes.read_s:.0f})", flush=True)
        ctx.close()
    print(f"passed {passed} of {args.seeds}; actions {min(actions)}–{max(actions)} "
          f"(median {np.median(actions):.0f}); {min(secs):.0f}–{max(secs):.0f} s "
          f"(median {np.median(secs):.0f} s)")


if __name__ == "__main__":
    main()
