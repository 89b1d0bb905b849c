"""Reading YAML input with clear errors, and writing output files whole or not at all.

Every problem in an input file becomes one :class:`~stereoplotter.errors.ConfigError` whose
message names the file, the field (a dotted path such as ``photos[1].exterior.alpha_deg``), what
was expected and what was found.
"""

from __future__ import annotations

import math
import os
import secrets
from collections.abc import Iterable, Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import Any, BinaryIO

import yaml

from stereoplotter.errors import ConfigError, describe_value, did_you_mean
from stereoplotter.io.validation import range_text

__all__ = [
    "Fields",
    "atomic_write_bytes",
    "atomic_write_text",
    "describe_value",
    "did_you_mean",
    "load_yaml_mapping",
    "read_text_file",
]

_MISSING = object()


#: Bounds of an input document, far above any real scenario, instrument or block file. A
#: document beyond them is refused before anything walks it: YAML aliases let a few hundred bytes
#: stand for billions of nodes ("billion laughs"), and deep nesting exhausts Python's stack.
MAX_YAML_NODES = 1_000_000  # after expanding aliases
MAX_YAML_DEPTH = 64


def read_text_file(path: str | os.PathLike[str]) -> str:
    """The UTF-8 text of ``path``; a missing or unreadable file is one ConfigError line."""
    source = str(path)
    try:
        return Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError(source, "(file)", "an existing file", "no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(source, "(file)", "a readable UTF-8 text file", str(exc)) from None


def load_yaml_mapping(path: str | os.PathLike[str]) -> tuple[dict[str, Any], str]:
    """Read a YAML file whose top level is a mapping.

    Returns
    -------
    data, source : dict, str
        The parsed mapping and the path as given (for messages).

    Raises
    ------
    ConfigError
        The file is missing, unreadable, not valid YAML, or not a mapping; a key is given twice
        in one mapping; the document nests deeper than :data:`MAX_YAML_DEPTH`, refers to itself
        through an alias, or expands (through aliases) to more than :data:`MAX_YAML_NODES` nodes.
    """
    source = str(path)
    text = read_text_file(path)
    data = _parse_yaml(text, source)
    if data is None:
        raise ConfigError(source, "(top level)", "a mapping of fields", "an empty document")
    if not isinstance(data, dict):
        raise ConfigError(source, "(top level)", "a mapping of fields", type(data).__name__)
    return data, source


class _TooDeep(Exception):
    def __init__(self, mark: Any):
        self.mark = mark


class _BoundedLoader(yaml.SafeLoader):
    """:class:`yaml.SafeLoader` that stops composing at :data:`MAX_YAML_DEPTH` levels, before
    PyYAML's recursive composer exhausts the stack."""

    _depth = 0

    def compose_node(self, parent: Any, index: Any) -> Any:
        self._depth += 1
        try:
            if self._depth > MAX_YAML_DEPTH + 1:
                raise _TooDeep(self.peek_event().start_mark)
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1


def _parse_yaml(text: str, source: str) -> Any:
    """``yaml.safe_load`` with the document checked (:func:`_check_document`) before it is
    constructed, and every failure as a :class:`ConfigError`."""
    try:
        loader = _BoundedLoader(text)  # the reader refuses control characters here
    except yaml.YAMLError as exc:
        raise _yaml_error(source, exc) from None
    try:
        try:
            node = loader.get_single_node()
        except yaml.YAMLError as exc:
            raise _yaml_error(source, exc) from None
        except _TooDeep as exc:
            raise ConfigError(
                source,
                "(file)",
                f"YAML nested at most {MAX_YAML_DEPTH} levels deep",
                f"deeper nesting (line {exc.mark.line + 1}, column {exc.mark.column + 1})",
            ) from None
        if node is None:
            return None
        _check_document(node, source)
        try:
            return loader.construct_document(node)
        except yaml.YAMLError as exc:
            raise _yaml_error(source, exc) from None
        except Exception as exc:  # PyYAML's own constructors: dates, !!int, !!timestamp, …
            raise ConfigError(
                source,
                "(file)",
                "valid YAML values",
                f"a value YAML cannot construct ({type(exc).__name__}: {exc})",
            ) from None
    finally:
        loader.dispose()


def _yaml_error(source: str, exc: yaml.YAMLError) -> ConfigError:
    mark = getattr(exc, "problem_mark", None)
    if mark is not None:
        where = f"line {mark.line + 1}, column {mark.column + 1}"
    elif isinstance(exc, yaml.reader.ReaderError):
        where = f"character {exc.position + 1}"
    else:
        where = "unknown place"
    problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
    return ConfigError(source, "(file)", "valid YAML", f"{problem} at {where}")


def _node_line(node: yaml.Node) -> str:
    return f"line {node.start_mark.line + 1}"


def _check_document(root: yaml.Node, source: str) -> None:
    """Refuse what :func:`yaml.safe_load` would build without complaint but no input file needs:
    a key given twice in one mapping (the last would silently win), text with lone surrogates
    (it cannot be printed), nesting deeper than :data:`MAX_YAML_DEPTH`, an alias to an enclosing
    node (a cycle), and more than :data:`MAX_YAML_NODES` nodes once aliases are expanded.

    One pass over the composed nodes, each node once (aliased nodes are shared, so the expanded
    size is summed without expanding anything): time and memory grow with the file, not with
    what its aliases stand for.
    """
    expanded: dict[int, int] = {}  # id(node) -> node count with aliases expanded
    open_nodes: set[int] = set()  # nodes whose children are being walked
    # (node, field path, depth, children done?)
    stack: list[tuple[yaml.Node, str, int, bool]] = [(root, "", 0, False)]
    while stack:
        node, path, depth, done = stack.pop()
        key = id(node)
        if done:
            open_nodes.discard(key)
            total = 1 + sum(expanded[id(child)] for child in _children(node))
            if total > MAX_YAML_NODES:
                raise ConfigError(
                    source,
                    path or "(top level)",
                    f"at most {MAX_YAML_NODES:,} YAML nodes with aliases (*name) expanded",
                    f"more than {MAX_YAML_NODES:,} from {_node_line(node)} on",
                    "a YAML alias bomb?",
                )
            expanded[key] = total
            continue
        if key in expanded:
            continue  # an alias to a node already walked
        if key in open_nodes:
            raise ConfigError(
                source,
                path or "(top level)",
                "no alias to an enclosing node",
                f"an alias that makes the document contain itself ({_node_line(node)})",
            )
        if depth > MAX_YAML_DEPTH:
            raise ConfigError(
                source,
                path[:40] + "…" if len(path) > 40 else path or "(top level)",
                f"YAML nested at most {MAX_YAML_DEPTH} levels deep",
                f"deeper nesting ({_node_line(node)})",
            )
        if isinstance(node, yaml.ScalarNode):
            if _has_surrogate(node.value):
                raise ConfigError(
                    source,
                    path or "(top level)",
                    "text without lone surrogates (\\ud800–\\udfff escapes)",
                    f"a lone surrogate ({_node_line(node)})",
                )
            expanded[key] = 1
            continue
        open_nodes.add(key)
        stack.append((node, path, depth, True))
        if isinstance(node, yaml.SequenceNode):
            for i, child in enumerate(node.value):
                stack.append((child, f"{path}[{i}]", depth + 1, False))
            continue
        seen: dict[tuple[str, str], yaml.Node] = {}
        for k, v in node.value:
            name = k.value if isinstance(k, yaml.ScalarNode) else None
            if name is not None and k.tag != "tag:yaml.org,2002:merge":
                first = seen.setdefault((k.tag, name), k)
                if first is not k:
                    raise ConfigError(
                        source,
                        f"{path}.{name}" if path else name,
                        "each key once in a mapping",
                        f"it twice ({_node_line(first)} and {_node_line(k)})",
                        "the second would silently replace the first",
                    )
            child_path = (f"{path}.{name}" if path else name) if name is not None else path
            stack.append((k, path, depth + 1, False))
            stack.append((v, child_path, depth + 1, False))


def _children(node: yaml.Node) -> list[yaml.Node]:
    if isinstance(node, yaml.SequenceNode):
        return node.value
    if isinstance(node, yaml.MappingNode):
        return [n for pair in node.value for n in pair]
    return []


def _has_surrogate(text: str) -> bool:
    return not text.isascii() and any("\ud800" <= ch <= "\udfff" for ch in text)


class Fields:
    """Typed, range-checked access to a parsed YAML document, with messages that name the field.

    Superseded by the pydantic models of :mod:`stereoplotter.io.validation` (scenario,
    instrument, block, injected-errors and geometry files no longer use it); kept only until
    ``io/job_file.py`` moves over, then to be removed.

    Parameters
    ----------
    source : str
        The file name, for messages.
    """

    def __init__(self, source: str):
        self.source = source

    def error(self, path: str, expected: str, found: object, hint: str = "") -> ConfigError:
        """A :class:`ConfigError` for this file."""
        return ConfigError(self.source, path, expected, found, hint)

    @staticmethod
    def join(path: str, key: str | int) -> str:
        """Dotted path of a child: ``camera`` + ``focal_length_mm``, or ``photos`` + 1."""
        if isinstance(key, int):
            return f"{path}[{key}]"
        return f"{path}.{key}" if path else key

    def mapping(
        self,
        value: Any,
        path: str,
        allowed: Iterable[str] | None = None,
        required: Iterable[str] = (),
    ) -> dict[str, Any]:
        """Check ``value`` is a mapping with only ``allowed`` keys and the ``required`` ones."""
        if not isinstance(value, dict):
            raise self.error(path or "(top level)", "a mapping", describe_value(value))
        for key in value:
            if not isinstance(key, str):
                raise self.error(path, "text keys", key)
        if allowed is not None:
            allowed = list(allowed)
            unknown = [k for k in value if k not in allowed]
            if unknown:
                hint = "allowed here: " + ", ".join(allowed)
                suggestion = did_you_mean(unknown[0], allowed)
                raise self.error(
                    self.join(path, unknown[0]),
                    "no such field",
                    unknown[0],
                    f"{hint}; {suggestion}" if suggestion else hint,
                )
        for key in required:
            if key not in value:
                raise self.error(self.join(path, key), "a value (the field is required)", "nothing")
        return value

    def get(self, node: Mapping[str, Any], key: str, path: str, default: Any = _MISSING) -> Any:
        """``node[key]``, or ``default``; a missing required field is an error."""
        if key in node and node[key] is not None:
            return node[key]
        if default is _MISSING:
            raise self.error(self.join(path, key), "a value (the field is required)", "nothing")
        return default

    def number(
        self,
        node: Mapping[str, Any],
        key: str,
        path: str,
        *,
        unit: str,
        low: float = -math.inf,
        high: float = math.inf,
        low_open: bool = False,
        high_open: bool = False,
        default: Any = _MISSING,
        basis: str = "",
    ) -> float:
        """A finite real number inside [low, high] (ends open where asked)."""
        value = self.get(node, key, path, default)
        return self.check_number(
            value,
            self.join(path, key),
            unit=unit,
            low=low,
            high=high,
            low_open=low_open,
            high_open=high_open,
            basis=basis,
        )

    def check_number(
        self,
        value: Any,
        path: str,
        *,
        unit: str,
        low: float = -math.inf,
        high: float = math.inf,
        low_open: bool = False,
        high_open: bool = False,
        basis: str = "",
    ) -> float:
        """Validate one number already taken from the document."""
        expected = range_text(unit, low, high, low_open, high_open)
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.error(path, f"a number {expected}", describe_value(value))
        try:
            value = float(value)
        except OverflowError:  # an integer beyond the float range
            raise self.error(
                path, f"a number {expected}", "an integer too large for a float", basis
            ) from None
        too_low = value < low or (low_open and value == low)
        too_high = value > high or (high_open and value == high)
        if not math.isfinite(value) or too_low or too_high:
            raise self.error(path, f"a number {expected}", value, basis)
        return value

    def integer(
        self,
        node: Mapping[str, Any],
        key: str,
        path: str,
        *,
        low: int,
        high: int,
        default: Any = _MISSING,
    ) -> int:
        """An integer inside [low, high]."""
        value = self.get(node, key, path, default)
        if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
            raise self.error(
                self.join(path, key), f"an integer in [{low}, {high}]", describe_value(value)
            )
        return value

    def text(self, node: Mapping[str, Any], key: str, path: str, default: Any = _MISSING) -> str:
        """A non-empty string (numbers are accepted and turned into text, as for point ids)."""
        value = self.get(node, key, path, default)
        if isinstance(value, bool) or not isinstance(value, str | int) or str(value) == "":
            raise self.error(self.join(path, key), "a non-empty text", describe_value(value))
        return str(value)

    def choice(
        self,
        node: Mapping[str, Any],
        key: str,
        path: str,
        choices: Iterable[str],
        default: Any = _MISSING,
    ) -> str:
        """One of a fixed set of words."""
        choices = list(choices)
        value = self.get(node, key, path, default)
        if value not in choices:
            raise self.error(
                self.join(path, key), "one of " + ", ".join(choices), describe_value(value)
            )
        return value

    def vector(
        self,
        node: Mapping[str, Any],
        key: str,
        path: str,
        length: int,
        *,
        unit: str,
        low: float = -math.inf,
        high: float = math.inf,
        default: Any = _MISSING,
    ) -> tuple[float, ...]:
        """A list of ``length`` numbers, each inside [low, high]."""
        value = self.get(node, key, path, default)
        full = self.join(path, key)
        if not isinstance(value, list | tuple) or len(value) != length:
            raise self.error(full, f"a list of {length} numbers [{unit}]", describe_value(value))
        return tuple(
            self.check_number(v, self.join(full, i), unit=unit, low=low, high=high)
            for i, v in enumerate(value)
        )

    def sequence(
        self,
        node: Mapping[str, Any],
        key: str,
        path: str,
        *,
        min_length: int = 0,
        default: Any = _MISSING,
    ) -> list[Any]:
        """A list with at least ``min_length`` entries."""
        value = self.get(node, key, path, default)
        if not isinstance(value, list):
            raise self.error(self.join(path, key), "a list", describe_value(value))
        if len(value) < min_length:
            raise self.error(
                self.join(path, key),
                f"a list of at least {min_length} entries",
                f"{len(value)} entries",
            )
        return value


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to ``path`` whole or not at all (:func:`atomic_stream`)."""
    with atomic_stream(path) as f:
        f.write(data)


@contextmanager
def atomic_stream(path: str | os.PathLike[str]) -> Iterator[BinaryIO]:
    """A binary file that appears under ``path`` whole or not at all, for streamed writing.

    The bytes go to a new temporary file in the same folder (``.NAME.XXXXXXXXXXXX.tmp``); when
    the ``with`` block ends without an exception they are flushed to disk and the file is renamed
    onto ``path`` (:func:`os.replace`, atomic on one file system). The temporary file is created
    with mode 0o666, which the kernel reduces by the process umask as for any ``open``: 0644
    under umask 022, 0600 under 077 (and a default ACL of the folder applies as usual). On any
    exception, ``KeyboardInterrupt`` included, the temporary file is removed and ``path`` is left
    as it was.
    """
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp, fd = _create_temporary(target)
    try:
        with os.fdopen(fd, "wb") as f:
            yield f
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, target)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    _fsync_folder(target.parent)


def _create_temporary(target: Path) -> tuple[Path, int]:
    """A new, empty file next to ``target`` (mode 0o666 less the umask) and its descriptor."""
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0)
    for _ in range(100):
        tmp = target.parent / f".{target.name}.{secrets.token_hex(6)}.tmp"
        try:
            return tmp, os.open(tmp, flags, 0o666)
        except FileExistsError:
            continue
    raise FileExistsError(f"{target.parent}: no free temporary file name for {target.name}")


def _fsync_folder(folder: Path) -> None:
    """Make a rename in ``folder`` durable where the platform allows it (best effort)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def atomic_write_text(path: str | os.PathLike[str], text: str) -> None:
    """Write UTF-8 ``text`` to ``path`` whole or not at all."""
    atomic_write_bytes(path, text.encode("utf-8"))
