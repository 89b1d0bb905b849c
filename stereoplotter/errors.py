"""Domain exceptions (all subclass :class:`ValueError`), the helpers of their messages, and the
SIGTERM handler that ends a run as Ctrl-C does."""

from __future__ import annotations

import re
from collections.abc import Iterable
from typing import Any

__all__ = [
    "ConfigError",
    "GeometryError",
    "StereoplotterError",
    "TrainerError",
    "describe_value",
    "did_you_mean",
    "raise_keyboard_interrupt",
]

#: Control characters and line breaks: a message quoting user text stays one printable line.
_CONTROL = re.compile("[\x00-\x1f\x7f-\x9f\u2028\u2029]")


class StereoplotterError(ValueError):
    """Base class of every error stereoplotter raises on purpose.

    Its text is one line: control characters and line breaks of quoted user text (a name with
    a newline, say) are shown as escapes (``\\n``).
    """

    def __str__(self) -> str:
        return _CONTROL.sub(lambda m: repr(m.group())[1:-1], super().__str__())


class ConfigError(StereoplotterError):
    """A scenario or instrument file is invalid.

    The message names the file, the field (as a dotted path), what was expected and what was
    found. The same pieces are kept as attributes for programs that want them.
    """

    def __init__(self, source: str, field: str, expected: str, found: object, hint: str = ""):
        self.source = source
        self.field = field
        self.expected = expected
        self.found = found
        self.hint = hint
        found_text = found if isinstance(found, str) else repr(found)
        message = f"{source}: {field}: expected {expected}, found {found_text}"
        if hint:
            message += f" ({hint})"
        super().__init__(message)


class GeometryError(StereoplotterError):
    """The geometry is degenerate: too few points, collinear points, rays that do not meet."""


class TrainerError(StereoplotterError):
    """A trainee's action refused by the session (one line: what and why)."""


# --- helpers of the messages -----------------------------------------------------------------


def did_you_mean(word: str, choices: Iterable[str]) -> str:
    """``"did you mean NAME?"`` for the one choice closest to a mistyped ``word``, or ``""``
    when none is close (:func:`difflib.get_close_matches`, case ignored) or two are equally
    close (then the list of choices says more than a guess).

    Examples
    --------
    >>> did_you_mean("focal_lenght_mm", ["focal_length_mm", "format_mm"])
    'did you mean focal_length_mm?'
    >>> did_you_mean("w_mm", ["x_mm", "y_mm", "z_mm"])
    ''
    """
    # imported here: only a mistyped name reaches it, and every command imports this module
    import difflib

    choices = [str(c) for c in choices]
    lowered = {c.lower(): c for c in choices}
    matches = difflib.get_close_matches(str(word).lower(), list(lowered), n=2, cutoff=0.6)
    if not matches:
        return ""
    if len(matches) == 2:
        ratio = [difflib.SequenceMatcher(None, str(word).lower(), m).ratio() for m in matches]
        if ratio[0] == ratio[1]:
            return ""
    return f"did you mean {lowered[matches[0]]}?"


def describe_value(value: Any) -> str:
    """How a YAML value is named in an error message ("a mapping", "the text 'x'", …)."""
    if isinstance(value, dict):
        return "a mapping"
    if isinstance(value, list):
        return f"a list of {len(value)}"
    if value is None:
        return "nothing"
    if isinstance(value, str):
        return f"the text {value!r}"
    return repr(value)


def raise_keyboard_interrupt(signum: int, frame: object) -> None:
    """A SIGTERM handler: a termination ends the run as Ctrl-C does (the command's one line,
    its exit code, and whatever the interpreter does at a normal exit)."""
    raise KeyboardInterrupt
