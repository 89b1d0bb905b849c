"""The web layer's only door to the trainer core (issue 13): exercises, sessions, grades, logs.

Every call the server makes into :mod:`stereoplotter.trainer`, :mod:`stereoplotter.io` and
:mod:`stereoplotter.report` goes through here, so a change of the core's contract
(``notes: trainer_contract``) is met in one module.
"""

from __future__ import annotations

import threading
from typing import Any

from stereoplotter.errors import StereoplotterError, TrainerError
from stereoplotter.imagery.cache import ViewCache
from stereoplotter.imagery.eyepiece import SCREEN_PIXEL_MM
from stereoplotter.io.exercise_file import load_exercise, shipped_exercises
from stereoplotter.io.images import png_bytes
from stereoplotter.io.session_log import log_bytes
from stereoplotter.report.grade import grade_markdown
from stereoplotter.trainer.exercise import resolve_exercise
from stereoplotter.trainer.grading import grade
from stereoplotter.trainer.session import Session

__all__ = [
    "SCREEN_PIXEL_MM",
    "CoreError",
    "TrainerError",
    "exercise_list",
    "grade_of",
    "grade_text",
    "log_of",
    "log_text",
    "operator_script",
    "photo_patch",
    "replay",
    "replay_frames",
    "start",
]

#: Any refusal the core raises (a trainee's action, a bad exercise name, a bad log).
CoreError = StereoplotterError

#: Grading population (Monte Carlo runs of the simulated operator) used by the server; the
#: core's default is 10 000; 256 gives the percentile to ±3 points at a fraction of a second.
GRADE_POPULATION = 256


def exercise_list() -> list[dict[str, Any]]:
    """The shipped exercises, easiest first: name, title, level, mode, description."""
    out = []
    for path in shipped_exercises():
        ex = load_exercise(path)
        out.append(
            {
                "name": ex.name,
                "title": ex.title,
                "level": ex.level,
                "mode": ex.mode,
                "instrument": ex.spec.key,
                "description": ex.description,
                "assists": dict(ex.assists),
            }
        )
    return sorted(out, key=lambda e: (e["level"], e["name"]))


def start(exercise_name: str, trainee: str, seed: int | None = None) -> Session:
    """A new session on a shipped exercise (by name)."""
    return Session.start(load_exercise(exercise_name), trainee=trainee, seed=seed)


def operator_script(session: Session) -> list[dict[str, Any]]:
    """The simulated operator's actions for the session's exercise (demonstration mode)."""
    return session.operator_script()


def log_of(session: Session) -> list[dict[str, Any]]:
    """The session log as records: the header, then one record per action."""
    return [session.header(), *session.log]


def log_text(session: Session) -> bytes:
    """The session log as JSON lines (the format ``io.session_log`` writes)."""
    return log_bytes(log_of(session))


def replay(records: list[dict[str, Any]]) -> Session:
    """A session run again from its log."""
    return Session.replay(records)


def grade_of(session_or_log: Session | list[dict[str, Any]]) -> dict[str, Any]:
    """The grade (``stereoplotter-grade/1`` dict) of a session or its log."""
    return grade(session_or_log, population=GRADE_POPULATION)


def grade_text(grade_dict: dict[str, Any]) -> str:
    """The grade as Markdown."""
    return grade_markdown(grade_dict)


def replay_frames(records: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The log stepped through: for each action, the action and the state after it (the
    instructor's replay). The session is started afresh from the header and fed each recorded
    action at its recorded time; refused actions stay refused."""
    head = records[0]
    session = Session(resolve_exercise(head["exercise"]), str(head["trainee"]), int(head["seed"]),
                      clock=False)
    frames = [{"action": None, "state": session.state(), "refused": None}]
    for rec in records[1:]:
        action = dict(rec["action"], t=rec["t"])
        refused = None
        try:
            session.act(action)
        except TrainerError as exc:
            refused = str(exc)
        frames.append({"action": rec["action"], "t": rec["t"], "state": session.state(),
                       "refused": refused})
    return frames


#: Both photos of a (scenario, seed) as the imagery's tile pyramid, built once and shared by the
#: sessions that use them (building pair60 takes ~4 s).
_CACHES: dict[tuple[str, int], ViewCache] = {}
_CACHE_LOCK = threading.Lock()


def view_cache(session: Session) -> ViewCache:
    """The imagery view cache of the session's photos (built on first use)."""
    key = (session.exercise.scenario_name, int(session.seed))
    with _CACHE_LOCK:
        if key not in _CACHES:
            _CACHES[key] = ViewCache(session.exercise.scenario, session.seed)
        return _CACHES[key]


def photo_patch(
    session: Session, side: str, x_mm: float, y_mm: float, magnification: float, size_px: int
) -> bytes:
    """PNG of the photo ``side`` around photo point x, y [mm], unrotated (κ = 0), one pixel
    = SCREEN_PIXEL_MM / magnification mm of photo, x to the right, y up: the page turns and
    places it under the mark itself, so a move needs no new image."""
    cache = view_cache(session)
    return png_bytes(cache.view(side, x_mm, y_mm, 0.0, magnification, size_px))
