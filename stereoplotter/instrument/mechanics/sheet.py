"""The map sheet on the coordinatograph table, rotated about a pinned corner (``mechanics.md`` §6).

Book procedure (chapter 6, stages 4–5; ``instruments.md`` §6.1): put corner 1 under the needle;
set the counters to corner 3 and rotate the sheet about corner 1 until the needle meets corner 3;
repeat 1/3; check corner 4 (≤ 0.3 mm). Corner 3 is taken diagonal to corner 1 (an assumption).

Model (pymunk, one fresh space per sheet): a sheet body; a ``PivotJoint`` at the needle's actual
position whose anchor on the sheet is mark 1 plus the hand placement error; a ``GearJoint`` with
``max_bias = 0`` as rotary friction; a ``SimpleMotor`` with a torque limit as the handwheel; and an
operator who looks every 50 ms, turns the handwheel proportionally to the tangential offset of
mark 3 from the needle, and stops when the offset looks smaller than his acuity. All randomness
(placement errors, perception noise) comes from an explicit ``numpy.random.Generator``.

The radial part of a pin placement error cannot be removed by rotation; it is geometry and is
computed in closed form by :func:`pin_radial_residual`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import partial
from typing import TYPE_CHECKING

import numpy as np
import pymunk

from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.mechanics.base import N_M, Side
from stereoplotter.instrument.mechanics.pymunk_axis import new_space

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from stereoplotter.instrument.mechanics.coordinatograph import Coordinatograph
    from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = [
    "OperatorParams",
    "SheetOnTable",
    "SheetOrientation",
    "SheetParams",
    "orient_sheet",
    "pin_radial_residual",
]


@dataclass(frozen=True, slots=True)
class SheetParams:
    """The sheet and its handwheel.

    Parameters
    ----------
    size_mm : (float, float)
        Sheet width and height (for its moment of inertia). [mm]
    mass_kg : float
        Sheet (with its backing) mass. [kg]
    friction_torque : float
        Rotary Coulomb friction about the pin; 0.2 N·m = 2·10⁵. [kg·mm²/s²]
    motor_torque : float
        Torque limit of the handwheel; 1 N·m = 10⁶. [kg·mm²/s²]
    max_rate_rad_s : float
        Fastest turning rate the operator uses. [rad/s]
    dt_s : float
        Time step. [s]
    iterations : int
        Solver iterations. [—]
    settle_s : float
        Wait after the handwheel stops. [s]
    """

    size_mm: tuple[float, float] = (500.0, 500.0)
    mass_kg: float = 3.0
    friction_torque: float = 0.2 * N_M
    motor_torque: float = 1.0 * N_M
    max_rate_rad_s: float = 0.02
    dt_s: float = 1.0e-3
    iterations: int = 10
    settle_s: float = 0.1

    @classmethod
    def from_instrument(cls, spec: InstrumentSpec, **overrides: object) -> SheetParams:
        """Rotary friction from ``mechanics.sheet_friction_torque_Nm``; the rest as given.

        Examples
        --------
        >>> from stereoplotter.io.instrument_file import load_instrument
        >>> SheetParams.from_instrument(load_instrument("sc1")).friction_torque  # 0.2 N·m
        200000.0
        """
        fields: dict[str, object] = {"friction_torque": spec.sheet_friction_torque_Nm * N_M}
        fields.update(overrides)
        return cls(**fields)  # type: ignore[arg-type]

    def __post_init__(self) -> None:
        if not (self.mass_kg > 0 and min(self.size_mm) > 0 and self.dt_s > 0):
            raise StereoplotterError(f"sheet: mass, size and dt must be > 0, found {self}")
        if not self.motor_torque > self.friction_torque >= 0.0:
            raise StereoplotterError(
                "sheet: the handwheel torque must exceed the friction torque, found "
                f"{self.motor_torque:g} ≤ {self.friction_torque:g} kg·mm²/s²"
            )


@dataclass(frozen=True, slots=True)
class OperatorParams:
    """The operator who pins and turns the sheet.

    Parameters
    ----------
    acuity_mm : float
        Offset of mark and needle the operator accepts as "on" (cannot see). [mm]
    pointing_sigma_mm : float
        σ of the perception noise added to each look (m_q ≈ 15 µm typical). [mm]
    pin_sigma_mm : float
        σ per coordinate of the hand placement error of the pin, drawn at each pinning. [mm]
    look_interval_s : float
        Time between looks; the handwheel rate is held between them. [s]
    gain_per_s : float
        Proportional gain: rate = gain · offset / radius. Keep gain · look_interval < 1. [1/s]
    max_time_s : float
        Give up turning after this simulated time (``converged = False``). [s]
    floor_mm : float
        Stopping threshold used when ``acuity_mm`` is 0. [mm]
    """

    acuity_mm: float = 0.0
    pointing_sigma_mm: float = 0.0
    pin_sigma_mm: float = 0.0
    look_interval_s: float = 0.05
    gain_per_s: float = 10.0
    max_time_s: float = 30.0
    floor_mm: float = 1.0e-9

    def __post_init__(self) -> None:
        values = (self.acuity_mm, self.pointing_sigma_mm, self.pin_sigma_mm)
        if min(values) < 0.0 or not 0.0 < self.gain_per_s * self.look_interval_s < 2.0:
            raise StereoplotterError(
                f"operator: acuity, sigmas must be ≥ 0 and 0 < gain·look_interval < 2, found {self}"
            )


@dataclass(frozen=True, slots=True)
class SheetOrientation:
    """Result of :func:`orient_sheet`. Corner order 1, 2, 3, 4 along the frame.

    Attributes
    ----------
    marks_mm : numpy.ndarray, shape (4, 2)
        Where the four corner marks lie on the table at the end. [mm]
    residuals_mm : numpy.ndarray, shape (4, 2)
        ``marks_mm`` minus the ideal corner positions (the counter targets). [mm]
    misclosure_mm : numpy.ndarray, shape (2,)
        Corner-4 check: mark 4 minus the needle set to corner 4. [mm]
    misclosure_norm_mm : float
        Its length. [mm]
    tolerance_mm : float
        The corner-4 tolerance. [mm]
    passed : bool
        ``misclosure_norm_mm ≤ tolerance_mm``.
    rotation_error_rad : float
        Sheet angle minus the ideal (0). [rad]
    pin_errors_mm : numpy.ndarray, shape (passes, 2)
        Hand placement error of the pin at each pass (sheet frame). [mm]
    looks : int
        Operator looks over all passes.
    simulated_s : float
        Simulated time. [s]
    converged : bool
        Every pass ended because the operator was satisfied (not by ``max_time_s``).
    """

    marks_mm: np.ndarray
    residuals_mm: np.ndarray
    misclosure_mm: np.ndarray
    misclosure_norm_mm: float
    tolerance_mm: float
    passed: bool
    rotation_error_rad: float
    pin_errors_mm: np.ndarray
    looks: int
    simulated_s: float
    converged: bool


def pin_radial_residual(
    pin_error_mm: ArrayLike, pinned_corner_mm: ArrayLike, target_corner_mm: ArrayLike
) -> np.ndarray:
    """Residual at the target corner that rotation about a misplaced pin cannot remove.

    Parameters
    ----------
    pin_error_mm : array_like, shape (..., 2)
        The pin pierces the sheet at the pinned mark plus this error (sheet frame ≈ table frame
        for small angles). [mm]
    pinned_corner_mm, target_corner_mm : array_like, shape (..., 2)
        Ideal positions of the pinned corner (needle at the pin) and of the corner brought under
        the needle by rotation. [mm]

    Returns
    -------
    numpy.ndarray, shape (..., 2)
        Mark minus needle at the target corner, along the ray from the pin:
        (|c₃ − c₁ − e| − |c₃ − c₁|)·û with û the unit vector from c₁ to c₃. [mm]

    Examples
    --------
    >>> r = pin_radial_residual([0.05, -0.03], [0.0, 0.0], [500.0, 0.0])  # §6: radial 50 µm
    >>> [round(float(v) * 1e3, 3) + 0.0 for v in r]  # µm
    [-49.999, 0.0]
    """
    e = np.asarray(pin_error_mm, float)
    chord = np.asarray(target_corner_mm, float) - np.asarray(pinned_corner_mm, float)
    length = np.linalg.norm(chord, axis=-1, keepdims=True)
    reach = np.linalg.norm(chord - e, axis=-1, keepdims=True)
    return (reach - length) * chord / length


class SheetOnTable:
    """A sheet lying on the coordinatograph table, free to be pinned and turned.

    Parameters
    ----------
    corners_mm : array_like, shape (4, 2)
        Ideal table positions of corners 1–4 (the counter targets). The sheet's marks are these
        corners in the sheet frame, so the ideal pose is angle 0 with the marks on them. [mm]
    params : SheetParams, optional
    angle_rad : float
        Initial misorientation about the sheet centre. [rad]
    offset_mm : (float, float)
        Initial displacement of the sheet. [mm]

    Examples
    --------
    >>> sheet = SheetOnTable([[0, 0], [400, 0], [400, 400], [0, 400]])
    >>> sheet.pin([0.0, 0.0])
    >>> sheet.turn(0.01, 100)  # a positive handwheel rate turns the sheet counter-clockwise
    >>> sheet.angle_rad > 0
    True
    """

    def __init__(
        self,
        corners_mm: ArrayLike,
        params: SheetParams | None = None,
        *,
        angle_rad: float = 0.0,
        offset_mm: ArrayLike = (0.0, 0.0),
    ):
        self.params = SheetParams() if params is None else params
        corners = np.asarray(corners_mm, float)
        if corners.shape != (4, 2) or not np.isfinite(corners).all():
            raise StereoplotterError(
                f"sheet: corners_mm must be 4 finite (x, y) pairs, found shape {corners.shape}"
            )
        self.ideal = corners.copy()
        centre = corners.mean(axis=0)
        self.marks_local = corners - centre
        p = self.params
        self.space = new_space(p.iterations)
        w, h = p.size_mm
        self.body = pymunk.Body(p.mass_kg, p.mass_kg * (w * w + h * h) / 12.0)
        self.body.position = tuple(centre + np.asarray(offset_mm, float))
        self.body.angle = float(angle_rad)
        static = self.space.static_body
        friction = pymunk.GearJoint(static, self.body, 0.0, 1.0)
        friction.max_bias = 0.0
        friction.max_force = p.friction_torque
        # SimpleMotor(a, b, rate) enforces b.w − a.w = −rate: with a = sheet, b = static the
        # sheet turns at +rate (counter-clockwise for rate > 0).
        self.motor = pymunk.SimpleMotor(self.body, static, 0.0)
        self.motor.max_force = p.motor_torque
        self.space.add(self.body, friction, self.motor)
        self.pivot: pymunk.PivotJoint | None = None
        self.needle_at_pin: np.ndarray | None = None
        self.steps = 0

    @property
    def angle_rad(self) -> float:
        """Sheet rotation from the ideal orientation (counter-clockwise). [rad]"""
        return float(self.body.angle)

    def marks(self) -> np.ndarray:
        """Table positions of the four corner marks, shape (4, 2). [mm]"""
        return np.array([tuple(self.body.local_to_world(tuple(m))) for m in self.marks_local])

    def pin(self, needle_mm: ArrayLike, pin_error_mm: ArrayLike = (0.0, 0.0)) -> None:
        """Slide the sheet (at rest) so that mark 1 + ``pin_error_mm`` is under the needle; pin it.

        Parameters
        ----------
        needle_mm : (float, float)
            Actual needle position. [mm]
        pin_error_mm : (float, float)
            Hand placement error, in the sheet frame. [mm]
        """
        if self.pivot is not None:
            self.space.remove(self.pivot)
        needle = np.asarray(needle_mm, float)
        anchor = self.marks_local[0] + np.asarray(pin_error_mm, float)
        c, s = math.cos(self.body.angle), math.sin(self.body.angle)
        rotated = np.array([c * anchor[0] - s * anchor[1], s * anchor[0] + c * anchor[1]])
        self.body.position = tuple(needle - rotated)
        self.body.velocity = (0.0, 0.0)
        self.body.angular_velocity = 0.0
        self.pivot = pymunk.PivotJoint(self.space.static_body, self.body, tuple(needle))
        self.space.add(self.pivot)
        self.needle_at_pin = needle

    def turn(self, rate_rad_s: float, steps: int) -> None:
        """Hold the handwheel at ``rate_rad_s`` (counter-clockwise > 0) for ``steps`` steps."""
        self.motor.rate = float(rate_rad_s)
        for _ in range(steps):
            self.space.step(self.params.dt_s)
        self.steps += steps

    def stop(self) -> None:
        """Brake the handwheel (rate 0) and wait ``settle_s``."""
        self.turn(0.0, round(self.params.settle_s / self.params.dt_s))


def _turn_to_corner_3(board, pivot, target, op, rng, max_looks, look_steps, threshold):
    """Turn the pinned sheet about ``pivot`` until corner 3's mark is seen on ``target``.

    Each look draws one perception normal; returns (satisfied, looks used).
    """
    p = board.params
    for k in range(max_looks):
        mark = np.asarray(board.body.local_to_world(tuple(board.marks_local[2])))
        radius = mark - pivot
        r = float(np.hypot(*radius))
        tangent = np.array([-radius[1], radius[0]]) / r
        seen = float((target - mark) @ tangent) + op.pointing_sigma_mm * rng.standard_normal()
        if abs(seen) <= threshold:
            return True, k + 1
        rate = float(np.clip(op.gain_per_s * seen / r, -p.max_rate_rad_s, p.max_rate_rad_s))
        board.turn(rate, look_steps)
    return False, max_looks


# long: 12 documented parameters make the docstring 50 lines; the code is ~45
def orient_sheet(
    corners_mm: ArrayLike,
    rng: np.random.Generator,
    *,
    sheet: SheetParams | None = None,
    operator: OperatorParams | None = None,
    initial_angle_rad: float = math.radians(1.5),
    initial_offset_mm: ArrayLike = (3.0, -2.0),
    pin_error_mm: ArrayLike = (0.0, 0.0),
    passes: int = 2,
    coordinatograph: Coordinatograph | None = None,
    side: Side = None,
    tolerance_mm: float = 0.3,
) -> SheetOrientation:
    """Orient a sheet on the table: corner 1 under the needle, rotate to corner 3, repeat, check 4.

    Parameters
    ----------
    corners_mm : array_like, shape (4, 2)
        Ideal table positions (counter targets) of corners 1–4 in order along the frame. [mm]
    rng : numpy.random.Generator
        Source of the pin placement errors and the perception noise (two normals per pinning
        and one per look are always drawn, whatever the σ).
    sheet : SheetParams, optional
    operator : OperatorParams, optional
        Default: ideal operator (acuity 0, no noise).
    initial_angle_rad : float
        Misorientation of the sheet as laid down. [rad]
    initial_offset_mm : (float, float)
        Displacement as laid down (removed by the first pinning). [mm]
    pin_error_mm : (float, float)
        Systematic hand placement error of the pin, added to the random one. [mm]
    passes : int
        Pin-and-rotate passes (2: the book's "repeat 1/3").
    coordinatograph : Coordinatograph, optional
        Real drives: the needle goes where :meth:`Coordinatograph.move_pen` puts it. Default:
        ideal drives, the needle exactly on the targets.
    side : {None, "below", "above"}
        Operator strategy for the coordinatograph settings.
    tolerance_mm : float
        Corner-4 tolerance (``InstrumentSpec.corner_tolerance_mm``). [mm]

    Returns
    -------
    SheetOrientation

    Examples
    --------
    >>> corners = [[100, 100], [500, 100], [500, 500], [100, 500]]
    >>> r = orient_sheet(corners, np.random.default_rng(1))
    >>> r.passed, bool(np.abs(r.residuals_mm).max() < 1e-5)
    (True, True)
    """
    if passes < 1:
        raise StereoplotterError(f"orient_sheet: passes must be ≥ 1, found {passes}")
    op = OperatorParams() if operator is None else operator
    board = SheetOnTable(
        corners_mm, sheet, angle_rad=initial_angle_rad, offset_mm=initial_offset_mm
    )
    needle = partial(_needle, coordinatograph, side)
    pins, looks, converged = _pin_and_rotate(board, needle, op, rng, passes, pin_error_mm)
    check = needle(board.ideal[3])
    marks = board.marks()
    misclosure = marks[3] - check
    norm = float(np.hypot(*misclosure))
    return SheetOrientation(
        marks_mm=marks,
        residuals_mm=marks - board.ideal,
        misclosure_mm=misclosure,
        misclosure_norm_mm=norm,
        tolerance_mm=float(tolerance_mm),
        passed=norm <= tolerance_mm,
        rotation_error_rad=board.angle_rad,
        pin_errors_mm=pins,
        looks=looks,
        simulated_s=board.steps * board.params.dt_s,
        converged=converged,
    )


def _needle(coordinatograph: Coordinatograph | None, side: Side, target: np.ndarray) -> np.ndarray:
    """Where the needle goes when the counters are set on ``target``: exactly there with ideal
    drives (no coordinatograph), else where :meth:`Coordinatograph.move_pen` puts it. [mm]"""
    if coordinatograph is None:
        return target.copy()
    return coordinatograph.move_pen(target, side)


def _pin_and_rotate(
    board: SheetOnTable,
    needle,
    op: OperatorParams,
    rng: np.random.Generator,
    passes: int,
    pin_error_mm: ArrayLike,
) -> tuple[np.ndarray, int, bool]:
    """The passes of :func:`orient_sheet`: pin corner 1 under the needle (hand placement error
    ``pin_error_mm`` + σ_pin), turn the sheet until corner 3 lies under the needle. Returns the
    pin errors (passes, 2) [mm], the looks used and whether every turn was satisfied."""
    p = board.params
    corners = board.ideal
    look_steps = max(1, round(op.look_interval_s / p.dt_s))
    max_looks = max(1, math.ceil(op.max_time_s / (look_steps * p.dt_s)))
    threshold = max(op.acuity_mm, op.floor_mm)
    pins = np.empty((passes, 2))
    looks = 0
    converged = True
    for k in range(passes):
        pins[k] = np.asarray(pin_error_mm, float) + op.pin_sigma_mm * rng.standard_normal(2)
        pivot = needle(corners[0])
        board.pin(pivot, pins[k])
        target = needle(corners[2])
        satisfied, used = _turn_to_corner_3(
            board, pivot, target, op, rng, max_looks, look_steps, threshold
        )
        looks += used
        converged &= satisfied
        board.stop()
    return pins, looks, converged
