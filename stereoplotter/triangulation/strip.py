r"""Strip triangulation by dependent or by independent models, then the block by polynomials.

Reference
---------
.. [1] Kushtin & Lyskov, *Фотограмметрия снимка и стереоскопических моделей*, Nedra, 1984, ch. 5,
   §22, Eqs. (5.10)–(5.11) (OCR L2928–3012): the y-parallax condition of relative orientation
   in the basis system (independent pair: α′₁, κ′₁, α′₂, ω′₂, κ′₂) and in the system of the left
   photo (dependent pair: Δα, Δω, Δκ of the right photo and the base angles τ, ν).

Relative orientation. Both photos' rays d = M·(x, y, −f) (Eq. (2.52), M of (2.50)) are turned
into the system whose x axis is the base; the y-parallax of a point is q = y′₁ − y′₂ with
y′ = −f·d_y/d_z. (5.10) is its first-order form in the five elements and (5.11) its closed
solution for six standard points; here the five elements are found by Gauss–Newton on all the
pair's points with a numerical Jacobian of q, from zero (photos near-vertical, x along the base:
strips flown along +x of the photos). The model follows by space intersection of the rays
(:func:`~stereoplotter.geometry.intersection.space_intersection`).

Strip formation. *Dependent models*: the left photo of each model keeps the orientation it got in
the previous model; the right photo's Δα, Δω, Δκ and the base direction τ, ν come from the
relative orientation; the model's base length (its scale) is chosen so that the points common to
the previous model lie at the same distances from the common projection centre (median ratio).
*Independent models*: every model in its own basis system, connected to the strip by the
7-parameter similarity (:mod:`~stereoplotter.triangulation.absolute`) on its points common with
the strip and the common projection centre; a point's strip coordinates are the mean over its
models.

Block. Each strip is brought to the ground by a 7-parameter absolute orientation on its control,
then the deformation of all strips is removed together by polynomials of degree 2 or 3
(:mod:`~stereoplotter.triangulation.polynomial`), tied by the points common to neighbouring
strips. Every photo's exterior orientation is finally its space resection on the adjusted points
it measured (:func:`~stereoplotter.geometry.resection.space_resection`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from itertools import pairwise

import numpy as np
from numpy.typing import NDArray

from stereoplotter.errors import GeometryError
from stereoplotter.geometry.collinearity import image_ray_direction
from stereoplotter.geometry.intersection import space_intersection
from stereoplotter.geometry.resection import space_resection
from stereoplotter.geometry.rotation import angles_from_matrix, rotation_matrix
from stereoplotter.triangulation.absolute import apply_similarity7, fit_similarity7
from stereoplotter.triangulation.block import Block, interior_orientation
from stereoplotter.triangulation.bundle import problem
from stereoplotter.triangulation.polynomial import StripAxes, adjust_strip_polynomials
from stereoplotter.triangulation.solution import BlockSolution, photo_residuals

__all__ = [
    "StripModel",
    "common_points",
    "form_strip",
    "measurement_rows",
    "relative_orientation",
    "strip_block",
    "y_parallax",
]

MODELS = ("independent", "dependent")


def _base_frame(base: NDArray) -> NDArray:
    """Rows: unit x along the base, y horizontal-ish (⊥ base and Z), z completing the triad."""
    ex = base / np.linalg.norm(base)
    ey = np.cross([0.0, 0.0, 1.0], ex)
    ey /= np.linalg.norm(ey)
    return np.stack([ex, ey, np.cross(ex, ey)])


def y_parallax(
    xy_left: NDArray, xy_right: NDArray, m_left: NDArray, m_right: NDArray, base: NDArray, f: float
) -> NDArray[np.float64]:
    """y-parallax q = y′₁ − y′₂ [mm] of homologous points in the system of the base.

    The rays M·(x, y, −f) of Eq. (2.52) turned into the base system; y′ = −f·d_y/d_z: the q that
    the first equation of (5.10) linearises (zero for every point of a relatively oriented
    pair).
    """
    r = _base_frame(np.asarray(base, float))
    d1 = image_ray_direction(xy_left, r @ m_left, f)
    d2 = image_ray_direction(xy_right, r @ m_right, f)
    return -f * d1[:, 1] / d1[:, 2] + f * d2[:, 1] / d2[:, 2]


def _gauss_newton(residual: Callable[[NDArray], NDArray], x0: NDArray, iterations: int = 30):
    """Minimise |residual(x)|² from x0 with a central-difference Jacobian; (x, iterations)."""
    x = np.asarray(x0, float).copy()
    h = 1e-7
    for it in range(1, iterations + 1):
        r = residual(x)
        jac = np.column_stack(
            [(residual(x + h * e) - residual(x - h * e)) / (2 * h) for e in np.eye(x.size)]
        )
        delta, *_ = np.linalg.lstsq(jac, -r, rcond=None)
        x += delta
        if np.max(np.abs(delta)) < 1e-10:
            return x, it
    raise GeometryError(
        f"relative orientation did not converge in {iterations} iterations: check the point "
        "identification of the pair"
    )


def relative_orientation(
    xy_left: NDArray, xy_right: NDArray, f: float, m_left: NDArray | None = None
) -> tuple[NDArray, NDArray, NDArray, int]:
    """Relative orientation of a pair by the y-parallax condition of (5.10).

    Without ``m_left``: the independent pair in the basis system (α′₁, κ′₁ of the left photo,
    α′₂, ω′₂, κ′₂ of the right; base along x). With ``m_left`` (the left photo's M in the strip
    system): the dependent pair (the right photo's α, ω, κ in that system and the base angles
    τ, ν: base ∝ (1, τ, ν)).

    Returns
    -------
    m_left, m_right : ndarray (3, 3)
    base_direction : ndarray (3,)
        Unit base vector in the system of the result.
    iterations : int

    Raises
    ------
    GeometryError
        Fewer than 5 common points, or no convergence.
    """
    if xy_left.shape[0] < 5:
        raise GeometryError(
            f"relative orientation: expected at least 5 common points, found {xy_left.shape[0]}"
        )
    if m_left is None:

        def q(e: NDArray) -> NDArray:
            return y_parallax(
                xy_left,
                xy_right,
                rotation_matrix(e[0], 0.0, e[1]),
                rotation_matrix(e[2], e[3], e[4]),
                np.array([1.0, 0, 0]),
                f,
            )

        e, it = _gauss_newton(q, np.zeros(5))
        m1, m2 = rotation_matrix(e[0], 0.0, e[1]), rotation_matrix(e[2], e[3], e[4])
        return m1, m2, np.array([1.0, 0.0, 0.0]), it
    a0 = np.array(angles_from_matrix(m_left), float)

    def qd(e: NDArray) -> NDArray:
        base = np.array([1.0, e[3], e[4]])
        return y_parallax(xy_left, xy_right, m_left, rotation_matrix(*e[:3]), base, f)

    e, it = _gauss_newton(qd, np.concatenate([a0, [0.0, 0.0]]))
    base = np.array([1.0, e[3], e[4]])
    return m_left, rotation_matrix(*e[:3]), base / np.linalg.norm(base), it


class StripModel:
    """A strip being formed: photo centres and rotations and the points in the strip system."""

    def __init__(self) -> None:
        self.centres: list[NDArray] = []
        self.rotations: list[NDArray] = []
        self.sums: dict[int, NDArray] = {}
        self.counts: dict[int, int] = {}
        self.iterations = 0

    def add_points(self, ids: NDArray, xyz: NDArray) -> None:
        for i, p in zip(ids.tolist(), xyz, strict=True):
            self.sums[i] = self.sums.get(i, 0.0) + p
            self.counts[i] = self.counts.get(i, 0) + 1

    def points(self) -> tuple[NDArray, NDArray]:
        ids = np.array(sorted(self.sums), dtype=np.int64)
        return ids, np.array([self.sums[i] / self.counts[i] for i in ids.tolist()]).reshape(-1, 3)


def common_points(block_xy, rows_of, a: int, b: int) -> tuple[NDArray, NDArray, NDArray]:
    """The points measured on both photos ``a`` and ``b``: their ids (ascending) and their
    coordinates of ``block_xy`` on ``a`` and on ``b`` (rows as :func:`measurement_rows` gives)."""
    ra, rb = rows_of[a], rows_of[b]
    ids = np.array(sorted(set(ra) & set(rb)), dtype=np.int64)
    return (
        ids,
        block_xy[[ra[i] for i in ids.tolist()]].reshape(-1, 2),
        block_xy[[rb[i] for i in ids.tolist()]].reshape(-1, 2),
    )


def _known(strip: StripModel, ids: NDArray) -> tuple[NDArray, NDArray]:
    """Mask of ``ids`` already in the strip, and their strip coordinates."""
    have = np.isin(ids, list(strip.sums))
    if have.sum() < 2:
        raise GeometryError(
            f"model connection: expected at least 2 points common to three photos, found "
            f"{int(have.sum())}"
        )
    return have, np.array([strip.sums[i] / strip.counts[i] for i in ids[have].tolist()])


def form_strip(
    xy: NDArray,
    rows_of: list[dict[int, int]],
    photos: list[int],
    f: float,
    models: str,
    names: tuple[str, ...] = (),
    point_ids: tuple[str, ...] = (),
) -> StripModel:
    """The strip of ``photos`` (indices in flight order) in the system of its first model.

    ``xy`` photo coordinates of every measurement [mm]; ``rows_of[j]`` point → measurement row
    of photo j; ``models``: ``"independent"`` or ``"dependent"``; ``names`` the photo numbers
    and ``point_ids`` the point ids (for messages). The first model is an independent pair with
    a base of 1000 units.

    Raises
    ------
    GeometryError
        A model that cannot be oriented or connected: names the model, its photos, the points
        they share and what is missing.
    """
    strip = StripModel()
    for k, (a, b) in enumerate(pairwise(photos)):
        try:
            _add_model(strip, xy, rows_of, photos, k, a, b, f, models)
        except GeometryError as exc:
            raise GeometryError(_model_message(exc, rows_of, photos, k, names, point_ids)) from None
    return strip


def _model_message(exc, rows_of, photos, k, names, point_ids) -> str:
    """``exc`` with the model, its photos and the points they share (and with the previous
    photo, the model's tie to the strip)."""

    def name(j: int) -> str:
        return names[photos.index(j)] if names else f"#{j}"

    def ids(points: set[int]) -> str:
        shown = sorted(point_ids[i] if point_ids else f"#{i}" for i in points)
        return ", ".join(shown[:8]) + (" …" if len(shown) > 8 else "") if shown else "none"

    a, b = photos[k], photos[k + 1]
    common = set(rows_of[a]) & set(rows_of[b])
    text = f"model {name(a)}–{name(b)}: {exc}; points on photos {name(a)} and {name(b)}: "
    text += f"{len(common)} ({ids(common)})"
    if k > 0:
        three = common & set(rows_of[photos[k - 1]])
        text += (
            f"; also on photo {name(photos[k - 1])} (the tie to the strip): {len(three)} "
            f"({ids(three)}): measure more points in the triple overlap"
        )
    return text


def _add_model(strip, xy, rows_of, photos, k, a, b, f, models) -> None:
    """Model k (photos a, b) oriented and connected to the strip (:func:`form_strip`)."""
    ids, xa, xb = common_points(xy, rows_of, a, b)
    if k == 0 or models == "independent":
        m1, m2, direction, it = relative_orientation(xa, xb, f)
        s1, s2 = np.zeros(3), 1000.0 * direction
        pts = space_intersection(xa, xb, s1, m1, s2, m2, f).points_m
        if k == 0:
            strip.centres += [s1, s2]
            strip.rotations += [m1, m2]
        else:  # connection by the 7-parameter similarity on common points and centre
            have, known = _known(strip, ids)
            t = fit_similarity7(np.vstack([pts[have], s1]), np.vstack([known, strip.centres[-1]]))
            pts = apply_similarity7(t, pts)
            strip.centres.append(apply_similarity7(t, s2))
            strip.rotations.append(t.rotation @ m2)
    else:
        m1, s1 = strip.rotations[-1], strip.centres[-1]
        _, m2, direction, it = relative_orientation(xa, xb, f, m1)
        trial = space_intersection(xa, xb, s1, m1, s1 + direction, m2, f).points_m
        have, known = _known(strip, ids)
        ratio = np.linalg.norm(known - s1, axis=1) / np.linalg.norm(trial[have] - s1, axis=1)
        s2 = s1 + float(np.median(ratio)) * direction  # the model's scale: its base length
        pts = space_intersection(xa, xb, s1, m1, s2, m2, f).points_m
        strip.centres.append(s2)
        strip.rotations.append(m2)
    strip.iterations = max(strip.iterations, it)
    strip.add_points(ids, pts)


def measurement_rows(block: Block) -> list[dict[int, int]]:
    """Per photo, point index → the row of its measurement in the block's observations."""
    out: list[dict[int, int]] = [{} for _ in block.photos]
    for row, (j, i) in enumerate(
        zip(block.obs_photo.tolist(), block.obs_point.tolist(), strict=True)
    ):
        out[j][i] = row
    return out


def _axes(centres: NDArray) -> StripAxes:
    first, last = centres[0, :2], centres[-1, :2]
    length = float(np.linalg.norm(last - first))
    return StripAxes((first + last) / 2.0, (last - first) / length, length / 2.0)


@dataclass(frozen=True, slots=True)
class OrientedStrip:
    """A strip after its 7-parameter absolute orientation: photo indices, their rotations
    (n, 3, 3) and centres (n, 3), the strip's point indices and ground coordinates [m]."""

    photos: tuple[int, ...]
    rotations: NDArray[np.float64]
    centres: NDArray[np.float64]
    point_ids: NDArray[np.int64]
    points_m: NDArray[np.float64]


def oriented_strips(block: Block, models: str = "independent") -> tuple[list[OrientedStrip], int]:
    """Every strip formed (:func:`form_strip`) and absolutely oriented on its control by the
    7-parameter similarity; and the most iterations a relative orientation took.

    Raises
    ------
    GeometryError
        A strip without 3 full control points (names the strip).
    """
    if models not in MODELS:
        raise GeometryError(f"strip models: expected one of {', '.join(MODELS)}, found {models!r}")
    xy = interior_orientation(block)
    rows_of = measurement_rows(block)
    prob = problem(block)
    index = {p: j for j, p in enumerate(block.photos)}
    out, iterations = [], 0
    for s, names in enumerate(block.strips):
        photos = [index[p] for p in names]
        sm = form_strip(
            xy, rows_of, photos, block.camera.focal_length_mm, models, names, block.point_ids
        )
        iterations = max(iterations, sm.iterations)
        ids, pts = sm.points()
        where = {i: k for k, i in enumerate(ids.tolist())}
        c = [k for k, i in enumerate(prob.control_point.tolist()) if i in where]
        try:
            t = fit_similarity7(
                pts[[where[i] for i in prob.control_point[c].tolist()]],
                prob.control_m[c].reshape(-1, 3),
                prob.control_weight[c].reshape(-1, 3),
            )
        except GeometryError as exc:
            raise GeometryError(
                f"strip {s + 1} ({names[0]} …): absolute orientation: {exc}"
            ) from None
        out.append(
            OrientedStrip(
                tuple(photos),
                t.rotation @ np.array(sm.rotations),
                apply_similarity7(t, np.array(sm.centres)),
                ids,
                apply_similarity7(t, pts),
            )
        )
    return out, iterations


def _check_height_stations(block: Block, strips: list[OrientedStrip], degree: int) -> None:
    """Refuse a degree the height control cannot fix: each strip needs height control at
    degree + 1 stations along it (control points more than half a base apart count as two
    stations; ties to other strips fix no heights)."""
    prob = problem(block)
    heights = prob.control_point[prob.control_weight[:, 2] > 0]
    for s, st in enumerate(strips):
        ax = _axes(st.centres)
        inside = np.isin(st.point_ids, heights)
        u = np.sort(ax.uv(st.points_m[inside, :2])[0] * ax.half)
        base = 2.0 * ax.half / max(1, len(st.photos) - 1)
        stations = int(u.size > 0) + int(np.count_nonzero(np.diff(u) > base / 2.0))
        if stations < degree + 1:
            raise GeometryError(
                f"strip {s + 1} ({block.strips[s][0]} …) has height control at {stations} "
                f"stations along it: polynomials of degree {degree} need {degree + 1} (give "
                "more control or a lower degree)"
            )


# long: strips formed and oriented, adjusted by polynomials, photos resected: the method's steps
def strip_block(block: Block, models: str = "independent", degree: int = 3) -> BlockSolution:
    """Exterior orientation of every photo by strip triangulation and polynomial adjustment.

    Parameters
    ----------
    block : Block
    models : {"independent", "dependent"}
        How each strip is formed (module docstring).
    degree : {2, 3}
        Degree of the strip polynomials (1 for a linear correction only).

    Raises
    ------
    GeometryError
        A strip without 3 full control points, a pair without 5 common points, too little
        control for the polynomials.
    """
    strips, iterations = oriented_strips(block, models)
    _check_height_stations(block, strips, degree)
    xy = interior_orientation(block)
    f = block.camera.focal_length_mm
    rows_of = measurement_rows(block)
    prob = problem(block)
    initial = {}
    for s, st in enumerate(strips):
        for j, m, centre in zip(st.photos, st.rotations, st.centres, strict=True):
            initial[j] = (s, m, centre)
    obs_strip = [np.full(st.point_ids.size, s) for s, st in enumerate(strips)]
    obs_point = [st.point_ids for st in strips]
    strip_xyz = [st.points_m for st in strips]
    axes = [_axes(st.centres) for st in strips]
    height = np.mean([c[2][2] for c in initial.values()]) - np.mean(prob.control_m[:, 2])
    sigma_model = block.sigmas.photo_mm * height / f  # σ of a model coordinate at photo scale
    poly = adjust_strip_polynomials(
        np.concatenate(obs_strip),
        np.concatenate(obs_point),
        np.vstack(strip_xyz),
        tuple(axes),
        len(block.point_ids),
        prob.control_point,
        prob.control_m,
        prob.control_weight,
        sigma_model,
        degree,
    )
    orient = np.empty((len(block.photos), 6))
    for j in range(len(block.photos)):
        s, m, centre = initial[j]
        pts = [i for i in rows_of[j] if np.all(np.isfinite(poly.points_m[i]))]
        start = np.concatenate([angles_from_matrix(m), poly.correct(s, centre)[0]])
        r = space_resection(xy[[rows_of[j][i] for i in pts]], poly.points_m[pts], f, initial=start)
        orient[j] = np.concatenate([r.angles, r.projection_centre_m])
    notes = (
        f"{models} models, relative orientation by the y-parallax condition (5.10) "
        f"(≤ {iterations} iterations per pair)",
        f"each strip: 7-parameter absolute orientation on its control; strip deformation by "
        f"polynomials of degree {degree}, all strips at once",
        "each photo's orientation: space resection on the adjusted points (no σ propagated)",
        "σ of the points: propagated through the polynomial adjustment with its a posteriori σ₀ "
        "(model coordinates independent; X, Y, Z uncorrelated)",
    )
    cov = None
    if poly.sigma_m is not None:
        cov = np.einsum("ni,ij->nij", poly.sigma_m**2, np.eye(3))
    sol = BlockSolution("strip", orient, None, poly.points_m, iterations, float("nan"), notes)
    v = photo_residuals(block, sol)
    ok = np.all(np.isfinite(v), axis=1)
    sigma0 = float(np.sqrt(np.mean(v[ok] ** 2))) / block.sigmas.photo_mm
    return BlockSolution(
        "strip", orient, None, poly.points_m, iterations, sigma0, notes, point_covariances=cov
    )
