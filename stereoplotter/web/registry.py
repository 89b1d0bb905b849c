"""The server's live sessions: one :class:`Live` per trainee, keyed by a random id."""

from __future__ import annotations

import secrets
import threading
import time
from dataclasses import dataclass, field
from typing import Any

from stereoplotter.web import core

__all__ = ["Live", "Registry"]


@dataclass
class Live:
    """A trainee's session on the server: the core session plus what the page needs."""

    id: str
    exercise: str
    trainee: str
    demonstration: bool
    session: Any
    started: float = field(default_factory=time.time)
    script: list[dict[str, Any]] = field(default_factory=list)
    demo_next: int = 0
    last_error: str | None = None
    lock: threading.Lock = field(default_factory=threading.Lock)

    def summary(self) -> dict[str, Any]:
        """One row of the instructor's live table."""
        state = self.session.state()
        return {
            "id": self.id,
            "trainee": self.trainee,
            "exercise": self.exercise,
            "mode": "demonstration" if self.demonstration else state["mode"],
            "stage": state["stage"],
            "done": state["done"],
            "actions": len(self.session.log),
            "started": time.strftime("%H:%M:%S", time.localtime(self.started)),
            "last_error": self.last_error,
        }

    def act(self, action: dict[str, Any]) -> dict[str, Any]:
        """Carry one action out; returns the message for the page (state, or the refusal)."""
        with self.lock:
            try:
                state = self.session.act(action)
                self.last_error = None
            except core.CoreError as exc:
                self.last_error = str(exc)
                return {"state": self.session.state(), "error": str(exc)}
            result = self.session.log[-1].get("result") if self.session.log else None
            return {"state": state, "error": None, "result": result}

    def demo_step(self) -> dict[str, Any]:
        """Demonstration: the simulated operator's next action."""
        if self.demo_next >= len(self.script):
            return {"state": self.session.state(), "error": "demonstration finished"}
        action = self.script[self.demo_next]
        self.demo_next += 1
        msg = self.act(action)
        msg["demo"] = {"done": self.demo_next, "of": len(self.script), "action": action}
        return msg


class Registry:
    """Live sessions by id, and the instructor's token."""

    def __init__(self, token: str | None = None):
        self.token = token or secrets.token_urlsafe(12)
        self.sessions: dict[str, Live] = {}

    def start(
        self, exercise: str, trainee: str, *, seed: int | None = None, demonstration: bool = False
    ) -> Live:
        session = core.start(exercise, trainee, seed)
        live = Live(
            id=secrets.token_hex(6),
            exercise=exercise,
            trainee=trainee,
            demonstration=demonstration,
            session=session,
        )
        if demonstration:
            live.script = core.operator_script(session)
        self.sessions[live.id] = live
        return live

    def get(self, sid: str) -> Live | None:
        return self.sessions.get(sid)
