"""Process measures counted on a hand-written log, and the percentile's definition."""

from __future__ import annotations

import numpy as np

from stereoplotter.trainer.grading import percentile, process_measures


def _rec(n, t, stage, action, refused=None):
    rec = {"n": n, "t": t, "stage": stage, "action": action}
    if refused:
        rec["refused"] = refused
    return rec


def test_process_measures_of_a_hand_written_log():
    log = [
        _rec(1, 0.0, "2", {"kind": "turn", "control": "X", "delta": 1.0}),
        _rec(2, 1.0, "2", {"kind": "turn", "control": "X", "delta": 0.5}),
        _rec(3, 2.0, "2", {"kind": "turn", "control": "kappa_left", "delta": 1e-4}),
        _rec(4, 3.0, "2", {"kind": "turn", "control": "X", "delta": -0.2}),  # reversal, return
        _rec(5, 4.0, "2", {"kind": "set", "control": "Y", "value": 5.0, "side": "above"}),
        _rec(6, 5.0, "2", {"kind": "hint", "level": 2}),
        _rec(7, 6.0, "2", {"kind": "undo"}),
        _rec(8, 7.0, "2", {"kind": "claim", "step": "3"}, refused="the stage in hand is 2"),
        _rec(9, 9.5, "2", {"kind": "claim", "step": "2"}),
    ]
    p = process_measures(log, {"2": {"X", "kappa_left"}})
    assert p["time_s"] == 9.5
    assert p["moves"] == 5  # four turns and a set
    assert p["reversals"] == 1
    assert p["iterations"] == 1  # back to X after κ
    assert p["final_approach"] == {"X": "from above", "Y": "from above"}
    assert p["final_approach_one_side"] is True
    assert p["steps_out_of_order"] == 2  # Y is not a stage-2 control; a claim of stage 3
    assert p["checks_skipped"] == 1  # stage 2 claimed without a single reading
    assert (p["hints"], p["undos"], p["refused"]) == (1, 1, 1)


def test_percentile_is_the_share_that_did_no_better():
    population = np.arange(1.0, 101.0)  # 1 … 100
    assert percentile(25.0, population) == 76.0  # 25 … 100 are ≥ 25
    assert percentile(0.5, population) == 100.0
    assert percentile(100.5, population) == 0.0
