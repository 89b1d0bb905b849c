"""The declared identity of every draw of the procedure.

A draw of the simulated operator (a pointing, a judgment, a reading, a setting) is keyed by
*what it is*, never by where it happens in the run: the step that makes it (``step``: "1" … "5"
for the stages of the setup-data method, "C1" … "C4" for the conventional method), the path
within the step (iteration, side, point, quantity: ``path``) and the act of the operator that
draws (``act``: "mono" a monocular pointing, "stereo" an x-parallax judged, "q" a y-parallax
judged, "read" a scale read, "set" a scale set, "servo" the coordinatograph's servo). Its stream
key is :func:`stereoplotter.random_streams.stream_key` of its parts, so a step added, removed
or moved leaves every other step's draws as they are.

Examples
--------
>>> omega = NoiseKey("2").at(1, "left", "omega")
>>> omega.by("mono").at("knob").stream()
'mono/2/1/left/omega/knob'
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from stereoplotter.random_streams import stream_key

__all__ = ["Act", "KeyLike", "NoiseKey", "Part", "as_key", "pointing"]

#: One part of an identity's path: a name ("left", "omega", a point id) or a number (an
#: iteration, a standard point). [—]
Part = str | int
#: The acts of the operator (and the coordinatograph's servo) that draw.
Act = Literal["", "mono", "stereo", "q", "read", "set", "servo"]


@dataclass(frozen=True, slots=True)
class NoiseKey:
    """The identity of a draw (or of a step whose draws hang below it).

    Attributes
    ----------
    step : str
        The step that draws: a stage ("1", "C2") or a named act outside the methods ("goto").
    path : tuple of str or int
        Where within the step: iteration, side, point, quantity, in the order declared.
    act : str
        The operator's act that draws ("" while the identity names a step, not yet a draw).
    """

    step: str
    path: tuple[Part, ...] = ()
    act: Act = ""

    def at(self, *parts: Part) -> NoiseKey:
        """The identity ``parts`` below this one."""
        return NoiseKey(self.step, (*self.path, *parts), self.act)  # replace(), without its checks

    def by(self, act: Act) -> NoiseKey:
        """The draw of ``act`` at this identity."""
        return NoiseKey(self.step, self.path, act)

    def parts(self) -> tuple[Part, ...]:
        """The parts in the order of the encoding: act (where one draws), step, path."""
        head: tuple[Part, ...] = (self.act,) if self.act else ()
        return (*head, self.step, *self.path)

    def stream(self) -> str:
        """The key of this identity's stream (:func:`~stereoplotter.random_streams.stream_key`)."""
        return stream_key(self.parts())


#: What the procedure's functions take as a key: an identity, or the text of a step's name
#: (an identity with that step and no path).
KeyLike = NoiseKey | str


def as_key(key: KeyLike) -> NoiseKey:
    """``key`` as an identity (a text names the step)."""
    return key if isinstance(key, NoiseKey) else NoiseKey(key)


def pointing(j: int) -> tuple[Part, ...]:
    """The path part of the ``j``-th repeated pointing on one point: none for the first (so a
    single pointing keeps the identity of the book's single reading), ``p<j>`` after it."""
    return (f"p{j}",) if j else ()
