"""The trainer page's own endpoints: the symbols' glossary and the page's names, a session's
hint costs, going to a point, a stage's feedback, the trainee's stereo acuity and the class's.

Who may see what (as :mod:`stereoplotter.web.app`): the glossary is public; the rest needs the
session's key or the instructor's token; the class's acuities the instructor's token. Feedback
on a stage (its checks and the likely wrong setting) is given in practice only: an exam's
outcome is the grade's. Every refusal is one line of JSON (:class:`~.guard.Refused`); the
session's work runs on the registry's fair actor pool.
"""

from __future__ import annotations

import asyncio
import math
from typing import Any

from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import JSONResponse, Response
from starlette.routing import Route

from stereoplotter.errors import TrainerError
from stereoplotter.trainer.acuity import ACUITY_RECORDS
from stereoplotter.trainer.feedback import stage_feedback
from stereoplotter.trainer.grade_tables import FULL_POINTS, HINT_COST
from stereoplotter.trainer.navigation import goto_actions
from stereoplotter.trainer.panel import least_count
from stereoplotter.trainer.step_words import CONTROL_NAMES, SHEET_NAMES, glossary
from stereoplotter.trainer.tour import tour_of
from stereoplotter.web.guard import Refused
from stereoplotter.web.routes import instructor_only, own_or_instructor, web_of
from stereoplotter.web.sockets import address_of

__all__ = ["ROUTES"]

_NO_STORE = {"Cache-Control": "no-store"}


async def glossary_json(request: Request) -> Response:
    """The symbols with their explanations (Russian, English) and the page's names."""
    body = {"symbols": glossary(), "controls": CONTROL_NAMES, "sheet": SHEET_NAMES}
    return JSONResponse(body, headers={"Cache-Control": "max-age=600"})


async def _live(request: Request):
    sid, row = own_or_instructor(request)  # the credential before anything else is looked at
    reg = web_of(request).reg
    live = await run_in_threadpool(reg.resume, sid)
    return reg, live, row


async def _on_actor(request: Request, reg, live, fn, *args):
    """``fn(*args)`` on the session's fair actor pool (queued under the client's address and
    the session, under the session's lock), awaited off the event loop."""
    return await asyncio.wrap_future(reg.read(live, address_of(request), fn, *args))


def _words(session) -> dict[str, Any]:
    share = FULL_POINTS / max(len(session.stages), 1)
    stage = session.stage
    n = len(session.par.stage_actions(stage)) if stage is not None else 0
    if not session.exercise.allows("hints"):  # no show-me: its length is the operator's run
        n = None
    return {
        "stage": stage,
        "hint_points": {str(k): round(share * v, 2) for k, v in HINT_COST.items()},
        "show_me_actions": n,
        "tour": tour_of(session.exercise.name),
    }


async def words(request: Request) -> Response:
    """What hints cost in this exercise (points of the grade, per level) and how many actions
    show-me plays in the stage in hand (the page says both before they run); the exercise's
    newcomer's tour (:mod:`stereoplotter.trainer.tour`)."""
    reg, live, _ = await _live(request)
    body = await _on_actor(request, reg, live, _words, live.session)
    return JSONResponse(body, headers=_NO_STORE)


def _goto(session, point: str | None, xy: list[float] | None) -> list[dict[str, Any]]:
    """Where the read-out is hidden, each setting to its counter's least count (a setting to
    the µm would give where the left mark truly projects, the instrument's hidden errors)."""
    actions = goto_actions(session, point=point, left_xy=xy)
    if session.hides_readout():
        for action in actions:
            step = least_count(session.exercise.spec, action["control"])
            action["value"] = round(round(action["value"] / step) * step, 9)
    return actions


async def goto(request: Request) -> Response:
    """The X, Y settings that put the left mark on a point (``?point=3``, a standard point or a
    control point's id) or on a place of the left photo (``?x=…&y=…`` mm): the page sends them
    as the trainee's actions."""
    own_or_instructor(request)
    q = request.query_params
    point = q.get("point")
    xy = None
    if point is None:
        try:
            xy = [float(q["x"]), float(q["y"])]
        except (KeyError, ValueError):
            xy = None
        if xy is None or not all(math.isfinite(v) for v in xy):
            raise Refused(400, "go to: expected point=N or x, y in mm on the left photo")
    elif len(point) > 16:
        raise Refused(400, "go to: point: expected a standard point 1–6 or a control point id")
    reg, live, _ = await _live(request)
    if live.demonstration:
        raise Refused(403, "go to: a demonstration takes no actions")
    try:
        actions = await _on_actor(request, reg, live, _goto, live.session, point, xy)
    except TrainerError as exc:
        raise Refused(400, str(exc)) from None
    return JSONResponse({"actions": actions}, headers=_NO_STORE)


def _feedback(session, which: str) -> dict[str, Any]:
    if which == "now":
        if session.stage is None:
            raise TrainerError("feedback: every stage is claimed (ask for stage=last)")
        return stage_feedback(session, session.stage, session.inst)
    if not session.claimed:
        raise TrainerError("feedback: no stage is claimed yet")
    stage = session.claimed[-1]
    return stage_feedback(session, stage, session.at_claim.get(stage, session.inst))


async def feedback(request: Request) -> Response:
    """A stage's checks and the likely wrong setting (practice only): ``?stage=now`` the stage
    in hand on the instrument as it stands (before claiming), ``?stage=last`` the last stage
    claimed, on the instrument as it stood at its claim."""
    own_or_instructor(request)
    which = request.query_params.get("stage", "last")
    if which not in ("now", "last"):
        raise Refused(400, "feedback: stage: expected now or last")
    reg, live, row = await _live(request)
    if row["mode"] == "exam":
        raise Refused(403, "feedback: an exam's outcome is given by its grade")
    if which == "now" and live.session.hides_readout():  # the stage's checks are a read-out
        raise Refused(403, "feedback: the read-out is off in this exercise: feedback comes "
                      "with the claim")
    try:
        body = await _on_actor(request, reg, live, _feedback, live.session, which)
    except TrainerError as exc:
        raise Refused(400, str(exc)) from None
    return JSONResponse(body, headers=_NO_STORE)


def _acuity_of(records: list[dict[str, Any]]) -> dict[str, float]:
    out = {}
    for rec in records[1:]:
        action = rec.get("action") or {}
        name = action.get("name")
        if action.get("kind") == "record" and name in ACUITY_RECORDS and rec.get("refused") is None:
            value = action.get("value")
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                out[ACUITY_RECORDS[name]] = float(value)
    return out


async def class_acuity(request: Request) -> Response:
    """The instructor's view of the class's stereo acuities: per session the trainee's measured
    thresholds (recorded by the page's acuity test in the session log). [arc-seconds]"""
    instructor_only(request)
    reg = web_of(request).reg

    def collect() -> list[dict[str, Any]]:
        rows = []
        for row in reg.table():
            found = _acuity_of(reg.store.records(row["id"]))
            if found:
                rows.append({"id": row["id"], "trainee": row["trainee"], **found})
        return rows

    return JSONResponse(await run_in_threadpool(collect), headers=_NO_STORE)


#: The page's routes (registered beside :data:`stereoplotter.web.app.ROUTES`).
ROUTES = [
    Route("/api/glossary", glossary_json),
    Route("/api/sessions/{sid}/words", words),
    Route("/api/sessions/{sid}/goto", goto),
    Route("/api/sessions/{sid}/feedback", feedback),
    Route("/api/instructor/acuity", class_acuity),
]
