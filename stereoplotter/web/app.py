"""The trainer's Starlette application: pages, a JSON API and WebSockets (:mod:`.sockets`).

Who may see what:

- anyone who reaches the server: the pages, the exercise list, and starting a session (which
  answers the session's id and its secret, given once);
- a session's secret (``Authorization: Bearer SECRET`` or ``?key=SECRET``): its socket, photo
  patches, setup sheet, photo overview and stage checklist at any time, the operator's actions
  of the stage for an animated "show me" where the exercise gives hints; its grade and log once
  every stage is claimed;
- the instructor's token (``?token=`` or ``Authorization: Bearer``): every session's table,
  grade, log and replay, the results CSV, an archive of the logs, extra exam attempts,
  uploading an exercise and retiring an upload. The grade of an exam that is not finished is
  given to nobody (it would read out the true outcome of stages not yet claimed).

Every refusal is ``{"error": "one line"}`` with 400, 403, 404, 405 or 413 (:mod:`.guard`).
"""

from __future__ import annotations

import logging
import os
from concurrent.futures import Executor, ProcessPoolExecutor, ThreadPoolExecutor
from contextlib import asynccontextmanager
from importlib import resources
from multiprocessing import get_context
from urllib.parse import urlsplit

from starlette.applications import Starlette
from starlette.exceptions import HTTPException
from starlette.middleware import Middleware
from starlette.requests import Request
from starlette.responses import FileResponse, Response
from starlette.routing import Mount, Route, WebSocketRoute
from starlette.staticfiles import StaticFiles
from starlette.websockets import WebSocket

from stereoplotter.io.session_store import SessionStore
from stereoplotter.web import core, page_routes, routes
from stereoplotter.web.guard import (
    BURST,
    RATE,
    Guard,
    Refused,
    error,
    local_names,
    public_origin,
    server_roots,
)
from stereoplotter.web.registry import PATCHERS, Registry
from stereoplotter.web.render import Renderers
from stereoplotter.web.routes import START_LIMIT, Web
from stereoplotter.web.sockets import ADDRESS_LIMIT, instructor_socket, trainee_socket
from stereoplotter.web.workers import watch_parent

__all__ = ["create_app", "worker_pool"]

log = logging.getLogger(__name__)

STATIC = resources.files("stereoplotter.web") / "static"


def _page(name: str):
    async def endpoint(request: Request) -> Response:
        return FileResponse(
            str(STATIC / name), media_type="text/html", headers={"Cache-Control": "no-store"}
        )

    return endpoint


def worker_pool(processes: bool) -> Executor:
    """The server's pool of one worker for slow work off the event loop: a process of its own
    (spawned, watching this process: it ends when the server dies) or, for tests, a thread."""
    if processes:  # spawn: the server's threads are never forked
        return ProcessPoolExecutor(
            max_workers=1,
            mp_context=get_context("spawn"),
            initializer=watch_parent,
            initargs=(os.getpid(),),
        )
    return ThreadPoolExecutor(max_workers=1)


async def _ws_trainee(websocket: WebSocket) -> None:
    await trainee_socket(websocket, websocket.app.state.web.reg)


async def _ws_instructor(websocket: WebSocket) -> None:
    await instructor_socket(websocket, websocket.app.state.web.reg)


#: Every route of the server (``tests/web/test_routes.py`` walks them all with bad input).
ROUTES = [
    Route("/", _page("index.html")),
    Route("/s/{sid}", _page("instrument.html")),
    Route("/grade/{sid}", _page("grade.html")),
    Route("/instructor", _page("instructor.html")),
    Route("/api/exercises", routes.exercises),
    Route("/api/sessions", routes.new_session, methods=["POST"]),
    Route("/api/sessions/{sid}/sheet", routes.sheet),
    Route("/api/sessions/{sid}/overview", routes.overview),
    Route("/api/sessions/{sid}/checklist", routes.checklist),
    Route("/api/sessions/{sid}/showme", routes.show_me),
    Route("/api/sessions/{sid}/grade", routes.grade_json),
    Route("/api/sessions/{sid}/grade.md", routes.grade_md),
    Route("/api/sessions/{sid}/log.jsonl", routes.log_jsonl),
    Route("/api/sessions/{sid}/patch.png", routes.patch_png),
    Route("/api/instructor/sessions", routes.live_sessions),
    Route("/api/instructor/results.csv", routes.results_csv),
    Route("/api/instructor/archive.zip", routes.archive_zip),
    Route("/api/instructor/replay/{sid}", routes.replay_states),
    Route("/api/instructor/grant", routes.grant, methods=["POST"]),
    Route("/api/instructor/exercises", routes.upload, methods=["POST"]),
    Route("/api/instructor/exercises/{name}", routes.retire, methods=["DELETE"]),
    *page_routes.ROUTES,
    WebSocketRoute("/ws-instructor", _ws_instructor),
    WebSocketRoute("/ws/{sid}", _ws_trainee),
    Mount("/static", StaticFiles(directory=str(STATIC)), name="static"),
]


def create_app(
    token: str | None = None,
    data_dir=None,
    *,
    processes: bool = False,
    prepare_photos: bool = False,
    hosts: tuple[str, ...] = (),
    start_limit: tuple[float, int] = START_LIMIT,
    message_limit: tuple[float, int] = (RATE, BURST),
    address_limit: tuple[float, int] = ADDRESS_LIMIT,
    public_url: str | None = None,
) -> Starlette:
    """The application.

    ``token`` guards the instructor's pages (random when None); ``data_dir`` holds the SQLite
    file (None: in memory, nothing kept); ``processes`` grades, replays, builds photos and
    renders photo patches in worker processes (else in threads: tests); ``prepare_photos`` starts
    building every exercise's photos at start-up; ``hosts`` are names besides localhost, this
    machine's name and IP addresses that pages may use to reach the server; ``start_limit``
    the sessions a client address may start (a rate [1/s] and a burst); ``message_limit`` the
    socket messages one session may send (a rate [1/s] and a burst; the page paces itself by
    it), ``address_limit`` those of all sessions of one client address; ``public_url`` the
    address trainees use behind a reverse proxy (``https://class.example``): its Host and
    Origin are this server's. ``token`` None keeps the data folder's instructor token (its
    hash), or makes one (``registry.new_token``, to print).
    """
    public = public_origin(public_url)
    if public is not None:
        hosts = (*hosts, urlsplit(public).hostname or "")
    store = SessionStore(data_dir)
    server_roots(data_dir)
    catalogue = core.Catalogue(store.exercises(), store.exercises(retired=True))
    reg = Registry(
        token,
        store,
        catalogue,
        worker_pool(processes),
        worker_pool(processes),
        message_limit,
        address_limit,
        Renderers(PATCHERS, processes),
    )
    if prepare_photos:
        reg.prepare_photos()

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
        reg.starter.shutdown(wait=True)
        reg.patcher.shutdown(wait=True)
        reg.renderers.shutdown()
        store.close()

    app = Starlette(
        routes=ROUTES,
        middleware=[Middleware(Guard, names=local_names(hosts), public=public)],
        exception_handlers={
            Refused: _refused,
            HTTPException: _http_error,
            core.CoreError: _core_error,
            Exception: _server_error,
        },
        lifespan=lifespan,
    )
    app.state.registry = reg
    app.state.web = Web(reg, catalogue, start_limit)
    return app


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
