"""Schematics of the three correction mechanisms for docs/instruments.md (issue 11).

Run from the repository root: ``python docs/make_instrument_figures.py``; writes
docs/img/mechanisms.png. Simple 2-D cross-sections in the X–Z plane, not to scale except where
labelled; the dimensions are the ASSUMED ones of stereoplotter.instrument.principles.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np


def _sd3(ax):
    f, t = 100.0, np.tan(np.radians(8.0))  # tilt exaggerated for the drawing
    x = np.linspace(-90, 90, 2)
    ax.plot(x, f + x * t, "b-", lw=2, label="correction plane, slope kα")
    ax.plot([0, 0], [0, f], "k:", lw=1)
    ax.plot([0, 70], [0, 100], "k-", lw=1.5, label="space rod")
    tau = f / (f + 70 * t)
    r = 5.0
    c = np.array([70 * tau, 100 * tau]) * (1 + r / 100)
    ax.add_patch(plt.Circle(c, r, fill=False, color="r", lw=1.5, label="follower ball r = 5 mm"))
    ax.plot([-90, 90], [-5, -5], "g-", lw=4, label="photo (horizontal)")
    ax.set_title("SD-3: plane and follower")


def _spr3(ax):
    ax.plot([-90, 90], [0, 0], "g-", lw=4, label="photo carriage (moves)")
    ax.plot([0], [-20], "r+", ms=14, mew=2, label="fixed measuring mark")
    ax.annotate("", xy=(30, 8), xytext=(-10, 8), arrowprops={"arrowstyle": "->"})
    arm, d = 100.0, 40.0  # arm drawn shortened (L = 400 mm), δ exaggerated
    lens_z = 200.0 - np.sqrt(arm * arm - d * d)
    ax.plot([0, d], [200, lens_z], "k-", label="arm about a pivot (L = 400 mm, drawn short)")
    ax.plot([d], [lens_z], "bo", ms=8, label="lens shifted by δ (lifted by L(1 − cos ψ))")
    ax.plot([0], [100], "bo", ms=8, mfc="none")
    ax.set_title("SPR-3: lens shift, photo moves")


def _sc1(ax):
    th = np.radians(8.0)
    h = 20.0
    x = np.linspace(-90, 90, 2)
    ax.plot(x * np.cos(th), -h + h * np.cos(th) + x * np.sin(th), "g-", lw=4, label="photo carrier")
    ax.plot([0], [-h], "ks", ms=8, label="gimbal axis h = 20 mm below the emulsion")
    ax.plot([0, 0], [0, 100], "k:")
    ax.plot([0, 60], [100, -10], "k-", lw=1.5, label="mechanical projection rod")
    ax.set_title("SC-1: tilted carrier in a gimbal")


def main() -> None:
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2))
    for ax, draw in zip(axes, (_sd3, _spr3, _sc1), strict=True):
        draw(ax)
        ax.set_aspect("equal")
        ax.set_xlabel("X [mm]")
        ax.legend(fontsize=7, loc="upper left")
    axes[0].set_ylabel("Z [mm]")
    fig.tight_layout()
    out = Path(__file__).parent / "img" / "mechanisms.png"
    fig.savefig(out, dpi=110)
    print(out)


if __name__ == "__main__":
    main()
