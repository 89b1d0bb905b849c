"""Figures for the accuracy verification (matplotlib, Agg backend; edge layer only).

* :func:`plot_error_maps` — RMS x-parallax error over the working area per error source
  (like Fig. 40 of the book), from exact covariance propagation;
* :func:`plot_mc_histogram` — per-trial RMS of a Monte Carlo row against the formula's σ;
* :func:`plot_verification_chart` — printed / book / rigorous / MC per row.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from stereoplotter.accuracy import montecarlo as mc

__all__ = ["plot_error_maps", "plot_mc_histogram", "plot_verification_chart"]


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
    from stereoplotter.accuracy.verification import _both

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
