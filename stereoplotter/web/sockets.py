"""The trainer's WebSockets: a trainee's session (``/ws/{id}``) and the instructor's table
(``/ws-instructor``). JSON text frames.

Trainee socket, page → server: first ``{"auth": SECRET}`` (the session's secret, given once
when it was started), then ``{"action": {...}, "seq": n}`` (an action of the trainer contract
without ``t``: the server times it) or ``{"demo": "step", "seq": n}``. Server → page:
``{"state": {...}, "error": null | "one line", "n": actions so far, "seq": n}``; the first
frame also carries ``"hello"``. A malformed, oversized or too frequent message gets
``{"error": "one line"}`` and the socket stays open. A page that reconnects (a dropped
network, a restarted server) sends its secret again and resumes where the log ends.

Instructor socket: first ``{"auth": TOKEN}``; the server then pushes ``{"sessions": [...]}``
whenever a row changes (an action, a new session, a stored grade), at most every
:data:`PUSH_S` seconds. Nothing is regraded for it: rows carry the grade stored at the end.
"""

from __future__ import annotations

import asyncio
import hmac
import json
import logging
from typing import Any

from starlette.concurrency import run_in_threadpool
from starlette.websockets import WebSocket, WebSocketDisconnect

from stereoplotter.web import core
from stereoplotter.web.guard import (
    RateLimit,
    Refused,
    clean_action,
    one_line,
    parse_message,
    scrub_paths,
)
from stereoplotter.web.registry import Registry

__all__ = ["AUTH_TIMEOUT_S", "PUSH_S", "instructor_socket", "trainee_socket"]

log = logging.getLogger(__name__)

#: Time a new socket has to send its credential. [s]
AUTH_TIMEOUT_S = 10.0
#: Shortest interval between two pushes of the instructor's table. [s]
PUSH_S = 0.5
#: Patch side the page composites from [px]: three eyepiece fields (256 px) across.
PATCH_PX = 768


def _dump(body: dict[str, Any]) -> str:
    return json.dumps(body, allow_nan=False)


async def _auth(websocket: WebSocket) -> Any:
    """The credential of the socket's first message (None: none within the time)."""
    try:
        text = await asyncio.wait_for(websocket.receive_text(), AUTH_TIMEOUT_S)
        return parse_message(text).get("auth")
    except (TimeoutError, Refused, KeyError, RuntimeError, WebSocketDisconnect):
        return None


async def _refuse(websocket: WebSocket, text: str, code: int = 4403) -> None:
    try:
        await websocket.send_text(_dump({"error": text, "state": None}))
        await websocket.close(code)
    except (WebSocketDisconnect, RuntimeError):  # the page has gone already
        pass


async def trainee_socket(websocket: WebSocket, reg: Registry) -> None:
    sid = websocket.path_params["sid"]
    await websocket.accept()
    secret = await _auth(websocket)
    if sid not in reg.rows or not reg.check(sid, secret):
        return await _refuse(
            websocket, "this session's key is required (start a session from the exercises page)"
        )
    try:
        live = await run_in_threadpool(reg.resume, sid)
    except Exception as exc:  # a log that no longer replays: refused in one line, logged
        log.warning("session %s does not resume: %s", sid, exc)
        return await _refuse(websocket, "this session cannot be resumed", 4500)
    ex = live.session.exercise
    hello = {
        "exercise": live.exercise,
        "trainee": live.trainee,
        "demonstration": live.demonstration,
        "id": live.id,
        "screen_pixel_mm": core.SCREEN_PIXEL_MM,
        "patch_px": PATCH_PX,
        "format_mm": core.format_mm(ex),
        "description": ex.description,
        "coarse_mag": core.COARSE_MAG,
        "actions": core.action_catalogue(),
        "rate": list(reg.message_limit),
        "mode": ex.mode,
    }
    state = await _on_actor(reg, live.session.state)  # not while an action changes it
    hello = scrub_paths(hello)
    limit = RateLimit(*reg.message_limit)
    try:
        await websocket.send_text(
            _dump({"hello": hello, "state": state, "error": None, "n": len(live.session.log)})
        )
        while True:
            message = await websocket.receive()
            if message["type"] == "websocket.disconnect":
                return
            reply = await _answer(reg, live, message, limit)
            if reply.get("error"):  # an instrument's refusal may name a file: never shown
                reply["error"] = one_line(reply["error"])
            reply["n"] = len(live.session.log)
            await websocket.send_text(_dump(reply))
    except (WebSocketDisconnect, OSError):  # the page went away (uvicorn: ClientDisconnected)
        return


async def _answer(reg: Registry, live, message: dict[str, Any], limit: RateLimit) -> dict:
    """The reply to one message: the new state, or one line of refusal."""
    seq = None
    try:
        if not limit.allow():
            raise Refused(429, "too many messages: at most 60 a second")
        msg = parse_message(message.get("text"))
        seq = msg.get("seq")
        if msg.get("demo") == "step" and live.demonstration:
            reply = await _on_actor(reg, reg.demo_step, live)
        elif "action" in msg and not live.demonstration:
            action = clean_action(msg["action"], live.session.records)
            reply = await _on_actor(reg, reg.act, live, action)
        elif "action" in msg:
            raise Refused(400, "a demonstration takes demonstration steps, not actions")
        else:
            raise Refused(400, 'expected {"action": {...}} (or a demonstration step)')
    except Refused as exc:
        reply = {"error": one_line(exc)}
    except Exception as exc:  # a bug must not close a trainee's socket: one line, logged
        log.exception("session %s: message refused by an error", live.id)
        reply = {"error": one_line(f"the server could not carry this out ({type(exc).__name__})")}
    if seq is not None:
        reply["seq"] = seq
    return reply


async def _on_actor(reg: Registry, fn, *args):
    """Run an action on the registry's one actor thread: actions of all sessions one after the
    other (first come, first served) instead of threads that share the interpreter's lock and
    all finish late together."""
    return await asyncio.get_running_loop().run_in_executor(reg.actor, fn, *args)


async def instructor_socket(websocket: WebSocket, reg: Registry) -> None:
    await websocket.accept()
    token = await _auth(websocket)
    if not isinstance(token, str) or not hmac.compare_digest(token.encode(), reg.token.encode()):
        return await _refuse(websocket, "instructor token required")
    seen = -1
    try:
        while True:
            if reg.version != seen:
                seen = reg.version
                await websocket.send_text(_dump({"sessions": reg.table()}))
            try:  # a message from the page (none expected) or its going away
                message = await asyncio.wait_for(websocket.receive(), PUSH_S)
                if message["type"] == "websocket.disconnect":
                    return
            except TimeoutError:
                pass
    except (WebSocketDisconnect, OSError):  # the page went away
        return
