"""A trainee's actions file (``session run --actions FILE``): a JSON list or JSON lines."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from stereoplotter.errors import ConfigError

__all__ = ["read_actions"]


def read_actions(path: str) -> list[dict[str, Any]]:
    """Actions from a JSON list or JSON lines file (one line: file, line, what is wrong)."""
    text = Path(path).read_text(encoding="utf-8")
    try:
        data = json.loads(text)
        rows = data if isinstance(data, list) else [data]
    except json.JSONDecodeError:
        rows = []
        for number, line in enumerate(text.splitlines(), 1):
            if line.strip():
                try:
                    rows.append(json.loads(line))
                except json.JSONDecodeError as exc:
                    raise ConfigError(path, f"line {number}", "a JSON action", exc.msg) from None
    return rows
