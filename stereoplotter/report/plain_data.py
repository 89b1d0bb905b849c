"""Results as plain data and JSON text (numpy scalars and arrays turned into numbers and lists)."""

from __future__ import annotations

import json
import sys
from typing import Any

__all__ = ["json_ready", "json_text"]


def _numpy() -> Any:
    """numpy if it is loaded (a numpy value cannot exist before): ``info`` never loads it."""
    return sys.modules.get("numpy")


def _json_default(value: Any) -> Any:
    np = _numpy()
    if np is None:
        raise TypeError(f"not JSON serialisable: {type(value).__name__}")
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


def json_text(data: Any) -> str:
    """``data`` as indented JSON text (what ``--json`` prints), text unescaped, a final newline;
    anything but numpy values, numbers, text, lists and mappings is a TypeError."""
    return json.dumps(data, indent=2, ensure_ascii=False, default=_json_default) + "\n"


def _plain(v: Any) -> Any:
    np = _numpy()
    if np is None:
        return str(v)
    if isinstance(v, np.ndarray):
        return v.tolist()
    if isinstance(v, np.generic):
        return v.item()
    return str(v)


def json_ready(data: Any) -> Any:
    """Plain lists, floats and strings only (anything else becomes its text)."""
    return json.loads(json.dumps(data, default=_plain))
