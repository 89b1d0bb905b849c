"""The "As formula" and "Decomposition" tables of ``docs/accuracy.md`` from ``verify --json``.

Run from the repository root::

    stereoplotter verify --json > verify.json
    python3 docs/make_as_formula_tables.py verify.json

(or without an argument, which runs ``verify --json`` with its defaults). Prints the two
Markdown tables: each row's ``as_formula`` block (value ± CI, the formula at the simulated
geometry, their ratio, the run on vertical photos over flat terrain and b_x at the terrain's
depth) beside the default procedure MC, and each setup row's ``decomposition`` (one switch a
step, as shares of the formula at the simulated geometry).
"""

from __future__ import annotations

import json
import sys

# the table's rows: label, the eq whose JSON row it prints (the others in the label repeat it)
AS_FORMULA_ROWS = (
    ("(6.39), (6.41), (6.43)", "(6.39)"),
    ("(6.40), (6.42), (6.44)", "(6.40)"),
    ("(6.47), (6.49)", "(6.47)"),
    ("(6.48), (6.50)", "(6.48)"),
    ("(6.58)", "(6.58)"),
    ("(6.59)", "(6.59)"),
    ("(6.45), (6.60)", "(6.45)"),
    ("(6.46), (6.53), (6.61)", "(6.46)"),
    ("(6.51), (6.56)", "(6.51)"),
    ("(6.52), (6.57)", "(6.52)"),
    ("(6.54)", "(6.54)"),
    ("(6.55) (k = ·f/p)", "(6.55)"),
)
DECOMPOSITION_ROWS = ("(6.39)", "(6.40)", "(6.47)", "(6.48)", "(6.58)", "(6.59)")
AS_FORMULA_HEAD = (
    "| row | as formula ± CI | formula at the simulated geometry | ratio | vertical photos, "
    "flat terrain: ratio | … b_x at the terrain's depth | default (procedure MC) |\n"
    "|---|---|---|---|---|---|---|"
)


def _by_eq(rows: list[dict]) -> dict[str, dict]:
    out: dict[str, dict] = {}
    for r in rows:
        out.setdefault(r["eq"], r)
    return out


def _signed(x: float, d: int = 1) -> str:
    s = f"{x:+.{d}f}"
    return s.replace("-", "−")


def as_formula_rows(rows: list[dict]) -> list[str]:
    """One Markdown line per row of AS_FORMULA_ROWS."""
    eq = _by_eq(rows)
    out = []
    for label, key in AS_FORMULA_ROWS:
        r = eq[key]
        a = r["as_formula"]
        vf = a.get("vertical_flat")
        vertical = f"{vf['ratio']:.4f}" if vf else "—"
        depth = f"{vf['ratio_at_depth']:.4f}" if vf and vf.get("ratio_at_depth") else "—"
        out.append(
            f"| {label} | {a['value']:.4f} ± {a['ci']:.4f} | {a['formula']:.4f} | "
            f"{a['ratio']:.4f} | {vertical} | {depth} | "
            f"{r['mc_procedure']:.4f} ± {r['mc_procedure_ci']:.4f} |"
        )
    return out


def decomposition_rows(rows: list[dict]) -> tuple[str, list[str]]:
    """The header (the steps' switches) and one Markdown line per setup row."""
    eq = _by_eq(rows)
    first = eq[DECOMPOSITION_ROWS[0]]["decomposition"]["steps"]
    switches = [s["switch"].replace("-", "−") for s in first]
    head = (
        "| row | as formula, same trials | "
        + " | ".join(f"`{s}`" for s in switches)
        + " | sum | procedure MC | closes |\n|"
        + "---|" * (len(switches) + 5)
    )
    out = []
    for key in DECOMPOSITION_ROWS:
        d = eq[key]["decomposition"]
        cells = []
        for s in d["steps"]:
            formula = s["contribution"] / s["relative"] if s["relative"] else float("nan")
            ci = 100 * s["ci"] / formula if s["relative"] else 0.0
            cells.append(f"{_signed(100 * s['relative'])} ± {ci:.1f}")
        a, p = d["as_formula"], d["procedure"]
        out.append(
            f"| {key} | {a['value']:.4f} ± {a['ci']:.4f} | " + " | ".join(cells) + " | "
            f"{d['sum']:.4f} ± {d['sum_ci']:.4f} | {p['value']:.4f} ± {p['ci']:.4f} | "
            f"{'yes' if d['closes'] else 'no'} |"
        )
    return head, out


def main(argv: list[str]) -> int:
    if argv:
        with open(argv[0], encoding="utf-8") as fh:
            rows = json.load(fh)
    else:
        import contextlib
        import io

        from stereoplotter.cli import main as cli

        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            cli(["verify", "--json", "-q"])
        rows = json.loads(buf.getvalue())
    print(AS_FORMULA_HEAD)
    print("\n".join(as_formula_rows(rows)))
    print()
    head, lines = decomposition_rows(rows)
    print(head)
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
