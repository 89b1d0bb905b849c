"""The trainer's Starlette application: pages, a JSON API and WebSockets (:mod:`.sockets`).

Who may see what:

- anyone who reaches the server: the pages, the exercise list, and starting a session (which
  answers the session's id and its secret, given once);
- a session's secret (``Authorization: Bearer SECRET`` or ``?key=SECRET``): its socket and photo
  patches at any time; its grade and log once every stage is claimed;
- the instructor's token (``?token=`` or ``Authorization: Bearer``): every session's table,
  grade, log and replay, the results CSV, an archive of the logs, extra exam attempts, and
  uploading an exercise. The grade of an exam that is not finished is given to nobody (it
  would read out the true outcome of stages not yet claimed).

Every refusal is ``{"error": "one line"}`` with 400, 403, 404, 405 or 413 (:mod:`.guard`).
"""

from __future__ import annotations

import asyncio
import csv
import hmac
import io
import json
import logging
import math
import zipfile
from concurrent.futures import Executor, ProcessPoolExecutor, ThreadPoolExecutor
from contextlib import asynccontextmanager
from importlib import resources
from multiprocessing import get_context
from typing import Any

from starlette.applications import Starlette
from starlette.concurrency import run_in_threadpool
from starlette.exceptions import HTTPException
from starlette.middleware import Middleware
from starlette.requests import Request
from starlette.responses import FileResponse, JSONResponse, Response
from starlette.routing import Mount, Route, WebSocketRoute
from starlette.staticfiles import StaticFiles
from starlette.websockets import WebSocket

from stereoplotter.io.session_store import SessionStore, exercise_upload
from stereoplotter.web import core
from stereoplotter.web.guard import (
    Guard,
    RateLimit,
    Refused,
    error,
    local_names,
    read_body,
    read_json,
    seed_value,
    trainee_key,
    trainee_name,
)
from stereoplotter.web.registry import Registry
from stereoplotter.web.sockets import PATCH_PX, instructor_socket, trainee_socket

__all__ = ["create_app"]

log = logging.getLogger(__name__)

STATIC = resources.files("stereoplotter.web") / "static"

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


def _page(name: str):
    async def endpoint(request: Request) -> Response:
        return FileResponse(
            str(STATIC / name), media_type="text/html", headers={"Cache-Control": "no-store"}
        )

    return endpoint


def _spreadsheet_safe(value: Any) -> Any:
    """A CSV cell a spreadsheet shows as text (a leading = + - @ would make it a formula)."""
    if isinstance(value, str) and value[:1] in ("=", "+", "-", "@", "\t", "\r"):
        return "'" + value
    return value


def _executor(processes: bool) -> Executor:
    if processes:  # spawn: the server's threads are never forked
        return ProcessPoolExecutor(max_workers=1, mp_context=get_context("spawn"))
    return ThreadPoolExecutor(max_workers=1)


def create_app(
    token: str | None = None,
    data_dir=None,
    *,
    processes: bool = False,
    prepare_photos: bool = False,
    hosts: tuple[str, ...] = (),
    start_limit: tuple[float, int] = START_LIMIT,
) -> Starlette:
    """The application.

    ``token`` guards the instructor's pages (random when None); ``data_dir`` holds the SQLite
    file (None: in memory, nothing kept); ``processes`` grades, replays and builds photos in
    worker processes (else in one worker thread each: tests); ``prepare_photos`` starts
    building every exercise's photos at start-up; ``hosts`` are names besides localhost, this
    machine's name and IP addresses that pages may use to reach the server; ``start_limit``
    the sessions a client address may start (a rate [1/s] and a burst).
    """
    store = SessionStore(data_dir)
    catalogue = core.Catalogue(store.exercises())
    reg = Registry(token, store, catalogue, _executor(processes), _executor(processes))
    if prepare_photos:
        reg.prepare_photos()

    starts: dict[str, RateLimit] = {}

    def start_allowed(request: Request) -> None:
        if len(starts) > 10_000:  # forget old addresses rather than grow without bound
            starts.clear()
        addr = request.client.host if request.client else "?"
        if not starts.setdefault(addr, RateLimit(*start_limit)).allow():
            raise Refused(429, "too many sessions started from this address: wait a moment")

    def is_instructor(request: Request) -> bool:
        given = request.query_params.get("token") or _bearer(request)
        return isinstance(given, str) and hmac.compare_digest(given.encode(), reg.token.encode())

    def session_row(request: Request) -> tuple[str, dict[str, Any]]:
        sid = request.path_params["sid"]
        if sid not in reg.rows:
            raise Refused(404, "no such session")
        return sid, reg.rows[sid]

    def may_read(request: Request, sid: str, row: dict[str, Any]) -> bool:
        """Instructor: always; the session's own secret: once it is finished."""
        if is_instructor(request):
            return True
        key = request.query_params.get("key") or _bearer(request)
        if not reg.check(sid, key):
            raise Refused(403, "this session's key or the instructor's token is required")
        if not row["done"]:
            raise Refused(403, "the grade and the log are given when every stage is claimed")
        return True

    def instructor_only(request: Request) -> None:
        if not is_instructor(request):
            raise Refused(403, "instructor token required")

    async def exercises(request: Request) -> Response:
        return JSONResponse(catalogue.listing())

    async def new_session(request: Request) -> Response:
        start_allowed(request)
        body = await read_json(request)
        exercise = body.get("exercise")
        if not isinstance(exercise, str):
            raise Refused(400, "exercise: expected the name of an exercise")
        trainee = trainee_name(body.get("trainee"))
        seed = seed_value(body.get("seed"))
        demo = body.get("demonstration", False)
        if not isinstance(demo, bool):
            raise Refused(400, "demonstration: expected true or false")
        live, secret = await run_in_threadpool(
            reg.start, exercise, trainee, seed=seed, demonstration=demo
        )
        return JSONResponse(
            {"id": live.id, "secret": secret}, headers={"Cache-Control": "no-store"}
        )

    async def _grade(request: Request) -> tuple[dict[str, Any], dict[str, Any]]:
        sid, row = session_row(request)
        may_read(request, sid, row)
        if row["mode"] == "exam" and not row["done"]:
            raise Refused(403, "an exam is graded when every stage is claimed")
        return row, await asyncio.wrap_future(reg.grade(sid))

    async def grade_json(request: Request) -> Response:
        _, g = await _grade(request)
        return JSONResponse(
            {"grade": g, "markdown": core.grade_text(g)}, headers={"Cache-Control": "no-store"}
        )

    async def grade_md(request: Request) -> Response:
        row, g = await _grade(request)
        return Response(
            core.grade_text(g),
            media_type="text/markdown; charset=utf-8",
            headers={
                "Content-Disposition": f'attachment; filename="grade-{row["id"]}.md"',
                "Cache-Control": "no-store",
            },
        )

    async def log_jsonl(request: Request) -> Response:
        sid, row = session_row(request)
        may_read(request, sid, row)
        body = core.log_bytes(reg.store.records(sid))
        return Response(
            body,
            media_type="application/x-ndjson",
            headers={
                "Content-Disposition": f'attachment; filename="session-{sid}.jsonl"',
                "Cache-Control": "no-store",
            },
        )

    async def patch_png(request: Request) -> Response:
        sid, row = session_row(request)
        if not (
            is_instructor(request)
            or reg.check(sid, request.query_params.get("key") or _bearer(request))
        ):
            raise Refused(403, "this session's key is required")
        side, x, y, mag, size = _patch_query(request)
        ex = catalogue.get(row["exercise"])
        fut = reg.photos(ex)
        cache = await asyncio.wrap_future(fut)
        lock = reg.photo_locks[core.photo_key(ex)]

        def render() -> bytes:
            with lock:
                return core.photo_patch(cache, side, x, y, mag, size)

        png = await run_in_threadpool(render)
        return Response(
            png, media_type="image/png", headers={"Cache-Control": "private, max-age=3600"}
        )

    async def live_sessions(request: Request) -> Response:
        instructor_only(request)
        return JSONResponse(reg.table(), headers={"Cache-Control": "no-store"})

    async def results_csv(request: Request) -> Response:
        instructor_only(request)
        return Response(
            _csv(reg.table()),
            media_type="text/csv; charset=utf-8",
            headers={
                "Content-Disposition": 'attachment; filename="results.csv"',
                "Cache-Control": "no-store",
            },
        )

    async def archive_zip(request: Request) -> Response:
        instructor_only(request)
        data = await run_in_threadpool(_archive, reg)
        return Response(
            data,
            media_type="application/zip",
            headers={
                "Content-Disposition": 'attachment; filename="class.zip"',
                "Cache-Control": "no-store",
            },
        )

    async def replay_states(request: Request) -> Response:
        instructor_only(request)
        sid, _ = session_row(request)
        body = await asyncio.wrap_future(reg.replay_json(sid))
        return Response(body, media_type="application/json", headers={"Cache-Control": "no-store"})

    async def grant(request: Request) -> Response:
        instructor_only(request)
        body = await read_json(request)
        trainee = trainee_name(body.get("trainee"))
        ex = catalogue.get(body.get("exercise"))
        if ex is None:
            raise Refused(404, "exercise: no such exercise")
        extra = await run_in_threadpool(reg.store.grant, trainee_key(trainee), ex.name)
        return JSONResponse({"trainee": trainee, "exercise": ex.name, "extra_attempts": extra})

    async def upload(request: Request) -> Response:
        instructor_only(request)
        raw = await read_body(request)
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError:
            raise Refused(400, "uploaded exercise: expected UTF-8 text") from None

        def check() -> Any:
            data = exercise_upload(text)
            ex = catalogue.add_upload(data)
            reg.store.add_exercise(ex.name, data)
            reg.photos(ex)
            return ex

        ex = await run_in_threadpool(check)
        reg.version += 1
        return JSONResponse({"name": ex.name, "title": ex.title})

    async def ws_trainee(websocket: WebSocket) -> None:
        await trainee_socket(websocket, reg)

    async def ws_instructor(websocket: WebSocket) -> None:
        await instructor_socket(websocket, reg)

    routes = [
        Route("/", _page("index.html")),
        Route("/s/{sid}", _page("instrument.html")),
        Route("/grade/{sid}", _page("grade.html")),
        Route("/instructor", _page("instructor.html")),
        Route("/api/exercises", exercises),
        Route("/api/sessions", new_session, methods=["POST"]),
        Route("/api/sessions/{sid}/grade", grade_json),
        Route("/api/sessions/{sid}/grade.md", grade_md),
        Route("/api/sessions/{sid}/log.jsonl", log_jsonl),
        Route("/api/sessions/{sid}/patch.png", patch_png),
        Route("/api/instructor/sessions", live_sessions),
        Route("/api/instructor/results.csv", results_csv),
        Route("/api/instructor/archive.zip", archive_zip),
        Route("/api/instructor/replay/{sid}", replay_states),
        Route("/api/instructor/grant", grant, methods=["POST"]),
        Route("/api/instructor/exercises", upload, methods=["POST"]),
        WebSocketRoute("/ws-instructor", ws_instructor),
        WebSocketRoute("/ws/{sid}", ws_trainee),
        Mount("/static", StaticFiles(directory=str(STATIC)), name="static"),
    ]

    @asynccontextmanager
    async def lifespan(app):
        yield
        for pool in (reg.grader, reg.imager):
            # a worker busy building photos would run on for seconds after the server
            workers = list((getattr(pool, "_processes", None) or {}).values())
            pool.shutdown(wait=False, cancel_futures=True)
            for proc in workers:
                proc.terminate()
        reg.actor.shutdown(wait=True)
        store.close()

    app = Starlette(
        routes=routes,
        middleware=[Middleware(Guard, names=local_names(hosts))],
        exception_handlers={
            Refused: _refused,
            HTTPException: _http_error,
            core.CoreError: _core_error,
            Exception: _server_error,
        },
        lifespan=lifespan,
    )
    app.state.registry = reg
    return app


def _bearer(request: Request) -> str | None:
    auth = request.headers.get("authorization", "")
    return auth[7:].strip() if auth[:7].lower() == "bearer " else None


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


def _csv(rows: list[dict[str, Any]]) -> str:
    out = io.StringIO()
    writer = csv.DictWriter(out, fieldnames=CSV_FIELDS, extrasaction="ignore")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: _spreadsheet_safe(v) for k, v in row.items()})
    return out.getvalue()


def _archive(reg: Registry) -> bytes:
    """The class as a zip: results.csv, and each session's log (JSON lines) and stored grade."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
        rows = reg.table()
        z.writestr("results.csv", _csv(rows))
        for row in rows:
            sid = row["id"]
            z.writestr(f"logs/session-{sid}.jsonl", core.log_bytes(reg.store.records(sid)))
            if sid in reg.grades:
                z.writestr(f"grades/grade-{sid}.json", json.dumps(reg.grades[sid], indent=1))
    return buf.getvalue()


async def _refused(request: Request, exc: Refused) -> Response:
    return error(exc.status, exc)


async def _http_error(request: Request, exc: HTTPException) -> Response:
    text = {404: "no such page", 405: "method not allowed"}.get(exc.status_code, exc.detail)
    return error(exc.status_code, text)


async def _core_error(request: Request, exc: Exception) -> Response:
    return error(400, exc)


async def _server_error(request: Request, exc: Exception) -> Response:
    log.error("request %s failed", request.url.path, exc_info=exc)
    return error(500, "the server could not answer this request")
