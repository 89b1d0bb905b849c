"""Run the trainer server (``stereoplotter trainer``): uvicorn on a local port."""

from __future__ import annotations

import uvicorn

from stereoplotter.web.app import create_app

__all__ = ["serve"]


def serve(host: str = "127.0.0.1", port: int = 8000, token: str | None = None) -> None:
    """Serve until interrupted; prints the trainee and instructor addresses (the instructor's
    token is random unless given)."""
    app = create_app(token)
    reg = app.state.registry
    shown = "localhost" if host in ("127.0.0.1", "0.0.0.0") else host
    print(f"trainee page:    http://{shown}:{port}/", flush=True)
    print(f"instructor page: http://{shown}:{port}/instructor?token={reg.token}", flush=True)
    uvicorn.run(app, host=host, port=port, log_level="warning")
