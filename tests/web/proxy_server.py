"""A trainer server for ``test_operations.py``: uvicorn with the server's own settings for a
public URL (``stereoplotter.web.server.uvicorn_config``), in memory, one session start per
client address; prints its port, serves until interrupted.

``python -m tests.web.proxy_server DATA_DIR PUBLIC_URL``
"""

from __future__ import annotations

import sys

import uvicorn

from stereoplotter.web.app import create_app
from stereoplotter.web.server import listen, uvicorn_config
from tests.web.conftest import TOKEN


def main() -> None:
    data, public = sys.argv[1], sys.argv[2]
    app = create_app(TOKEN, data, public_url=public, start_limit=(0.001, 1))
    sock = listen("127.0.0.1", 0)
    print(sock.getsockname()[1], flush=True)
    uvicorn.Server(uvicorn_config(app, public)).run(sockets=[sock])


if __name__ == "__main__":
    main()
