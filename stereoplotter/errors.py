"""Domain exceptions. All subclass :class:`ValueError` so callers may catch them generically."""

from __future__ import annotations

import re

__all__ = ["ConfigError", "GeometryError", "StereoplotterError"]

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
