"""The browser trainer's results on disk: sessions, action logs, grades, exam attempts and
instructor-uploaded exercises in one SQLite file (stdlib :mod:`sqlite3`, WAL journal).

One :class:`SessionStore` is shared by the server's threads (one connection behind a lock;
every write is its own transaction, committed before the call returns). A session is a row with
its log header; each action record is a row appended as the action happens, so a restart of the
server finds every action that was answered. A session's secret is kept only as its SHA-256.

:func:`exercise_upload` reads an exercise file sent by the instructor (YAML or JSON text) with
the same bounded YAML reader as the files on disk; the server validates it and stores its
content here (no path from a client is ever opened).
"""

from __future__ import annotations

import hashlib
import hmac
import json
import os
import secrets
import sqlite3
import threading
import time
from pathlib import Path
from typing import Any

from stereoplotter.errors import ConfigError
from stereoplotter.io.yaml_input import parse_yaml

__all__ = [
    "DB_NAME",
    "SessionStore",
    "default_data_dir",
    "exercise_upload",
    "secret_hash",
    "storable",
]

#: The database file inside the data folder.
DB_NAME = "trainer.sqlite3"
#: How often the write-ahead log is copied into the store's file, off the writers' path
#: (SQLite's own default copies it within a write once the log holds 1 000 pages). [s]
CHECKPOINT_S = 1.0

_SCHEMA = """
CREATE TABLE IF NOT EXISTS sessions (
    id TEXT PRIMARY KEY,
    secret_hash TEXT NOT NULL,
    trainee TEXT NOT NULL,
    trainee_key TEXT NOT NULL,
    exercise TEXT NOT NULL,
    mode TEXT NOT NULL,
    demonstration INTEGER NOT NULL,
    started REAL NOT NULL,
    header TEXT NOT NULL,
    stage TEXT,
    done INTEGER NOT NULL DEFAULT 0,
    actions INTEGER NOT NULL DEFAULT 0
);
CREATE TABLE IF NOT EXISTS actions (
    session_id TEXT NOT NULL,
    n INTEGER NOT NULL,
    record TEXT NOT NULL,
    PRIMARY KEY (session_id, n)
);
CREATE TABLE IF NOT EXISTS grades (session_id TEXT PRIMARY KEY, grade TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS grants (
    trainee_key TEXT NOT NULL,
    exercise TEXT NOT NULL,
    extra INTEGER NOT NULL,
    PRIMARY KEY (trainee_key, exercise)
);
CREATE TABLE IF NOT EXISTS exercises (name TEXT PRIMARY KEY, source TEXT NOT NULL, added REAL);
CREATE TABLE IF NOT EXISTS retired (name TEXT PRIMARY KEY, retired REAL NOT NULL);
CREATE TABLE IF NOT EXISTS server_keys (name TEXT PRIMARY KEY, value TEXT NOT NULL);
"""

_ROW = (
    "id",
    "trainee",
    "trainee_key",
    "exercise",
    "mode",
    "demonstration",
    "started",
    "stage",
    "done",
    "actions",
)


def default_data_dir() -> Path:
    """The per-user data folder: ``$XDG_DATA_HOME/stereoplotter/trainer``, else
    ``~/.local/share/stereoplotter/trainer`` (``%LOCALAPPDATA%`` on Windows)."""
    base = os.environ.get("XDG_DATA_HOME") or os.environ.get("LOCALAPPDATA")
    root = Path(base) if base else Path.home() / ".local" / "share"
    return root / "stereoplotter" / "trainer"


def secret_hash(secret: str) -> str:
    """SHA-256 (hex) of a session secret: what the store keeps."""
    return hashlib.sha256(secret.encode("utf-8")).hexdigest()


def exercise_upload(text: str) -> dict[str, Any]:
    """The mapping of an uploaded exercise file (YAML or JSON text); one-line ConfigError
    naming "uploaded exercise" (never a path) otherwise."""
    data = parse_yaml(text, "uploaded exercise")
    if not isinstance(data, dict):
        found = "an empty document" if data is None else type(data).__name__
        raise ConfigError("uploaded exercise", "(top level)", "a mapping of fields", found)
    return data


def _dumps(value: Any) -> str:
    return json.dumps(value, ensure_ascii=False, allow_nan=False, separators=(",", ":"))


def storable(value: Any) -> bool:
    """Whether ``value`` can be kept as a record: JSON without NaN or infinity whose text is
    valid UTF-8 (a lone surrogate is not)."""
    try:
        _dumps(value).encode("utf-8")
    except (TypeError, ValueError, RecursionError, UnicodeEncodeError):
        return False
    return True


class SessionStore:
    """The trainer's SQLite file (``data_dir/trainer.sqlite3``; ``None``: in memory, nothing
    kept after the process ends)."""

    def __init__(self, data_dir: str | os.PathLike[str] | None = None):
        if data_dir is None:
            self.path = None
            target = ":memory:"
        else:
            folder = Path(data_dir)
            folder.mkdir(parents=True, exist_ok=True)
            self.path = folder / DB_NAME
            target = str(self.path)
        self._lock = threading.Lock()
        self._db = sqlite3.connect(target, check_same_thread=False, isolation_level=None)
        self._db.execute("PRAGMA journal_mode=WAL")
        self._db.execute("PRAGMA synchronous=NORMAL")
        self._db.executescript(_SCHEMA)
        self._stop = threading.Event()
        self._checkpointer: threading.Thread | None = None
        if self.path is not None:
            # the log's pages are copied into the file (and the file synced to the disk) by a
            # thread of its own on its own connection, not by the write that fills the WAL
            # with the store's lock held: a sync of a busy disk took up to 180 ms there, and
            # every write and check waited for it
            self._db.execute("PRAGMA wal_autocheckpoint=0")
            self._checkpointer = threading.Thread(
                target=self._checkpoints, args=(target,), name="store-checkpoint", daemon=True)
            self._checkpointer.start()

    def _checkpoints(self, target: str) -> None:
        """Copy the write-ahead log into the file every :data:`CHECKPOINT_S` (SQLite's passive
        checkpoint: writers are never blocked, readers keep their snapshot)."""
        db = sqlite3.connect(target, check_same_thread=False, isolation_level=None)
        try:
            while not self._stop.wait(CHECKPOINT_S):
                try:
                    db.execute("PRAGMA wal_checkpoint(PASSIVE)")
                except sqlite3.Error:  # busy or failing now: the next round tries again
                    pass
        finally:
            db.close()

    def close(self) -> None:
        self._stop.set()
        if self._checkpointer is not None:
            self._checkpointer.join(10)
        with self._lock:
            self._db.close()  # the last connection: SQLite copies the log into the file

    def _run(self, sql: str, args: tuple = ()) -> list[tuple]:
        with self._lock:
            return self._db.execute(sql, args).fetchall()

    # --- sessions -----------------------------------------------------------------------------

    def add_session(
        self,
        row: dict[str, Any],
        secret: str,
        header: dict[str, Any],
        max_attempts: int | None = None,
    ) -> bool:
        """Insert a session; with ``max_attempts``, only if the trainee has fewer sessions of
        the exercise than that plus the instructor's grants (checked in the same transaction).
        Returns whether it was inserted."""
        with self._lock:
            cur = self._db.cursor()
            cur.execute("BEGIN IMMEDIATE")
            try:
                if max_attempts is not None:
                    (used,) = cur.execute(
                        "SELECT COUNT(*) FROM sessions WHERE trainee_key=? AND exercise=? "
                        "AND demonstration=0",
                        (row["trainee_key"], row["exercise"]),
                    ).fetchone()
                    got = cur.execute(
                        "SELECT extra FROM grants WHERE trainee_key=? AND exercise=?",
                        (row["trainee_key"], row["exercise"]),
                    ).fetchone()
                    if used >= max_attempts + (got[0] if got else 0):
                        cur.execute("ROLLBACK")
                        return False
                cur.execute(
                    "INSERT INTO sessions (id, secret_hash, trainee, trainee_key, exercise, mode, "
                    "demonstration, started, header, stage, done, actions) "
                    "VALUES (?,?,?,?,?,?,?,?,?,?,?,?)",
                    (
                        row["id"],
                        secret_hash(secret),
                        row["trainee"],
                        row["trainee_key"],
                        row["exercise"],
                        row["mode"],
                        int(row["demonstration"]),
                        row["started"],
                        _dumps(header),
                        row["stage"],
                        int(row["done"]),
                        0,
                    ),
                )
                cur.execute("COMMIT")
            except BaseException:
                cur.execute("ROLLBACK")
                raise
        return True

    def attempts(self, trainee_key: str, exercise: str) -> tuple[int, int]:
        """(sessions started, extra attempts granted) of a trainee at an exercise."""
        (used,) = self._run(
            "SELECT COUNT(*) FROM sessions WHERE trainee_key=? AND exercise=? AND demonstration=0",
            (trainee_key, exercise),
        )[0]
        got = self._run(
            "SELECT extra FROM grants WHERE trainee_key=? AND exercise=?", (trainee_key, exercise)
        )
        return int(used), int(got[0][0]) if got else 0

    def grant(self, trainee_key: str, exercise: str) -> int:
        """One more attempt for a trainee at an exercise; returns the extra attempts now."""
        with self._lock:
            self._db.execute(
                "INSERT INTO grants VALUES (?,?,1) ON CONFLICT(trainee_key, exercise) "
                "DO UPDATE SET extra = extra + 1",
                (trainee_key, exercise),
            )
            return int(
                self._db.execute(
                    "SELECT extra FROM grants WHERE trainee_key=? AND exercise=?",
                    (trainee_key, exercise),
                ).fetchone()[0]
            )

    def append_action(
        self, sid: str, record: dict[str, Any], stage: str | None, done: bool
    ) -> None:
        """Append one action record and update the session's stage, done and action count."""
        with self._lock:
            self._db.execute("BEGIN")
            try:
                self._db.execute(
                    "INSERT INTO actions VALUES (?,?,?)", (sid, int(record["n"]), _dumps(record))
                )
                self._db.execute(
                    "UPDATE sessions SET stage=?, done=?, actions=? WHERE id=?",
                    (stage, int(done), int(record["n"]), sid),
                )
                self._db.execute("COMMIT")
            except BaseException:
                self._db.execute("ROLLBACK")
                raise

    def sessions(self) -> list[dict[str, Any]]:
        """Every session's row (no secret, no log), oldest first."""
        rows = self._run(f"SELECT {', '.join(_ROW)} FROM sessions ORDER BY started, id")
        return [dict(zip(_ROW, r, strict=True)) for r in rows]

    def check_secret(self, sid: str, secret: str) -> bool:
        """Whether ``secret`` is the session's (compared by hash, in constant time)."""
        got = self._run("SELECT secret_hash FROM sessions WHERE id=?", (sid,))
        if not got:
            return False
        return hmac.compare_digest(got[0][0], secret_hash(secret))

    def records(self, sid: str) -> list[dict[str, Any]] | None:
        """The session log (header, then the action records), or None."""
        head = self._run("SELECT header FROM sessions WHERE id=?", (sid,))
        if not head:
            return None
        rows = self._run("SELECT record FROM actions WHERE session_id=? ORDER BY n", (sid,))
        return [json.loads(head[0][0]), *(json.loads(r[0]) for r in rows)]

    # --- grades -------------------------------------------------------------------------------

    def put_grade(self, sid: str, grade: dict[str, Any]) -> None:
        self._run("INSERT OR REPLACE INTO grades VALUES (?,?)", (sid, _dumps(grade)))

    def grades(self) -> dict[str, dict[str, Any]]:
        """Every stored grade by session id."""
        return {sid: json.loads(g) for sid, g in self._run("SELECT session_id, grade FROM grades")}

    # --- uploaded exercises -------------------------------------------------------------------

    def add_exercise(self, name: str, source: dict[str, Any]) -> bool:
        """Keep an uploaded exercise under a name never used before (a retired upload's name
        stays used: its sessions replay from their logs); returns whether it was added."""
        with self._lock:
            cur = self._db.cursor()
            cur.execute("BEGIN IMMEDIATE")
            try:
                used = cur.execute("SELECT 1 FROM exercises WHERE name=?", (name,)).fetchone()
                if used:
                    cur.execute("ROLLBACK")
                    return False
                cur.execute(
                    "INSERT INTO exercises VALUES (?,?,?)", (name, _dumps(source), time.time())
                )
                cur.execute("COMMIT")
            except BaseException:
                cur.execute("ROLLBACK")
                raise
        return True

    def retire_exercise(self, name: str) -> bool:
        """Take an uploaded exercise off the list of those offered (its content is kept, for its
        sessions to resume and replay; its name stays used); whether it was offered."""
        with self._lock:
            cur = self._db.cursor()
            cur.execute("BEGIN IMMEDIATE")
            try:
                found = cur.execute(
                    "SELECT 1 FROM exercises WHERE name=? "
                    "AND name NOT IN (SELECT name FROM retired)",
                    (name,),
                ).fetchone()
                if found:
                    cur.execute("INSERT INTO retired VALUES (?,?)", (name, time.time()))
                cur.execute("COMMIT")
            except BaseException:
                cur.execute("ROLLBACK")
                raise
        return bool(found)

    def exercises(self, retired: bool = False) -> dict[str, dict[str, Any]]:
        """Uploaded exercises offered (``retired``: those retired instead): name → content."""
        op = "IN" if retired else "NOT IN"
        rows = self._run(
            f"SELECT name, source FROM exercises WHERE name {op} (SELECT name FROM retired)"
        )
        return {n: json.loads(s) for n, s in rows}

    # --- the server's own secrets ---------------------------------------------------------------

    def server_key(self, name: str) -> bytes:
        """A random 32-byte key of the server's, made on first use and kept in the store (the
        data folder): e.g. what exam seeds are derived from. Never sent to a client."""
        fresh = secrets.token_hex(32)
        with self._lock:
            self._db.execute("INSERT OR IGNORE INTO server_keys VALUES (?,?)", (name, fresh))
            (value,) = self._db.execute(
                "SELECT value FROM server_keys WHERE name=?", (name,)
            ).fetchone()
        return bytes.fromhex(value)

    def get_value(self, name: str) -> str | None:
        got = self._run("SELECT value FROM server_keys WHERE name=?", (name,))
        return got[0][0] if got else None

    def put_value(self, name: str, value: str) -> None:
        self._run("INSERT OR REPLACE INTO server_keys VALUES (?,?)", (name, value))
