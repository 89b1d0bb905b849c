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

import zlib
from collections.abc import Callable, Iterable, Iterator
from functools import lru_cache

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
        rng = _RESUME.pop((seed, key, start + at), None) if skip else None
        if rng is not None:
            rng.standard_normal(n - skip, out=out[at : at + n - skip])
        else:
            rng = _generator(seed, code, block)
            if skip:
                out[at : at + n - skip] = rng.standard_normal(n)[skip:]
            else:
                rng.standard_normal(n, out=out[at : at + n])
        if n < BLOCK:  # the block goes on after this range: keep its generator there
            if len(_RESUME) >= _RESUME_MAX:
                _RESUME.clear()
            _RESUME[(seed, key, start + at + n - skip)] = rng
    return out


#: Generators of blocks a range left unfinished, by (seed, key, the trial they would draw next).
_RESUME: dict[tuple[int, str, int], np.random.Generator] = {}
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
