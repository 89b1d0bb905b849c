"""Condition equations of the polygon method: sub-block polygons and control paths.

A condition is a closed polygon of centres (misclosure Σ σ_s l_s, expected 0) or a path between
two centres of known elements (expected: the known difference). Pure bookkeeping over centre ids;
:mod:`~stereoplotter.triangulation.polygon` builds the equations from it.
"""

from __future__ import annotations

import itertools
from collections import deque
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from stereoplotter.errors import GeometryError

__all__ = ["Condition", "build_conditions", "default_polygons", "find_cells"]


@dataclass(frozen=True)
class Condition:
    """One condition: ``kind`` "polygon" or "control", its centres in traverse order, the side
    indices and signs (+1 from → to), the expected sum per element ``known`` (6,) and the
    elements it applies to ``applies`` (6,) bool."""

    kind: str
    centres: tuple[str, ...]
    sides: tuple[int, ...]
    signs: tuple[int, ...]
    known: np.ndarray
    applies: np.ndarray


def _neighbours(
    centres: Sequence[str], sides: Sequence[tuple[str, str]]
) -> tuple[dict[str, int], list[set[int]]]:
    """Centre positions and, for each centre, the positions of the centres joined to it."""
    index = {c: i for i, c in enumerate(centres)}
    nbr: list[set[int]] = [set() for _ in centres]
    for a, b in sides:
        nbr[index[a]].add(index[b])
        nbr[index[b]].add(index[a])
    return index, nbr


def _side_lookup(sides: Sequence[tuple[str, str]]) -> dict[tuple[str, str], tuple[int, int]]:
    lookup: dict[tuple[str, str], tuple[int, int]] = {}
    for s, (a, b) in enumerate(sides):
        if (a, b) in lookup or (b, a) in lookup:
            raise GeometryError(
                f"sides[{s}]: expected one side per pair, found ({a!r}, {b!r}) again"
            )
        lookup[(a, b)] = (s, 1)
        lookup[(b, a)] = (s, -1)
    return lookup


def find_cells(
    centres: Sequence[str], sides: Sequence[tuple[str, str]]
) -> tuple[tuple[str, ...], ...]:
    """Every chordless 4-cycle of the side graph (the four-centre sub-blocks of a regular block).

    Each cycle starts at its centre listed first in ``centres`` and goes on to the earlier-listed
    of its two neighbours; cycles are ordered by their centres' positions.
    """
    _, nbr = _neighbours(centres, sides)
    found = set()
    for a in range(len(centres)):
        for b in nbr[a]:
            for d in nbr[a]:
                if d <= b:
                    continue
                for c in nbr[b] & nbr[d]:
                    if c == a or c in nbr[a] or d in nbr[b]:
                        continue  # a chord: not a cell
                    cyc = (a, b, c, d)
                    k = cyc.index(min(cyc))
                    cyc = cyc[k:] + cyc[:k]
                    if cyc[3] < cyc[1]:
                        cyc = (cyc[0], cyc[3], cyc[2], cyc[1])
                    found.add(cyc)
    return tuple(tuple(centres[i] for i in cyc) for cyc in sorted(found, key=sorted))


def _cycle_vector(cycle: Sequence[str], lookup, n_sides: int) -> np.ndarray:
    sides, signs = _oriented(cycle, lookup, True)
    vec = np.zeros(n_sides)
    vec[list(sides)] = signs
    return vec


def _reduce(vec: np.ndarray, basis: list[tuple[int, np.ndarray]]) -> np.ndarray:
    """vec minus its components along the pivoted basis (Gaussian elimination, ±1 entries)."""
    vec = vec.copy()
    for pivot, row in basis:
        if vec[pivot] != 0:
            vec -= vec[pivot] / row[pivot] * row
    return vec


def _tree_cycles(centres: Sequence[str], sides: Sequence[tuple[str, str]]):
    """Fundamental cycles of a breadth-first spanning forest (one per non-tree side)."""
    index, nbr = _neighbours(centres, sides)
    parent = [-1] * len(centres)
    depth = [0] * len(centres)
    seen = [False] * len(centres)
    tree = set()
    for root in range(len(centres)):
        if seen[root]:
            continue
        seen[root] = True
        queue = deque([root])
        while queue:
            i = queue.popleft()
            for j in sorted(nbr[i]):
                if not seen[j]:
                    seen[j], parent[j], depth[j] = True, i, depth[i] + 1
                    tree.add(frozenset((i, j)))
                    queue.append(j)
    for a, b in sides:
        i, j = index[a], index[b]
        if frozenset((i, j)) in tree:
            continue
        left, right = [i], [j]
        while left[-1] != right[-1]:
            if depth[left[-1]] >= depth[right[-1]]:
                left.append(parent[left[-1]])
            else:
                right.append(parent[right[-1]])
        yield tuple(centres[k] for k in left + right[-2::-1])


def default_polygons(
    centres: Sequence[str], sides: Sequence[tuple[str, str]]
) -> tuple[tuple[str, ...], ...]:
    """A complete independent set of closed polygons: the sub-blocks first.

    The chordless 4-cycles (:func:`find_cells`) and triangles of the side graph, kept while
    independent; then, if the net has more independent cycles (sides − centres + parts), the
    fundamental cycles of a spanning forest that are independent of those. For a regular block
    this is exactly its sub-blocks; an irregular connection across strips adds its triangles or
    longer loops, so no closure condition is lost.
    """
    lookup = _side_lookup(sides)
    _, nbr = _neighbours(centres, sides)
    triangles = [
        (centres[a], centres[b], centres[c])
        for a in range(len(centres))
        for b in sorted(nbr[a])
        if b > a
        for c in sorted(nbr[a] & nbr[b])
        if c > b
    ]
    basis: list[tuple[int, np.ndarray]] = []
    out = []
    parts = len(set(_components(len(centres), nbr)))
    needed = len(sides) - len(centres) + parts
    for cycle in (*find_cells(centres, sides), *triangles, *_tree_cycles(centres, sides)):
        if len(basis) == needed:
            break
        rest = _reduce(_cycle_vector(cycle, lookup, len(sides)), basis)
        nonzero = np.flatnonzero(np.abs(rest) > 1e-9)
        if nonzero.size:
            basis.append((int(nonzero[0]), rest))
            out.append(tuple(cycle))
    return tuple(out)


def _components(n: int, nbr: Sequence[set[int]]) -> list[int]:
    label = [-1] * n
    for seed in range(n):
        if label[seed] >= 0:
            continue
        label[seed] = seed
        queue = deque([seed])
        while queue:
            i = queue.popleft()
            for j in nbr[i]:
                if label[j] < 0:
                    label[j] = seed
                    queue.append(j)
    return label


def _hops(start: int, nbr: Sequence[set[int]]) -> list[int]:
    """Number of sides from ``start`` to every centre (−1 where unreachable)."""
    dist = [-1] * len(nbr)
    dist[start] = 0
    queue = deque([start])
    while queue:
        i = queue.popleft()
        for j in nbr[i]:
            if dist[j] < 0:
                dist[j] = dist[i] + 1
                queue.append(j)
    return dist


def _shortest_path(start: int, goal: int, nbr: Sequence[set[int]]) -> list[int]:
    prev = {start: start}
    queue = deque([start])
    while queue:
        i = queue.popleft()
        if i == goal:
            break
        for j in sorted(nbr[i]):
            if j not in prev:
                prev[j] = i
                queue.append(j)
    if goal not in prev:
        return []
    path = [goal]
    while path[-1] != start:
        path.append(prev[path[-1]])
    return path[::-1]


def _oriented(path: Sequence[str], lookup, closed: bool) -> tuple[tuple[int, ...], tuple[int, ...]]:
    pairs = list(itertools.pairwise(path))
    if closed:
        pairs.append((path[-1], path[0]))
    sides, signs = [], []
    for a, b in pairs:
        if (a, b) not in lookup:
            raise GeometryError(f"polygons: expected a side between {a!r} and {b!r}, found none")
        s, sign = lookup[(a, b)]
        sides.append(s)
        signs.append(sign)
    return tuple(sides), tuple(signs)


def build_conditions(
    centres: Sequence[str],
    sides: Sequence[tuple[str, str]],
    cells: Sequence[Sequence[str]],
    fixed: Mapping[str, np.ndarray],
) -> list[Condition]:
    """The polygons, then the control paths: for each element and each connected part of the
    net, the shortest paths joining its control centres known in that element in a minimum
    spanning tree of their path lengths (Prim, from the first in ``centres`` order): an
    independent set of short paths. (The least-squares result does not depend on the choice;
    the iteration's speed hardly does: 10 × 4 acceptance block of part B, four corner control
    centres, 1e-10 tolerance: 204–229 sweeps with paths from the first control centre, 219–238
    with this tree, against 55–57 without control.)"""
    lookup = _side_lookup(sides)
    out = [
        Condition("polygon", tuple(c), *_oriented(c, lookup, True), np.zeros(6), np.ones(6, bool))
        for c in cells
    ]
    index, nbr = _neighbours(centres, sides)
    component = _components(len(centres), nbr)
    control = sorted(fixed, key=index.__getitem__)
    hops = {c: _hops(index[c], nbr) for c in control}
    paths: dict[tuple[str, str], np.ndarray] = {}
    for e in range(6):
        known = [c for c in control if np.isfinite(fixed[c][e])]
        for part in sorted({component[index[c]] for c in known}):
            members = [c for c in known if component[index[c]] == part]
            joined = members[:1]
            while len(joined) < len(members):
                a, b = min(
                    ((a, b) for a in joined for b in members if b not in joined),
                    key=lambda ab: hops[ab[0]][index[ab[1]]],
                )
                paths.setdefault((a, b), np.zeros(6, bool))[e] = True
                joined.append(b)
    for (a, b), applies in paths.items():
        path = _shortest_path(index[a], index[b], nbr)
        ids = tuple(centres[i] for i in path)
        s, g = _oriented(ids, lookup, False)
        diff = np.where(applies, np.nan_to_num(fixed[b] - fixed[a]), 0.0)
        out.append(Condition("control", ids, s, g, diff, applies))
    return out
