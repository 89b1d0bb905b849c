"""The robot trainee's script in the core (one page control use per action) passes every
shipped exercise when replayed through :class:`Session`, graded on the true values
against the book's tolerances. A new exercise file is covered without code."""

from __future__ import annotations

import pytest

from stereoplotter.io.exercise_file import load_exercise, shipped_exercises
from stereoplotter.trainer.actions import ACTION_CATALOGUE
from stereoplotter.trainer.grading import grade
from stereoplotter.trainer.robot import robot_script, without_sides
from stereoplotter.trainer.session import Session

SHIPPED = shipped_exercises()


@pytest.mark.parametrize("path", SHIPPED, ids=[p.stem for p in SHIPPED])
def test_the_robot_script_passes_the_exercise(path):
    """The script as a page without a "finish from" choice sends it (each side turned into a
    pre-position and a plain setting); every action one control use of the catalogue."""
    ex = load_exercise(path)
    session = Session.start(ex, trainee="robot")
    script = without_sides(robot_script(session), session)
    assert not any("side" in a for a in script)
    kinds = {k["kind"] for k in ACTION_CATALOGUE}
    assert {a["kind"] for a in script} <= kinds - {"hint", "undo", "redo"}
    for action in script:
        session.act(action)
    g = grade(session, population=0)
    assert session.state()["done"]
    failed = [
        (stage, row["name"], row["value"], row["tolerance"])
        for stage, body in g["stages"].items()
        for row in body["measures"]
        if not row["passed"]
    ]
    assert failed == []
    assert g["overall"]["passed"], g["overall"]
    assert g["overall"]["score"] <= 1.0
