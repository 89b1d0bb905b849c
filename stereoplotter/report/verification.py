"""The verification table as text: Markdown, CSV and JSON files, and the console summary."""

from __future__ import annotations

import csv
import io
import json

from stereoplotter.verification import linear_mc as mc
from stereoplotter.verification import table
from stereoplotter.verification.table import CSV_KEYS, closing_comparison

__all__ = ["verification_console", "verification_files", "verification_markdown"]


def _fmt(v, digits=4):
    if v is None:
        return "—"
    if isinstance(v, float):
        return f"{v:.{digits}g}" if abs(v) < 1e-3 or abs(v) >= 1e4 else f"{v:.{digits}f}"
    return str(v)


def _proc(r, key="mc_procedure"):
    if r.get(key) is None:
        return "—"
    return f"{_fmt(r[key])} ± {r[key + '_ci']:.2g}"


def _procedure_trials_text(trials) -> str:
    if trials == 0:
        return ""
    if trials is None:
        per = ", ".join(f"{k} {v}" for k, v in table.PROCEDURE_TRIALS.items())
        inst = ", ".join(f"{k} {v}" for k, v in table.INSTRUMENT_TRIALS.items())
        return f", procedure MC trials per run: {per}; with instrument errors: {inst}"
    return f", procedure MC trials = {trials}"


def verification_markdown(rows, closing, meta):
    """``verification.md``: the rows and the closing comparison; ``meta`` holds trials, seed,
    seconds and procedure_trials."""
    lines = [
        "# Verification of Kushtin & Lyskov 1984, §27 and chapter 5",
        "",
        f"trials = {meta['trials']}, seed = {meta['seed']}, CI = ±{mc.CI_Z} s.e. (99.9 %),"
        f" runtime {meta['seconds']:.1f} s" + _procedure_trials_text(meta.get("procedure_trials")),
        "",
        "Verdicts are decided from the numbers (stereoplotter/verification/verdicts.py): a printed "
        "number agrees when the value rounded or truncated to its decimals equals it (both are "
        "shown), formula values within 0.5 %; `convention` and `not reproducible` are the "
        "row's own findings (docs/errata.md). *from printed inputs*: the book's arithmetic "
        "redone from its own printed intermediates.",
        "",
        "| eq | quantity | printed | from printed inputs | book | rigorous | covariance | "
        "linear MC ± CI | procedure MC ± CI | formula at the simulated geometry | procedure MC "
        "with instrument errors | verdict | note |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['eq']} | {r['quantity']} | {_fmt(r['printed'])} | "
            f"{_fmt(r.get('from_printed_inputs'))} | {_fmt(r['book'])} | "
            f"{_fmt(r['rigorous'])} | {_fmt(r['covariance'])} | {_fmt(r['mc_linear'])} ± "
            f"{r['mc_linear_ci']:.2g} | {_proc(r)} | {_fmt(r.get('mc_procedure_formula'))} | "
            f"{_proc(r, 'mc_procedure_instrument')} | {r['verdict']} | {r['note']} |"
        )
    lines += [
        "",
        "## Closing comparison (setup data vs conventional method)",
        "",
        "| overlap | book claim | printed setup/conv | book setup/conv (gain) | "
        "rigorous setup/conv (gain) | MC setup/conv | procedure MC setup/conv (gain) |",
        "|---|---|---|---|---|---|---|",
    ]
    for c in closing:
        lines.append(
            f"| {c['overlap']} | {c['book_claim']} | {_fmt(c['setup_printed'], 2)} / "
            f"{_fmt(c['conventional_printed'], 2)} | {_fmt(c['setup_book'])} / "
            f"{_fmt(c['conventional_book'])} ({c['gain_book']:+.0%}) | "
            f"{_fmt(c['setup_rigorous'])} / {_fmt(c['conventional_rigorous'])} "
            f"({c['gain_rigorous']:+.0%}) | {_fmt(c['setup_mc_linear'])} / "
            f"{_fmt(c['conventional_mc_linear'])} | {_fmt(c['setup_mc_procedure'])} / "
            f"{_fmt(c['conventional_mc_procedure'])}"
            + (f" ({c['gain_mc_procedure']:+.0%})" if c["gain_mc_procedure"] is not None else "")
            + " |"
        )
    return "\n".join(lines + decomposition_markdown(rows)) + "\n"


_STEP_HEAD = {
    "geometry": "geometry",
    "element_errors": "(6.22) elements, own errors",
    "principal_distance": "f_пр as set",
    "decentrations": "decentrations, MO",
    "non_linear": "non-linear rest",
    "levelling_points": "procedure's levelling points",
    "procedure": "rest of the procedure",
}


def decomposition_markdown(rows) -> list[str]:
    """Each procedure row against its formula: the procedure with every mechanism switch at the
    formula's assumption (``as_formula``: value ± CI, ratio to the formula at the simulated
    geometry), the steps from it to the row's run, one switch each (contribution ± CI, 99.9 %,
    share of the formula), their sum and the row's value; then the first-order breakdown of the
    row's own trials (``decomposition.first_order``)."""
    rows = [r for r in rows if r.get("decomposition")]
    if not rows:
        return []
    out = [
        "",
        "## Decomposition of the procedure rows",
        "",
        "As formula: the procedure with every mechanism switch at the formula's assumption "
        "(`--as-formula`); ratio to the formula at the simulated geometry. Steps: from it to the "
        "row's run, one switch each (`switch`: the flag that removes the step), paired on the "
        "same trials, ± CI (99.9 %). *closes*: as formula + Σ steps agrees with the row's value "
        "within the CIs. Vertical photos, flat terrain: the as-formula run's ratio to the "
        "formula on the scenario's vertical-photo, flat-terrain twin (and, unlevelled rows, with "
        "b_x's coefficient at the terrain's model depth H̄/M_в). Conventional rows: their run is "
        "the as-formula one (no step).",
        "",
        "| eq | as formula | ratio | vertical photos, flat terrain | steps | sum | procedure MC "
        "| closes |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        a, d = r["as_formula"], r["decomposition"]
        flat = a.get("vertical_flat")
        shown = "—"
        if flat is not None:
            shown = f"{flat['ratio']:.4f}"
            if "ratio_at_depth" in flat:
                shown += f"; b_x at the terrain's depth {flat['ratio_at_depth']:.4f}"
        steps = (
            "; ".join(
                f"{s['switch']} {s['contribution']:+.4f} ± {s['ci']:.4f} ({s['relative']:+.1%})"
                for s in d["steps"]
            )
            or "—"
        )
        out.append(
            f"| {r['eq']} | {a['value']:.4f} ± {a['ci']:.4f} | {a['ratio']:.4f}"
            f"{'' if a['agrees'] else ' (differs)'} | {shown} | {steps} | {d['sum']:.4f} | "
            f"{d['procedure']['value']:.4f} ± {d['procedure']['ci']:.4f} | "
            f"{'yes' if d['closes'] else 'NO'} |"
        )
    out += [
        "",
        "### First order of the row's own trials",
        "",
        "Formula at the book geometry → at the simulated geometry → first order of each "
        "trial's own errors (the (6.22) elements, then f_пр, then the decentrations and model "
        "origin) → the procedure; every step on the same trials, ± CI (99.9 %). Conventional "
        "rows: → the formula with the plane at the procedure's levelling points → the rest. "
        "*closes*: book + Σ steps (the plain mean) agrees with the row's value within the CIs.",
        "",
        "| eq | linkage | book geometry | steps | sum | procedure MC | closes |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        d = r["decomposition"]["first_order"]
        steps = "; ".join(
            f"{_STEP_HEAD.get(s['step'], s['step'])} {s['contribution']:+.4f} ± {s['ci']:.4f} "
            f"({s['relative']:+.1%})"
            for s in d["steps"]
        )
        out.append(
            f"| {r['eq']} | {d.get('linkage') or '—'} | {d['values']['book_geometry']['value']:.4f}"
            f" | {steps} | {d['sum']:.4f} | {d['procedure']['value']:.4f} ± "
            f"{d['procedure']['ci']:.4f} | {'yes' if d['closes'] else 'NO'} |"
        )
    return out


def verification_files(
    rows: list[dict], *, trials=None, seed=None, seconds=0.0, procedure_trials=None
) -> dict[str, bytes]:
    """``verification.md``, ``verification.csv``, ``verification.json`` and
    ``closing_comparison.json`` of the rows, rendered in memory."""
    closing = closing_comparison(rows)
    meta = {
        "trials": trials,
        "seed": seed,
        "seconds": seconds,
        "procedure_trials": procedure_trials,
    }
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=list(CSV_KEYS), extrasaction="ignore")
    w.writeheader()
    for r in rows:
        w.writerow({k: ("" if r.get(k) is None else r.get(k)) for k in CSV_KEYS})
    files = {
        "verification.md": verification_markdown(rows, closing, meta),
        "verification.csv": buf.getvalue(),
        "verification.json": json.dumps(rows, ensure_ascii=False, indent=1),
        "closing_comparison.json": json.dumps(closing, ensure_ascii=False, indent=1),
    }
    return {name: text.encode("utf-8") for name, text in files.items()}


def _cell(v) -> str:
    return f"{v:10.4g}" if isinstance(v, int | float) else f"{'—':>10}"


def verification_console(rows: list[dict], *, trials, seed, seconds, output=None) -> str:
    """What ``verify`` prints: one line per row (printed, rigorous, linear MC, procedure MC,
    verdict), and the files written into ``output``."""
    lines = [
        f"verification of Eqs. (6.28)–(6.61): {len(rows)} rows, {trials} trials, "
        f"seed {seed}, {seconds:.1f} s",
        "",
        f"{'eq':<14}{'printed':>10}{'rigorous':>10}{'MC':>10}{'proc. MC':>10}  verdict",
    ]
    for r in rows:
        lines.append(
            f"{r['eq']:<14}{_cell(r['printed'])}{_cell(r['rigorous'])}{_cell(r['mc_linear'])}"
            f"{_cell(r['mc_procedure'])}  {r['verdict']}"
        )
    if output:
        lines.append(
            f"\nwritten: verification.md, .csv, .json, closing_comparison.json, "
            f"error_maps.png, verification_chart.png, mc_histograms.png in {output}"
        )
    return "\n".join(lines) + "\n"
