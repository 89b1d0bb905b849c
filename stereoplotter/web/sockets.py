"""The trainer's WebSockets: a trainee's session (``/ws/{id}``) and the instructor's table
(``/ws-instructor``). JSON text frames.

Trainee socket, page → server: first ``{"auth": SECRET}`` (the session's secret, given once
when it was started), then ``{"action": {...}, "seq": n}`` (an action of the trainer contract
without ``t``: the server times it) or ``{"demo": "step", "seq": n}``. Server → page:
``{"state": {...}, "error": null | "one line", "n": actions so far, "seq": n}``; the first
frame also carries ``"hello"``. A page whose first message says ``"patches": true`` gets the
whole state in its first frame only and, after it, ``"patch"`` in place of ``"state"``: what
changed since the state this socket sent before (:mod:`stereoplotter.web.statepatch`). A
malformed, oversized or too frequent message gets ``{"error": "one line"}`` and the socket
stays open. A page that reconnects (a dropped
network, a restarted server) sends its secret again and resumes where the log ends.

One live socket per session: a newer one (the page reloaded, or opened twice) replaces the
older, which is closed with code 4409. Sockets are limited per client address (checked before
the socket is accepted) and per session; a socket refused for either is answered after
:data:`REFUSAL_DELAY_S`, so a client reconnecting in a loop is paced by the server; a socket
that sends on after :data:`FLOOD_REFUSALS` refusals for the rate in a row is closed (4429).
Messages are limited per session (however many sockets
it opens one after the other) and per client address (:data:`ADDRESS_LIMIT`: a class behind
one address has room), and carried out on the registry's fair pool.

Instructor socket: first ``{"auth": TOKEN}``; the server then pushes ``{"sessions": [...]}``
whenever a row changes (an action, a new session, a stored grade), at most every
:data:`PUSH_S` seconds. Nothing is regraded for it: rows carry the grade stored at the end.
"""

from __future__ import annotations

import asyncio
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
from stereoplotter.web.registry import CONNECT_LIMIT, Registry
from stereoplotter.web.statepatch import state_patch

__all__ = ["AUTH_TIMEOUT_S", "PUSH_S", "REFUSAL_DELAY_S", "instructor_socket", "trainee_socket"]

log = logging.getLogger(__name__)

#: Time a new socket has to send its credential. [s]
AUTH_TIMEOUT_S = 10.0
#: Shortest interval between two pushes of the instructor's table. [s]
PUSH_S = 0.5
#: Patch side the page composites from [px]: three eyepiece fields (256 px) across.
PATCH_PX = 768
#: Socket messages all sessions of one client address may send together: a sustained rate and
#: a burst (assumed: a class of 40 behind one address acting at once). [1/s], [messages]
ADDRESS_LIMIT = (1_200.0, 2_400)
#: Addresses whose limits are remembered (beyond: forgotten, rather than grow without bound).
MAX_ADDRESSES = 10_000
#: Messages refused for the rate in a row after which the socket is closed (4429): a page
#: paces itself by the rate its hello gives, and a page's retries of a refused action come
#: after a pause; a client that sends on regardless costs the server a reply each. [messages]
FLOOD_REFUSALS = 200
_TOO_MANY = "too many messages"
#: A socket refused for the rate at which its address or session opens sockets is answered
#: after this delay: a client that reconnects the moment it is refused (a flood) then costs
#: the server one handshake per delay for each connection it holds, not one per round trip.
#: A page's own reconnects stay within the limits and are never delayed. [s]
REFUSAL_DELAY_S = 2.0


def address_of(conn) -> str:
    """The client's address (the proxy's X-Forwarded-For where the server trusts it: uvicorn's
    proxy headers)."""
    return conn.client.host if conn.client else "?"


def address_limit(reg: Registry, address: str, table: dict[str, RateLimit]) -> RateLimit:
    if len(table) > MAX_ADDRESSES:
        table.clear()
    return table.setdefault(address, RateLimit(*reg.address_limit))


def _dump(body: dict[str, Any]) -> str:
    return json.dumps(body, allow_nan=False)


async def _first(websocket: WebSocket) -> dict[str, Any]:
    """The socket's first message (empty: none, or none valid, within the time)."""
    try:
        text = await asyncio.wait_for(websocket.receive_text(), AUTH_TIMEOUT_S)
        return parse_message(text)
    except (TimeoutError, Refused, KeyError, RuntimeError, WebSocketDisconnect):
        return {}


async def _auth(websocket: WebSocket) -> Any:
    """The credential of the socket's first message (None: none within the time)."""
    return (await _first(websocket)).get("auth")


async def _refuse(websocket: WebSocket, text: str, code: int = 4403) -> None:
    try:
        await websocket.send_text(_dump({"error": text, "state": None}))
        await websocket.close(code)
    except (WebSocketDisconnect, RuntimeError):  # the page has gone already
        pass


async def _held(reg: Registry, address: str) -> None:
    """Wait :data:`REFUSAL_DELAY_S` before a refusal is sent, while the registry's holds allow
    (``registry.HELD_REFUSALS``):
    a client that reconnects the moment it is refused is then paced by the server."""
    if not reg.refusal_holds.take(address):
        return
    try:
        await asyncio.sleep(REFUSAL_DELAY_S)
    finally:
        reg.refusal_holds.give(address)


def _hello(reg: Registry, live) -> dict[str, Any]:
    """What the page is told once when its socket opens: the exercise, the screen and the
    controls (the state follows in the same message)."""
    ex = live.session.exercise
    return {
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


async def trainee_socket(websocket: WebSocket, reg: Registry) -> None:
    sid = websocket.path_params["sid"]
    if not reg.connect_allowed(address_of(websocket)):  # refused before any work (HTTP 403)
        await _held(reg, address_of(websocket))
        try:
            await websocket.close(4429)
        except (RuntimeError, OSError, WebSocketDisconnect):  # the client left meanwhile
            pass
        return
    await websocket.accept()
    first = await _first(websocket)
    secret = first.get("auth")
    if sid not in reg.rows or not reg.check(sid, secret):
        return await _refuse(
            websocket, "this session's key is required (start a session from the exercises page)"
        )
    try:
        live = await run_in_threadpool(reg.resume, sid)
    except Exception as exc:  # a log that no longer replays: refused in one line, logged
        log.warning("session %s does not resume: %s", sid, exc)
        return await _refuse(websocket, "this session cannot be resumed", 4500)
    if live.connects is None:
        live.connects = RateLimit(*CONNECT_LIMIT)
    if not live.connects.allow():
        reg.refused(address_of(websocket))
        await _held(reg, address_of(websocket))
        return await _refuse(websocket, "too many connections of this session: wait a moment",
                             4429)
    hello = _hello(reg, live)
    address = address_of(websocket)
    live.address = address
    # not while an action changes it
    state = await asyncio.wrap_future(reg.read(live, address, live.session.state))
    hello = scrub_paths(hello)
    older, live.socket = live.socket, websocket
    if older is not None:  # one live socket per session: the newer one replaces it
        try:
            await older.close(4409)
        except (RuntimeError, OSError, WebSocketDisconnect):
            pass
    if live.limit is None:
        live.limit = RateLimit(*reg.message_limit)
    limits = (live.limit, address_limit(reg, address, reg.address_limits))
    flooding = 0  # messages refused for the rate in a row
    # the state this socket sent last, when its page takes patches
    sent = _Sent(state) if first.get("patches") is True else None
    try:
        await websocket.send_text(
            _dump({"hello": hello, "state": state, "error": None, "n": len(live.session.log)})
        )
        while True:
            message = await websocket.receive()
            if message["type"] == "websocket.disconnect" or live.socket is not websocket:
                return
            reply = await _answer(reg, live, message, limits, sent)
            flooding = flooding + 1 if (reply.get("error") or "").startswith(_TOO_MANY) else 0
            if flooding > FLOOD_REFUSALS:  # sent on regardless of the refusals: closed
                await _refuse(websocket, "too many messages: this socket is closed", 4429)
                return
            if reply.get("error"):  # an instrument's refusal may name a file: never shown
                reply["error"] = one_line(reply["error"])
            reply["n"] = len(live.session.log)
            await websocket.send_text(_dump(reply))
            if live.broken:  # not stored: the page reconnects and resumes from the store
                await websocket.close(4503)
                return
    except (WebSocketDisconnect, OSError, RuntimeError):  # the page went away, or replaced
        return
    finally:
        if live.socket is websocket:
            live.socket = None


class _Sent:
    """The state a socket sent last (its page holds it): the base of the next patch."""

    __slots__ = ("state",)

    def __init__(self, state: dict[str, Any]):
        self.state = state


def _patched(sent: _Sent | None, fn, *args) -> dict[str, Any]:
    """``fn(*args)``'s reply, its state replaced by a patch against the state sent before
    (on the actor thread: the event loop only sends it). The messages of one socket are
    answered one after the other, so ``sent`` is never read and written at once."""
    reply = fn(*args)
    if sent is None:
        return reply
    state = reply.pop("state", None)
    if state is not None:
        reply["patch"] = state_patch(sent.state, state)
        sent.state = state
    return reply


async def _answer(reg: Registry, live, message: dict[str, Any], limits,
                  sent: _Sent | None = None) -> dict:
    """The reply to one message: the new state (or what changed in it, ``sent``), or one line
    of refusal."""
    seq = None
    try:
        session_limit, address_limit_ = limits
        if not session_limit.allow():
            reg.refused(live.address)
            raise Refused(
                429, f"{_TOO_MANY}: at most {session_limit.rate:g} a second a session"
            )
        if not address_limit_.allow():
            reg.refused(live.address)
            raise Refused(429, f"{_TOO_MANY} from this address: wait a moment")
        msg = parse_message(message.get("text"))
        seq = msg.get("seq")
        if msg.get("demo") == "step" and live.demonstration:
            reply = await _on_actor(reg, live, _patched, sent, reg.demo_step, live)
        elif "action" in msg and not live.demonstration:
            action = clean_action(msg["action"], live.session.records)
            reply = await _on_actor(reg, live, _patched, sent, reg.act, live, action)
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


async def _on_actor(reg: Registry, live, fn, *args):
    """Run an action on the registry's fair pool of actor threads, queued under the session's
    client address and the session (a flood from one client waits behind itself)."""
    return await asyncio.wrap_future(reg.run(reg.actor, live.address, live.id, fn, *args))


async def instructor_socket(websocket: WebSocket, reg: Registry) -> None:
    await websocket.accept()
    token = await _auth(websocket)
    if not reg.is_instructor(token):
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
