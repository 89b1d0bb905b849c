"""YAML text of output files (``sheet.yaml``, ``evaluation.yaml``, a job's and a block's sheets).

The only place output YAML is emitted: the other layers hand over plain data (lists, floats,
strings) and get text back; writing it is :mod:`stereoplotter.io.atomic_write`'s.
"""

from __future__ import annotations

from typing import Any

import yaml

__all__ = ["yaml_text"]


def yaml_text(data: Any, *, width: int | None = None, c_emitter: bool = False) -> str:
    """``data`` (plain lists, numbers, strings) as block-style YAML, keys in their order, text
    unescaped (``allow_unicode``).

    ``width`` is the preferred line width (None: PyYAML's 80); ``c_emitter`` uses libyaml's
    emitter where installed (block files: many models), the pure-Python one otherwise.
    """
    dumper = getattr(yaml, "CSafeDumper", yaml.SafeDumper) if c_emitter else yaml.SafeDumper
    return yaml.dump(data, Dumper=dumper, sort_keys=False, allow_unicode=True, width=width)
