"""Compaction: a round of a bounded loop run on the trials of a chunk still in it only.

A remedy (R1, R2, R3 of the setup-data method; CR1, CR2 of the conventional method) works on
the trials whose check failed, and each pass of a stage's loop (the L-check, stage 2's k_ω,
D8's κ, C2's passes) on the trials still outside the tolerance. With masks alone every act of a
round still costs the whole
chunk: the arrays are (T,) and the inactive trials are carried along. :func:`compacted` cuts
the run down to the active trials — the instrument's state (every per-trial array of its
scales, axes, units and injected errors), the operator's (commanded knobs, stops) and the zero
readings — runs the round on that sub-run, and scatters the new state back.

The operator's judgment noise stays keyed by the trial index (:class:`SubsetNoise` takes the
chunk's keyed draws at the sub-run's trials), so a trial draws the same numbers compacted or not.
The trial of the transcript always goes along (masked as before), so its records are unchanged.
Unlike a masked round, a compacted one does not re-set the screws of the other trials at rest
to their present reading (``Operator.set`` and ``drive`` turn every trial); on the runs
compared (``tests/procedure/test_compaction.py``; ``simulate --json`` of pair60 on the SC-1,
SPR-3 and SD-3, both methods, against the masked code) the results were equal to the last bit.

Runs of fewer than :data:`COMPACT_MIN_TRIALS` trials are not compacted (a single procedure, the
per-trial oracle and the small pinned runs keep the masked arithmetic), nor rounds that keep
more than :data:`COMPACT_MAX_SHARE` of the trials.
"""

from __future__ import annotations

import copy
import dataclasses
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from stereoplotter.procedure.operator import DrivenControl, Noise
from stereoplotter.procedure.run import Run
from stereoplotter.procedure.transcript import Transcript

__all__ = ["COMPACT_MAX_SHARE", "COMPACT_MIN_TRIALS", "Cut", "SubsetNoise", "compacted", "scatter"]

#: Smallest chunk that is compacted (a convention: below it the copies cost about what the
#: inactive trials would). [trials]
COMPACT_MIN_TRIALS = 64

#: Largest share of a chunk's trials that is cut out for a round (a convention: a cut gathers
#: and scatters ≈ 200 per-trial arrays, ≈ 3–7 ms; a round on nearly all trials gains less). [—]
COMPACT_MAX_SHARE = 0.8

#: Instrument attributes without per-trial state (not walked).
_FIXED = frozenset({"spec", "errors", "options", "variant", "backend", "ideal_mechanics"})
#: Instrument caches of its own state (emptied in a sub-run, the parent's kept: each is checked
#: against the state it was built from).
_CACHES = frozenset({"_unit_maps", "_setting_cache"})


class SubsetNoise(Noise):
    """The keyed noise of trials ``index`` of a parent :class:`Noise` (shape (n,))."""

    def __init__(self, parent: Noise, index: NDArray[np.intp]):
        super().__init__(parent.seed, len(index), None, parent.first_trial)
        self.parent = parent
        self.index = index

    def normal(self, key: str, sigma: float) -> NDArray[np.float64]:
        return self.parent.normal(key, sigma)[self.index]


#: Per type: (walked, fixed attribute names, a dataclass). A stereoplotter class is walked: a
#: dataclass by its fields, another object by its ``__dict__`` and slots.
_TYPES: dict[type, tuple[bool, list[str], bool]] = {}

#: What a cut took that cannot change in place (arrays, frozen dataclasses): id(part) → (part,
#: whole), so that :func:`scatter` leaves alone what the sub-run did not replace.
Memo = dict[int, tuple[Any, Any]]


def _attributes(value: Any) -> list[str] | None:
    """The attribute names of a walked object, None for any other value."""
    kind = type(value)
    entry = _TYPES.get(kind)
    if entry is None:
        walked = kind.__module__.startswith("stereoplotter.") and not isinstance(value, type)
        is_dc = dataclasses.is_dataclass(value)
        fixed = []
        if walked:
            fixed = [f.name for f in dataclasses.fields(value)] if is_dc else _slot_names(kind)
        entry = _TYPES[kind] = (walked, fixed, is_dc)
    walked, fixed, is_dc = entry
    if not walked:
        return None
    if is_dc or not hasattr(value, "__dict__"):
        return fixed
    return [*vars(value), *fixed]


def _slot_names(kind: type) -> list[str]:
    out: list[str] = []
    for cls in kind.__mro__:
        out += [n for n in getattr(cls, "__slots__", ()) if n not in ("__dict__", "__weakref__")]
    return out


def _rebuilt(value: Any, changes: dict[str, Any]) -> Any:
    if not changes:
        return value
    out = copy.copy(value)
    for name, v in changes.items():
        object.__setattr__(out, name, v)
    return out


def _take(value: Any, index: NDArray[np.intp], trials: int, memo: Memo | None = None) -> Any:
    """``value`` with every per-trial array (leading axis ``trials``) cut to ``index``."""
    if isinstance(value, np.ndarray):
        if not (value.ndim and value.shape[0] == trials):
            return value
        out: Any = value[index]
    elif isinstance(value, dict):
        out = {k: _take(v, index, trials, memo) for k, v in value.items()}
    elif isinstance(value, list | tuple) and not hasattr(value, "_fields"):
        out = type(value)(_take(v, index, trials, memo) for v in value)
    else:
        names = _attributes(value)
        if names is None:
            return value
        changes = {}
        for name in names:
            if not hasattr(value, name):
                continue
            old = getattr(value, name)
            new = _take(old, index, trials, memo)
            if new is not old:
                changes[name] = new
        out = _rebuilt(value, changes)
        if out is value:
            return value
    if memo is not None and _immutable(out):
        memo[id(out)] = (out, value)
    return out


def _immutable(value: Any) -> bool:
    """An array (the state is replaced, never written into) or a frozen dataclass: a part
    still in place after the sub-run is unchanged. Dicts and other objects are changed in
    place (``inst._units[side] = …``, ``axis._car = …``) and always walked back."""
    if isinstance(value, np.ndarray):
        return True
    params = getattr(type(value), "__dataclass_params__", None)
    return bool(params is not None and params.frozen)


def scatter(
    whole: Any, part: Any, index: NDArray[np.intp], trials: int, memo: Memo | None = None
) -> Any:
    """``whole`` with the trials ``index`` replaced by ``part`` (:func:`_take`'s inverse)."""
    if part is whole:
        return whole
    if memo is not None:
        hit = memo.get(id(part))
        if hit is not None and hit[0] is part and hit[1] is whole:
            return whole  # taken and left in place: unchanged
    if isinstance(part, np.ndarray) and part.ndim and part.shape[0] == len(index):
        if isinstance(whole, np.ndarray) and whole.ndim and whole.shape[0] == trials:
            out = whole.astype(np.result_type(whole, part), copy=True)
        else:  # a value common to the trials that the sub-run made per trial
            shape = (trials, *part.shape[1:])
            out = np.broadcast_to(np.asarray(whole, np.result_type(whole, part)), shape).copy()
        out[index] = part
        return out
    if isinstance(part, dict) and isinstance(whole, dict):
        return {
            **whole,
            **{k: scatter(whole.get(k), v, index, trials, memo) for k, v in part.items()},
        }
    if isinstance(part, list | tuple) and type(part) is type(whole) and len(part) == len(whole):
        if hasattr(part, "_fields"):
            return part
        pairs = zip(whole, part, strict=True)
        return type(whole)(scatter(w, p, index, trials, memo) for w, p in pairs)
    names = _attributes(part)
    if names is not None and type(part) is type(whole):
        changes = {}
        for name in names:
            if not hasattr(part, name):
                continue
            old = getattr(whole, name)
            new = scatter(old, getattr(part, name), index, trials, memo)
            if new is not old:
                changes[name] = new
        return _rebuilt(whole, changes)
    return part  # a state common to all trials (a scalar) set by the sub-run


def _sub_run(run: Run, index: NDArray[np.intp], memo: Memo) -> Run:
    op, trials = run.op, cast(int, run.op.trials)  # a run of trials (compacted() checks)
    inst = copy.copy(op.inst)
    for name, value in vars(op.inst).items():
        if name not in _FIXED and name not in _CACHES:
            setattr(inst, name, _take(value, index, trials, memo))
    inst.trials = len(index)
    inst._unit_maps = {}  # caches of the parent's state
    inst._setting_cache = None
    log = Transcript(enabled=False)
    where = np.flatnonzero(index == op.log.shown)
    if op.log.enabled and where.size:
        log = Transcript(shown=int(where[0]))
        log.records = op.log.records  # one transcript: the records go on in order
    sub_op = copy.copy(op)
    sub_op.inst, sub_op.log, sub_op.trials = inst, log, len(index)
    sub_op.noise = SubsetNoise(op.noise, index)
    sub_op.commanded = _take(op.commanded, index, trials, memo)
    sub_op.stopped = _take(op.stopped, index, trials, memo)
    sub_op._stops = _take(op._stops, index, trials, memo)
    sub = copy.copy(run)
    sub.op = sub_op
    sub.zero = _take(run.zero, index, trials, memo)
    sub.results, sub.stages = (
        _take(run.results, index, trials, memo),
        _take(run.stages, index, trials, memo),
    )
    sub.remedies = _take(run.remedies, index, trials, memo)
    return sub


def _merge(run: Run, sub: Run, index: NDArray[np.intp], memo: Memo) -> None:
    op, trials = run.op, cast(int, run.op.trials)  # a run of trials (compacted() checks)
    for name, value in vars(sub.op.inst).items():
        if name in _FIXED or name in _CACHES or name == "trials":
            continue
        setattr(op.inst, name, scatter(getattr(op.inst, name, None), value, index, trials, memo))
    # the parent's unit maps stay: each is checked against its unit (by identity) when used
    for control, value in sub.op.commanded.items():
        old = op.commanded.get(control)
        if old is None:  # first turned in the sub-run (a knob, a cassette): the others are
            old = op.physical(cast(DrivenControl, control))  # where they physically are
        op.commanded[control] = scatter(old, value, index, trials, memo)
    for control, value in sub.op.stopped.items():
        was = op.stopped.get(control, np.zeros(trials, np.bool_))
        op.stopped[control] = scatter(was, value, index, trials, memo)
    # the stops' readings: a cache of the scales, the parent's own where it has them
    op._stops = {
        k: scatter(v, sub.op._stops[k], index, trials, memo) if k in sub.op._stops else v
        for k, v in op._stops.items()
    }
    run.zero = scatter(run.zero, sub.zero, index, trials, memo)
    run.results = scatter(run.results, sub.results, index, trials, memo)
    run.stages = scatter(run.stages, sub.stages, index, trials, memo)
    run.remedies = scatter(run.remedies, sub.remedies, index, trials, memo)


class Cut:
    """A compacted round: ``run`` (the sub-run), ``active`` (its mask), ``take`` and ``put``."""

    def __init__(
        self,
        run: Run,
        active: NDArray[np.bool_],
        index: NDArray[np.intp] | None,
        trials: int | None,
    ) -> None:
        self.run = run
        self.active = active
        self.index = index
        self._trials = trials

    def take(self, value: Any) -> Any:
        """A per-trial array of the whole run cut to the sub-run's trials."""
        if self.index is None:
            return value
        return _take(value, self.index, cast(int, self._trials))

    def put(self, whole: Any, part: Any) -> NDArray[Any]:
        """``whole`` (over the run's trials) with the sub-run's *active* trials replaced by
        ``part`` (``np.where(active, part, whole)`` of the masked round)."""
        mask = np.asarray(self.active, bool)
        part_a: NDArray[Any] = np.asarray(part)
        whole_a: NDArray[Any] = np.asarray(whole)
        if self.index is None:
            ndim = max(part_a.ndim, whole_a.ndim)
            shape = mask.shape + (1,) * (ndim - mask.ndim)
            return np.where(mask.reshape(shape), part_a, whole_a)
        trials = cast(int, self._trials)
        out: NDArray[Any] = scatter(whole_a, part_a[mask], self.index[mask], trials)
        return out

    def put_all(self, whole: Any, part: Any) -> NDArray[Any]:
        """``whole`` with every trial of the sub-run replaced by ``part`` (active or not: a
        value the masked round computed for all its trials), ``part`` itself uncut."""
        if self.index is None:
            return np.asarray(part)
        trials = cast(int, self._trials)
        out: NDArray[Any] = scatter(np.asarray(whole), np.asarray(part), self.index, trials)
        return out


@contextmanager
def compacted(run: Run, active: NDArray[np.bool_]) -> Iterator[Cut]:
    """``with compacted(run, active) as cut:`` a round on the active trials (``cut.run``).

    ``cut.run`` is the run cut to the trials of ``active`` and the transcript's trial (kept
    whether active or not, so that its records are those of the masked round) — or ``run``
    itself when they are more than :data:`COMPACT_MAX_SHARE` of them, the run is a single
    procedure or it has fewer than :data:`COMPACT_MIN_TRIALS` trials; ``cut.active`` is the
    mask within ``cut.run``;
    ``cut.take(x)`` cuts a per-trial array of the caller to the sub-run, ``cut.put(whole,
    part)`` puts a sub-run's result back at its active trials. On leaving, the sub-run's state
    is written back into ``run``.
    """
    trials = run.op.trials
    mask = np.asarray(active, bool)
    if not trials or trials < COMPACT_MIN_TRIALS:
        yield Cut(run, mask, None, trials)
        return
    keep = mask.copy()
    if run.op.log.enabled:  # the transcript's trial goes along, masked as before
        keep[run.op.log.shown] = True
    if keep.sum() > COMPACT_MAX_SHARE * trials:
        yield Cut(run, mask, None, trials)
        return
    index = np.flatnonzero(keep)
    memo: Memo = {}
    sub = _sub_run(run, index, memo)
    yield Cut(sub, mask[index], index, trials)
    _merge(run, sub, index, memo)
