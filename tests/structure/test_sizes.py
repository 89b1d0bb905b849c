"""Small modules, short functions: no module of the package over 1,000 lines, no function over
80 lines but the ones listed here, none longer than when it was listed.

The list only shrinks: a new long function fails this test, and so does a listed one that has
been split (remove it from the list then).
"""

from __future__ import annotations

import ast
from pathlib import Path

import stereoplotter

PACKAGE = Path(stereoplotter.__file__).parent
MAX_MODULE_LINES = 1000
MAX_FUNCTION_LINES = 80

#: Functions over the limit → their length in lines when listed, which they may not exceed. Empty:
#: no function of the package is over the limit, and the list can only shrink.
LONG_FUNCTIONS: dict[str, int] = {}


def _sizes():
    modules, functions = {}, {}
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        text = path.read_text(encoding="utf-8")
        modules[rel] = text.count("\n")
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                functions[f"{rel}:{node.name}"] = node.end_lineno - node.lineno + 1
    return modules, functions


def test_no_module_over_1000_lines():
    modules, _ = _sizes()
    assert {m: n for m, n in modules.items() if n > MAX_MODULE_LINES} == {}


def test_long_functions_are_only_the_listed_ones():
    _, functions = _sizes()
    long = {f for f, n in functions.items() if n > MAX_FUNCTION_LINES}
    assert long - set(LONG_FUNCTIONS) == set(), "new functions over 80 lines"
    assert set(LONG_FUNCTIONS) - long == set(), "split: remove them from LONG_FUNCTIONS"
    grown = {f: functions[f] for f in long if functions[f] > LONG_FUNCTIONS[f]}
    assert grown == {}, "listed functions grew"
