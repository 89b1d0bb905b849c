"""The procedure rows of ``verify`` against their formula: the ``as_formula`` block (the
procedure with every mechanism switch of :mod:`stereoplotter.procedure.fidelity` at the formula's
assumption) and the ``decomposition`` from it to the row's run, one switch a step.

Reads the results of :func:`~stereoplotter.verification.procedure_mc.procedure_mc` (photo mm
inside, the rows' units outside); pure numpy.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from stereoplotter.accuracy.setup_accuracy import setup_element_sigmas
from stereoplotter.procedure.fidelity import MECHANISMS, Fidelity, mechanism
from stereoplotter.verification import decomposition as dc

__all__ = [
    "CONVENTIONAL_REST",
    "ProcedureResults",
    "RunResult",
    "as_formula_block",
    "element_ratios",
    "procedure_value",
    "switch_chain",
    "switch_decomposition",
    "vertical_flat_block",
]

#: The result of one procedure-MC run (:func:`~.procedure_mc.procedure_mc`): named values of
#: several kinds (numbers, arrays, the geometry, nested blocks), as documented there.
RunResult = dict[str, Any]
#: The runs of a ``verify``: (slot, configuration) or (slot, configuration, "instrument") → run.
ProcedureResults = Mapping[tuple[str, ...], RunResult]


def procedure_value(
    res: Mapping[str, Any], field: str | None, scaled: bool
) -> tuple[float, float, float]:
    """(value, CI half-width, rigorous formula at the simulated geometry) of a row from its
    procedure-MC run: the ``field`` of a setup run, or the run's coefficient (the formula then
    with the levelling plane at the procedure's control points,
    :func:`~stereoplotter.verification.procedure_mc.levelling_formula`);
    × f/p if ``scaled``."""
    if field is not None:
        f = res["fields"][field]
        v, h, ref = f["coefficient"], f["ci"], f["formula"]
    else:  # the conventional formula with the plane at the procedure's own levelling points
        v, h, ref = res["coefficient"], res["ci"], res["formula"]["procedure"]
    k = res["f"] / res["p"] if scaled else 1.0
    return v * k, h * k, ref * k


def switch_chain(fidelity: Fidelity | None = None) -> list[str]:
    """The switches that take the setup method from the formula's assumptions to ``fidelity``
    (default: the competent operator's), in :data:`~stereoplotter.procedure.fidelity.MECHANISMS`
    order; the linkage left None counts as the instrument's (never the formula's)."""
    f = fidelity or Fidelity()
    return [
        m.name
        for m in MECHANISMS
        if getattr(f, m.name) != m.as_formula or (m.name == "linkage" and f.linkage is None)
    ]


#: The departures a conventional row's run keeps from its formula where it differs beyond the
#: CI (its configuration is the formula's otherwise: σ_q, σ_p as the formula, the relative
#: orientation by the six measured q and (5.11), 3 fixed passes, standard points at a = c − p),
#: each with the run that showed it; configuration → text.
_TILTED = (
    "the scenario's tilted photos and relief: on vertical photos over flat terrain "
    "(procedure_mc on idealised_geometry, python3 docs/make_verification_switches.py item 3) "
    "the σ_q part is the formula within its CI"
)
CONVENTIONAL_REST = {
    "y_parallax": _TILTED,
    "conventional": "its σ_q part (the y_parallax row, σ_q only): " + _TILTED,
}


def as_formula_block(
    eq: str,
    proc: ProcedureResults,
    slot: str,
    config: str,
    field: str | None,
    scaled: bool,
) -> dict[str, Any] | None:
    """The ``as_formula`` block of a procedure row: ``value``, ``ci``, ``ci_rel``, ``formula``
    (the rigorous formula at the simulated geometry), ``ratio``, ``agrees`` (|value − formula|
    ≤ CI), ``fidelity`` (the switches), ``trials``; where it does not agree, ``mechanism`` (what
    still differs, with the run that shows it; setup rows: ``elements``, each (6.22) element's
    RMS error in the as-formula run against (6.32)–(6.38)).

    Setup rows: the setup method with every switch at the formula's assumption
    (:meth:`Fidelity.as_formula`, configuration "setup_formula"). Conventional rows: the row's
    own run, whose configuration is the formula's (:data:`PROCEDURE_CONFIGS`)."""
    if field is not None:
        res = proc.get((slot, "setup_formula"))
        if res is None:
            return None
        fidelity: dict[str, Any] | None = {m.name: m.as_formula for m in MECHANISMS}
    else:
        res, fidelity = proc[(slot, config)], None
    v, h, ref = procedure_value(res, field, scaled)
    out: dict[str, Any] = {
        "value": v,
        "ci": h,
        "ci_rel": h / v,
        "formula": ref,
        "ratio": v / ref,
        "agrees": bool(abs(v - ref) <= h),
        "trials": res["trials"],
        "fidelity": fidelity,
        "mechanism": None,
    }
    if field is not None:
        out["elements"] = element_ratios(res)
        flat = proc.get((slot, "setup_formula_flat"))
        if flat is not None:
            out["vertical_flat"] = vertical_flat_block(flat, field, scaled)
        if not out["agrees"]:
            out["mechanism"] = _formula_rest(out)
    elif not out["agrees"]:
        out["mechanism"] = CONVENTIONAL_REST.get(config, "not traced (no switch run yet)")
    return out


def element_ratios(res: Mapping[str, Any]) -> dict[str, dict[str, float]]:
    """Each (6.22) element's RMS error in a setup run against (6.32)–(6.38) with the least-squares
    m_ω and the unit-consistent m_bz (``setup_element_sigmas(mode="rigorous")``), at m_x = m_y
    = n_л·σ, photo scale: element → (``procedure``, ``formula``, ``ratio``). b_y has no term
    in (6.22) and is left out."""
    n, f, fi = res["n"], res["f"], res["f_instrument"]
    sig = setup_element_sigmas(f, res["l"], n, n * res["sigma_mm"], mode="rigorous")
    rms = res["element_rms"]
    photo = {  # instrument units → photo scale
        "setting.base_x_mm": ("base_x", 1.0 / n),
        "setting.base_z_mm": ("base_z", f / (fi * n)),
        **{f"{s}.tan_{a}": (a, 1.0) for s in ("left", "right") for a in ("alpha", "omega")},
        **{f"{s}.kappa": ("kappa", 1.0) for s in ("left", "right")},
    }
    out = {}
    for key, (name, k) in photo.items():
        value, formula = rms[key] * k, float(sig[name])
        out[key] = {"procedure": value, "formula": formula, "ratio": value / formula}
    return out


def vertical_flat_block(res: Mapping[str, Any], field: str, scaled: bool) -> dict[str, Any]:
    """The as-formula run on the scenario with vertical photos over flat terrain
    (:func:`~stereoplotter.verification.procedure_mc.idealised_geometry`), against the formula
    there; for the unlevelled reading ("parallax", (6.39)–(6.44)) also against the formula with
    b_x's coefficient taken at the terrain's depth: the model of the terrain lies at
    D_t = H̄/M_в, not at the carriage's D = n_л·f_пр where the counters (and the formula's n)
    are, so δp/δb_x = f_пр/D_t = (D/D_t)/n_л; m_p² + (√2·m_x/n_л)²·((D/D_t)² − 1), per m_xy.
    ``value``, ``ci``, ``formula``, ``ratio``, ``depth_ratio`` (D/D_t), ``formula_at_depth``
    and ``ratio_at_depth``; ``elements`` as :func:`element_ratios`."""
    v, h, ref = procedure_value(res, field, scaled)
    out = {"value": v, "ci": h, "formula": ref, "ratio": v / ref, "trials": res["trials"]}
    if field == "parallax":
        k = res["n"] * res["f_instrument"] / res["terrain_depth_mm"]
        bx = math.sqrt(2.0) / res["n"]  # m_bx of (6.38) per m_xy = n_л·σ, photo scale
        at_depth = math.sqrt(ref**2 + bx**2 * (k**2 - 1.0))
        out.update(depth_ratio=k, formula_at_depth=at_depth, ratio_at_depth=v / at_depth)
    out["elements"] = element_ratios(res)
    return out


def _formula_rest(block: Mapping[str, Any]) -> str:
    """What still differs in the as-formula run, from the runs themselves: the elements whose
    RMS error departs from (6.32)–(6.38) by more than 5 %, and the run on vertical photos over
    flat terrain."""
    off = [
        f"{k.replace('setting.', '')} ×{e['ratio']:.2f}"
        for k, e in block["elements"].items()
        if abs(e["ratio"] - 1.0) > 0.05
    ]
    what = ", ".join(off) if off else "none beyond 5 %"
    text = f"elements' RMS errors against (6.32)–(6.38): {what}"
    flat = block.get("vertical_flat")
    if flat is None:
        return text + "; not traced further (no run on vertical photos over flat terrain)"
    text += (
        f"; the scenario's tilted photos and relief: on vertical photos over flat terrain "
        f"the as-formula run is {flat['ratio']:.4f} of the formula there"
    )
    if "ratio_at_depth" in flat:
        text += (
            f", and {flat['ratio_at_depth']:.4f} of it with b_x's coefficient at the terrain's "
            f"depth (the carriage at D = {flat['depth_ratio']:.4f}·H̄/M_в: the sheet's D_max "
            "and the round vertical scale M_в put the terrain's model above the counters' "
            "depth, which (6.22)/(6.38) take as one n)"
        )
    return text


def switch_decomposition(
    proc: ProcedureResults,
    slot: str,
    field: str | None,
    scaled: bool,
    as_formula: Mapping[str, Any] | None,
) -> dict[str, Any]:
    """The ``decomposition`` block: from the ``as_formula`` run to the row's run, one switch a
    step (:func:`switch_chain`), each step a paired difference of RMS values on the first
    :data:`STEP_TRIALS` trials of the setup run's seed, with its CI; ``sum`` = the as-formula
    value on those trials + Σ steps (= the row's run on them, plain mean), ``closes``: the sum
    agrees with the row's value within the two CIs. Conventional rows: no step (their run is
    the as-formula one)."""
    if field is None or as_formula is None:
        v = as_formula["value"] if as_formula else None
        h = as_formula["ci"] if as_formula else None
        return {
            "as_formula": {"value": v, "ci": h},
            "steps": [],
            "sum": v,
            "procedure": {"value": v, "ci": h},
            "closes": True,
        }
    main = proc[(slot, "setup")]
    runs = [proc[(slot, "setup_formula")]] + [proc[(slot, c)] for c in _step_names(proc, slot)]
    runs.append(main)
    k = main["f"] / main["p"] if scaled else 1.0
    fields = [r["fields"][field] for r in runs]
    t = min(len(f["mean_squares"]) for f in fields)
    unit = fields[0]["unit"] / k
    ms = [np.asarray(f["mean_squares"][:t], float) for f in fields]
    start, start_ci = dc.rms_ci(ms[0], unit)
    ref = as_formula["formula"]
    steps = []
    for i, name in enumerate(switch_chain(main.get("fidelity"))):
        c, h = dc.paired_step(ms[i + 1], ms[i], unit)
        m = mechanism(name)
        steps.append({
            "step": name,
            "switch": m.option(m.as_formula),
            "to": getattr(main.get("fidelity"), name, None),
            "text": m.basis,
            "contribution": c,
            "ci": h,
            "relative": c / ref,
        })  # fmt: skip
    _, end_ci = dc.rms_ci(ms[-1], unit)
    value, ci, _ = procedure_value(main, field, scaled)
    total = start + sum(s["contribution"] for s in steps)
    return {
        "as_formula": {"value": start, "ci": start_ci, "trials": t},
        "steps": steps,
        "sum": total,
        "sum_ci": end_ci,
        "procedure": {"value": value, "ci": ci},
        "closes": bool(abs(total - value) <= end_ci + ci),
        "linkage": main.get("linkage"),
    }


def _step_names(proc: ProcedureResults, slot: str) -> list[str]:
    """The step configurations run at ``slot``, in order."""
    names = [k[1] for k in proc if len(k) == 2 and k[0] == slot and k[1].startswith("setup_step")]
    return sorted(names, key=lambda c: int(c.rsplit("_", 1)[1]))
