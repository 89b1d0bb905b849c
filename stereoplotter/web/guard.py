"""What the classroom server checks before it believes a client.

Nothing a client sends is trusted: every HTTP request passes :class:`Guard` (the Host must be
this server's, a state-changing request must come from this server's pages, and every response
carries a Content-Security-Policy that forbids inline script); every WebSocket message passes
:func:`parse_message` and :func:`clean_action` (size, shape, fields, values); a connection's
messages pass a :class:`RateLimit`. A refusal is one line of text (:func:`one_line`), never a
traceback nor a server path.
"""

from __future__ import annotations

import functools
import ipaddress
import json
import math
import os
import re
import socket
import sys
import tempfile
import time
import unicodedata
from typing import Any
from urllib.parse import urlsplit

from starlette.datastructures import Headers
from starlette.responses import JSONResponse

import stereoplotter
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
    "public_origin",
    "quote",
    "scrub_paths",
    "seed_value",
    "server_roots",
    "text_ok",
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

#: Folders of this server whose paths an error text must not show (a refusal quoting what a
#: client sent is never rewritten: only these prefixes are). Registered by the application.
_SERVER_ROOTS: set[str] = set()


def server_roots(*folders: Any) -> None:
    """Add folders (the data folder, the package, the interpreter's) whose paths are shown by
    their file names only."""
    for f in folders:
        if f:
            text = str(f).rstrip("\\/")
            if len(text) > 1:
                _SERVER_ROOTS.add(text)


def _default_roots() -> None:
    here = os.path.dirname(os.path.dirname(os.path.abspath(stereoplotter.__file__)))
    server_roots(here, sys.prefix, sys.base_prefix, os.path.expanduser("~"), os.getcwd(),
                 tempfile.gettempdir())


_default_roots()


def _path_pattern() -> re.Pattern:
    return _pattern_of(frozenset(_SERVER_ROOTS))


@functools.lru_cache(maxsize=4)
def _pattern_of(roots: frozenset[str]) -> re.Pattern:
    """The pattern of paths into ``roots`` (made once for a set of roots: a hello scrubs many
    texts, and a client may have many refused)."""
    alts = "|".join(re.escape(r) for r in sorted(roots, key=len, reverse=True))
    return re.compile(rf"(?:{alts})(?:[\\/][^\s'\"]*)?")


def _file_name(match: re.Match) -> str:
    """A server path as the name of its file only (``…/instruments/sc1.yaml`` → ``file
    sc1.yaml``): what it names stays readable, where it lies is not shown."""
    name = re.split(r"[\\/]", match.group(0).rstrip("\\/").strip())[-1]
    return f"file {name}" if name else "a server folder"


class Refused(Exception):
    """A client's request refused: ``status`` and one line."""

    def __init__(self, status: int, text: str):
        super().__init__(text)
        self.status = status


def one_line(text: object) -> str:
    """``text`` as one line, each path into a server folder replaced by its file's name (what
    a client sent is quoted as sent), at most 300 characters, valid UTF-8 (a lone surrogate
    quoted from a client shows as U+FFFD)."""
    s = " ".join(str(text).split())
    s = _path_pattern().sub(_file_name, s)
    s = s.encode("utf-8", "replace").decode("utf-8")
    return s if len(s) <= 300 else s[:299] + "…"


def quote(value: Any, limit: int = 40) -> str:
    """What a client sent, quoted for an error text: its repr, shortened to ``limit``."""
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 1] + "…"


def text_ok(value: Any) -> bool:
    """Whether ``value`` is text that can be stored: valid UTF-8 (no lone surrogate)."""
    if not isinstance(value, str):
        return False
    try:
        value.encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True


def scrub_paths(value: Any) -> Any:
    """``value`` (JSON-like) with every server path in its text replaced by its file's name."""
    if isinstance(value, str):
        return _path_pattern().sub(_file_name, value)
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
    name = host.rsplit(":", 1)[0] if host.count(":") == 1 else host
    return name[:-1] if name.endswith(".") else name  # the root's dot: localhost. is localhost


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
    return frozenset({"localhost", me, f"{me}.local", *(e.lower().rstrip(".") for e in extra)})


def host_ok(host: str | None, names: frozenset[str]) -> bool:
    """Whether a Host header names this server: an IP address or one of ``names`` (a page
    served under any other name is a DNS-rebinding page: refused)."""
    if not host:
        return False
    name = _hostname(host)
    return _is_ip(name) or name in names


def public_origin(url: str | None) -> str | None:
    """The origin (``scheme://host[:port]``, lower case) of the address trainees use when the
    server runs behind a reverse proxy (``--public-url``); ValueError for anything else."""
    if not url:
        return None
    parts = urlsplit(url.strip())
    if parts.scheme not in ("http", "https") or not parts.hostname:
        raise ValueError(f"public URL: expected http(s)://host[:port], found {quote(url)}")
    default = {"http": 80, "https": 443}[parts.scheme]
    port = f":{parts.port}" if parts.port and parts.port != default else ""
    host = f"[{parts.hostname}]" if ":" in parts.hostname else parts.hostname
    return f"{parts.scheme}://{host.rstrip('.')}{port}".lower()


def _same_host(a: str, b: str) -> bool:
    """Two Host/netloc values naming the same host and port (a trailing dot ignored)."""
    def norm(v: str) -> str:
        v = v.strip().lower()
        name, _, port = v.rpartition(":") if v.count(":") == 1 else (v, "", "")
        return f"{name.rstrip('.')}:{port}" if name else v.rstrip(".")

    return norm(a) == norm(b)


def origin_ok(headers: Headers, public: str | None = None) -> bool:
    """A browser's request from this server's own pages: the Origin, when sent, has the
    request's Host (scheme http or https), or is the public origin the server is reached by
    behind a reverse proxy (``public``; the proxy may rewrite Host, never the Origin). When the
    proxy says which scheme the page used (``X-Forwarded-Proto``), the Origin's must be it. A
    client that sends no Origin is not a browser page (it cannot be made to act for someone
    else) and passes."""
    origin = headers.get("origin")
    if origin is None:
        return True
    parts = urlsplit(origin)
    if parts.scheme not in ("http", "https"):
        return False
    if public is not None and origin.strip().lower().rstrip("/") == public:
        return True
    proto = headers.get("x-forwarded-proto")
    if proto is not None and proto.split(",")[0].strip().lower() != parts.scheme:
        return False
    return _same_host(parts.netloc, headers.get("host") or "")


class Guard:
    """ASGI middleware: Host check (HTTP and WebSocket), Origin check on state-changing
    requests, and the security headers on every response."""

    def __init__(self, app, names: frozenset[str], public: str | None = None):
        self.app = app
        self.names = names
        self.public = public

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
            if not origin_ok(headers, self.public):
                return await self._refuse(scope, receive, send, 403, "wrong Origin")
            return await self.app(scope, receive, send)
        if scope["method"] not in ("GET", "HEAD") and not origin_ok(headers, self.public):
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
    if not trainee_key(name):
        raise Refused(400, "trainee: expected visible characters")
    return name


#: Characters no one sees that are not default-ignorable in Unicode's own list (they render
#: as blank space): the Hangul fillers and the braille blank.
_BLANKS = dict.fromkeys(map(ord, "\u115f\u1160\u3164\uffa0\u2800"))


def _visible(text: str) -> str:
    """``text`` less its default-ignorable code points (Unicode's
    Default_Ignorable_Code_Point: format characters, variation selectors, U+034F, …) and the
    blank-rendering fillers."""
    return "".join(
        c for c in text.translate(_BLANKS)
        if unicodedata.category(c) != "Cf"
        and not 0xFE00 <= ord(c) <= 0xFE0F
        and not 0xE0100 <= ord(c) <= 0xE01EF
        and c != "\u034f"
    )


def trainee_key(name: str) -> str:
    """The name an exam attempt is counted under: two names a reader cannot tell apart get the
    same key. NFKC (compatibility forms: fullwidth, ligatures), case fold, default-ignorable
    and invisible characters removed, spaces collapsed, then the Unicode TR 39 confusable
    skeleton (``disarm.skeleton_key``: Cyrillic а is Latin a)."""
    from disarm import skeleton_key  # the trainer extra: imported where names are compared

    text = _visible(unicodedata.normalize("NFKC", name).casefold())
    text = " ".join(text.split())
    return skeleton_key(text)


def seed_value(value: Any) -> int | None:
    """A practice seed: None or an integer 0 ≤ seed < 2⁶³."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value < 2**63:
        raise Refused(400, f"seed: expected an integer from 0 to 2^63 - 1, found {quote(value)}")
    return value


# --- WebSocket messages ---------------------------------------------------------------------

_MESSAGE_KEYS = {"action", "seq", "demo", "auth", "patches"}
_OPTIONAL = ("side", "origin_mm")


def parse_message(text: Any) -> dict[str, Any]:
    """A page's message: a JSON object of at most :data:`MAX_MESSAGE` characters with the
    keys ``action``, ``seq``, ``demo``, ``auth`` or ``patches``; :class:`Refused` (one line)
    otherwise."""
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
        raise Refused(400, f"message: unknown field {quote(sorted(extra)[0])}")
    seq = msg.get("seq")
    if seq is not None and (
        isinstance(seq, bool) or not isinstance(seq, int) or not 0 <= seq < 2**53
    ):
        raise Refused(400, "message: seq: expected a non-negative integer")
    return msg


#: Largest number any field of an action may hold (a scale denominator M_в of a few
#: thousand, readings of a few hundred mm; the control's own range is checked when the action
#: is carried out). Beyond it, or not finite: refused before anything counts.
MAX_NUMBER = 1e7


def _scalar(value: Any) -> bool:
    if isinstance(value, bool) or value is None:
        return True
    if isinstance(value, int):  # a huge integer overflows a float: compared as an integer
        return abs(value) <= MAX_NUMBER
    if isinstance(value, float):
        return math.isfinite(value) and abs(value) <= MAX_NUMBER
    return isinstance(value, str) and len(value) <= 64 and text_ok(value)


def clean_action(action: Any, records: dict[str, Any]) -> dict[str, Any]:
    """A page's action with only its kind's fields (no ``t``: the server's clock times it);
    :class:`Refused` for an unknown kind or field, a value that is not a number, short text
    or a short list of numbers, or a recorded value over :data:`MAX_RECORD` bytes."""
    if not isinstance(action, dict):
        raise Refused(400, "action: expected a JSON object with a kind")
    kind = action.get("kind")
    if not isinstance(kind, str) or kind not in ACTION_FIELDS:
        raise Refused(
            400, f"action kind: expected one of {', '.join(ACTION_FIELDS)}, found {quote(kind)}"
        )
    allowed = {"kind", *ACTION_FIELDS[kind], *_OPTIONAL}
    extra = set(action) - allowed
    if extra:
        raise Refused(
            400,
            f"action {kind}: unknown field {quote(sorted(map(str, extra))[0])} "
            "(the time t is the server's)",
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
                f"action {kind}: {key}: expected a number within ±{MAX_NUMBER:g}, short text "
                f"(UTF-8) or a short list of numbers, found {quote(value)}",
            )
    if kind == "record":
        name = action.get("name")
        if not isinstance(name, str) or not 1 <= len(name) <= 64 or not text_ok(name):
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
