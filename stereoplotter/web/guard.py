"""What the classroom server checks before it believes a client (issue 22).

Nothing a client sends is trusted: every HTTP request passes :class:`Guard` (the Host must be
this server's, a state-changing request must come from this server's pages, and every response
carries a Content-Security-Policy that forbids inline script); every WebSocket message passes
:func:`parse_message` and :func:`clean_action` (size, shape, fields, values); a connection's
messages pass a :class:`RateLimit`. A refusal is one line of text (:func:`one_line`), never a
traceback nor a server path.
"""

from __future__ import annotations

import ipaddress
import json
import math
import re
import socket
import time
import unicodedata
from typing import Any
from urllib.parse import urlsplit

from starlette.datastructures import Headers
from starlette.responses import JSONResponse

from stereoplotter.trainer.actions import ACTION_FIELDS

__all__ = [
    "CSP",
    "MAX_BODY",
    "MAX_MESSAGE",
    "MAX_NAME",
    "Guard",
    "RateLimit",
    "Refused",
    "clean_action",
    "error",
    "one_line",
    "origin_ok",
    "parse_message",
    "scrub_paths",
    "seed_value",
    "trainee_key",
    "trainee_name",
]

#: Content-Security-Policy of every response: scripts, styles, images and sockets from this
#: server only (no inline script, no inline style attribute, no eval), never framed.
CSP = (
    "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self' blob:; "
    "connect-src 'self'; base-uri 'none'; form-action 'none'; frame-ancestors 'none'"
)
_HEADERS = [
    (b"content-security-policy", CSP.encode()),
    (b"x-content-type-options", b"nosniff"),
    (b"referrer-policy", b"no-referrer"),  # the instructor's token is in its page address
    (b"x-frame-options", b"DENY"),
    (b"cross-origin-opener-policy", b"same-origin"),
]
#: Largest HTTP request body (an uploaded exercise file is a few kB). [bytes]
MAX_BODY = 64_000
#: Largest WebSocket message (an action is under 200 bytes). [characters]
MAX_MESSAGE = 4_096
#: Longest trainee name. [characters]
MAX_NAME = 64
#: Largest recorded value (``record`` action) as JSON, and the most names a session records.
MAX_RECORD = 256
MAX_RECORDS = 64
#: Messages a connection may send: a sustained rate and a burst (a fast wheel spin sends about
#: 30 notches a second; assumed ample for a person, small for a flood). [1/s], [messages]
RATE, BURST = 60.0, 120

_PATH = re.compile(r"(?:[A-Za-z]:)?[\w.\-~]*(?:[\\/][\w.\-~ ]+){2,}[\\/]?")


def _file_name(match: re.Match) -> str:
    """A server path as the name of its file only (``…/instruments/sc1.yaml`` → ``file
    sc1.yaml``): what it names stays readable, where it lies is not shown."""
    return "file " + re.split(r"[\\/]", match.group(0).rstrip("\\/").strip())[-1]


class Refused(Exception):
    """A client's request refused: ``status`` and one line."""

    def __init__(self, status: int, text: str):
        super().__init__(text)
        self.status = status


def one_line(text: object) -> str:
    """``text`` as one line, each server path replaced by its file's name, at most 300
    characters."""
    s = " ".join(str(text).split())
    s = _PATH.sub(_file_name, s)
    return s if len(s) <= 300 else s[:299] + "…"


def scrub_paths(value: Any) -> Any:
    """``value`` (JSON-like) with every server path in its text replaced by its file's name."""
    if isinstance(value, str):
        return _PATH.sub(_file_name, value)
    if isinstance(value, dict):
        return {k: scrub_paths(v) for k, v in value.items()}
    if isinstance(value, list):
        return [scrub_paths(v) for v in value]
    return value


def error(status: int, text: object) -> JSONResponse:
    """A refusal: ``{"error": "one line"}`` with the status."""
    return JSONResponse(
        {"error": one_line(text)}, status_code=status, headers={"Cache-Control": "no-store"}
    )


# --- hosts and origins ----------------------------------------------------------------------


def _hostname(host: str) -> str:
    """The name part of a Host header value or URL netloc (no port, IPv6 unbracketed)."""
    host = host.strip().lower()
    if host.startswith("["):
        return host[1:].split("]", 1)[0]
    return host.rsplit(":", 1)[0] if host.count(":") == 1 else host


def _is_ip(name: str) -> bool:
    try:
        ipaddress.ip_address(name)
    except ValueError:
        return False
    return True


def local_names(extra: tuple[str, ...] = ()) -> frozenset[str]:
    """Names a page may reach this server by (an IP address always may): localhost, this
    machine's host name (and ``.local``), and ``extra`` (the ``--host`` given)."""
    me = socket.gethostname().lower()
    return frozenset({"localhost", me, f"{me}.local", *(e.lower() for e in extra)})


def host_ok(host: str | None, names: frozenset[str]) -> bool:
    """Whether a Host header names this server: an IP address or one of ``names`` (a page
    served under any other name is a DNS-rebinding page: refused)."""
    if not host:
        return False
    name = _hostname(host)
    return _is_ip(name) or name in names


def origin_ok(headers: Headers) -> bool:
    """A browser's request from this server's own pages: the Origin, when sent, has the
    request's Host (scheme http or https). A client that sends no Origin is not a browser
    page (it cannot be made to act for someone else) and passes."""
    origin = headers.get("origin")
    if origin is None:
        return True
    parts = urlsplit(origin)
    return (
        parts.scheme in ("http", "https")
        and parts.netloc.lower() == (headers.get("host") or "").lower()
    )


class Guard:
    """ASGI middleware: Host check (HTTP and WebSocket), Origin check on state-changing
    requests, and the security headers on every response."""

    def __init__(self, app, names: frozenset[str]):
        self.app = app
        self.names = names

    async def __call__(self, scope, receive, send):
        if scope["type"] not in ("http", "websocket"):
            return await self.app(scope, receive, send)
        headers = Headers(scope=scope)
        if not host_ok(headers.get("host"), self.names):
            return await self._refuse(
                scope,
                receive,
                send,
                400,
                "unknown Host: use this server's address or an IP address",
            )
        if scope["type"] == "websocket":
            if not origin_ok(headers):
                return await self._refuse(scope, receive, send, 403, "wrong Origin")
            return await self.app(scope, receive, send)
        if scope["method"] not in ("GET", "HEAD") and not origin_ok(headers):
            return await self._refuse(scope, receive, send, 403, "wrong Origin")

        async def send_with_headers(message):
            if message["type"] == "http.response.start":
                message.setdefault("headers", [])
                message["headers"] = list(message["headers"]) + _HEADERS
            await send(message)

        return await self.app(scope, receive, send_with_headers)

    async def _refuse(self, scope, receive, send, status, text):
        if scope["type"] == "websocket":
            await receive()  # websocket.connect
            await send({"type": "websocket.close", "code": 4000 + status})
            return None
        response = error(status, text)
        response.raw_headers.extend(_HEADERS)
        return await response(scope, receive, send)


# --- request bodies and fields --------------------------------------------------------------


async def read_json(request, limit: int = MAX_BODY) -> dict[str, Any]:
    """The request's JSON object body, or :class:`Refused` (400, 413)."""
    body = await read_body(request, limit)
    try:
        value = json.loads(body)
    except (ValueError, RecursionError):
        raise Refused(400, "body: expected a JSON object") from None
    if not isinstance(value, dict):
        raise Refused(400, f"body: expected a JSON object, found {type(value).__name__}")
    return value


async def read_body(request, limit: int = MAX_BODY) -> bytes:
    size = request.headers.get("content-length")
    if size is not None and not size.isdigit():
        raise Refused(400, "Content-Length: expected a number of bytes")
    if size is not None and int(size) > limit:
        raise Refused(413, f"body: at most {limit} bytes")
    chunks, n = [], 0
    async for chunk in request.stream():
        n += len(chunk)
        if n > limit:
            raise Refused(413, f"body: at most {limit} bytes")
        chunks.append(chunk)
    return b"".join(chunks)


def trainee_name(value: Any) -> str:
    """A trainee's name: text of 1–64 printable characters (NFC, spaces collapsed)."""
    if value is None:
        return "trainee"
    if not isinstance(value, str):
        raise Refused(400, f"trainee: expected text, found {type(value).__name__}")
    name = " ".join(unicodedata.normalize("NFC", value).split())
    if not 1 <= len(name) <= MAX_NAME:
        raise Refused(400, f"trainee: expected 1 to {MAX_NAME} characters, found {len(name)}")
    if any(unicodedata.category(c)[0] == "C" for c in name):
        raise Refused(400, "trainee: expected printable characters")
    return name


def trainee_key(name: str) -> str:
    """The name an exam attempt is counted under (case and compatibility forms folded)."""
    return unicodedata.normalize("NFKC", name).casefold()


def seed_value(value: Any) -> int | None:
    """A practice seed: None or an integer 0 ≤ seed < 2⁶³."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value < 2**63:
        raise Refused(400, f"seed: expected an integer from 0 to 2^63 - 1, found {value!r:.40}")
    return value


# --- WebSocket messages ---------------------------------------------------------------------

_MESSAGE_KEYS = {"action", "seq", "demo", "auth"}
_OPTIONAL = ("side", "origin_mm")


def parse_message(text: Any) -> dict[str, Any]:
    """A page's message: a JSON object of at most :data:`MAX_MESSAGE` characters with the
    keys ``action``, ``seq``, ``demo`` or ``auth``; :class:`Refused` (one line) otherwise."""
    if not isinstance(text, str):
        raise Refused(400, "message: expected a JSON text frame")
    if len(text) > MAX_MESSAGE:
        raise Refused(413, f"message: at most {MAX_MESSAGE} characters, found {len(text)}")
    try:
        msg = json.loads(text)
    except (ValueError, RecursionError):
        raise Refused(400, "message: expected JSON") from None
    if not isinstance(msg, dict):
        raise Refused(400, f"message: expected a JSON object, found {type(msg).__name__}")
    extra = set(msg) - _MESSAGE_KEYS
    if extra:
        raise Refused(400, f"message: unknown field {sorted(extra)[0]!r:.40}")
    seq = msg.get("seq")
    if seq is not None and (
        isinstance(seq, bool) or not isinstance(seq, int) or not 0 <= seq < 2**53
    ):
        raise Refused(400, "message: seq: expected a non-negative integer")
    return msg


def _scalar(value: Any) -> bool:
    if isinstance(value, float):
        return math.isfinite(value)
    return (
        value is None
        or isinstance(value, (bool, int))
        or (isinstance(value, str) and len(value) <= 64)
    )


def clean_action(action: Any, records: dict[str, Any]) -> dict[str, Any]:
    """A page's action with only its kind's fields (no ``t``: the server's clock times it);
    :class:`Refused` for an unknown kind or field, a value that is not a number, short text
    or a short list of numbers, or a recorded value over :data:`MAX_RECORD` bytes."""
    if not isinstance(action, dict):
        raise Refused(400, "action: expected a JSON object with a kind")
    kind = action.get("kind")
    if not isinstance(kind, str) or kind not in ACTION_FIELDS:
        raise Refused(400, f"action kind: expected one of {', '.join(ACTION_FIELDS)}")
    allowed = {"kind", *ACTION_FIELDS[kind], *_OPTIONAL}
    extra = set(action) - allowed
    if extra:
        raise Refused(
            400,
            f"action {kind}: unknown field {sorted(extra)[0]!r:.40} (the time t is the server's)",
        )
    for key, value in action.items():
        if kind == "record" and key == "value":
            size = len(json.dumps(value, allow_nan=True))
            if size > MAX_RECORD:
                raise Refused(
                    413, f"action record: value: at most {MAX_RECORD} bytes of JSON, found {size}"
                )
            ok = _scalar(value) or (
                isinstance(value, list) and len(value) <= 8 and all(_scalar(v) for v in value)
            )
        elif isinstance(value, list):
            ok = len(value) <= 4 and all(_scalar(v) and not isinstance(v, str) for v in value)
        else:
            ok = _scalar(value)
        if not ok:
            raise Refused(
                400,
                f"action {kind}: {key}: expected a number, short text or a short list of numbers",
            )
    if kind == "record":
        name = action.get("name")
        if not isinstance(name, str) or not 1 <= len(name) <= 64:
            raise Refused(400, "action record: name: expected text of 1 to 64 characters")
        if name not in records and len(records) >= MAX_RECORDS:
            raise Refused(400, f"action record: at most {MAX_RECORDS} names per session")
    return dict(action)


class RateLimit:
    """A token bucket: :data:`RATE` messages a second, bursts of :data:`BURST`."""

    def __init__(self, rate: float = RATE, burst: int = BURST):
        self.rate, self.burst = rate, burst
        self.tokens = float(burst)
        self.last = time.monotonic()

    def allow(self) -> bool:
        now = time.monotonic()
        self.tokens = min(self.burst, self.tokens + (now - self.last) * self.rate)
        self.last = now
        if self.tokens < 1:
            return False
        self.tokens -= 1
        return True
