"""Sockets under abuse: a socket refused for its address's or its session's connection rate is
answered only after a delay (a client reconnecting in a loop is paced by the server), and the
refusals held back are bounded per client address and in all."""

from __future__ import annotations

import json
import time

import pytest
from starlette.websockets import WebSocketDisconnect

from stereoplotter.web import registry, sockets
from stereoplotter.web.app import create_app
from stereoplotter.web.fair import Holds
from tests.web.conftest import PRACTICE, TOKEN, make_test_client, open_socket, start


def test_a_refused_socket_waits_for_its_refusal(tmp_path, monkeypatch):
    monkeypatch.setattr(registry, "ADDRESS_CONNECT_LIMIT", (0.01, 2))
    monkeypatch.setattr(sockets, "REFUSAL_DELAY_S", 0.4)
    with make_test_client(create_app(TOKEN, tmp_path, hosts=("testserver",))) as c:
        sid, secret = start(c, PRACTICE, trainee="looping")
        for _ in range(2):
            ws, _, hello = open_socket(c, sid, secret)
            ws.__exit__(None, None, None)
            assert "hello" in hello
        t0 = time.monotonic()
        with pytest.raises(WebSocketDisconnect) as refused:
            with c.websocket_connect(f"/ws/{sid}") as conn:
                conn.receive_text()
        assert refused.value.code == 4429
        assert time.monotonic() - t0 >= 0.4  # held back for the delay, then refused
        assert c.app.state.registry.refusal_holds.count == 0  # and let go


def test_a_session_reconnecting_in_a_loop_waits_for_its_refusal(tmp_path, monkeypatch):
    monkeypatch.setattr(sockets, "CONNECT_LIMIT", (0.01, 2))
    monkeypatch.setattr(sockets, "REFUSAL_DELAY_S", 0.4)
    with make_test_client(create_app(TOKEN, tmp_path, hosts=("testserver",))) as c:
        sid, secret = start(c, PRACTICE, trainee="reloading")
        for _ in range(2):
            ws, _, hello = open_socket(c, sid, secret)
            ws.__exit__(None, None, None)
            assert "hello" in hello
        t0 = time.monotonic()
        with c.websocket_connect(f"/ws/{sid}") as conn:
            conn.send_text(json.dumps({"auth": secret}))
            answer = json.loads(conn.receive_text())
        assert "too many connections" in answer["error"]
        assert time.monotonic() - t0 >= 0.4


def test_refusals_held_back_are_bounded():
    holds = Holds(per_address=2, total=3)
    assert [holds.take("10.0.0.66") for _ in range(3)] == [True, True, False]  # its own bound
    assert holds.take("10.0.0.7") is True
    assert holds.take("10.0.0.8") is False  # the bound of all: answered at once
    holds.give("10.0.0.66")
    assert holds.take("10.0.0.8") is True
    for address in ("10.0.0.66", "10.0.0.7", "10.0.0.8"):
        holds.give(address)
    assert holds.count == 0 and holds.held == {}


def test_a_socket_sending_on_regardless_of_its_refusals_is_closed(tmp_path, monkeypatch):
    monkeypatch.setattr(sockets, "FLOOD_REFUSALS", 5)
    app = create_app(TOKEN, tmp_path, hosts=("testserver",), message_limit=(0.01, 3))
    read = json.dumps({"action": {"kind": "read", "counter": "X"}})
    with make_test_client(app) as c:
        sid, secret = start(c, PRACTICE, trainee="flooding")
        ws, conn, _ = open_socket(c, sid, secret)
        try:
            answers = []
            for _ in range(3 + 6):
                conn.send_text(read)
                answers.append(json.loads(conn.receive_text())["error"])
            with pytest.raises(WebSocketDisconnect) as closed:
                conn.receive_text()
        finally:
            ws.__exit__(None, None, None)
    assert answers[:3] == [None] * 3
    assert all(a.startswith("too many messages: at most") for a in answers[3:8]), answers
    assert answers[8] == "too many messages: this socket is closed"
    assert closed.value.code == 4429
