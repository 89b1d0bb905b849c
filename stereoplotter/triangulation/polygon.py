"""Block adjustment by the polygon method (Dorozhinsky, after Popov's method for levelling nets).

Source: A. L. Dorozhinsky, *Уравнивание блока аналитической фототриангуляции способом полигонов*
("Adjustment of a block of analytical phototriangulation by the polygon method"), 1968.
``docs/triangulation-papers.md`` §2 reproduces its worked example (Fig. 1 and its table).

A block's projection centres are joined by *sides*: models along a strip and connections across
strips. Each side carries measured increments from → to of the six elements α, ω, κ (rad) and
B_x, B_y, B_z (m). Around every sub-block of four centres (a *polygon*, the paper's подблок) the
true increments close::

    Σα = Σω = Σκ = 0   (paper Eq. (1)),    ΣB_x = ΣB_y = ΣB_z = 0   (Eq. (2))

and between two centres of known elements (control) the increments along any path sum to their
difference. The six elements are mutually independent, so each is adjusted on its own
("уравнивание можно вести раздельно по каждому элементу"), exactly like a levelling net.

Condition equations, element e: for condition P with oriented sides s (sign σ_Ps = +1 when the
side is traversed from → to, −1 against), misclosure f_P = Σ σ_Ps l_s − c_P (c_P = 0 for a
polygon, the known difference for a control path), corrections v with Σ σ_Ps (l_s + v_s) = c_P.

- ``method="least_squares"``: the rigorous correlate solution min Σ w_s v_s²:
  N k = −f, N = A W⁻¹ Aᵀ, v = W⁻¹ Aᵀ k (scipy sparse).
- ``method="iterative"``: the paper's successive approximations (Popov). Starting at the polygon
  with the largest |f| and sweeping the polygons in their listed order (from it to the last, then
  back from the one before it to the first — the paper's snake over the sub-blocks), each
  polygon's current misclosure F_P is distributed over its sides in proportion to 1/w_s
  (equal weights: F_P/4 per side of a sub-block), which zeroes it and adds F_P r_s/R_P to the
  misclosure of the neighbour across each shared side. Sweeps repeat from the same polygon until
  every |F_P| ≤ the tolerance Δ; the paper's control |Σδ − f| ≤ |Δ| is then met by every
  polygon. This is Gauss–Seidel on the correlate normal equations, so it converges to the
  least-squares solution (tested).

Accuracy estimate of the paper: m = ±√([vv]/n), n the number of sides.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
import scipy.linalg
import scipy.sparse as sp
from numpy.typing import NDArray

from stereoplotter.errors import GeometryError
from stereoplotter.triangulation.polygon_conditions import (
    Condition,
    build_conditions,
    default_polygons,
)

__all__ = [
    "ELEMENTS",
    "Condition",
    "PolygonAdjustment",
    "PolygonNetwork",
    "adjust_polygons",
]

#: The six adjusted elements, in the column order of ``values``.
ELEMENTS = ("alpha", "omega", "kappa", "B_x", "B_y", "B_z")

Method = Literal["iterative", "least_squares"]


@dataclass(frozen=True)
class PolygonNetwork:
    """Projection centres, directed sides with measured increments, control (see module doc).

    ``polygons`` (added to the interface): the sub-blocks as cycles of centre ids, in the order
    the iterative method sweeps them (the paper's snake: row 1 left → right, row 2 right → left,
    …). ``None``: every chordless 4-cycle of the side graph (the sub-blocks of a regular block),
    in the order found. A polygon may have any number ≥ 3 of centres.
    ``fixed`` values may be NaN for an element not known at that centre.
    """

    centres: tuple[str, ...]
    sides: tuple[tuple[str, str], ...]
    values: np.ndarray
    weights: np.ndarray | None = None
    fixed: Mapping[str, np.ndarray] = field(default_factory=dict)
    polygons: tuple[tuple[str, ...], ...] | None = None

    def __post_init__(self) -> None:
        centres = tuple(str(c) for c in self.centres)
        if len(set(centres)) != len(centres):
            raise GeometryError("centres: expected distinct ids, found a repeated id")
        object.__setattr__(self, "centres", centres)
        object.__setattr__(self, "sides", tuple((str(a), str(b)) for a, b in self.sides))
        known = set(centres)
        for i, (a, b) in enumerate(self.sides):
            if a not in known or b not in known:
                raise GeometryError(f"sides[{i}]: expected ids of centres, found ({a!r}, {b!r})")
            if a == b:
                raise GeometryError(
                    f"sides[{i}]: expected two different centres, found {a!r} twice"
                )
        values = np.asarray(self.values, float)
        if values.shape != (len(self.sides), 6):
            raise GeometryError(
                f"values: expected shape ({len(self.sides)}, 6), found {values.shape}"
            )
        if not np.isfinite(values).all():
            raise GeometryError("values: expected finite numbers, found NaN or infinity")
        object.__setattr__(self, "values", values)
        if self.weights is not None:
            w = np.asarray(self.weights, float)
            if w.shape == (len(self.sides),):
                w = np.repeat(w[:, None], 6, axis=1)
            if w.shape != (len(self.sides), 6) or not (np.isfinite(w).all() and (w > 0).all()):
                raise GeometryError(
                    f"weights: expected positive numbers of shape ({len(self.sides)},) or "
                    f"({len(self.sides)}, 6), found shape {np.shape(self.weights)}"
                )
            object.__setattr__(self, "weights", w)
        fixed = {}
        for cid, elements in self.fixed.items():
            if cid not in known:
                raise GeometryError(f"fixed: expected ids of centres, found {cid!r}")
            e = np.asarray(elements, float)
            if e.shape != (6,):
                raise GeometryError(f"fixed[{cid!r}]: expected 6 elements, found shape {e.shape}")
            fixed[cid] = e
        object.__setattr__(self, "fixed", fixed)
        if self.polygons is not None:
            for i, poly in enumerate(self.polygons):
                if len(poly) < 3 or any(c not in known for c in poly):
                    raise GeometryError(
                        f"polygons[{i}]: expected ≥ 3 ids of centres, found {tuple(poly)!r}"
                    )

    def side_weights(self) -> NDArray[np.float64]:
        """(n_sides, 6) weights (1 where ``weights`` is None)."""
        if self.weights is None:
            return np.ones((len(self.sides), 6))
        return np.asarray(self.weights, float)

    def cells(self) -> tuple[tuple[str, ...], ...]:
        """The polygons (given, or :func:`default_polygons` of the side graph)."""
        if self.polygons is not None:
            return tuple(tuple(p) for p in self.polygons)
        return default_polygons(self.centres, self.sides)


@dataclass(frozen=True)
class PolygonAdjustment:
    """Result of :func:`adjust_polygons` (arrays per element in the column order of ELEMENTS).

    ``conditions``: the polygons (kind ``"polygon"``) then the control paths (kind
    ``"control"``); ``misclosures_before``/``after`` (n_conditions, 6), NaN where a control path
    does not apply to an element (not known at both ends).
    """

    method: str
    corrections: NDArray[np.float64]  # (n_sides, 6) v, in the direction of each side
    side_values: NDArray[np.float64]  # (n_sides, 6) l + v
    centre_elements: dict[str, NDArray[np.float64]]  # id → α, ω, κ, X, Y, Z
    conditions: tuple[Condition, ...]
    misclosures_before: NDArray[np.float64]
    misclosures_after: NDArray[np.float64]
    iterations: NDArray[np.int64]  # (6,) sweeps per element (0 for least squares)
    converged: bool
    tolerance: NDArray[np.float64]  # (6,) Δ per element
    trace: tuple[tuple[int, int, int, float], ...] = ()  # (element, sweep, condition, F) steps

    @property
    def polygons(self) -> tuple[Condition, ...]:
        """The sub-block conditions only."""
        return tuple(c for c in self.conditions if c.kind == "polygon")

    def rms_correction(self) -> NDArray[np.float64]:
        """The paper's accuracy estimate m = √([vv]/n) per element."""
        return np.sqrt(np.mean(self.corrections**2, axis=0))


def _tolerances(tolerance, f: NDArray[np.float64]) -> NDArray[np.float64]:
    if tolerance is None:
        # default Δ: converged to rounding, 1e-10 of the largest misclosure (or absolute 1e-15)
        scale = np.nanmax(np.abs(f), axis=0, initial=0.0) if f.size else np.zeros(6)
        return np.maximum(1e-10 * scale, 1e-15)
    tol = np.broadcast_to(np.asarray(tolerance, float), (6,)).copy()
    if not (np.isfinite(tol).all() and (tol > 0).all()):
        raise GeometryError(f"tolerance: expected positive numbers, found {tolerance!r}")
    return tol


def _condition_matrix(conds: Sequence[Condition], e: int, n_sides: int):
    rows = [i for i, c in enumerate(conds) if c.applies[e]]
    data, ri, ci = [], [], []
    for r, i in enumerate(rows):
        for s, sign in zip(conds[i].sides, conds[i].signs, strict=True):
            ri.append(r)
            ci.append(s)
            data.append(float(sign))
    a = sp.csr_matrix((data, (ri, ci)), shape=(len(rows), n_sides))
    a.sum_duplicates()
    return rows, a


def _least_squares(a, f: NDArray, inv_w: NDArray) -> NDArray:
    """Correlates N k = −f, N = A W⁻¹ Aᵀ; v = W⁻¹ Aᵀ k (min Σ w v²)."""
    if a.shape[0] == 0:
        return np.zeros(a.shape[1])
    n = (a @ sp.diags(inv_w) @ a.T).toarray()
    dependent = GeometryError(
        "polygons: the condition equations are dependent (a polygon repeats others)"
    )
    try:
        factor = scipy.linalg.cho_factor(n)
    except np.linalg.LinAlgError:
        raise dependent from None
    pivots = np.abs(np.diag(factor[0]))
    if pivots.min() < 1e-7 * np.sqrt(np.diag(n).max()):
        raise dependent
    k = scipy.linalg.cho_solve(factor, -f)
    return inv_w * (a.T @ k)


def _hand_round(x: float, step: float | None) -> float:
    if step is None:
        return x
    # a hand computation: to the nearest step, a half to the even step (Gauss's rule)
    return round(round(x / step, 9)) * step


def _iterate(rows, a, f, inv_w, tol, max_iterations, step, e, trace):
    """Popov's successive approximations for one element; returns v, sweeps, converged."""
    a = a.tocsr()
    n_rows = len(rows)
    v = np.zeros(a.shape[1])
    if n_rows == 0:
        return v, 0, True
    member = a.T.tocsr()  # side → conditions containing it (with signs)
    current = f.copy()
    start = int(np.argmax(np.abs(current)))
    order = list(range(start, n_rows)) + list(range(start - 1, -1, -1))
    for sweep in range(1, max_iterations + 1):
        before = v.copy()
        for p in order:
            big_f = current[p]
            lo, hi = a.indptr[p], a.indptr[p + 1]
            sides, signs = a.indices[lo:hi], a.data[lo:hi]
            r = inv_w[sides]
            for s, sign, rs in zip(sides, signs, r, strict=True):
                portion = _hand_round(big_f * rs / r.sum(), step)
                dv = -sign * portion
                v[s] += dv
                mlo, mhi = member.indptr[s], member.indptr[s + 1]
                current[member.indices[mlo:mhi]] += member.data[mlo:mhi] * dv
            if trace is not None:
                trace.append((e, sweep, rows[p], float(big_f)))
        if np.max(np.abs(current)) <= tol:
            return v, sweep, True
        if np.array_equal(v, before):  # rounded portions all zero: a hand computation stops
            return v, sweep, False
    return v, max_iterations, False


def _centre_elements(network: PolygonNetwork, side_values: NDArray) -> dict[str, NDArray]:
    """Propagate the adjusted increments from the control (or a datum of zeros) over a tree."""
    index = {c: i for i, c in enumerate(network.centres)}
    adjacency: list[list[tuple[int, int, float]]] = [[] for _ in network.centres]
    for s, (a, b) in enumerate(network.sides):
        adjacency[index[a]].append((index[b], s, 1.0))
        adjacency[index[b]].append((index[a], s, -1.0))
    out = np.full((len(network.centres), 6), np.nan)
    for e in range(6):
        seeds = [index[c] for c, x in network.fixed.items() if np.isfinite(x[e])]
        seeds += list(range(len(network.centres)))  # unreached components: datum 0 at first
        for seed in seeds:
            if np.isfinite(out[seed, e]):
                continue
            known = network.fixed.get(network.centres[seed])
            out[seed, e] = known[e] if known is not None and np.isfinite(known[e]) else 0.0
            queue = deque([seed])
            while queue:
                i = queue.popleft()
                for j, s, sign in adjacency[i]:
                    if not np.isfinite(out[j, e]):
                        out[j, e] = out[i, e] + sign * side_values[s, e]
                        queue.append(j)
    return {c: out[i] for i, c in enumerate(network.centres)}


def adjust_polygons(
    network: PolygonNetwork,
    method: Method = "iterative",
    tolerance: float | np.ndarray | None = None,
    max_iterations: int = 100,
    step: float | None = None,
    record: bool = False,
) -> PolygonAdjustment:
    """Adjust a block by the polygon method (see the module docstring).

    ``tolerance``: the paper's Δ per element (scalar or (6,)), in the element's unit; None =
    converged to rounding (1e-10 of the largest misclosure). ``step`` (iterative only, added):
    round every distributed portion to this step, as the paper's hand computation in 0.1′ does.
    ``record`` (added): keep every step (element, sweep, condition, misclosure distributed) in
    ``trace``.
    Centre elements: control values propagated along the adjusted sides; a part of the net
    without control starts at zeros at its first centre (arbitrary datum).
    """
    if method not in ("iterative", "least_squares"):
        raise GeometryError(f"method: expected 'iterative' or 'least_squares', found {method!r}")
    if int(max_iterations) != max_iterations or max_iterations < 1:
        raise GeometryError(f"max_iterations: expected an integer ≥ 1, found {max_iterations!r}")
    n_sides = len(network.sides)
    conds = build_conditions(network.centres, network.sides, network.cells(), network.fixed)
    f_all = np.full((len(conds), 6), np.nan)
    for i, c in enumerate(conds):
        total = np.sum(np.asarray(c.signs)[:, None] * network.values[list(c.sides)], axis=0)
        f_all[i] = np.where(c.applies, total - c.known, np.nan)
    tol = _tolerances(tolerance, f_all)
    inv_w = 1.0 / network.side_weights()
    v = np.zeros((n_sides, 6))
    sweeps = np.zeros(6, np.int64)
    converged = True
    trace: list[tuple[int, int, int, float]] | None = [] if record else None
    for e in range(6):
        rows, a = _condition_matrix(conds, e, n_sides)
        f = f_all[rows, e]
        if method == "least_squares":
            v[:, e] = _least_squares(a, f, inv_w[:, e])
        else:
            v[:, e], sweeps[e], ok = _iterate(
                rows, a, f, inv_w[:, e], tol[e], max_iterations, step, e, trace
            )
            converged &= ok
    side_values = network.values + v
    after = np.full_like(f_all, np.nan)
    for i, c in enumerate(conds):
        total = np.sum(np.asarray(c.signs)[:, None] * side_values[list(c.sides)], axis=0)
        after[i] = np.where(c.applies, total - c.known, np.nan)
    return PolygonAdjustment(
        method=method,
        corrections=v,
        side_values=side_values,
        centre_elements=_centre_elements(network, side_values),
        conditions=tuple(conds),
        misclosures_before=f_all,
        misclosures_after=after,
        iterations=sweeps,
        converged=bool(converged),
        tolerance=tol,
        trace=tuple(trace or ()),
    )
