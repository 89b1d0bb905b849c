"""Procedural ground texture (seeded): fields, roads, forest, fine grain and premarked targets.

Brightness in [0, 1] as a function of ground X, Y [m]. Every random number comes from one
``numpy.random.Generator`` built from the seed, drawn in a fixed order, so the same seed gives
the same texture bit for bit. Features (all ``assumed``, chosen to look like a 1:10 000–1:30 000
panchromatic aerial photograph and to give parallax something to hold on at the eyepiece):

* fields: cells of about 110 m with warped borders, each with its own tone and ploughing
  stripes of 3–6 m period;
* forest: where a 350 m noise exceeds a threshold, dark with 4 m crown texture;
* roads: three straight 6 m wide bright roads;
* fine grain: noise of 1.5 m and 0.6 m wavelength everywhere (the parallax texture);
* premarked targets at every control point: a white square of side ``premark`` (default
  :data:`PREMARK_PHOTO_MM` at photo scale) in a dark square surround three times as wide.

Edges of roads and targets are box-filtered over the pixel footprint, so the target's centroid
is sub-pixel exact.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.ndimage import map_coordinates

__all__ = ["PREMARK_PHOTO_MM", "GroundTexture"]

PREMARK_PHOTO_MM = 0.1
"""Side of a premark's white square at photo scale [mm] (assumed: signalised targets are laid
out to image as 0.05–0.1 mm squares, the size a 0.04 mm floating mark can be centred on)."""

_LATTICE = 256


@dataclass(frozen=True)
class GroundTexture:
    """Seeded texture of the ground. Build with :meth:`build`."""

    lattices: tuple[NDArray[np.float32], ...]
    field_tone: NDArray[np.float64]
    field_angle: NDArray[np.float64]
    roads: NDArray[np.float64]  # (n, 3): unit normal (a, b) and offset c, a X + b Y = c [m]
    targets_m: NDArray[np.float64]  # (n, 2) control points X, Y [m]
    premark_m: float

    @classmethod
    def build(
        cls, seed: int, centre_m: NDArray, targets_m: NDArray, premark_m: float
    ) -> GroundTexture:
        """Draw the texture's random parts from ``numpy.random.default_rng(seed)``."""
        rng = np.random.default_rng(seed)
        lattices = tuple(rng.random((_LATTICE, _LATTICE)).astype(np.float32) for _ in range(7))
        tone = rng.uniform(0.35, 0.8, (64, 64))
        angle = rng.uniform(0.0, np.pi, (64, 64))
        theta = rng.uniform(0.0, np.pi, 3)
        offs = rng.uniform(-900.0, 900.0, 3)
        a, b = np.cos(theta), np.sin(theta)
        c = a * centre_m[0] + b * centre_m[1] + offs
        roads = np.stack([a, b, c], axis=1)
        return cls(lattices, tone, angle, roads, np.asarray(targets_m, float)[:, :2], premark_m)

    def _noise(self, k: int, X: NDArray, Y: NDArray, wavelength_m: float) -> NDArray:
        coords = np.stack([Y.ravel() / wavelength_m, X.ravel() / wavelength_m])
        out = map_coordinates(self.lattices[k], coords, order=1, mode="grid-wrap")
        return out.reshape(X.shape).astype(np.float64)

    def brightness(self, X: NDArray, Y: NDArray, footprint_m: NDArray) -> NDArray[np.float64]:
        """Brightness 0–1 at ground X, Y [m]; ``footprint_m`` is the pixel's ground size [m]."""
        fp = np.maximum(footprint_m, 1e-3)
        warp = 25.0 * (self._noise(0, X, Y, 90.0) - 0.5)
        ci = np.floor((X + warp) / 110.0).astype(np.int64) % 64
        cj = np.floor((Y - warp) / 110.0).astype(np.int64) % 64
        tone = self.field_tone[ci, cj]
        ang = self.field_angle[ci, cj]
        period = 3.0 + 3.0 * (tone - 0.35) / 0.45
        stripes = np.sin(2 * np.pi * (X * np.cos(ang) + Y * np.sin(ang)) / period)
        v = tone + 0.035 * stripes * np.clip(1.5 - fp / period * 2.0, 0.0, 1.0)
        forest = self._noise(1, X, Y, 350.0) + 0.3 * self._noise(2, X, Y, 60.0)
        crowns = self._noise(3, X, Y, 4.0)
        wood = np.clip((forest - 0.78) / 0.05, 0.0, 1.0)
        v = (1 - wood) * v + wood * (0.06 + 0.45 * crowns**2)
        for k, lam, amp in ((4, 1.5, 0.10), (5, 0.6, 0.08)):
            fade = np.clip(lam / fp - 0.5, 0.0, 1.0)  # no grain finer than the pixel (aliasing)
            v = v + amp * fade * (self._noise(k, X, Y, lam) - 0.5)
        for a, b, c in self.roads:
            dist = np.abs(a * X + b * Y - c)
            road = np.clip((3.0 - dist) / fp + 0.5, 0.0, 1.0)
            v = (1 - road) * v + road * 0.82
        return self._targets(X, Y, fp, v)

    def _targets(self, X: NDArray, Y: NDArray, fp: NDArray, v: NDArray) -> NDArray:
        h = self.premark_m / 2.0
        for tx, ty in self.targets_m:
            u, w = np.abs(X - tx), np.abs(Y - ty)
            near = (u < 4 * h + 2 * fp) & (w < 4 * h + 2 * fp)
            if not near.any():
                continue
            uu, ww, ff = u[near], w[near], fp[near]
            ring = np.clip((3 * h - uu) / ff + 0.5, 0, 1) * np.clip((3 * h - ww) / ff + 0.5, 0, 1)
            white = np.clip((h - uu) / ff + 0.5, 0, 1) * np.clip((h - ww) / ff + 0.5, 0, 1)
            vv = (1 - ring) * v[near] + ring * 0.08
            v[near] = (1 - white) * vv + white * 1.0
        return v
