"""Figures for the accuracy verification (matplotlib, Agg backend; edge layer only).

* :func:`plot_error_maps` — RMS x-parallax error over the working area per error source
  (like Fig. 40 of the book), from exact covariance propagation;
* :func:`plot_mc_histogram` — per-trial RMS of a Monte Carlo row against the formula's σ;
* :func:`plot_mc_histograms` — the figure ``verify -o`` writes: per-trial RMS of the procedure
  MC (setup data, conventional; 60 %, 80 %) and of two linear-MC rows against the formulas;
* :func:`plot_verification_chart` — printed / book / rigorous / MC per row.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from stereoplotter.accuracy import setup_accuracy as sa
from stereoplotter.verification import linear_mc as mc
from stereoplotter.verification.entry import BOOK, both_photos

__all__ = ["plot_error_maps", "plot_mc_histogram", "plot_mc_histograms", "plot_verification_chart"]


def plot_error_maps(
    focal_length_mm=70.0,
    x_parallax_mm=70.0,
    a_mm=0.0,
    c_mm=70.0,
    sigmas=None,
    *,
    levelled=True,
    grid=(32, 64),
):
    """Maps of the pointwise σ of δp per setup-element source (one panel each) [mm].

    Returns
    -------
    matplotlib.figure.Figure
    """
    if sigmas is None:
        sigmas = both_photos(sa.setup_element_sigmas(focal_length_mm, 85.0, 1.42, 0.01))
    names = [k for k in mc.SETUP_SOURCES if sigmas.get(k, 0.0)]
    fig, axes = plt.subplots(
        2, (len(names) + 1) // 2, figsize=(3 * len(names) / 2 + 1, 6), squeeze=False
    )
    for ax, name in zip(axes.ravel(), names, strict=False):
        m = mc.setup_model(
            focal_length_mm,
            x_parallax_mm,
            a_mm,
            c_mm,
            {name: sigmas[name]},
            levelled=levelled,
            grid=grid,
        )
        Ge = mc.effective_G(m)
        sd = np.sqrt(np.einsum("kp,kl,lp->p", Ge, m.M @ m.M.T, Ge)).reshape(grid)
        im = ax.imshow(sd.T * 1000, origin="lower", aspect="auto")
        ax.set_title(f"{name} [µm]")
        fig.colorbar(im, ax=ax)
    for ax in axes.ravel()[len(names) :]:
        ax.set_visible(False)
    fig.tight_layout()
    return fig


def plot_mc_histogram(model, sigma_formula, trials=20000, seed=0, ax=None):
    """Histogram of per-trial RMS over the domain, with the formula's σ marked.

    Returns
    -------
    matplotlib.axes.Axes
    """
    if ax is None:
        _, ax = plt.subplots()
    rms, h, per_trial = mc.mc_rms(model, trials, np.random.default_rng(seed))
    ax.hist(np.sqrt(per_trial), bins=60, color="0.7")
    ax.axvline(sigma_formula, color="r", label=f"formula {sigma_formula:.4g}")
    ax.axvline(rms, color="b", ls="--", label=f"MC RMS {rms:.4g} ± {h:.2g}")
    ax.legend()
    return ax


def _row_label(r) -> str:
    """The row's equation, with its overlap when the quantity names one ((5.54) 60 %)."""
    q = r["quantity"]
    ov = next((f" {o} %" for o in ("60", "80") if f"{o} %" in q), "")
    return r["eq"] + ("" if ov and ov.strip() in r["eq"] else ov)


def plot_verification_chart(rows, ax=None):
    """Ratio printed/rigorous, from-printed-inputs/rigorous, book/rigorous and MC/rigorous per
    row, on a log axis (the printed values of misprinted rows are off by factors up to 70).

    Returns
    -------
    matplotlib.axes.Axes
    """
    if ax is None:
        _, ax = plt.subplots(figsize=(14, 5.5))
    idx = np.arange(len(rows))
    rig = np.array([r["rigorous"] for r in rows])
    series = (
        ("printed", "o", "printed"),
        ("from_printed_inputs", "D", "from printed inputs"),
        ("book", "s", "book formula"),
        ("mc_linear", "x", "linear MC"),
    )
    for key, marker, label in series:
        v = np.array([np.nan if r.get(key) is None else r[key] for r in rows], float)
        ax.plot(idx, v / rig, marker, label=label, ls="none", ms=6, mfc="none")
    ax.set_yscale("log")
    ax.axhline(1.0, color="k", lw=0.6)
    for lim in (0.995, 1.005):
        ax.axhline(lim, color="0.6", lw=0.4, ls=":")
    ax.set_xticks(idx, [_row_label(r) for r in rows], rotation=60, ha="right", fontsize=8)
    ax.set_xlim(-0.7, len(rows) - 0.3)
    ax.grid(axis="x", color="0.9", lw=0.5)
    lo, hi = np.nanmin(ax.get_ylim()), np.nanmax(ax.get_ylim())
    ticks = [v for v in (0.2, 0.5, 1.0, 2, 5, 10, 20, 50, 100) if lo <= v <= hi]
    ax.set_yticks(ticks, [f"{v:g}" for v in ticks])
    ax.minorticks_off()
    ax.set_ylabel("value / rigorous (log)")
    ax.set_title("Verification table: each column against the rigorous value", fontsize=10)
    ax.legend(fontsize=8, ncol=4, loc="upper right")
    ax.figure.tight_layout()
    return ax


def _procedure_reference(res) -> float:
    """The rigorous formula at the procedure's simulated geometry (f, p, c, a, l, n of the run)."""
    if res["method"] == "setup":
        return float(
            sa.setup_parallax_rms_from_pointing(
                res["f"], res["p"], res["c"], res["l"], res["n"], 1.0, mode="rigorous"
            )
        )
    return float(
        sa.conventional_parallax_rms(res["a"], res["c"], res["p"], res["f"], 1.0, 1.0, "rigorous")
    )


def plot_mc_histograms(rows, procedure=None, trials=4000, seed=0, geometry=None):
    """Histograms of per-trial RMS / σ for representative rows, each against the rigorous
    formula at the geometry it simulates.

    Parameters
    ----------
    rows : list of dict
        Verification rows (their rigorous values, at ``geometry``).
    procedure : dict, optional
        :func:`~stereoplotter.verification.table.run_procedure_mc` output; one panel per
        (overlap, method) with the per-trial coefficient, the procedure-MC RMS and the rigorous
        formula at the scenario's own f, p, c, a, l, n.
    geometry : mapping, optional
        The table's geometry (keys of ``BOOK``; default the book's) for the linear-MC panels.

    Returns
    -------
    matplotlib.figure.Figure
    """
    by = {r["eq"]: r for r in rows}
    panels = []
    g = {**BOOK, **(geometry or {})}
    sb = both_photos(sa.setup_element_sigmas(g["f"], g["l"], g["n"], 1.0, mode="rigorous"))
    for eq, p, a in (("(6.43)", g["p60"], g["a60"]), ("(6.44)", g["p80"], g["a80"])):
        m = mc.setup_model(g["f"], p, a, g["c"], sb, levelled=False)
        panels.append(("linear", eq, m, by[eq]["rigorous"]))
    shown = {
        k: v
        for k, v in (procedure or {}).items()
        if len(k) == 2 and k[1] in ("setup", "conventional")  # the ideal runs of (6.43)/(6.60)
    }
    for (slot, method), res in sorted(shown.items()):
        eq = {"setup": "(6.43)", "conventional": "(6.60)"}[method]
        if slot == "80":
            eq = {"(6.43)": "(6.44)", "(6.60)": "(6.61)"}[eq]
        panels.append(("procedure", eq, res, _procedure_reference(res)))
    cols = 3 if len(panels) > 4 else 2
    nrows = (len(panels) + cols - 1) // cols
    fig, axes = plt.subplots(nrows, cols, figsize=(5.2 * cols, 3.6 * nrows), squeeze=False)
    for ax, (kind, eq, obj, formula) in zip(axes.ravel(), panels, strict=False):
        if kind == "linear":
            plot_mc_histogram(obj, formula, trials=trials, seed=seed, ax=ax)
            ax.set_title(
                f"{eq} linear MC, per m_xy (f = {g['f']:g}, l = {g['l']:.3g}, n = {g['n']:.3g})",
                fontsize=9,
            )
        else:
            ax.hist(obj["per_trial"], bins=50, color="0.7")
            ax.axvline(formula, color="r", label=f"rigorous at simulated geometry {formula:.3g}")
            ax.axvline(
                obj["coefficient"],
                color="b",
                ls="--",
                label=f"procedure MC {obj['coefficient']:.3g} ± {obj['ci']:.2g}",
            )
            unit = "m_xy = n_л σ" if obj["method"] == "setup" else "m_p = m_q = σ"
            ax.set_title(
                f"{eq} procedure MC {obj['scenario']}, {obj['method']}, per {unit}\n"
                f"p = {obj['p']:.1f}, c = {obj['c']:.1f}, n = {obj['n']:.2f}",
                fontsize=9,
            )
            ax.legend(fontsize=7)
        ax.set_xlabel("per-trial RMS of δp / σ")
    for ax in axes.ravel()[len(panels) :]:
        ax.set_visible(False)
    fig.tight_layout()
    return fig
