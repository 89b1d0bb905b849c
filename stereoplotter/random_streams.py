"""Keyed random streams over a trial index: the same draw for trial t however the run is cut.

A run of T trials is processed in chunks (``procedure.trials``) whose size follows a memory
budget. So that the chunk size cannot change a single result, every random quantity of the
procedure is a *keyed stream*: the value for (seed, key, trial t) is fixed, whichever chunk
``[start, stop)`` asks for it. The trial axis is cut into blocks of :data:`BLOCK` trials; block
b of a key is drawn from its own ``numpy.random.Generator`` seeded with ``[seed, crc32(key)]``
(block 0) or ``[seed, crc32(key), b]`` (block b ≥ 1). Block 0 is seeded as the procedure's
streams were before chunking, so runs of at most :data:`BLOCK` trials kept their numbers.

A single run (no trial axis) is trial 0 of the same streams.
"""

from __future__ import annotations

import threading
import zlib
from collections.abc import Callable, Iterable, Iterator
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["BLOCK", "key_code", "keyed_draws", "keyed_standard_normal", "stream_key"]

#: Trials per keyed block (a convention: large enough that a block's generator costs little per
#: trial, small enough that a per-trial oracle draws few unused numbers).
BLOCK = 4096

Draw = Callable[[np.random.Generator, int], NDArray[np.float64]]


def stream_key(parts: Iterable[str | int]) -> str:
    """The key of the stream of a declared identity: its parts, in their declared order, joined
    by "/" (the one encoding; an identity's parts must not contain "/").

    Examples
    --------
    >>> stream_key(("mono", "2", 1, "left", "omega", "knob"))
    'mono/2/1/left/omega/knob'
    """
    return "/".join(str(part) for part in parts)


@lru_cache(maxsize=1 << 14)
def key_code(key: str) -> int:
    """The 32-bit code of a stream key (CRC-32 of its UTF-8 bytes); remembered per key, since
    every chunk of a run draws the same keys."""
    return zlib.crc32(key.encode("utf-8"))


def keyed_draws(seed: int, key: str, start: int, stop: int, draw: Draw) -> NDArray[np.float64]:
    """Values of trials ``start … stop−1`` of the stream (seed, key), shape (stop − start,).

    ``draw(rng, n)`` must fill n values in sequence (as every ``Generator`` method does), so that
    a prefix of a block equals the same block drawn shorter.

    Examples
    --------
    >>> normal = lambda rng, n: rng.standard_normal(n)
    >>> whole = keyed_draws(5, "x", 0, 10_000, normal)
    >>> part = keyed_draws(5, "x", 4000, 4200, normal)
    >>> bool(np.array_equal(whole[4000:4200], part))
    True
    """
    seed, code = int(seed), key_code(key)
    blocks = list(_blocks(start, stop))
    if len(blocks) == 1 and blocks[0][1] == 0:  # one block, from its start: no copy
        block, _, _, n = blocks[0]
        return draw(_generator(seed, code, block), n)
    out = np.empty(stop - start)
    for block, skip, at, n in blocks:
        out[at : at + n - skip] = draw(_generator(seed, code, block), n)[skip:]
    return out


def keyed_standard_normal(seed: int, key: str, start: int, stop: int) -> NDArray[np.float64]:
    """:func:`keyed_draws` of ``rng.standard_normal``, each block drawn straight into the result
    where the range covers the block from its start (the same numbers, without a copy).

    A block the range leaves unfinished keeps its generator (:data:`_RESUME`), so that the range
    starting where this one stopped (the next chunk of a run) goes on drawing it instead of
    drawing and dropping its prefix again: a generator's normals are a sequence, drawn in one
    call or in two.

    Examples
    --------
    >>> normal = lambda rng, n: rng.standard_normal(n)
    >>> a = keyed_draws(5, "x", 1000, 9000, normal)
    >>> bool(np.array_equal(a, keyed_standard_normal(5, "x", 1000, 9000)))
    True
    >>> b = keyed_standard_normal(5, "x", 9000, 9500)  # goes on with the block left at 9000
    >>> bool(np.array_equal(b, keyed_draws(5, "x", 9000, 9500, normal)))
    True
    """
    seed, code = int(seed), key_code(key)
    out = np.empty(stop - start)
    for block, skip, at, n in _blocks(start, stop):
        kept = _RESUME.pop((seed, key, start + at), None) if skip else None
        if kept is not None:
            rng = _scratch(kept) if isinstance(kept, dict) else kept
            rng.standard_normal(n - skip, out=out[at : at + n - skip])
        else:
            rng = _block_generator(seed, code, block, start, stop)
            if skip:
                out[at : at + n - skip] = rng.standard_normal(n)[skip:]
            else:
                rng.standard_normal(n, out=out[at : at + n])
        if n < BLOCK:  # the block goes on after this range: keep its generator (or state) there
            if len(_RESUME) >= _RESUME_MAX:
                _RESUME.clear()
            scratch = rng is _SCRATCH.__dict__.get("rng")
            keep: np.random.Generator | dict[str, Any] = (
                dict(rng.bit_generator.state) if scratch else rng
            )
            _RESUME[(seed, key, start + at + n - skip)] = keep
    return out


#: Generators (or the states of this thread's scratch generator) of blocks a range left
#: unfinished, by (seed, key, the trial they would draw next).
_RESUME: dict[tuple[int, str, int], np.random.Generator | dict[str, Any]] = {}
#: At most this many kept (a convention: above the keys of one chunk of either method on pair60,
#: 1 666 and 3 505; ≈ 1.3 kB each, so ≤ ≈ 10 MB), all dropped when full.
_RESUME_MAX = 8192


def _blocks(start: int, stop: int) -> Iterator[tuple[int, int, int, int]]:
    """Per block of trials ``start … stop−1``: its number, the trials of its prefix before
    ``start`` (drawn and dropped), where its values go in the result, and how many to draw."""
    if not 0 <= start <= stop:
        raise ValueError(f"trial range: expected 0 ≤ start ≤ stop, found [{start}, {stop})")
    t = start
    while t < stop:
        block = t // BLOCK
        first = block * BLOCK
        end = min(stop, first + BLOCK)
        yield block, t - first, t - start, end - first
        t = end


def _block_generator(
    seed: int, code: int, block: int, start: int, stop: int
) -> np.random.Generator:
    """The generator of block ``block`` of the stream (seed, key code) at its start, for a range
    ``start … stop−1`` that needs it: this thread's scratch generator set to the block's state
    where the state was computed with those of the other keys (:func:`_states_for_range`), else
    :func:`_generator`. The scratch generator is good until the next call."""
    codes = _CODES.get(seed)
    if codes is None:
        if len(_CODES) >= _CODES_SEEDS:
            _CODES.clear()
        codes = _CODES[seed] = {}
    if len(codes) < _CODES_MAX:
        codes[code] = None
    state = _STATES.pop((seed, code, block), None)
    if state is None and (seed, start, stop) != _STATES_RANGE[0] and 0 <= seed < 2**32:
        _states_for_range(seed, start, stop, list(codes))
        state = _STATES.pop((seed, code, block), None)
    if state is None:
        return _generator(seed, code, block)
    return _scratch(
        {
            "bit_generator": "PCG64",
            "state": {"state": state[0], "inc": state[1]},
            "has_uint32": 0,
            "uinteger": 0,
        }
    )


#: Per seed, the key codes drawn in this process, in their first order (the keys a chunk of a
#: run draws are nearly all those the chunk before drew).
_CODES: dict[int, dict[int, None]] = {}
#: At most this many seeds' codes kept (all dropped when full), and this many codes a seed (a
#: convention: a run of pair60 draws ≈ 1 700 keys with the setup method, ≈ 4 000 with the
#: conventional one; a long-lived process, the trainer's server, sees many seeds).
_CODES_SEEDS, _CODES_MAX = 8, 1 << 14
#: PCG64 (state, increment) of blocks of the known keys, by (seed, code, block): those of the
#: range of :data:`_STATES_RANGE`, each taken once.
_STATES: dict[tuple[int, int, int], tuple[int, int]] = {}
#: The (seed, start, stop) whose blocks' states :data:`_STATES` holds.
_STATES_RANGE: list[tuple[int, int, int] | None] = [None]
#: This thread's scratch generator (``rng``), its state set for each block it draws.
_SCRATCH = threading.local()


def _scratch(state: dict[str, Any]) -> np.random.Generator:
    rng: np.random.Generator | None = _SCRATCH.__dict__.get("rng")
    if rng is None:
        rng = _SCRATCH.rng = np.random.Generator(np.random.PCG64(0))
    rng.bit_generator.state = state
    return rng


def _states_for_range(seed: int, start: int, stop: int, codes: list[int]) -> None:
    """The states of the blocks of ``start … stop−1`` of every key code in ``codes``
    (:func:`seeded_states`) into :data:`_STATES`, those of an earlier range dropped."""
    first, last = start // BLOCK, (stop - 1) // BLOCK
    blocks = np.arange(first, last + 1, dtype=np.uint32)
    code_of = np.repeat(np.asarray(codes, np.uint32), blocks.size)
    block_of = np.tile(blocks, len(codes))
    _STATES.clear()
    _STATES_RANGE[0] = (seed, start, stop)
    states = seeded_states(seed, code_of, block_of)
    keys = [(seed, c, b) for c, b in zip(code_of.tolist(), block_of.tolist(), strict=True)]
    _STATES.update(zip(keys, states, strict=True))


#: numpy's ``SeedSequence`` constants (hash multipliers and mixing; its pool of 4 words).
_INIT_A, _MULT_A, _INIT_B, _MULT_B = 0x43B0D7E5, 0x931E8875, 0x8B51F9DD, 0x58F38DED
_MIX_L, _MIX_R = 0xCA01F9DD, 0x4973F715
#: PCG64's 128-bit LCG multiplier.
_PCG_MULT = (2549297995355413924 << 64) + 4865540595714422341
_M128 = (1 << 128) - 1


def _hash_consts(init: int, mult: int, count: int) -> list[int]:
    out = [init]
    for _ in range(count):
        out.append(out[-1] * mult & 0xFFFFFFFF)
    return out


_HASH_A = _hash_consts(_INIT_A, _MULT_A, 16)
_HASH_B = _hash_consts(_INIT_B, _MULT_B, 8)


def seeded_states(
    seed: int, codes: NDArray[np.uint32], blocks: NDArray[np.uint32]
) -> list[tuple[int, int]]:
    """PCG64's (state, increment) of ``default_rng([seed, code(, block)])`` for each (code,
    block), the blocks' seeding of :func:`_generator`, computed for all at once: numpy's
    ``SeedSequence`` (entropy [seed, code, block, 0] in a pool of four 32-bit words, block 0's
    [seed, code] hashed alike: a missing word is hashed as 0) on uint32 arrays, whose products
    wrap as its C arithmetic does, then PCG64's seeding (state 0, increment 2·seq + 1, a step,
    the state word added, a step) on Python integers. 0 ≤ seed < 2³².

    Examples
    --------
    >>> codes, blocks = np.array([7, 7], np.uint32), np.array([0, 3], np.uint32)
    >>> got = seeded_states(5, codes, blocks)
    >>> want = [np.random.default_rng(e).bit_generator.state["state"] for e in ([5, 7], [5, 7, 3])]
    >>> got == [(w["state"], w["inc"]) for w in want]
    True
    """
    u32 = np.uint32
    n = codes.size
    calls = iter(range(len(_HASH_A) - 1))

    def hashmix(value: NDArray[np.uint32]) -> NDArray[np.uint32]:
        i = next(calls)
        v = (value ^ u32(_HASH_A[i])) * u32(_HASH_A[i + 1])
        out: NDArray[np.uint32] = v ^ (v >> u32(16))
        return out

    def mix(x: NDArray[np.uint32], y: NDArray[np.uint32]) -> NDArray[np.uint32]:
        r = x * u32(_MIX_L) - y * u32(_MIX_R)
        out: NDArray[np.uint32] = r ^ (r >> u32(16))
        return out

    entropy = (np.full(n, seed, u32), codes.astype(u32), blocks.astype(u32), np.zeros(n, u32))
    pool = [hashmix(e) for e in entropy]
    for src in range(4):
        for dst in range(4):
            if src != dst:
                pool[dst] = mix(pool[dst], hashmix(pool[src]))
    words = []
    for i in range(8):  # generate_state(4, uint64): eight 32-bit words, two to a 64-bit word
        v = (pool[i % 4] ^ u32(_HASH_B[i])) * u32(_HASH_B[i + 1])
        words.append((v ^ (v >> u32(16))).astype(np.uint64))
    w64 = [(words[2 * k] | (words[2 * k + 1] << np.uint64(32))).tolist() for k in range(4)]
    out = []
    for s_hi, s_lo, q_hi, q_lo in zip(*w64, strict=True):
        inc = ((((q_hi << 64) | q_lo) << 1) | 1) & _M128
        out.append((((inc + ((s_hi << 64) | s_lo)) * _PCG_MULT + inc) & _M128, inc))
    return out


def _generator(seed: int, code: int, block: int) -> np.random.Generator:
    """The generator of block ``block`` of the stream (seed, key code): what
    ``numpy.random.default_rng([seed, code(, block)])`` returns, built without its argument
    checks, which cost about as much as the building (the times: ``benchmarks/README.md``,
    keyed streams) and a chunk of the conventional method builds thousands.

    ``SeedSequence`` turns each integer of a list into its 32-bit words (one word for
    0 ≤ n < 2³², 0 included), so the list's entropy *is* the uint32 array of the same numbers,
    which it takes without converting."""
    seeds = [seed, code] if block == 0 else [seed, code, block]
    if 0 <= seed < 2**32 and block < 2**32:  # code < 2³² (CRC-32)
        entropy: object = np.array(seeds, dtype=np.uint32)
    else:  # a seed of more than one word (or a negative one, refused): the list
        entropy = seeds
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence(entropy)))
