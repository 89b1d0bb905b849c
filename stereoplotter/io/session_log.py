"""A trainee's session log as JSON lines (``stereoplotter-session/1``), written atomically.

Line 1 is the session's header (format, the exercise file's content, trainee, seed); every
further line one action record of :attr:`Session.log <stereoplotter.trainer.session.Session.log>`.
:func:`read_log` checks the lines are JSON objects and the first has the format; replaying
(:meth:`Session.replay`) checks the rest. The same records written again give the same bytes
(keys in their order, floats as ``repr``, UTF-8, one ``\\n`` per line).
"""

from __future__ import annotations

import json
import os
from typing import Any

from stereoplotter.errors import ConfigError
from stereoplotter.io.atomic_write import atomic_write_bytes
from stereoplotter.io.exercise_file import exercise_from_mapping
from stereoplotter.io.yaml_input import read_text_file
from stereoplotter.trainer.session import LOG_FORMAT, Session

__all__ = ["log_bytes", "read_log", "replay_log", "write_log"]


def log_bytes(records: list[dict[str, Any]]) -> bytes:
    """The JSON-lines bytes of a header and its action records."""
    return "".join(
        json.dumps(r, ensure_ascii=False, allow_nan=False) + "\n" for r in records
    ).encode("utf-8")


def write_log(path: str | os.PathLike[str], session: Session) -> None:
    """Write a session's header and action records to ``path`` (atomically)."""
    atomic_write_bytes(path, log_bytes([session.header(), *session.log]))


def read_log(path: str | os.PathLike[str]) -> list[dict[str, Any]]:
    """The records of a session log file (header first).

    Raises
    ------
    ConfigError
        Missing or unreadable file, a line that is not a JSON object, or no header line.
    """
    source = str(path)
    text = read_text_file(path)
    records = []
    for number, line in enumerate(text.splitlines(), 1):
        if not line.strip():
            continue
        try:
            value = json.loads(line)
        except json.JSONDecodeError as exc:
            raise ConfigError(source, f"line {number}", "a JSON object", exc.msg) from None
        if not isinstance(value, dict):
            raise ConfigError(source, f"line {number}", "a JSON object", type(value).__name__)
        records.append(value)
    if not records or records[0].get("format") != LOG_FORMAT:
        found = records[0].get("format") if records else "an empty file"
        raise ConfigError(source, "line 1: format", LOG_FORMAT, found)
    return records


def replay_log(path: str | os.PathLike[str]) -> Session:
    """The session a log file records, replayed."""
    return Session.replay(read_log(path), read_exercise=exercise_from_mapping)
