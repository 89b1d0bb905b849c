"""pymunk back-end: the lead-screw axis in the time domain (``mechanics.md`` §3, §4, §7).

One class for every linear axis. The chain, from handwheel to carriage:

* **nut**: a kinematic body whose velocity is the handwheel input (the screw is self-locking, so
  nothing back-drives it);
* **compliance**: a critically damped ``DampedSpring`` from the nut to a follower body (0.5 kg)
  on its own groove; omitted for a rigid screw (k = ∞);
* **backlash**: ``SlideJoint(follower, carriage, (−D, 0), (0, 0), D − b/2, D + b/2)`` with
  D = 10 mm (a ``PinJoint`` when b = 0);
* **carriage**: ``Body(m, moment=inf)`` on a ``GrooveJoint`` along the rail;
* **friction**: ``PivotJoint(static, carriage)`` with ``max_bias = 0`` and ``max_force = μ·m·g``.

The handwheel is a plan of ``(velocity, n_steps)`` segments: an acceleration staircase (mean
``accel_mm_s2`` < μ·g), slewing, a staircase down, creep over the last ``creep_distance_mm`` and one
fractional step that lands the nut exactly on the target. Velocities are set once per segment and
``space.step`` runs in a tight loop: no Python callback runs per step.

A vertical axis (Z) runs along the space's y axis with gravity (0, −g); horizontal axes run along x
and need no gravity (their grooves would carry the weight).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
import pymunk

from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.mechanics.base import (
    G_MM_S2,
    AxisParams,
    Side,
    check_side,
    check_travel,
    pre_position,
)

__all__ = [
    "SLIDE_OFFSET_MM",
    "PymunkAxis",
    "Segment",
    "new_space",
    "run_programs",
    "velocity_plan",
]

#: D: distance that keeps the SlideJoint and spring anchors away from zero length. [mm]
SLIDE_OFFSET_MM: float = 10.0
#: How far :meth:`PymunkAxis.place` rests a loaded carriage into its flank. [mm]
CONTACT_MM: float = 1.0e-9
#: Slop of the (unused) collision system, set explicitly because the default is in user units.
COLLISION_SLOP_MM: float = 1.0e-4


class Segment(NamedTuple):
    """One piece of a handwheel program.

    Attributes
    ----------
    velocity : float or None
        Signed nut velocity [mm/s]; None for the landing step, whose velocity puts the nut
        exactly on ``target``, or for a ``place``.
    steps : int
        Number of steps (0 for a ``place``).
    target : float
        Where the current stroke ends (landing) or where the nut is placed. [mm]
    place : str
        ``""`` for a driven segment; ``"below"``/``"above"`` for the long-move shortcut
        (:meth:`PymunkAxis.place` at ``target`` from that side).
    """

    velocity: float | None
    steps: int
    target: float
    place: str = ""


def new_space(iterations: int = 10, *, gravity: bool = False) -> pymunk.Space:
    """A pymunk space with the global settings of ``mechanics.md`` §3.

    Parameters
    ----------
    iterations : int
        Solver iterations per step (10: going to 30 changes results by ≤ 0.2 µm).
    gravity : bool
        Gravity (0, −g) with g = 9810 mm/s², for a vertical column.

    Returns
    -------
    pymunk.Space
        No damping, ``collision_slop`` 1·10⁻⁴ mm, sleeping disabled, not threaded.

    Examples
    --------
    >>> space = new_space(gravity=True)
    >>> space.iterations, space.damping, space.collision_slop, tuple(space.gravity)
    (10, 1.0, 0.0001, (0.0, -9810.0))
    """
    space = pymunk.Space()
    space.iterations = int(iterations)
    space.collision_slop = COLLISION_SLOP_MM
    space.damping = 1.0
    space.sleep_time_threshold = math.inf
    space.gravity = (0.0, -G_MM_S2 if gravity else 0.0)
    return space


def velocity_plan(
    distance_mm: float, params: AxisParams, *, final_creep: bool = True
) -> list[tuple[float, int]]:
    """The handwheel speed profile for a monotone move, without the landing step.

    Parameters
    ----------
    distance_mm : float
        Length of the move, ≥ 0. [mm]
    params : AxisParams
        Slew and creep speeds, creep distance, acceleration, staircase level length, dt.
    final_creep : bool
        End with ``creep_distance_mm`` at ``creep_mm_s``. Without it (a quick pre-positioning
        stroke) the move ends at the first staircase level.

    Returns
    -------
    list of (float, int)
        (speed ≥ 0 [mm/s], number of steps). The covered distance falls short of
        ``distance_mm`` by less than one step at the last speed; the landing step closes it.

    Notes
    -----
    Staircase levels are v_j = min(j·Δv, v_slew) held for n_s = round(stair_s/dt) steps, with
    Δv = a·n_s·dt. The peak level n is the largest whose up-and-down staircase fits before the
    creep; the slew at v_n takes whole steps, and what is left joins the final slow part.

    Examples
    --------
    >>> plan = velocity_plan(2.0, AxisParams())
    >>> plan[:3], plan[-1]
    ([(2.0, 10), (4.0, 10), (6.0, 10)], (0.2, 1000))
    >>> abs(2.0 - sum(v * n for v, n in plan) * 1e-3) < 0.2 * 1e-3  # mm: < one creep step short
    True
    """
    if not distance_mm >= 0.0:
        raise StereoplotterError(f"velocity_plan: distance must be ≥ 0 mm, found {distance_mm}")
    dt = params.dt_s
    n_stair = max(1, round(params.stair_s / dt))
    dv = params.accel_mm_s2 * n_stair * dt
    v_end = params.creep_mm_s if final_creep else min(dv, params.slew_mm_s)
    tail = min(params.creep_distance_mm, distance_mm) if final_creep else 0.0
    budget = distance_mm - tail
    levels: list[float] = []
    j = 1
    while True:
        v = min(j * dv, params.slew_mm_s)
        trial = [*levels, v]
        down = [u for u in trial[:-1] if u > v_end]
        if sum(trial) * n_stair * dt + sum(down) * n_stair * dt > budget or v <= v_end:
            break
        levels = trial
        if v >= params.slew_mm_s:
            break
        j += 1
    plan: list[tuple[float, int]] = []
    if levels:
        down = [u for u in levels[:-1] if u > v_end][::-1]
        used = (sum(levels) + sum(down)) * n_stair * dt
        v_peak = levels[-1]
        n_slew = math.floor((budget - used) / (v_peak * dt) + 1e-9)
        plan += [(v, n_stair) for v in levels[:-1]]
        plan.append((v_peak, n_stair + n_slew))
        plan += [(v, n_stair) for v in down]
        budget -= used + n_slew * v_peak * dt
    rest = budget + tail
    n_end = math.floor(rest / (v_end * dt) + 1e-9)
    if n_end:
        plan.append((v_end, n_end))
    return plan


def run_programs(
    space: pymunk.Space,
    dt_s: float,
    programs: Sequence[tuple[PymunkAxis, Sequence[Segment]]],
    settle_steps: int,
) -> int:
    """Step one space while several axes follow their handwheel programs at the same time.

    Parameters
    ----------
    space : pymunk.Space
        The space holding all the axes.
    dt_s : float
        Time step. [s]
    programs : sequence of (PymunkAxis, sequence of Segment)
        Per axis its segments; a landing segment (velocity None, 1 step) gets the velocity that
        puts the nut exactly on its target, computed from the nut position when it starts.
    settle_steps : int
        Steps with every nut at rest after the last segment.

    Returns
    -------
    int
        Number of ``space.step`` calls.
    """
    queues = [[list(seg) for seg in segments] for _, segments in programs]
    head = [0] * len(programs)
    steps = 0
    while True:
        for i, (axis, _) in enumerate(programs):
            while head[i] < len(queues[i]) and queues[i][head[i]][3]:
                _, _, target, side = queues[i][head[i]]
                axis.place(target, side)
                head[i] += 1
        active = [i for i, q in enumerate(queues) if head[i] < len(q)]
        if not active:
            break
        n = min(queues[i][head[i]][1] for i in active)
        for i, (axis, _) in enumerate(programs):
            if head[i] >= len(queues[i]):
                axis._set_nut_velocity(0.0)
                continue
            v, _, target, _ = queues[i][head[i]]
            if v is None:
                v = (target - axis.nut) / dt_s
            axis._set_nut_velocity(v)
        for _ in range(n):
            space.step(dt_s)
        steps += n
        for i in active:
            queues[i][head[i]][1] -= n
            if queues[i][head[i]][1] == 0:
                head[i] += 1
    for axis, _ in programs:
        axis._set_nut_velocity(0.0)
    for _ in range(settle_steps):
        space.step(dt_s)
    return steps + settle_steps


def _scalar(value: object, name: str) -> float:
    """One setting as a float; a PymunkAxis is a single trial."""
    array = np.asarray(value, dtype=float)
    if array.size != 1:
        raise StereoplotterError(
            f"axis {name}: a PymunkAxis simulates one trial, found {array.size} targets "
            "(use PlayAxis for many trials)"
        )
    return float(array.reshape(()))


class PymunkAxis:
    """A lead-screw axis simulated with pymunk (``mechanics.md`` §4).

    Parameters
    ----------
    params : AxisParams
        The axis. ``params.vertical`` puts it along the space's y axis (gravity must be on).
    space : pymunk.Space, optional
        The space to build in (several axes may share one, see :class:`~.Coordinatograph`).
        Default: a fresh :func:`new_space` (with gravity for a vertical axis).
    offset_mm : float
        Position of the rail across the axis (keeps axes of one space apart). [mm]
    start_mm : float, optional
        Initial nut setting, at rest with the carriage centred in the play. Default: 0 if inside
        the range, else the middle of the range. [mm]

    Attributes
    ----------
    space : pymunk.Space
    car_body, nut_body, follower_body : pymunk.Body
        ``follower_body`` is None for a rigid screw.
    coupling, friction_joint : pymunk.Constraint
        The backlash joint and the rail-friction joint (read ``impulse / dt``).
    steps : int
        ``space.step`` calls made by this axis' own moves.

    Examples
    --------
    >>> axis = PymunkAxis(AxisParams(name="X", stiffness_kg_s2=math.inf))
    >>> axis.place(499.0, "below")
    >>> round((axis.approach(500.0) - 500.0) * 1e3, 3)  # µm; mechanics.md §8: −9.800
    -9.8
    """

    def __init__(
        self,
        params: AxisParams,
        space: pymunk.Space | None = None,
        *,
        offset_mm: float = 0.0,
        start_mm: float | None = None,
    ):
        self.params = params
        self.space = (
            new_space(params.iterations, gravity=params.vertical) if space is None else space
        )
        if params.vertical and self.space.gravity.y != -G_MM_S2:
            raise StereoplotterError(
                f"axis {params.name}: a vertical axis needs gravity (0, −{G_MM_S2:g}) mm/s² in "
                f"its space, found {tuple(self.space.gravity)}"
            )
        self._along = (0.0, 1.0) if params.vertical else (1.0, 0.0)
        self._offset = offset_mm
        self.steps = 0
        lo, hi = params.range_mm
        if start_mm is None:
            start_mm = 0.0 if lo <= 0.0 <= hi else 0.5 * (lo + hi)
        check_travel(params, start_mm)
        self._build(start_mm)
        self.place(start_mm)

    # --- construction -------------------------------------------------------------------------

    def _world(self, u: float) -> tuple[float, float]:
        ex, ey = self._along
        return (u * ex - self._offset * ey, u * ey + self._offset * ex)

    def _u(self, body: pymunk.Body) -> float:
        p = body.position
        return p.y if self.params.vertical else p.x

    def _build(self, u0: float) -> None:
        p = self.params
        static = self.space.static_body
        lo, hi = p.range_mm
        margin = 10.0 * (1.0 + p.overtravel_mm)
        groove = (self._world(lo - margin), self._world(hi + margin))
        d = SLIDE_OFFSET_MM
        back = (-d * self._along[0], -d * self._along[1])
        self.car_body = pymunk.Body(p.mass_kg, math.inf)
        self.car_body.position = self._world(u0)
        self.nut_body = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        self.nut_body.position = self._world(u0)
        rail = pymunk.GrooveJoint(static, self.car_body, *groove, (0.0, 0.0))
        friction = pymunk.PivotJoint(static, self.car_body, self._world(u0))
        friction.max_bias = 0.0
        friction.max_force = p.friction_force
        bodies: list[pymunk.Body] = [self.car_body, self.nut_body]
        constraints: list[pymunk.Constraint] = [rail, friction]
        if p.rigid:
            self.follower_body = None
            driver = self.nut_body
        else:
            self.follower_body = pymunk.Body(p.follower_mass_kg, math.inf)
            self.follower_body.position = self._world(u0)
            damping = 2.0 * math.sqrt(p.stiffness_kg_s2 * p.follower_mass_kg)
            spring = pymunk.DampedSpring(
                self.nut_body, self.follower_body, back, (0.0, 0.0), d, p.stiffness_kg_s2, damping
            )
            bodies.append(self.follower_body)
            constraints += [
                pymunk.GrooveJoint(static, self.follower_body, *groove, (0.0, 0.0)),
                spring,
            ]
            driver = self.follower_body
        half = 0.5 * p.backlash_mm
        if half > 0.0:
            play = pymunk.SlideJoint(driver, self.car_body, back, (0.0, 0.0), d - half, d + half)
        else:
            play = pymunk.PinJoint(driver, self.car_body, back, (0.0, 0.0))
        constraints.append(play)
        self.coupling = play
        self.friction_joint = friction
        self.space.add(*bodies, *constraints)

    def _set_nut_velocity(self, v: float) -> None:
        self.nut_body.velocity = (v * self._along[0], v * self._along[1])

    # --- state ---------------------------------------------------------------------------------

    @property
    def nut(self) -> float:
        """Nut (command) position: the counter value. [mm]"""
        return self._u(self.nut_body)

    @property
    def position(self) -> float:
        """Carriage position. [mm]"""
        return self._u(self.car_body)

    def place(self, nut_mm: float, side: Side = None) -> None:
        """Put the axis at rest as a long monotone move from ``side`` would leave it.

        Only the last 1–2 mm of a long move and any reversal then need simulating
        (``mechanics.md`` §4: 0.012 µm from the full 20 mm simulation). All velocities are set to
        zero; only this method teleports the dynamic bodies.

        Parameters
        ----------
        nut_mm : float
            Nut setting. [mm]
        side : {None, "below", "above"}
            The carriage rests on the lower flank (below), the upper one (above) or, for
            ``None``, centred (a vertical column always rests on its lower flank).

        Raises
        ------
        TravelRefusal
            A setting beyond the range stops.
        """
        check_side(side)
        nut_mm = _scalar(nut_mm, self.params.name)
        check_travel(self.params, nut_mm)
        p = self.params
        sign = {None: 0.0, "below": -1.0, "above": 1.0}[side]
        f_over_k = 0.0 if p.rigid else p.friction_force / p.stiffness_kg_s2
        car = nut_mm + p.offset_mm + sign * p.half_play_mm
        # A SlideJoint is inactive exactly at its limit: rest the carriage CONTACT_MM into the
        # loaded flank so that the coupling carries the load from the first step.
        if p.backlash_mm > 0.0 and (p.vertical or sign):
            car += (-1.0 if p.vertical else sign) * CONTACT_MM
        follower = nut_mm + sign * f_over_k
        if p.vertical and not p.rigid:
            follower -= (p.mass_kg + p.follower_mass_kg) * G_MM_S2 / p.stiffness_kg_s2
        self.nut_body.position = self._world(float(nut_mm))
        self.car_body.position = self._world(float(car))
        bodies = [self.nut_body, self.car_body]
        if self.follower_body is not None:
            self.follower_body.position = self._world(float(follower))
            bodies.append(self.follower_body)
        for body in bodies:
            body.velocity = (0.0, 0.0)
            body.force = (0.0, 0.0)

    def program(self, target_mm: float, side: Side = None) -> list[Segment]:
        """The handwheel segments that take the nut to ``target_mm`` finishing from ``side``.

        Parameters
        ----------
        target_mm : float
            Nut target. [mm]
        side : {None, "below", "above"}
            ``None``: straight there; otherwise a pre-position ``overtravel_mm`` beyond the
            target first, when the nut is not already on that side of it.

        Returns
        -------
        list of Segment

        Raises
        ------
        TravelRefusal
            The target or the pre-position is beyond the range stops.
        """
        check_side(side)
        target_mm = _scalar(target_mm, self.params.name)
        check_travel(self.params, target_mm, "target")
        start = self.nut
        pre = float(pre_position(start, target_mm, side, self.params.overtravel_mm))
        segments: list[Segment] = []
        if not math.isnan(pre):
            check_travel(self.params, pre, "pre-position")
            segments += self._move(start, pre, final_creep=False)
            start = pre
        segments += self._move(start, float(target_mm), final_creep=True)
        return segments

    def _move(self, start: float, target: float, *, final_creep: bool) -> list[Segment]:
        sign = 1.0 if target >= start else -1.0
        segments: list[Segment] = []
        if abs(target - start) > self.params.simulate_last_mm:
            start = target - sign * self.params.simulate_last_mm
            segments.append(Segment(None, 0, start, "below" if sign > 0 else "above"))
        plan = velocity_plan(abs(target - start), self.params, final_creep=final_creep)
        segments += [Segment(sign * v, n, target) for v, n in plan]
        return [*segments, Segment(None, 1, target)]

    def approach(self, target: float, side: Side = None) -> float:
        """Drive the nut to ``target``, finishing from ``side``; return the settled carriage.

        Parameters
        ----------
        target : float
            Nut target. [mm]
        side : {None, "below", "above"}
            See :meth:`program`.

        Returns
        -------
        float
            Carriage position after ``params.settle_s`` at rest. [mm]

        Raises
        ------
        TravelRefusal
            Nothing moves if the target or a pre-position is beyond the stops.
        """
        segments = self.program(_scalar(target, self.params.name), side)
        settle = round(self.params.settle_s / self.params.dt_s)
        self.steps += run_programs(self.space, self.params.dt_s, [(self, segments)], settle)
        return self.position
