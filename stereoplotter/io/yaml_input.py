"""Reading text and YAML input files, with clear errors.

Every problem in an input file becomes one :class:`~stereoplotter.errors.ConfigError` whose
message names the file, the field (a dotted path such as ``photos[1].exterior.alpha_deg``), what
was expected and what was found.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import yaml

from stereoplotter.errors import ConfigError

__all__ = ["MAX_YAML_DEPTH", "MAX_YAML_NODES", "load_yaml_mapping", "parse_yaml", "read_text_file"]

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
    data = parse_yaml(text, source)
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


def parse_yaml(text: str, source: str) -> Any:
    """``yaml.safe_load`` with the document checked (:func:`_check_document`) before it is
    constructed, and every failure as a :class:`ConfigError`.

    Read with libyaml where PyYAML has it (:func:`_parse_fast`, PyYAML's C parser: reading the
    shipped files is much of ``stereoplotter info``); a document libyaml refuses, or that fails
    a check, is read again by the pure-Python loader, whose messages (line, column, the
    offending character) are the ones reported.
    """
    found = _parse_fast(text, source)
    if found is not _FAILED:
        return found
    return _parse_python(text, source)


#: :func:`_parse_fast` could not read the document (the pure-Python loader says why).
_FAILED = object()


def _parse_fast(text: str, source: str) -> Any:
    """The document read by libyaml's parser (the same nodes, resolver and constructor as
    :class:`_BoundedLoader`), or :data:`_FAILED`. Its depth is counted on the event stream
    first, without recursion, so that no deep document reaches libyaml's recursive composer."""
    if not getattr(yaml, "__with_libyaml__", False):
        return _FAILED
    try:
        events = yaml.CSafeLoader(text)
        try:
            depth = 0
            while events.check_event():
                event = events.get_event()
                if isinstance(event, yaml.CollectionStartEvent):
                    depth += 1
                    if depth > MAX_YAML_DEPTH + 1:
                        return _FAILED
                elif isinstance(event, yaml.CollectionEndEvent):
                    depth -= 1
        finally:
            events.dispose()
        loader = yaml.CSafeLoader(text)
        try:
            node = loader.get_single_node()
            if node is None:
                return None
            _check_document(node, source)
            return loader.construct_document(node)
        finally:
            loader.dispose()
    except Exception:  # every failure is reported by the pure-Python loader
        return _FAILED


def _parse_python(text: str, source: str) -> Any:
    """:func:`parse_yaml` by PyYAML's pure-Python loader, bounded (:class:`_BoundedLoader`)."""
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
