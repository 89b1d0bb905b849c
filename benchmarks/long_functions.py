"""List functions longer than a limit (default 80 lines, def to last line) via ``ast``.

A function counts as justified when a comment says why: a line of the comment block right above
its ``def`` (or its first decorator), or a comment line inside the function, starting ``# long:``
or ``# Over 80 lines``.

python benchmarks/long_functions.py stereoplotter/geometry stereoplotter/accuracy [--limit 80]
"""

import argparse
import ast
import pathlib


def scan(paths, limit):
    out = []
    for root in paths:
        p = pathlib.Path(root)
        files = [p] if p.is_file() else sorted(p.rglob("*.py"))
        for f in files:
            text = f.read_text().splitlines()
            for node in ast.walk(ast.parse("\n".join(text))):
                if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                    n = node.end_lineno - node.lineno + 1
                    if n > limit:
                        top = min([node.lineno] + [d.lineno for d in node.decorator_list])
                        first = top - 1  # the comment block right above the def or decorator
                        while first > 0 and text[first - 1].lstrip().startswith("#"):
                            first -= 1
                        above = text[first : top - 1]
                        body = text[node.lineno - 1 : node.end_lineno]
                        why = any(
                            line.strip().startswith(("# long:", "# Over 80 lines"))
                            for line in above + body
                        )
                        out.append((str(f), node.lineno, node.name, n, why))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("paths", nargs="+")
    ap.add_argument("--limit", type=int, default=80)
    a = ap.parse_args()
    rows = scan(a.paths, a.limit)
    for f, ln, name, n, why in rows:
        print(f"{f}:{ln}: {name} {n} lines" + ("  (justified)" if why else ""))
    print(f"total {len(rows)}, unjustified {sum(not r[4] for r in rows)}")


if __name__ == "__main__":
    main()
