"""The newcomer's page in numbers (docs/trainer.md, "A newcomer on the page"): the e01 checklist
before and after hint 3, its L note, the e05 go-to settings and the distance of the matching
detail at standard point 1 (what the zoom-out advice measures), and the feedback on a wrong gear.

    PYTHONPATH=. python3 benchmarks/bench_newcomer.py
"""

from __future__ import annotations

import time

import numpy as np

from stereoplotter.io.exercise_file import load_exercise
from stereoplotter.trainer.feedback import stage_feedback
from stereoplotter.trainer.navigation import goto_actions
from stereoplotter.trainer.panel import checklist, show_me_actions
from stereoplotter.trainer.session import Session


def main() -> None:
    s = Session.start(load_exercise("e01-setup-stage1"), trainee="newcomer")
    c = checklist(s)
    print(f"e01 at the start: {c['done']} / {c['total']} ticked ({len(c['steps'])} steps, "
          f"{len(c['steps']) - c['total']} conditional ones hidden)")
    print("  L note:", next(st["note"] for st in c["steps"] if st["note"]))
    s.act({"kind": "hint", "level": 3})
    c = checklist(s)
    print(f"e01 after hint 3: {c['done']} / {c['total']}")
    s = Session.start(load_exercise("e01-setup-stage1"), trainee="newcomer")
    t0 = time.perf_counter()
    actions = show_me_actions(s)
    for a in actions:
        s.act(a)
    ms = (time.perf_counter() - t0) / len(actions) * 1000
    print(f"e01, the operator's {len(actions)} actions one by one: {checklist(s)['done']} / "
          f"{checklist(s)['total']}; {ms:.2f} ms an action (ticks included)")
    s = Session.start(load_exercise("e01-setup-stage1"), trainee="wrong gear")
    s.act({"kind": "set", "control": "f_instrument", "value": 109.3748})
    s.act({"kind": "gear", "value": 12500})
    for line in stage_feedback(s, "1", s.inst)["lines"]:
        print("  feedback:", line)
    s = Session.start(load_exercise("e05-conventional-c2"), trainee="navigator")
    for n in range(1, 7):
        for a in goto_actions(s, str(n)):
            s.act(a)
        left = np.array([s.state()["marks"]["left"][k] for k in ("x_mm", "y_mm")])
        right = np.array([s.state()["marks"]["right"][k] for k in ("x_mm", "y_mm")])
        il, ir = (np.asarray(v[n - 1], float) for v in s.prep.scene.standard)
        off = float(np.hypot(*(ir + (left - il) - right)))
        print(f"e05 go to standard point {n}: left mark {1000 * np.hypot(*(left - il)):.1f} µm "
              f"from it; the matching detail {off:.2f} mm from the right mark")


if __name__ == "__main__":
    main()
