"""Code that speaks of the code: no module reads another module's private names, every import
inside a function of the package says why it is there (``docs/architecture.md``), and no
package module, test or benchmark refers to the tracker's numbers or to working sessions.

A private name is one with a leading underscore (not a dunder). "Another module's" means a name
a module of the package defines — a module-level function, class or variable, a method, or an
attribute it assigns on ``self`` — used in a file that does not define it: imported
(``from stereoplotter.x import _name``), read on a module (``x._name``) or on an object
(``inst._name``, ``getattr(inst, "_name")``, ``monkeypatch.setattr(x, "_name", …)``). The
privates of the standard library and of other packages are not the package's to change and are
not checked.
"""

from __future__ import annotations

import ast
import functools
import re
from collections import defaultdict
from pathlib import Path

import stereoplotter

PACKAGE = Path(stereoplotter.__file__).parent
ROOT = PACKAGE.parent
#: Where the package's privates may be read: ``file → names``, each with its reason.
PRIVATE_READS_ALLOWED: dict[str, set[str]] = {
    # the compaction cuts a run to its active trials and puts the cut back: it copies the
    # instrument's caches and the operator's stop masks with the rest of their per-trial state
    "stereoplotter/procedure/compaction.py": {"_unit_maps", "_setting_cache", "_stops"},
    # the phases benchmark wraps the procedure run's field set-up in a clock to time it apart
    "benchmarks/bench_verify.py": {"_setup_fields", "_conventional_fields"},
}
_ATTR_CALLS = {"getattr", "hasattr", "setattr", "delattr"}
#: The kinds of file searched for tracker numbers.
_TEXTS = (".py", ".md", ".js", ".html", ".yaml", ".txt")


def _private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


@functools.cache
def _trees() -> dict[str, tuple[list[str], ast.Module]]:
    """Every Python file of the package, the tests and the benchmarks: its lines and its tree."""
    out = {}
    for folder in ("stereoplotter", "tests", "benchmarks"):
        for path in sorted((ROOT / folder).rglob("*.py")):
            text = path.read_text(encoding="utf-8")
            out[path.relative_to(ROOT).as_posix()] = (text.splitlines(), ast.parse(text))
    return out


def _defined(tree: ast.AST) -> set[str]:
    """The private names a module defines (see the module docstring)."""
    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            out.add(node.name)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            out.add(node.id)
        elif (
            isinstance(node, ast.Attribute)
            and isinstance(node.ctx, ast.Store)
            and isinstance(node.value, ast.Name)
            and node.value.id in ("self", "cls")
        ):
            out.add(node.attr)
    return {n for n in out if _private(n)}


def _used(tree: ast.AST) -> list[tuple[int, str]]:
    """(line, name) of every private name a module takes from elsewhere or off an object."""
    out: list[tuple[int, str]] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("stereoplotter"):
            out += [(node.lineno, a.name) for a in node.names if _private(a.name)]
        elif isinstance(node, ast.Attribute) and _private(node.attr):
            v = node.value
            if not (isinstance(v, ast.Name) and v.id in ("self", "cls")):
                out.append((node.lineno, node.attr))
        elif isinstance(node, ast.Call) and len(node.args) >= 2:
            f = node.func
            name = getattr(f, "id", None) or getattr(f, "attr", "")
            obj, arg = node.args[0], node.args[1]
            on_self = isinstance(obj, ast.Name) and obj.id == "self"
            if name in _ATTR_CALLS and isinstance(arg, ast.Constant) and not on_self:
                if isinstance(arg.value, str) and _private(arg.value):
                    out.append((node.lineno, arg.value))
    return out


def test_no_private_name_is_read_across_modules():
    trees = {rel: tree for rel, (_, tree) in _trees().items()}
    owners: dict[str, set[str]] = defaultdict(set)
    for rel, tree in trees.items():
        if rel.startswith("stereoplotter/"):
            for name in _defined(tree):
                owners[name].add(rel)
    offenders = []
    for rel, tree in trees.items():
        own = _defined(tree)
        allowed = PRIVATE_READS_ALLOWED.get(rel, set())
        for line, name in _used(tree):
            if name in owners and name not in own and name not in allowed:
                where = ", ".join(sorted(owners[name]))
                offenders.append(f"{rel}:{line}: {name} (defined in {where})")
    assert offenders == []


def _import_groups(tree: ast.AST):
    """Runs of consecutive import statements in the bodies of functions: (first, last line)."""
    for fn in ast.walk(tree):
        if not isinstance(fn, ast.FunctionDef | ast.AsyncFunctionDef):
            continue
        for holder in ast.walk(fn):
            for field in ("body", "orelse", "finalbody"):
                body = getattr(holder, field, None)
                if not isinstance(body, list):
                    continue
                group: list[ast.stmt] = []
                for st in [*body, None]:
                    if isinstance(st, ast.Import | ast.ImportFrom):
                        group.append(st)
                    elif group:
                        yield group[0].lineno, group[-1].end_lineno
                        group = []


def test_every_import_inside_a_function_says_why():
    missing = set()
    for rel, (lines, tree) in _trees().items():
        if not rel.startswith("stereoplotter/"):
            continue
        for first, last in _import_groups(tree):
            block = lines[first - 1 : last]
            above = lines[first - 2].strip() if first >= 2 else ""
            if not (above.startswith("#") or any("#" in line for line in block)):
                missing.add(f"{rel}:{first}: {block[0].strip()}")
    assert sorted(missing) == []


def test_no_tracker_numbers_or_sessions():
    pattern = re.compile(r"issue [0-9]+|session [0-9]")
    found = []
    for folder in ("stereoplotter", "tests", "benchmarks"):
        for path in sorted((ROOT / folder).rglob("*")):
            if path.suffix not in _TEXTS or not path.is_file():
                continue
            for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
                if pattern.search(line):
                    found.append(f"{path.relative_to(ROOT).as_posix()}:{n}: {line.strip()}")
    assert found == []
