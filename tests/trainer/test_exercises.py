"""The shipped exercises: at least 24, levels from 1 to at least 10, every stage of both
methods on each instrument, each loads and its session starts; bad exercise files are refused in
one line naming the file and the field."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from stereoplotter.errors import ConfigError
from stereoplotter.io.exercise_file import TILT_TARGET_DEG, load_exercise, shipped_exercises
from stereoplotter.trainer.exercise import STAGES, trainee_seed
from stereoplotter.trainer.session import Session

SHIPPED = shipped_exercises()


def test_at_least_24_exercises_cover_every_stage_on_every_instrument():
    exercises = [load_exercise(p) for p in SHIPPED]
    assert len(exercises) >= 24
    levels = [e.level for e in exercises]
    assert min(levels) == 1 and max(levels) >= 10
    # every stage of both methods on each of the three instruments (alone or in an "all")
    covered = {(e.spec.key, s) for e in exercises for s in e.stages}
    wanted = {(i, s) for i in ("sc1", "spr3", "sd3") for m in STAGES.values() for s in m}
    assert wanted <= covered, sorted(wanted - covered)
    kinds = {(e.method, e.mode, e.errors, e.terrain, e.model) for e in exercises}
    assert {k[0] for k in kinds} == {"setup", "conventional"}
    assert {k[1] for k in kinds} == {"practice", "exam"}
    assert {k[2] for k in kinds} == {"off", "announced", "hidden"}
    assert {k[3] for k in kinds} == {"flat", "hilly", "mountainous"}
    assert {k[4] for k in kinds} == {"complete", "incomplete"}


@pytest.mark.parametrize("path", SHIPPED, ids=[p.stem for p in SHIPPED])
def test_each_exercise_starts_a_session(path):
    ex = load_exercise(path)
    assert ex.name == path.stem
    s = Session.start(ex, trainee="ann")
    state = s.state()
    assert state["stage"] == ex.stages[0]
    assert state["mode"] == ex.mode
    assert ("undo" in state["allowed"] or "hint" in state["allowed"]) == (ex.mode == "practice")
    assert ex.preset_stages == STAGES[ex.method][: STAGES[ex.method].index(ex.stages[0])]
    # the tilt class scaled the scenario's photos: the largest |α|, |ω| is the class's target
    tilts = [abs(getattr(p.exterior, a)) for p in ex.scenario.photos for a in ("alpha", "omega")]
    assert np.degrees(max(tilts)) == pytest.approx(TILT_TARGET_DEG[ex.tilt], abs=1e-6)


def test_flat_terrain_has_no_relief():
    ex = load_exercise("e01-setup-stage1")
    heights = [p.local_m[2] for p in ex.scenario.points]
    assert max(heights) - min(heights) == pytest.approx(0.0, abs=1e-9)


def test_per_trainee_seeds_differ_between_trainees_and_repeat_for_one():
    ex = load_exercise("e11-setup-exam")
    assert ex.seed is None
    assert ex.seed_for("ann") == ex.seed_for("ann") == trainee_seed(ex.name, "ann")
    assert ex.seed_for("ann") != ex.seed_for("bob")


BASE = {
    "format": "stereoplotter-exercise/1",
    "name": "x",
    "title": "x",
    "level": 1,
    "instrument": "sc1",
    "scenario": "pair60",
    "method": "setup",
    "terrain": "hilly",
}


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"method": "classic"}, "method"),
        ({"stages": "C2"}, "stages"),
        ({"model": "incomplete"}, "unusable_points"),
        ({"unusable_points": [7]}, "unusable_points[0]"),
        ({"errors": "sometimes"}, "errors"),
        ({"seed": -1}, "seed"),
        ({"terrain": "mountainous"}, "terrain"),
        ({"instrument": "sc9"}, "instrument"),
        ({"assists": {"parallax": True}}, "assists.parallax"),
        ({"levle": 2}, "levle"),
    ],
)
def test_a_bad_exercise_is_refused_in_one_line(tmp_path, change, field):
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump({**BASE, **change}, allow_unicode=True), encoding="utf-8")
    with pytest.raises(ConfigError) as exc:
        load_exercise(path)
    message = str(exc.value)
    assert "\n" not in message
    assert message.startswith(f"{path}: {field}: expected"), message
