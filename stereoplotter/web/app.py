"""The trainer's Starlette application: pages, a JSON API and one WebSocket per session.

WebSocket protocol (``/ws/{id}``), JSON text frames:

- page → server: ``{"action": {...}}`` (an action of the trainer contract, e.g.
  ``{"kind": "turn", "control": "X", "delta": 0.1}``) or ``{"demo": "step"}``.
- server → page: ``{"state": {...}, "error": null | "one line", "n": actions so far}``; the first
  frame also carries ``"hello"`` (exercise, trainee, mode, demonstration).

A move sends only the new state (counters, controls, marks): the page draws the eyepieces.
"""

from __future__ import annotations

import csv
import io
import json
from importlib import resources
from typing import Any

from starlette.applications import Starlette
from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import FileResponse, JSONResponse, PlainTextResponse, Response
from starlette.routing import Mount, Route, WebSocketRoute
from starlette.staticfiles import StaticFiles
from starlette.websockets import WebSocket, WebSocketDisconnect

from stereoplotter.web import core
from stereoplotter.web.registry import Registry

__all__ = ["create_app"]

STATIC = resources.files("stereoplotter.web") / "static"

#: Side of the photo patch the page composites from [px]: three eyepiece fields (256 px) across,
#: so the mark can travel a field before the page asks for the next patch.
PATCH_PX = 768

#: The results table the instructor downloads (one row per session).
CSV_FIELDS = ("id", "trainee", "exercise", "mode", "stage", "done", "actions", "score", "passed",
              "percentile")


def _page(name: str):
    async def endpoint(request: Request) -> Response:
        return FileResponse(str(STATIC / name), media_type="text/html")

    return endpoint


def _message(live, body: dict[str, Any]) -> str:
    body["n"] = len(live.session.log)
    return json.dumps(body, allow_nan=False)


def _result_row(live) -> dict[str, Any]:
    row = live.summary()
    if row["done"]:
        g = core.grade_of(live.session)
        row.update(score=round(g["overall"]["score"], 4), passed=g["overall"]["passed"],
                   percentile=round(g["overall"]["percentile"], 1))
    return row


def create_app(token: str | None = None) -> Starlette:
    """The application; ``token`` guards the instructor's pages (random when None)."""
    reg = Registry(token)

    def live_or_404(request: Request):
        live = reg.get(request.path_params["sid"])
        if live is None:
            return None, JSONResponse({"error": "no such session"}, status_code=404)
        return live, None

    def instructor(request: Request) -> bool:
        return request.query_params.get("token") == reg.token

    async def exercises(request: Request) -> Response:
        return JSONResponse(core.exercise_list())

    async def new_session(request: Request) -> Response:
        body = await request.json()
        try:
            live = reg.start(
                str(body["exercise"]),
                str(body.get("trainee") or "trainee"),
                seed=body.get("seed"),
                demonstration=bool(body.get("demonstration")),
            )
        except (KeyError, core.CoreError) as exc:
            return JSONResponse({"error": str(exc)}, status_code=400)
        return JSONResponse({"id": live.id})

    async def grade_json(request: Request) -> Response:
        live, err = live_or_404(request)
        if err:
            return err
        g = core.grade_of(live.session)
        return JSONResponse({"grade": g, "markdown": core.grade_text(g)})

    async def grade_md(request: Request) -> Response:
        live, err = live_or_404(request)
        if err:
            return err
        text = core.grade_text(core.grade_of(live.session))
        name = f"grade-{live.trainee}-{live.exercise}.md"
        return PlainTextResponse(
            text, media_type="text/markdown",
            headers={"Content-Disposition": f'attachment; filename="{name}"'},
        )

    async def log_jsonl(request: Request) -> Response:
        live, err = live_or_404(request)
        if err:
            return err
        return Response(
            core.log_text(live.session), media_type="application/x-ndjson",
            headers={"Content-Disposition": f'attachment; filename="session-{live.id}.jsonl"'},
        )

    async def patch_png(request: Request) -> Response:
        live, err = live_or_404(request)
        if err:
            return err
        q = request.query_params
        try:
            side = q["side"]
            x, y, mag = float(q["x"]), float(q["y"]), float(q["mag"])
            size = int(q.get("size", PATCH_PX))
            if side not in ("left", "right") or not 0 < size <= 1024:
                raise ValueError(side)
        except (KeyError, ValueError):
            return JSONResponse(
                {"error": "patch: expected side=left|right, x, y [mm], mag, size ≤ 1024"},
                status_code=400,
            )
        png = await run_in_threadpool(core.photo_patch, live.session, side, x, y, mag, size)
        return Response(png, media_type="image/png", headers={"Cache-Control": "max-age=3600"})

    async def live_sessions(request: Request) -> Response:
        if not instructor(request):
            return JSONResponse({"error": "instructor token required"}, status_code=403)
        return JSONResponse([_result_row(v) for v in reg.sessions.values()])

    async def results_csv(request: Request) -> Response:
        if not instructor(request):
            return PlainTextResponse("instructor token required", status_code=403)
        out = io.StringIO()
        writer = csv.DictWriter(out, fieldnames=CSV_FIELDS, extrasaction="ignore")
        writer.writeheader()
        for live in reg.sessions.values():
            writer.writerow(_result_row(live))
        return Response(
            out.getvalue(), media_type="text/csv",
            headers={"Content-Disposition": 'attachment; filename="results.csv"'},
        )

    async def replay_states(request: Request) -> Response:
        if not instructor(request):
            return JSONResponse({"error": "instructor token required"}, status_code=403)
        live, err = live_or_404(request)
        if err:
            return err
        return JSONResponse({
            "trainee": live.trainee, "exercise": live.exercise,
            "frames": core.replay_frames(core.log_of(live.session)),
        })

    async def ws(websocket: WebSocket) -> None:
        live = reg.get(websocket.path_params["sid"])
        await websocket.accept()
        if live is None:
            await websocket.send_text(json.dumps({"error": "no such session", "state": None}))
            await websocket.close()
            return
        hello = {"exercise": live.exercise, "trainee": live.trainee,
                 "demonstration": live.demonstration, "id": live.id,
                 "screen_pixel_mm": core.SCREEN_PIXEL_MM, "patch_px": PATCH_PX}
        await websocket.send_text(
            _message(live, {"hello": hello, "state": live.session.state(), "error": None}))
        try:
            while True:
                msg = json.loads(await websocket.receive_text())
                if msg.get("demo") == "step" and live.demonstration:
                    reply = live.demo_step()
                elif isinstance(msg.get("action"), dict) and not live.demonstration:
                    reply = live.act(msg["action"])
                else:
                    reply = {"state": live.session.state(),
                             "error": "expected {\"action\": {...}} (or a demonstration step)"}
                if "seq" in msg:
                    reply["seq"] = msg["seq"]
                await websocket.send_text(_message(live, reply))
        except WebSocketDisconnect:
            return

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
        Route("/api/instructor/replay/{sid}", replay_states),
        WebSocketRoute("/ws/{sid}", ws),
        Mount("/static", StaticFiles(directory=str(STATIC)), name="static"),
    ]
    app = Starlette(routes=routes)
    app.state.registry = reg
    return app
