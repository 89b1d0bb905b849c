"""Run the trainer server (``stereoplotter trainer``): uvicorn on a local port."""

from __future__ import annotations

import socket

import uvicorn

from stereoplotter.web.app import create_app

__all__ = ["listen", "serve"]


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


def serve(host: str = "127.0.0.1", port: int = 0, token: str | None = None) -> None:
    """Serve until interrupted; prints the trainee and instructor addresses with the port
    actually bound (the instructor's token is random unless given)."""
    sock = listen(host, port)
    bound = sock.getsockname()[1]
    app = create_app(token)
    reg = app.state.registry
    shown = "localhost" if host in ("127.0.0.1", "0.0.0.0") else host
    shown = f"[{shown}]" if ":" in shown else shown
    print(f"trainee page:    http://{shown}:{bound}/", flush=True)
    print(f"instructor page: http://{shown}:{bound}/instructor?token={reg.token}", flush=True)
    uvicorn.Server(uvicorn.Config(app, log_level="warning")).run(sockets=[sock])
