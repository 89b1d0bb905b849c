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

from stereoplotter.verification import linear_mc as mc

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
    from stereoplotter.accuracy.setup_accuracy import setup_element_sigmas
    from stereoplotter.verification.entry import both_photos as _both

    if sigmas is None:
        sigmas = _both(setup_element_sigmas(focal_length_mm, 85.0, 1.42, 0.01))
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
        Ge = mc._effective_G(m)
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


def plot_verification_chart(rows, ax=None):
    """Ratio printed/rigorous, book/rigorous and MC/rigorous per row.

    Returns
    -------
    matplotlib.axes.Axes
    """
    if ax is None:
        _, ax = plt.subplots(figsize=(12, 4))
    idx = np.arange(len(rows))
    rig = np.array([r["rigorous"] for r in rows])
    for key, marker in (("printed", "o"), ("book", "s"), ("mc_linear", "x")):
        v = np.array([np.nan if r[key] is None else r[key] for r in rows], float)
        ax.plot(idx, v / rig, marker, label=key, ls="none")
    ax.axhline(1.0, color="k", lw=0.5)
    ax.set_xticks(idx, [r["eq"] for r in rows], rotation=90, fontsize=7)
    ax.set_ylabel("value / rigorous")
    ax.legend()
    return ax


def plot_mc_histograms(rows, procedure=None, trials=4000, seed=0):
    """Histograms of per-trial RMS / σ for representative rows.

    Parameters
    ----------
    rows : list of dict
        Verification rows (for the formula values).
    procedure : dict, optional
        :func:`~stereoplotter.verification.table.run_procedure_mc` output; one panel per
        (overlap, method) with the per-trial coefficient, the procedure-MC RMS and the formula.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from stereoplotter.accuracy import setup_accuracy as sa
    from stereoplotter.verification.entry import BOOK
    from stereoplotter.verification.entry import both_photos as _both

    by = {r["eq"]: r for r in rows}
    panels = []
    g = BOOK
    sb = _both(sa.setup_element_sigmas(g["f"], g["l"], g["n"], 1.0))
    for eq, p, a in (("(6.43)", g["p60"], g["a60"]), ("(6.44)", g["p80"], g["a80"])):
        m = mc.setup_model(g["f"], p, a, g["c"], sb, levelled=False)
        panels.append(("linear", eq, m, by[eq]["rigorous"]))
    for (slot, method), res in sorted((procedure or {}).items()):
        eq = {"setup": "(6.43)", "conventional": "(6.60)"}[method]
        if slot == "80":
            eq = {"(6.43)": "(6.44)", "(6.60)": "(6.61)"}[eq]
        panels.append(("procedure", eq, res, by[eq]["rigorous"]))
    cols = 3 if len(panels) > 4 else 2
    fig, axes = plt.subplots(
        (len(panels) + cols - 1) // cols,
        cols,
        figsize=(5 * cols, 3.2 * ((len(panels) + 1) // cols)),
        squeeze=False,
    )
    for ax, (kind, eq, obj, formula) in zip(axes.ravel(), panels, strict=False):
        if kind == "linear":
            plot_mc_histogram(obj, formula, trials=trials, seed=seed, ax=ax)
            ax.set_title(f"{eq} linear MC, per m_xy", fontsize=9)
        else:
            ax.hist(obj["per_trial"], bins=50, color="0.7")
            ax.axvline(formula, color="r", label=f"rigorous (book geometry) {formula:.3g}")
            ax.axvline(
                obj["coefficient"],
                color="b",
                ls="--",
                label=f"procedure MC {obj['coefficient']:.3g} ± {obj['ci']:.2g}",
            )
            unit = "m_xy = n_л σ" if obj["method"] == "setup" else "m_p = m_q = σ"
            ax.set_title(
                f"{eq} procedure MC {obj['scenario']}, {obj['method']}, per {unit}", fontsize=9
            )
            ax.legend(fontsize=7)
        ax.set_xlabel("per-trial RMS of δp / σ")
    for ax in axes.ravel()[len(panels) :]:
        ax.set_visible(False)
    fig.tight_layout()
    return fig
