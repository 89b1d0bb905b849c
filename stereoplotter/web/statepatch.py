"""What changed between two trainee states: the patch a socket sends instead of the whole state.

A trainee's state is ≈ 3.3 kB of JSON and half of it (the controls' stops and units, the
exercise's checks) does not change from one action to the next. A page that asks for patches
(``{"auth": ..., "patches": true}``) gets the whole state once, in its first frame, and after
that ``{"patch": P}`` where ``P`` applied to the state it holds gives the new state exactly
(the same JSON text): ``P = {"set": {key: value}, "del": [key], "sub": {key: P'}}``, each part
only when not empty: ``set`` replaces or adds a key's value, ``del`` removes a key, ``sub``
patches a key whose value is an object in both states. A socket that reconnects starts again
from a whole state.

"Unchanged" is strict: the same JSON value, so ``1`` and ``1.0``, ``0.0`` and ``-0.0``, ``true``
and ``1`` differ (Python's ``==`` holds them equal).
"""

from __future__ import annotations

import math
from typing import Any

__all__ = ["apply_patch", "same", "state_patch"]


def same(a: Any, b: Any) -> bool:
    """Whether two JSON values are the same value (their JSON texts are equal, the order of an
    object's keys aside)."""
    if a is b:
        return True
    kind = type(a)
    if kind is not type(b):
        return False
    if kind is float:
        return a == b and (a != 0.0 or math.copysign(1.0, a) == math.copysign(1.0, b))
    if kind is dict:
        return a.keys() == b.keys() and all(same(v, b[k]) for k, v in a.items())
    if kind is list or kind is tuple:
        return len(a) == len(b) and all(map(same, a, b))
    return a == b


_MISSING = object()


def state_patch(old: dict[str, Any], new: dict[str, Any]) -> dict[str, Any]:
    """The patch that turns ``old`` into ``new`` (both JSON objects; see the module's text).
    Each value is visited once: an object in both states is patched in turn (nothing, when it
    did not change), anything else compared as :func:`same` does (inlined: this runs on every
    reply)."""
    put: dict[str, Any] = {}
    sub: dict[str, Any] = {}
    added = 0
    for key, value in new.items():
        before = old.get(key, _MISSING)
        if before is _MISSING:
            put[key] = value
            added += 1
            continue
        if before is value:
            continue
        kind = type(value)
        if kind is type(before):
            if kind is dict:
                inner = state_patch(before, value)
                if inner:
                    sub[key] = inner
                continue
            if kind is float:
                if before == value and (value or math.copysign(1.0, before) == math.copysign(
                        1.0, value)):
                    continue
            elif kind is list:
                if same(before, value):
                    continue
            elif before == value:
                continue
        put[key] = value
    patch: dict[str, Any] = {}
    if put:
        patch["set"] = put
    if len(old) > len(new) - added:  # keys of old that new has not
        gone = [key for key in old if key not in new]
        if gone:
            patch["del"] = gone
    if sub:
        patch["sub"] = sub
    return patch


def apply_patch(old: dict[str, Any], patch: dict[str, Any]) -> dict[str, Any]:
    """A new object: ``old`` with ``patch`` applied (``old`` itself is left as it was)."""
    out = dict(old)
    for key in patch.get("del", ()):
        out.pop(key, None)
    out.update(patch.get("set", {}))
    for key, inner in patch.get("sub", {}).items():
        out[key] = apply_patch(out[key], inner)
    return out
