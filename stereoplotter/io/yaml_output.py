"""YAML text of output files (``sheet.yaml``, ``evaluation.yaml``, a job's and a block's sheets,
``block.yaml`` and the triangulated ``job.yaml``).

The only place output YAML is emitted: the other layers hand over plain data (lists, floats,
strings) and get text back; writing it is :mod:`stereoplotter.io.atomic_write`'s. Every text
goes through PyYAML's safe emitter, which quotes what YAML would read as something else (a name
``a: b #c``, a photo number ``012417``); :class:`Flow`, :class:`Quoted` and :class:`Folded` only
choose how a node looks (one line, double quotes, a folded paragraph).
"""

from __future__ import annotations

from typing import Any

import yaml

__all__ = ["Flow", "Folded", "Quoted", "yaml_document", "yaml_text"]


def yaml_text(data: Any, *, width: int | None = None, c_emitter: bool = False) -> str:
    """``data`` (plain lists, numbers, strings) as block-style YAML, keys in their order, text
    unescaped (``allow_unicode``).

    ``width`` is the preferred line width (None: PyYAML's 80); ``c_emitter`` uses libyaml's
    emitter where installed (block files: many models), the pure-Python one otherwise.
    """
    dumper = getattr(yaml, "CSafeDumper", yaml.SafeDumper) if c_emitter else yaml.SafeDumper
    return yaml.dump(data, Dumper=dumper, sort_keys=False, allow_unicode=True, width=width)


class Flow:
    """A list or mapping written on one line (``[a, b]``, ``{k: v}``)."""

    __slots__ = ("value",)

    def __init__(self, value: list[Any] | tuple[Any, ...] | dict[str, Any]) -> None:
        self.value = value


class Quoted(str):
    """A text written in double quotes (an identifier or a date: never read back as a number)."""

    __slots__ = ()


class Folded(str):
    """A paragraph written folded (``>-``)."""

    __slots__ = ()


class _Dumper(yaml.SafeDumper):
    """The safe emitter with block sequences indented under their key."""

    def increase_indent(self, flow: bool = False, indentless: bool = False) -> None:
        super().increase_indent(flow, False)


def _flow(dumper: yaml.SafeDumper, data: Flow) -> yaml.Node:
    if isinstance(data.value, dict):
        return dumper.represent_mapping("tag:yaml.org,2002:map", data.value, flow_style=True)
    return dumper.represent_sequence("tag:yaml.org,2002:seq", list(data.value), flow_style=True)


def _quoted(dumper: yaml.SafeDumper, data: Quoted) -> yaml.Node:
    return dumper.represent_scalar("tag:yaml.org,2002:str", str(data), style='"')


def _folded(dumper: yaml.SafeDumper, data: Folded) -> yaml.Node:
    return dumper.represent_scalar("tag:yaml.org,2002:str", str(data), style=">")


_Dumper.add_representer(Flow, _flow)
_Dumper.add_representer(Quoted, _quoted)
_Dumper.add_representer(Folded, _folded)


def yaml_document(data: dict[str, Any], *, comment: str = "") -> str:
    """A mapping as a YAML document through the safe emitter, keys in their order, with
    :class:`Flow`, :class:`Quoted` and :class:`Folded` nodes styled as they say; ``comment``
    (lines) is written above it as ``#`` comments. Lines are not wrapped (a flow row, a folded
    paragraph stays on one line).

    >>> print(yaml_document({"name": "a: b #c", "photos": Flow([Quoted("012417")])}), end="")
    name: 'a: b #c'
    photos: ["012417"]
    """
    lines = [f"# {line}".rstrip() for line in comment.splitlines()]
    text = yaml.dump(
        data, Dumper=_Dumper, sort_keys=False, allow_unicode=True, width=4096,
        default_flow_style=False,
    )  # fmt: skip
    return "".join(f"{line}\n" for line in lines) + text
