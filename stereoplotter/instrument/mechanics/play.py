"""Closed-form back-end: the play operator, vectorised over trials.

In the quasi-static regime a lead-screw axis with backlash b, Coulomb friction F = μ·m·g and axial
stiffness k is a *play* (backlash) operator on the nut command s (``mechanics.md`` §2, §8)::

    x = clip(x_prev, s + c − h, s + c + h),   h = b/2 + F/k,   c = 0

For a vertical column under gravity (§7) the load keeps the carriage on the lower flank, so the
play shows as a constant sag c = −(b/2 + (m + m_f)·g/k) and only friction is left as a dead band,
h = F/k. pymunk reproduces this to about 0.5 µm for slow approaches; the operator is the test
oracle and the fast path for bulk Monte Carlo.

Shape layout: every function broadcasts; :class:`PlayAxis` keeps one state per trial, arrays of
shape (T,). A single axis is T = 1.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.mechanics.base import (
    AxisParams,
    Side,
    check_side,
    check_travel,
    detour_start,
)

__all__ = ["PlayAxis", "play"]


def play(x_prev: ArrayLike, s: ArrayLike, h: ArrayLike, c: ArrayLike = 0.0) -> np.ndarray:
    """The play operator: the carriage after a monotone move of the nut to ``s``.

    Parameters
    ----------
    x_prev : array_like
        Carriage position before the move. [mm]
    s : array_like
        Nut position at the end of the move. [mm]
    h : array_like
        Half-width of the dead band, h ≥ 0. [mm]
    c : array_like
        Centre offset of the dead band (sag of a vertical column). [mm]

    Returns
    -------
    numpy.ndarray
        x = clip(x_prev, s + c − h, s + c + h), broadcast over all inputs. [mm]

    Examples
    --------
    >>> play([0.0, 10.0, 10.02], 10.0, 0.01)
    array([ 9.99, 10.  , 10.01])
    """
    centre = np.asarray(s, float) + np.asarray(c, float)
    h = np.asarray(h, float)
    return np.minimum(np.maximum(np.asarray(x_prev, float), centre - h), centre + h)


class PlayAxis:
    """T independent copies of one axis under the play operator (closed form, vectorised).

    Parameters
    ----------
    params : AxisParams
        The axis: range stops, overtravel and, unless ``half_play_mm`` is given, b, μ, m, k.
    half_play_mm : array_like, optional
        Per-trial dead-band half-width h, shape (T,) (e.g. from :func:`half_play_mm` on sampled
        parameters). Default: ``params.half_play_mm`` for every trial. [mm]
    offset_mm : array_like, optional
        Per-trial centre offset c. Default: ``params.offset_mm``. [mm]
    trials : int, optional
        T when both h and c are scalars. Default 1.

    Attributes
    ----------
    h, c : numpy.ndarray
        Shape (T,). [mm]

    Examples
    --------
    >>> axis = PlayAxis(AxisParams(name="X", stiffness_kg_s2=np.inf), trials=3)
    >>> axis.place(0.0, "below")
    >>> axis.approach([5.0, 5.0, -5.0])
    array([ 4.99,  4.99, -4.99])
    >>> axis.approach(5.0, side="below")
    array([4.99, 4.99, 4.99])
    """

    def __init__(
        self,
        params: AxisParams,
        half_play_mm: ArrayLike | None = None,
        offset_mm: ArrayLike | None = None,
        trials: int | None = None,
    ):
        self.params = params
        h = np.asarray(params.half_play_mm if half_play_mm is None else half_play_mm, float)
        c = np.asarray(params.offset_mm if offset_mm is None else offset_mm, float)
        shape = np.broadcast_shapes(h.shape, c.shape, (1,) if trials is None else (trials,))
        if len(shape) != 1:
            raise StereoplotterError(
                f"axis {params.name}: per-trial parameters must have shape (T,), found {shape}"
            )
        if np.any(~(h >= 0.0)):
            raise StereoplotterError(f"axis {params.name}: half_play_mm must be ≥ 0, found {h}")
        self.h = np.broadcast_to(h, shape).copy()
        self.c = np.broadcast_to(c, shape).copy()
        self._nut = np.zeros(shape)
        self._car = self.c.copy()

    @property
    def trials(self) -> int:
        """Number of trials T."""
        return self.h.shape[0]

    @property
    def nut(self) -> np.ndarray:
        """Nut (command) positions, shape (T,). [mm]"""
        return self._nut.copy()

    @property
    def position(self) -> np.ndarray:
        """Carriage positions, shape (T,). [mm]"""
        return self._car.copy()

    @property
    def nut_view(self) -> np.ndarray:
        """:attr:`nut` without the copy, to compute with and not to keep or write into (a move
        replaces the array, it never writes into it). [mm]"""
        return self._nut

    @property
    def position_view(self) -> np.ndarray:
        """:attr:`position` without the copy, on the terms of :attr:`nut_view`. [mm]"""
        return self._car

    def place(self, nut_mm: ArrayLike, side: Side = None) -> None:
        """Put every trial at rest as a long monotone move from ``side`` leaves it.

        Parameters
        ----------
        nut_mm : float or array_like of shape (T,)
            Nut setting. [mm]
        side : {None, "below", "above"}
            ``None`` centres the carriage in the dead band.

        Raises
        ------
        TravelRefusal
            A setting beyond the range stops.
        """
        check_side(side)
        check_travel(self.params, nut_mm)
        s = np.broadcast_to(np.asarray(nut_mm, float), self.h.shape)
        sign = {None: 0.0, "below": -1.0, "above": 1.0}[side]
        self._nut = s.copy()
        self._car = s + self.c + sign * self.h

    def approach(self, target: ArrayLike, side: Side = None) -> np.ndarray:
        """Drive every nut to ``target``, finishing from ``side``; return the carriages.

        Parameters
        ----------
        target : float or array_like of shape (T,)
            Nut target. [mm]
        side : {None, "below", "above"}
            ``None``: straight there. ``"below"`` / ``"above"``: the last stroke is monotone
            and ``params.overtravel_mm`` long (a pre-position beyond the target if needed).

        Returns
        -------
        numpy.ndarray
            Carriage positions, shape (T,). [mm]

        Raises
        ------
        TravelRefusal
            If the target or a needed pre-position is beyond the range stops (nothing moves).
        """
        self.move(target, side)
        return self._car.copy()

    def move(self, target: ArrayLike, side: Side = None, *, owned: bool = False) -> None:
        """:meth:`approach` without returning the carriages (the same arithmetic).

        ``owned``: ``target`` is a new array of shape (T,) that the caller hands over (kept as
        the nuts without a copy)."""
        check_side(side)
        s = np.asarray(target, float)
        lo, hi = self.params.range_mm
        s_min, s_max = s.min(), s.max()
        if not (s_min >= lo and s_max <= hi):  # NaN fails both
            check_travel(self.params, s, "target")
        if s.shape != self.h.shape:
            s = np.broadcast_to(s, self.h.shape)
            owned = False
        x = self._car
        if side is not None:  # pre_position: a detour to the final stroke's start where needed
            ot = self.params.overtravel_mm
            start, detour = detour_start(self._nut, s, side, ot)
            if detour.any():
                # the starts are t ∓ overtravel, rounded monotonically: inside the stops when the
                # extreme target's is, else checked where a detour is made
                edge = s_min - ot if side == "below" else s_max + ot
                if not lo <= edge <= hi:
                    check_travel(self.params, start[detour], "pre-position")
                x = np.where(detour, play(x, start, self.h, self.c), x)
        self._car = play(x, s, self.h, self.c)
        self._nut = s if owned else s.copy()
