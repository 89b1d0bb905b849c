"""The trainer's HTTP endpoints (the pages' JSON API), one function each.

Each endpoint finds the server's parts through ``request.app.state.web`` (a :class:`Web`, made
by :func:`stereoplotter.web.app.create_app`); who may see what is the module docstring of
:mod:`stereoplotter.web.app`. A refusal raises :class:`~stereoplotter.web.guard.Refused` (one
line of JSON with its status); slow work runs in worker threads or processes, never on the
event loop.
"""

from __future__ import annotations

import asyncio
import csv
import functools
import io
import json
import math
import zipfile
from dataclasses import dataclass, field
from typing import Any

from starlette.concurrency import run_in_threadpool
from starlette.requests import HTTPConnection, Request
from starlette.responses import JSONResponse, Response

from stereoplotter.io.session_store import exercise_upload, storable
from stereoplotter.web import core
from stereoplotter.web.guard import (
    RateLimit,
    Refused,
    read_body,
    read_json,
    scrub_paths,
    seed_value,
    trainee_key,
    trainee_name,
)
from stereoplotter.web.registry import Registry
from stereoplotter.web.sockets import PATCH_PX, address_of

__all__ = [
    "CSV_FIELDS",
    "MAG_RANGE",
    "START_LIMIT",
    "XY_LIMIT_MM",
    "Web",
    "archive",
    "bearer",
    "instructor_only",
    "own_or_instructor",
    "results_csv_text",
    "web_of",
]

#: The results table the instructor downloads (one row per session).
CSV_FIELDS = (
    "id",
    "trainee",
    "exercise",
    "mode",
    "stage",
    "done",
    "actions",
    "started",
    "score",
    "passed",
    "percentile",
)
#: Photo patch requests: magnification (from the coarse-first patch's, core.COARSE_MAG = 0.625)
#: and photo coordinates accepted (the format is 180 mm; ±150 mm reaches past any mark the
#: instrument can place). [—], [mm]
MAG_RANGE = (0.6, 40.0)
XY_LIMIT_MM = 150.0
#: Sessions one client address may start: bursts of 60 (a class behind one address starting at
#: once), then one every 2 s (assumed: ample for people, small for a script). [1/s], [sessions]
START_LIMIT = (0.5, 60)
_NO_STORE = {"Cache-Control": "no-store"}


@dataclass
class Web:
    """What the endpoints share: the registry (sessions, store, workers), the exercises, the
    session-start rate limit of each client address."""

    reg: Registry
    catalogue: core.Catalogue
    start_limit: tuple[float, int] = START_LIMIT
    starts: dict[str, RateLimit] = field(default_factory=dict)
    #: Exercise name → its setup sheet for the page (computed once, in a worker thread).
    sheets: dict[str, dict[str, Any]] = field(default_factory=dict)


def web_of(conn: HTTPConnection) -> Web:
    return conn.app.state.web


def bearer(conn: HTTPConnection) -> str | None:
    auth = conn.headers.get("authorization", "")
    return auth[7:].strip() if auth[:7].lower() == "bearer " else None


def _is_instructor(request: Request) -> bool:
    return web_of(request).reg.is_instructor(request.query_params.get("token") or bearer(request))


def instructor_only(request: Request) -> None:
    if not _is_instructor(request):
        raise Refused(403, "instructor token required")


def _session_row(request: Request) -> tuple[str, dict[str, Any]]:
    sid = request.path_params["sid"]
    rows = web_of(request).reg.rows
    if sid not in rows:
        raise Refused(404, "no such session")
    return sid, rows[sid]


def own_or_instructor(request: Request) -> tuple[str, dict[str, Any]]:
    """The session of the request, which holds its key or the instructor's token."""
    sid, row = _session_row(request)
    key = request.query_params.get("key") or bearer(request)
    if not (_is_instructor(request) or web_of(request).reg.check(sid, key)):
        raise Refused(403, "this session's key is required")
    return sid, row


def _may_read(request: Request, sid: str, row: dict[str, Any]) -> None:
    """Instructor: always; the session's own secret: once it is finished."""
    if _is_instructor(request):
        return
    key = request.query_params.get("key") or bearer(request)
    if not web_of(request).reg.check(sid, key):
        raise Refused(403, "this session's key or the instructor's token is required")
    if not row["done"]:
        raise Refused(403, "the grade and the log are given when every stage is claimed")


def _start_allowed(request: Request) -> None:
    web = web_of(request)
    if len(web.starts) > 10_000:  # forget old addresses rather than grow without bound
        web.starts.clear()
    addr = address_of(request)
    if not web.starts.setdefault(addr, RateLimit(*web.start_limit)).allow():
        web.reg.refused(addr)
        raise Refused(429, "too many sessions started from this address: wait a moment")


def _attachment(body: bytes | str, media: str, name: str) -> Response:
    return Response(
        body,
        media_type=media,
        headers={"Content-Disposition": f'attachment; filename="{name}"', **_NO_STORE},
    )


# --- the trainee's endpoints ------------------------------------------------------------------


async def exercises(request: Request) -> Response:
    return JSONResponse(web_of(request).catalogue.listing())


async def new_session(request: Request) -> Response:
    _start_allowed(request)
    body = await read_json(request)
    exercise = body.get("exercise")
    if not isinstance(exercise, str):
        raise Refused(400, "exercise: expected the name of an exercise")
    trainee = trainee_name(body.get("trainee"))
    seed = seed_value(body.get("seed"))
    demo = body.get("demonstration", False)
    if not isinstance(demo, bool):
        raise Refused(400, "demonstration: expected true or false")
    reg = web_of(request).reg
    live, secret = await asyncio.wrap_future(reg.run(
        reg.starter, address_of(request), "start", functools.partial(
            reg.start, exercise, trainee, seed=seed, demonstration=demo)))
    return JSONResponse({"id": live.id, "secret": secret}, headers=_NO_STORE)


async def sheet(request: Request) -> Response:
    """The exercise's setup sheet (the data the trainee works from), for the sheet panel."""
    _, row = own_or_instructor(request)
    web = web_of(request)
    name = row["exercise"]
    if name not in web.sheets:
        ex = web.catalogue.known(name)
        if ex is None:  # an uploaded exercise of an earlier store, not known now
            raise Refused(404, "exercise: no longer known to this server")
        web.sheets[name] = scrub_paths(await run_in_threadpool(core.sheet_of, ex))
    return JSONResponse(web.sheets[name], headers=_NO_STORE)


async def overview(request: Request) -> Response:
    """Both photos at a glance: fiducials, standard, control and check points, the marks."""
    sid, _ = own_or_instructor(request)
    reg = web_of(request).reg
    live = await run_in_threadpool(reg.resume, sid)
    body = await asyncio.wrap_future(
        reg.read(live, address_of(request), core.overview_of, live.session)
    )
    return JSONResponse(body, headers=_NO_STORE)


async def checklist(request: Request) -> Response:
    """The steps of the stage in hand (their texts; the state ticks them on every action)."""
    sid, _ = own_or_instructor(request)
    reg = web_of(request).reg
    live = await run_in_threadpool(reg.resume, sid)
    body = await asyncio.wrap_future(
        reg.read(live, address_of(request), core.checklist_of, live.session)
    )
    return JSONResponse(body, headers=_NO_STORE)


async def show_me(request: Request) -> Response:
    """The operator's actions of the stage in hand, for an animated "show me": charged as the
    hint of level 3 it is (logged before the actions are given, so it shows on the grade);
    given only where the exercise allows hints, never in a demonstration."""
    sid, row = own_or_instructor(request)
    reg = web_of(request).reg
    live = await run_in_threadpool(reg.resume, sid)
    if live.demonstration or not live.session.exercise.allows("hints") or row["mode"] == "exam":
        raise Refused(403, "show me: this exercise gives no hints")

    def charge_and_show() -> tuple[dict[str, Any], list[dict[str, Any]]]:
        stage = live.session.stage
        reply = reg.act(live, {"kind": "hint", "level": 3, "animated": True})
        return reply, ([] if reply.get("error") else core.show_me(live.session, stage))

    reply, actions = await asyncio.wrap_future(
        reg.run(reg.actor, address_of(request), sid, charge_and_show)
    )
    if reply.get("error"):
        raise Refused(409, f"show me: {reply['error']}")
    return JSONResponse(
        {"stage": live.session.stage, "actions": actions, "charged": {"hint": 3}},
        headers=_NO_STORE,
    )


async def _grade(request: Request) -> tuple[dict[str, Any], dict[str, Any]]:
    sid, row = _session_row(request)
    _may_read(request, sid, row)
    if row["mode"] == "exam" and not row["done"]:
        raise Refused(403, "an exam is graded when every stage is claimed")
    return row, await asyncio.wrap_future(web_of(request).reg.grade(sid))


async def grade_json(request: Request) -> Response:
    _, g = await _grade(request)
    return JSONResponse({"grade": g, "markdown": core.grade_text(g)}, headers=_NO_STORE)


async def grade_md(request: Request) -> Response:
    row, g = await _grade(request)
    return _attachment(core.grade_text(g), "text/markdown; charset=utf-8", f"grade-{row['id']}.md")


async def log_jsonl(request: Request) -> Response:
    sid, row = _session_row(request)
    _may_read(request, sid, row)
    body = core.log_bytes(web_of(request).reg.store.records(sid))
    return _attachment(body, "application/x-ndjson", f"session-{sid}.jsonl")


async def patch_png(request: Request) -> Response:
    _, row = own_or_instructor(request)
    side, x, y, mag, size = _patch_query(request)
    web = web_of(request)
    ex = web.catalogue.known(row["exercise"])
    if ex is None:
        raise Refused(404, "exercise: no longer known to this server")
    if not web.reg.patch_allowed(row["id"], address_of(request)):
        raise Refused(429, "too many photo patches: wait a moment")
    cache = await asyncio.wrap_future(web.reg.photos(ex))
    png = await asyncio.wrap_future(
        web.reg.run(web.reg.patcher, address_of(request), row["id"], web.reg.patch,
                    address_of(request), ex, cache, side, x, y, mag, size)
    )
    return Response(png, media_type="image/png", headers={"Cache-Control": "private, max-age=3600"})


def _patch_query(request: Request) -> tuple[str, float, float, float, int]:
    q = request.query_params
    try:
        side = q["side"]
        x, y, mag = float(q["x"]), float(q["y"]), float(q["mag"])
        size = int(q.get("size", PATCH_PX))
    except (KeyError, ValueError):
        side, x, y, mag, size = "", math.nan, math.nan, math.nan, 0
    if (
        side not in ("left", "right")
        or not all(math.isfinite(v) for v in (x, y, mag))
        or not MAG_RANGE[0] <= mag <= MAG_RANGE[1]
        or max(abs(x), abs(y)) > XY_LIMIT_MM
        or not 16 <= size <= 1024
    ):
        raise Refused(
            400,
            f"patch: expected side=left|right, x, y within ±{XY_LIMIT_MM:g} mm, "
            f"mag {MAG_RANGE[0]:g}…{MAG_RANGE[1]:g}, size 16…1024",
        )
    return side, x, y, mag, size


# --- the instructor's endpoints ---------------------------------------------------------------


async def live_sessions(request: Request) -> Response:
    instructor_only(request)
    return JSONResponse(web_of(request).reg.table(), headers=_NO_STORE)


async def results_csv(request: Request) -> Response:
    instructor_only(request)
    body = results_csv_text(web_of(request).reg.table())
    return _attachment(body, "text/csv; charset=utf-8", "results.csv")


async def archive_zip(request: Request) -> Response:
    instructor_only(request)
    data = await run_in_threadpool(archive, web_of(request).reg)
    return _attachment(data, "application/zip", "class.zip")


async def replay_states(request: Request) -> Response:
    instructor_only(request)
    sid, _ = _session_row(request)
    body = await asyncio.wrap_future(web_of(request).reg.replay_json(sid))
    return Response(body, media_type="application/json", headers=_NO_STORE)


async def grant(request: Request) -> Response:
    instructor_only(request)
    body = await read_json(request)
    trainee = trainee_name(body.get("trainee"))
    web = web_of(request)
    ex = web.catalogue.get(body.get("exercise"))
    if ex is None:
        raise Refused(404, "exercise: no such exercise")
    extra = await run_in_threadpool(web.reg.store.grant, trainee_key(trainee), ex.name)
    return JSONResponse({"trainee": trainee, "exercise": ex.name, "extra_attempts": extra})


async def upload(request: Request) -> Response:
    instructor_only(request)
    raw = await read_body(request)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise Refused(400, "uploaded exercise: expected UTF-8 text") from None
    web = web_of(request)

    def check() -> Any:
        data = exercise_upload(text)
        if not storable(data):
            raise Refused(400, "uploaded exercise: expected UTF-8 text (no lone surrogate)")
        ex = web.catalogue.check_upload(data)
        if not web.reg.store.add_exercise(ex.name, data):  # another upload took the name
            raise core.NameInUse(f"uploaded exercise: name: {ex.name} is in use")
        web.catalogue.add(ex)
        web.reg.photos(ex)
        return ex

    try:
        ex = await run_in_threadpool(check)
    except core.NameInUse as exc:
        raise Refused(409, str(exc)) from None
    web.reg.version += 1
    return JSONResponse({"name": ex.name, "title": ex.title})


async def retire(request: Request) -> Response:
    """Offer an uploaded exercise no more (``DELETE /api/instructor/exercises/NAME``): new
    sessions are refused; its sessions still resume, and its name stays used."""
    instructor_only(request)
    name = request.path_params["name"]
    web = web_of(request)
    if name in web.catalogue.shipped:
        raise Refused(403, f"exercise {name}: a shipped exercise cannot be retired")
    ex = web.catalogue.retire(name)
    if ex is None:
        raise Refused(404, f"exercise: no uploaded exercise named {name[:66]!r} is offered")
    await run_in_threadpool(web.reg.store.retire_exercise, name)
    web.reg.version += 1
    return JSONResponse({"name": name, "retired": True})


# --- exports ----------------------------------------------------------------------------------


def _spreadsheet_safe(value: Any) -> Any:
    """A CSV cell a spreadsheet shows as text (a leading = + - @ would make it a formula)."""
    if isinstance(value, str) and value[:1] in ("=", "+", "-", "@", "\t", "\r"):
        return "'" + value
    return value


def results_csv_text(rows: list[dict[str, Any]]) -> str:
    out = io.StringIO()
    writer = csv.DictWriter(out, fieldnames=CSV_FIELDS, extrasaction="ignore")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: _spreadsheet_safe(v) for k, v in row.items()})
    return out.getvalue()


def archive(reg: Registry) -> bytes:
    """The class as a zip: results.csv, and each session's log (JSON lines) and stored grade."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
        rows = reg.table()
        z.writestr("results.csv", results_csv_text(rows))
        for row in rows:
            sid = row["id"]
            z.writestr(f"logs/session-{sid}.jsonl", core.log_bytes(reg.store.records(sid)))
            if sid in reg.grades:
                z.writestr(f"grades/grade-{sid}.json", json.dumps(reg.grades[sid], indent=1))
    return buf.getvalue()
