r"""The polygon network of a block, built from its strips, and its adjustment (method polygon).

The projection centres of the photos are the network's centres. Its sides carry the measured
increments from → to of α, ω, κ [rad] and B_x, B_y, B_z [m] in the ground system:

* along a strip, one side per model (photo k → k + 1): the increments of the strip formed by
  independent models and brought to the ground by its 7-parameter absolute orientation
  (:func:`~stereoplotter.triangulation.strip.oriented_strips`);
* across strips, photo k of strip s → the nearest photo of strip s + 1: the difference of the two
  strips' elements, the base components corrected by the mean discrepancy of the points the two
  strips share within one base of the side's middle (the strips' mutual shift there).

The first and last photos of the first and last strip (the block's corners, where the perimeter
control holds the strips' absolute orientation) are the fixed centres. The adjustment itself is
:func:`stereoplotter.triangulation.polygon.adjust_polygons` (the polygon method). The photos'
elements are the adjusted centre elements; object points are not adjusted (check points are
intersected from the adjusted orientations).
"""

from __future__ import annotations

import dataclasses

import numpy as np
from numpy.typing import NDArray

from stereoplotter.geometry.rotation import angles_from_matrix
from stereoplotter.triangulation.block import Block
from stereoplotter.triangulation.polygon import PolygonNetwork, adjust_polygons
from stereoplotter.triangulation.solution import (
    BlockSolution,
    catalogue_residuals,
    forward_intersection,
    photo_residuals,
)
from stereoplotter.triangulation.strip import OrientedStrip, oriented_strips

__all__ = ["polygon_block", "polygon_sides"]


def _elements(st: OrientedStrip) -> NDArray[np.float64]:
    return np.column_stack([np.column_stack(angles_from_matrix(st.rotations)), st.centres])


def _shift(a: OrientedStrip, b: OrientedStrip, x_mid: float, base: float) -> NDArray | None:
    """Mean (b − a) of the points both strips hold within one base of x_mid, or None."""
    _, ia, ib = np.intersect1d(a.point_ids, b.point_ids, return_indices=True)
    near = np.abs(a.points_m[ia, 0] - x_mid) <= base
    if not near.any():
        return None
    return np.mean(b.points_m[ib[near]] - a.points_m[ia[near]], axis=0)


def polygon_sides(
    block: Block, strips: list[OrientedStrip]
) -> tuple[list[tuple[str, str]], list[NDArray]]:
    """The sides (from, to photo numbers) and their increments (6,) of the block's network."""
    photos = block.photos
    elements = [_elements(st) for st in strips]
    sides, values = [], []
    for st, el in zip(strips, elements, strict=True):
        for k in range(len(st.photos) - 1):
            sides.append((photos[st.photos[k]], photos[st.photos[k + 1]]))
            values.append(el[k + 1] - el[k])
    for s in range(len(strips) - 1):
        a, b = strips[s], strips[s + 1]
        base = float(np.median(np.linalg.norm(np.diff(a.centres, axis=0), axis=1)))
        for k in range(len(a.photos)):
            kk = int(np.argmin(np.abs(b.centres[:, 0] - a.centres[k, 0])))
            shift = _shift(a, b, (a.centres[k, 0] + b.centres[kk, 0]) / 2.0, base)
            if shift is None:
                continue
            v = elements[s + 1][kk] - elements[s][k]
            v[3:] -= shift
            sides.append((photos[a.photos[k]], photos[b.photos[kk]]))
            values.append(v)
    return sides, values


def polygon_block(block: Block, method: str = "least_squares") -> BlockSolution:
    """Exterior orientation of every photo by the polygon method (module docstring).

    Raises
    ------
    GeometryError
        The strips cannot be formed and oriented.
    """
    strips, iterations = oriented_strips(block, "independent")
    sides, values = polygon_sides(block, strips)
    fixed = {}
    for st in (strips[0], strips[-1]):
        el = _elements(st)
        for k in (0, len(st.photos) - 1):
            fixed[block.photos[st.photos[k]]] = el[k]
    network = PolygonNetwork(block.photos, tuple(sides), np.array(values), fixed=fixed)
    result = adjust_polygons(network, method=method)
    orient = np.array([result.centre_elements[p] for p in block.photos])
    sol = BlockSolution("polygon", orient, None, np.full((len(block.point_ids), 3), np.nan), 0, 1.0)
    # every point measured twice: intersected from the adjusted orientations (its two most
    # distant rays), so that the photo residuals and σ₀ = RMS(v)/σ_photo are numbers
    points = forward_intersection(block, sol, np.arange(len(block.point_ids)))
    sol = dataclasses.replace(sol, points_m=points)
    v = photo_residuals(block, sol)
    sigma0 = float(np.sqrt(np.mean(v[np.all(np.isfinite(v), axis=1)] ** 2))) / block.sigmas.photo_mm
    # empirical σ of every point: the RMS residual at the control points per axis (the polygon
    # adjustment holds only the four corner photos; the control enters through the strips'
    # absolute orientation, and its residuals after the polygon adjustment are of the size of
    # the check points')
    rms = catalogue_residuals(block, sol).rms(block, "control")
    cov = None
    if np.all(np.isfinite(rms)):
        cov = np.where(np.isfinite(points)[:, :, None], np.diag(rms**2)[None], np.nan)
    notes = (
        f"polygon network: {len(block.photos)} centres, {len(sides)} sides (models along the "
        "strips, strip connections across), the block's four corner photos fixed",
        f"adjustment: {method}; strips by independent models (≤ {iterations} iterations per "
        "pair) and 7-parameter absolute orientation",
        "points intersected from the adjusted orientations (two rays); σ₀ = RMS photo residual "
        "/ σ_photo (empirical: no adjustment of the rays)",
        "σ of the points: an empirical rule, the RMS residual at the control points per axis, "
        "for every point",
    )
    return BlockSolution(
        "polygon",
        orient,
        None,
        points,
        int(np.max(result.iterations)),
        sigma0,
        notes,
        point_covariances=cov,
    )
