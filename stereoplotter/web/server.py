"""Run the trainer server (``stereoplotter trainer``): uvicorn on a local port."""

from __future__ import annotations

import gc
import signal
import socket
import sqlite3
import sys
from pathlib import Path

import uvicorn

from stereoplotter.errors import raise_keyboard_interrupt
from stereoplotter.io.session_store import SessionStore, default_data_dir
from stereoplotter.web.app import create_app
from stereoplotter.web.guard import public_origin

__all__ = ["listen", "serve", "uvicorn_config"]


def listen(host: str = "127.0.0.1", port: int = 0) -> socket.socket:
    """A listening socket on ``host:port`` (port 0: a free one chosen by the system).

    Raises OSError (address in use, unknown host) before anything is printed.
    """
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    sock = socket.socket(family, socket.SOCK_STREAM)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.bind((host, port))
        sock.listen(128)
    except OSError:
        sock.close()
        raise
    return sock


#: Largest WebSocket frame read at all (a larger one closes the socket with 1009); frames over
#: the protocol's own limit (guard.MAX_MESSAGE) are read and answered with an error. [bytes]
WS_MAX_SIZE = 4 * 1024 * 1024
#: How long a thread computing holds the interpreter's lock while another waits for it (Python's
#: default: 5 ms). A trainee's action takes the lock three times after waiting for something
#: (the event loop on the message, an actor thread on the job, the event loop on the answer),
#: and each may wait this long behind a thread computing (another client's action): up to
#: ~15 ms a round trip with the default. Measured on a loaded machine only
#: (``bench_trainer_load.py --abuser``, single runs): see ``benchmarks/README.md``. [s]
SWITCH_INTERVAL_S = 0.001
#: The cyclic garbage collector's thresholds (Python's: 700, 10, 10). A full pass walks every
#: session's log and undo copies and stops every thread meanwhile; with Python's third
#: threshold the server under the abuse benchmark made three full passes in its 20 s abuse
#: phase, each 100–520 ms of wall time on a loaded machine (the slowest round trips there);
#: with 100, none in the same span. Younger generations' passes are kept as they are (they
#: walk only new objects). Measured on a loaded machine only (``bench_trainer_load.py
#: --abuser``, the collector's passes timed by ``gc.callbacks``): see ``benchmarks/README.md``.
GC_THRESHOLDS = (700, 10, 100)


def serve(host: str = "127.0.0.1", port: int = 0, token: str | None = None,
          data_dir: str | None = None, *, public_url: str | None = None,
          rotate_token: bool = False, trusted_proxies: str = "127.0.0.1") -> None:
    """Serve until interrupted; prints the trainee and instructor addresses with the port
    actually bound and the data folder. Sessions, logs, grades, the exam-seed key and the
    instructor token's hash are kept in ``data_dir`` (default: the per-user folder).

    The instructor token: ``token`` when given; else the one kept (hashed) in the data folder,
    printed only when it is made (the first start, or ``rotate_token``: a new one replaces
    it). ``public_url``: the address trainees use behind a reverse proxy (its Host, Origin and
    X-Forwarded-Proto accepted; the client's address taken from X-Forwarded-For when the
    proxy is one of ``trusted_proxies``)."""
    folder = Path(data_dir) if data_dir else default_data_dir()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        SessionStore(folder).close()
    except (OSError, sqlite3.Error) as exc:
        print(f"error: trainer: data folder {folder}: {exc}", file=sys.stderr)
        raise SystemExit(1) from None
    if token is not None and len(token) < 16:
        print("warning: trainer: --token is shorter than 16 characters: easy to guess",
              file=sys.stderr)
    try:
        public_origin(public_url)
    except ValueError as exc:
        print(f"error: trainer: --public-url: {exc}", file=sys.stderr)
        raise SystemExit(1) from None
    sock = listen(host, port)
    bound = sock.getsockname()[1]
    names = (host,) if host not in ("0.0.0.0", "::", "") else ()
    app = create_app(token, folder, processes=True, prepare_photos=True, hosts=names,
                     public_url=public_url)
    reg = app.state.registry
    if rotate_token and token is None:
        reg.rotate_token()
    shown = "localhost" if host in ("127.0.0.1", "0.0.0.0") else host
    shown = f"[{shown}]" if ":" in shown else shown
    base = public_url.rstrip("/") if public_url else f"http://{shown}:{bound}"
    print(f"trainee page:    {base}/", flush=True)
    if token is not None or reg.new_token is not None:
        print(f"instructor page: {base}/instructor?token={token or reg.new_token}", flush=True)
    else:
        print(f"instructor page: {base}/instructor?token=… (the token printed when it was made; "
              "a new one: --rotate-token)", flush=True)
    print(f"data folder:     {folder}", flush=True)
    # what start-up built (modules, the exercise catalogue, the app) lives as long as the
    # server: the cyclic garbage collector's full passes no longer walk it
    gc.freeze()
    gc.set_threshold(*GC_THRESHOLDS)
    sys.setswitchinterval(SWITCH_INTERVAL_S)
    # SIGTERM (a service manager's stop) ends the server as Ctrl-C does: uvicorn shuts down
    # gracefully, then raises the signal again, and this handler turns it into the interrupt
    # the command answers in one line, so the worker pools are shut down at exit (with the
    # default handler the process died there and left the pools' semaphores behind)
    signal.signal(signal.SIGTERM, raise_keyboard_interrupt)
    uvicorn.Server(uvicorn_config(app, public_url, trusted_proxies)).run(sockets=[sock])


def uvicorn_config(app, public_url: str | None = None,
                   trusted_proxies: str = "127.0.0.1") -> uvicorn.Config:
    """The server's uvicorn settings: behind a reverse proxy (``public_url``) the client's
    address and scheme are the X-Forwarded-For and X-Forwarded-Proto of a proxy connecting
    from ``trusted_proxies`` (the per-address limits then count trainees, not the proxy)."""
    return uvicorn.Config(
        app,
        log_level="warning",
        ws_max_size=WS_MAX_SIZE,
        # no per-message compression: negotiating it for each handshake and deflating each
        # frame is the event loop's work, for states of a few kB on a classroom's network
        ws_per_message_deflate=False,
        proxy_headers=public_url is not None,
        forwarded_allow_ips=trusted_proxies,
    )
