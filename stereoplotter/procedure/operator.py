"""The simulated operator: acts only through the instrument's controls, with judgment errors.

``procedure.md`` §The operator model. The operator sees counter and scale readings and, in the
eyepieces, where each measuring mark sits relative to image detail. "Turn a control until X" is a
1-D solve on the instrument model (:mod:`stereoplotter.instrument.kinematics`, closed form or a
fixed number of Newton steps, vectorised over trials), then the judgment error, then the
mechanics: the operator turns the handwheel while looking, so the final *carriage* position is
the target plus the judgment error whatever the backlash (a fixed number of look-and-correct
passes, always finishing from the same side by default); a computed value is *set on its scale*,
so the backlash and the scale errors stay in the result.

Randomness comes only from :class:`Noise`: keyed streams (one per act and iteration) derived from
one seed, so that a vectorised run and a per-trial loop draw identical numbers for each trial.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, fields, replace
from typing import Any, Literal, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from stereoplotter.errors import StereoplotterError
from stereoplotter.instrument.kinematics import (
    CorrectionUnit,
    UnitMap,
    rod_frame,
    rods_intersection_xy,
    rods_y_parallax,
)
from stereoplotter.instrument.knobs import turn_correction_knob
from stereoplotter.instrument.virtual import (
    CONTROL_INFO,
    HEIGHT_SCALE,
    KNOBS,
    SCREWS,
    CassetteName,
    HeightScaleName,
    Instrument,
    KnobName,
    ScaleName,
    ScrewName,
    SetControl,
    Side,
    control_axis,
    control_kind,
    control_side,
)
from stereoplotter.procedure.evaluation import (
    instrument_frame_m,
    photo_points_mm,
    standard_points_m,
)
from stereoplotter.procedure.eye import EYE_MODES, LEGACY_SIGMA_MM, Eye, ObservationSystem
from stereoplotter.procedure.noise_key import KeyLike, NoiseKey, as_key
from stereoplotter.procedure.transcript import Transcript
from stereoplotter.random_streams import keyed_standard_normal
from stereoplotter.scenario.model import Camera, Photo, Point, Scenario
from stereoplotter.scenario.summary import mean_flying_height_m
from stereoplotter.scenario.synthetic import film_deformed

__all__ = [
    "DrivenControl",
    "Look",
    "Noise",
    "Operator",
    "OperatorModel",
    "Scene",
    "SetControlName",
    "solve_1d",
]

#: Controls the operator turns while looking until they are physically at a target
#: (:meth:`Operator.drive`): the lead screws, the cassettes, the correction knobs.
DrivenControl = Literal[ScrewName, CassetteName, KnobName]
#: Controls the operator sets to a computed reading on their scale (:meth:`Operator.set`).
SetControlName = Literal[ScrewName, SetControl, HeightScaleName]


@dataclass(frozen=True, slots=True)
class OperatorModel:
    """Judgment errors and habits of the operator (all **assumed**, ``procedure.md`` table).

    Bases (none of these is documented for the SC-1, SPR-3, SD-3; the book's only figure is the
    y-parallax pointing error m_q = 0.015 mm of its Table 18, ch. 5):

    Attributes
    ----------
    monocular_sigma_mm : float
        σ_mono, mark on a point of one photo, per axis, photo scale. [mm] Assumed 0.010:
        below the book's m_q = 0.015 mm (a monocular setting on a sharp fiducial is easier
        than judging y-parallax) and of the order of the 0.01 mm least count of the counters.
    stereo_sigma_mm : float or None
        σ_p, x-parallax judged zero (the fused mark "on the ground"), photo scale. [mm]
        None (default): from the operator's eye (:mod:`stereoplotter.procedure.eye`), stereo
        acuity of the first kind 30″ through the instrument's observation system,
        σ_p = 30″·d/V (6.06 µm at the assumed V = 6×, d = 250 mm); a number: a free σ.
    y_parallax_sigma_mm : float or None
        σ_q, y-parallax judged (cleared, or seen against ¼ mark). [mm] None (default): from the
        eye, second kind 10″, σ_q = 10″·d/V (2.02 µm at 6×, 250 mm); a number: a free σ. The
        book's m_q = 0.015 mm (Table 18) is a whole measurement error (film, diapositive,
        instrument and pointing, ch. 5), not the eye's alone.
    reading_sigma_lc : float
        σ_read in least counts of the scale read, before rounding to the least count. [—]
        Assumed 0.2: a vernier or drum read to the least count, no data.
    setting_sigma_lc : float
        σ_set in least counts of the scale set. [—] Assumed 0.2, as σ_read.
    quantise : bool
        Readings are rounded to the least count.
    finish_side : {"below", "above", None}
        Habit: always finish a setting from this side (default "below"); None: straight there.
    max_iterations : int
        Bound of every tolerance loop and of every remedy's rounds (reported when reached,
        never silent). A convention (6), not a figure of the book.
    eye : {"physiological", "sigma"}
        How σ_p and σ_q left None are resolved for an instrument (:meth:`for_instrument`):
        "physiological" (default) from the eye; "sigma" a free σ = 0.010 mm without the eye
        model (``simulate --operator`` file ``eye: sigma``).
    remeasure : bool
        Habit: a point whose y-parallax is seen over ¼ mark is looked at again (a new pointing
        and judgement) before it is declared failed (default True, a competent operator).
    observation : ObservationSystem or None
        The observation system the eye figures were derived for (set by :meth:`for_instrument`).
    assumed : bool
        Always True: none of these values is documented for the instruments.
    """

    monocular_sigma_mm: float = 0.010
    stereo_sigma_mm: float | None = None
    y_parallax_sigma_mm: float | None = None
    reading_sigma_lc: float = 0.2
    setting_sigma_lc: float = 0.2
    quantise: bool = True
    finish_side: str | None = "below"
    max_iterations: int = 6
    eye: str = "physiological"
    remeasure: bool = True
    observation: ObservationSystem | None = None
    assumed: bool = field(default=True, init=False)

    def for_instrument(self, spec: Any) -> OperatorModel:
        """σ_p and σ_q left None resolved for the instrument ``spec`` (class doc, ``eye``).

        Examples
        --------
        >>> from stereoplotter.io.instrument_file import load_instrument
        >>> op = OperatorModel().for_instrument(load_instrument("sc1"))
        >>> round(op.y_parallax_sigma_mm * 1000, 2), round(op.stereo_sigma_mm * 1000, 2)
        (2.02, 6.06)
        >>> OperatorModel(eye="sigma").for_instrument(None).y_parallax_sigma_mm
        0.01
        """
        if self.eye not in EYE_MODES:
            raise StereoplotterError(
                f"operator eye: expected one of {', '.join(EYE_MODES)}, found {self.eye!r}"
            )
        if self.stereo_sigma_mm is not None and self.y_parallax_sigma_mm is not None:
            return self
        if self.eye == "sigma":
            sp = sq = LEGACY_SIGMA_MM
            system = None
        else:
            eye = Eye(ObservationSystem.from_spec(spec))
            sp, sq, system = eye.stereo_sigma_mm, eye.y_parallax_sigma_mm, eye.system
        return replace(
            self,
            stereo_sigma_mm=_given(self.stereo_sigma_mm, sp),
            y_parallax_sigma_mm=_given(self.y_parallax_sigma_mm, sq),
            observation=system,
        )

    def eye_figures(self) -> dict[str, Any] | None:
        """The derived judgement figures (:meth:`Eye.to_dict`) where σ_p and σ_q both come from
        the eye, else None."""
        if self.observation is None or self.eye != "physiological":
            return None
        eye = Eye(self.observation)
        if (self.stereo_sigma_mm, self.y_parallax_sigma_mm) != (
            eye.stereo_sigma_mm,
            eye.y_parallax_sigma_mm,
        ):
            return None
        return eye.to_dict()

    def zero(self) -> OperatorModel:
        """The same habits with no judgment error and exact readings; no remeasure (a second look
        without judgment error sees the same; the verification builds its one-source operators
        on this, and keeps the single look of its rows).

        Examples
        --------
        >>> OperatorModel().zero().stereo_sigma_mm
        0.0
        """
        return replace(
            self,
            monocular_sigma_mm=0.0,
            stereo_sigma_mm=0.0,
            y_parallax_sigma_mm=0.0,
            reading_sigma_lc=0.0,
            setting_sigma_lc=0.0,
            quantise=False,
            remeasure=False,
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready parameters with their status."""
        skip = ("assumed", "observation")
        out = {k: getattr(self, k) for k in self.__slots__ if k not in skip}
        out["eye_figures"] = self.eye_figures()
        out["status"] = "assumed"
        return out


class Noise:
    """Keyed normal streams: the draw for an act depends on (seed, key, trial index) only.

    Parameters
    ----------
    seed : int
    trials : int or None
        Trials of this run or chunk (None: a single run, which is trial ``first_trial``).
    trial : int, optional
        Return only this trial's value (the per-trial oracle of a vectorised run).
    first_trial : int
        Index of the chunk's first trial in the whole run (chunked runs, ``procedure.trials``).

    Examples
    --------
    >>> a = Noise(7, 4).normal("stage 1/L/1", 1.0)
    >>> b = Noise(7, 4, trial=2).normal("stage 1/L/1", 1.0)
    >>> c = Noise(7, 2, first_trial=2).normal("stage 1/L/1", 1.0)
    >>> bool(a[2] == b == c[0])
    True
    """

    def __init__(
        self, seed: int, trials: int | None, trial: int | None = None, first_trial: int = 0
    ):
        self.seed = int(seed)
        self.trials = trials
        self.trial = trial
        self.first_trial = int(first_trial)

    def draw(self, key: NoiseKey, sigma: float | None) -> NDArray[np.float64]:
        """σ·z for the draw of the declared identity ``key``: :meth:`normal` of its stream key
        (:meth:`NoiseKey.stream`, the one encoding). ``sigma`` is an :class:`OperatorModel`'s,
        resolved for the instrument before a run (never None then)."""
        return self.normal(key.stream(), cast(float, sigma))

    def normal(self, key: str, sigma: float) -> NDArray[np.float64]:
        """σ·z for the stream ``key``: shape (T,), or () for a single run or a per-trial oracle."""
        if self.trial is not None:
            start = self.first_trial + self.trial
            stop = start + 1
        else:
            start = self.first_trial
            stop = start + (self.trials or 1)
        if sigma == 0.0:
            z = np.zeros(stop - start)
        else:
            z = keyed_standard_normal(self.seed, key, start, stop)
            z *= sigma
        if self.trial is not None or not self.trials:
            return np.asarray(z[0])
        return z


@dataclass(frozen=True)
class Look:
    """The operator's 1-D look: ``fn(value)`` is what is seen with a control at ``value``.
    ``stacked``: ``fn`` may be given x, x + h, x − h stacked on a new leading axis
    (:func:`solve_1d`)."""

    fn: Callable[[Any], NDArray[np.float64]]
    stacked: bool = False

    def __call__(self, value: Any) -> NDArray[np.float64]:
        return self.fn(value)


def solve_1d(
    fun: Callable[[Any], Any],
    x0: ArrayLike,
    target: ArrayLike,
    iterations: int = 6,
    h: float = 1e-6,
) -> NDArray[np.float64]:
    """x with fun(x) = target by a fixed number of Newton steps (central differences).

    A fixed count (no early exit) keeps a vectorised run and a per-trial loop bit-identical.
    A :class:`Look` with ``stacked`` set is evaluated once per step on x, x + h, x − h stacked
    on a new leading axis (it must give each the bits it gives alone: element-wise IEEE
    arithmetic, square roots and element-wise ufuncs such as cos, sin only).

    Examples
    --------
    >>> float(solve_1d(lambda x: x**3, 1.0, 8.0, iterations=12))
    2.0
    """
    x = np.asarray(x0, float) + 0.0
    t = np.asarray(target, float)
    stacked = isinstance(fun, Look) and fun.stacked
    for _ in range(iterations):
        if stacked:
            v = fun(np.stack([x, x + h, x - h]))
            r = v[0] - t
            d = (v[1] - v[2]) / (2.0 * h)
        else:
            r = fun(x) - t
            d = (fun(x + h) - fun(x - h)) / (2.0 * h)
        with np.errstate(divide="ignore", invalid="ignore"):
            step = np.where(d != 0.0, r / d, 0.0)
        x = x - step
    return x


@dataclass(frozen=True)
class Scene:
    """What lies in the cassettes and on the ground: the physical photos and the truth a run
    reads, taken from the scenario once (:meth:`build`); the procedure never reads the scenario.

    Attributes
    ----------
    camera : Camera
        The taking camera (f, principal point, format).
    photos : tuple of Photo
        The photos "left" and "right" in the scenario's order: true exterior orientation and
        film deformation.
    points : tuple of Point
        The scenario's control and check points (ids, roles, local and SK-42 coordinates).
    fiducials_mm : dict
        "left"/"right" → (4, 2) fiducial marks 1–4 on the (deformed) film. [mm]
    standard_points_m : ndarray, shape (6, 3)
        Ground points of the six standard points (Fig. 39): 1, 2 below the principal points,
        3, 4 at +c and 5, 6 at −c on the photo y axis of photos 1, 2 (local frame). [m]
    c_mm : float
        c of the standard points on the photo. [mm]
    source : str
        The scenario's file (named in a refusal).
    flying_height_m : float
        The scenario summary's mean flying height of the two photos above the mean point
        height (each rounded to 0.1 m,
        :func:`~stereoplotter.scenario.summary.mean_flying_height_m`). [m]
    grid_m : ndarray, shape (g, 3), or None
        The working-area grid where the true residual y-parallax is evaluated (local frame;
        ``procedure.run.residual_grid_m``). [m]
    standard, grid_images_mm : (ndarray, ndarray)
        True images of the standard points (shape (6, 2) each) and of the grid (None without
        one) on the left and right photo, computed once with the scene (:meth:`images`;
        read-only). [mm]
    """

    camera: Camera
    photos: tuple[Photo, ...]
    points: tuple[Point, ...]
    fiducials_mm: dict[str, NDArray[np.float64]]
    standard_points_m: NDArray[np.float64]
    c_mm: float
    source: str = ""
    flying_height_m: float = float("nan")
    grid_m: NDArray[np.float64] | None = None
    standard: tuple[NDArray[np.float64], NDArray[np.float64]] = field(init=False, repr=False)
    grid_images_mm: tuple[NDArray[np.float64], NDArray[np.float64]] | None = field(
        init=False, repr=False
    )
    #: Images of the ground points asked for before (:meth:`images`), kept for the scene's life.
    _images: dict[bytes, tuple[NDArray[np.float64], NDArray[np.float64]]] = field(
        init=False, repr=False, compare=False, default_factory=dict
    )

    def __post_init__(self) -> None:
        # frozen: set once here, so that dataclasses.replace (new standard points) recomputes them
        object.__setattr__(self, "standard", self.images(self.standard_points_m, read_only=True))
        grid = None if self.grid_m is None else self.images(self.grid_m, read_only=True)
        object.__setattr__(self, "grid_images_mm", grid)

    @classmethod
    def build(
        cls,
        scenario: Scenario,
        frame_origin_m: ArrayLike,
        frame_rotation: float,
        c_mm: float,
        grid_m: ArrayLike | None = None,
    ) -> Scene:
        """Photos of ``scenario``, its points, its six standard points (c from the instrument
        spec) and, if given, the residual grid ``grid_m`` (local frame) [m].

        The standard points are those of ``stereoplotter.procedure.evaluation.standard_points_m``
        (Fig. 39: nadirs ± c·H̄/f), H̄ the flying height of S_л over the mean control height.
        """
        calibrated = scenario.camera.fiducial_array_mm()
        fid = {p.name: film_deformed(p, calibrated) for p in scenario.photos}  # the true marks
        z0 = float(np.mean([p.local_m[2] for p in scenario.points]))
        h = float(scenario.photo("left").exterior.centre[2]) - z0
        frame = standard_points_m(scenario, frame_origin_m, frame_rotation, h, c_mm)
        local = instrument_frame_m(frame, frame_origin_m, frame_rotation, inverse=True)
        height = mean_flying_height_m(scenario)
        return cls(
            scenario.camera,
            scenario.photos,
            scenario.points,
            fid,
            local,
            c_mm,
            scenario.source,
            height,
            None if grid_m is None else np.asarray(grid_m, float),
        )

    def photo(self, name: str) -> Photo:
        """The photo ``name`` ("left" or "right")."""
        return next(p for p in self.photos if p.name == name)

    def point(self, point_id: str) -> Point:
        """The control or check point ``point_id``."""
        return next(p for p in self.points if p.id == point_id)

    def images(
        self, points_m: ArrayLike, *, read_only: bool = False
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """True images of ground points on the left and right photo (fiducial system). [mm]

        ``read_only``: the arrays refuse writes (images kept for the whole run)."""
        pts = np.asarray(points_m, float)
        key = pts.tobytes() + repr(pts.shape).encode()
        known = self._images.get(key)
        if known is None:  # the few control points a procedure fuses on, again and again
            known = (
                photo_points_mm(self.camera, self.photo("left"), pts),
                photo_points_mm(self.camera, self.photo("right"), pts),
            )
            if pts.size <= 30:
                self._images[key] = known
        out = (known[0].copy(), known[1].copy())
        for a in out if read_only else ():
            a.setflags(write=False)
        return out


class Operator:
    """An operator at one instrument (or at T instruments at once).

    Parameters
    ----------
    instrument : Instrument
    model : OperatorModel
    noise : Noise
    transcript : Transcript
    """

    def __init__(
        self, instrument: Instrument, model: OperatorModel, noise: Noise, transcript: Transcript
    ):
        self.inst = instrument
        self.model = model.for_instrument(instrument.spec)
        self.noise = noise
        #: Every act draws, its value used or not (:meth:`fuse_mark`): where the noise is not a
        #: plain keyed stream (one that records or designs its acts, whose list of acts is part
        #: of its result). A plain stream leaves an unused act undrawn: a key's draws are its
        #: own, so every other act draws the same numbers.
        self.draws_unused = type(noise) is not Noise
        self.log = transcript
        self.trials = instrument.trials
        self.commanded: dict[str, NDArray[np.float64]] = {}
        self.passes = 3 if instrument.backend == "pymunk" else 2
        #: Per control, the trials whose handwheel was turned against its stop.
        self.stopped: dict[str, NDArray[np.bool_]] = {}
        #: Per lead screw, the readings of its two stops (the scales never change).
        self._stops: dict[str, tuple[NDArray[np.float64], NDArray[np.float64]]] = {}

    # --- shapes -------------------------------------------------------------------------------

    def v(self, x: ArrayLike) -> NDArray[np.float64]:
        """A value in the run's shape: (T,) or ()."""
        a = np.asarray(x, float)
        if self.trials:
            if a.shape == (self.trials,):
                return a.copy()
            return np.broadcast_to(a, (self.trials,)).copy()
        return a.reshape(-1)[0] + np.zeros(()) if a.size == 1 else a

    def all(self) -> NDArray[np.bool_]:
        """An all-true mask."""
        return np.ones(self.trials, bool) if self.trials else np.array(True)

    # --- least counts -------------------------------------------------------------------------

    def least_count(self, control: ScaleName | SetControlName) -> float:
        """The least count of a control's scale (:meth:`ControlInfo.least_count`); 0 for κ and
        the knobs, whose scales the instrument file gives none (no setting error in least
        counts). [its unit]"""
        return CONTROL_INFO[control].least_count(self.inst.spec) or 0.0

    # --- reading and setting ------------------------------------------------------------------

    def read(self, control: ScaleName, key: KeyLike) -> NDArray[np.float64]:
        """Read a counter or scale: exact value + σ_read, rounded to the least count."""
        lc = self.least_count(control)
        exact = self.v(self.inst.read(control, exact=True))
        seen = exact + self.noise.draw(as_key(key).by("read"), self.model.reading_sigma_lc * lc)
        if self.model.quantise:
            seen = np.round(seen / lc) * lc
        return seen

    def set(
        self,
        control: SetControlName,
        value: ArrayLike,
        key: KeyLike,
        active: NDArray[np.bool_] | None = None,
    ) -> NDArray[np.float64]:
        """Set a computed value on a scale (σ_set); backlash and scale errors stay in."""
        active = self.all() if active is None else active
        if not np.any(active):
            return self.v(value)
        value = self.v(value)
        if control in SCREWS or control == HEIGHT_SCALE:
            lc = self.least_count(control)
            cmd = value + self.noise.draw(as_key(key).by("set"), self.model.setting_sigma_lc * lc)
            prev = self.v(self.inst.read(control, exact=True))
            cmd = self._at_stop(control, cmd)
            self.inst.set(control, np.where(active, cmd, prev), side=self.model.finish_side)
        else:
            lc = self.least_count(control)
            cmd = value + self.noise.draw(as_key(key).by("set"), self.model.setting_sigma_lc * lc)
            prev = self.commanded.get(control, cmd)
            cmd = np.where(active, cmd, prev)
            self.inst.set(control, cmd)
            self.commanded[control] = cmd
        return cmd

    def _at_stop(
        self, control: ScrewName | HeightScaleName, reading: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """The operator turns no further than the stop (the instrument would refuse): a reading
        beyond it becomes the stop's reading, and the trial is flagged in :attr:`stopped`."""
        if control == HEIGHT_SCALE:
            return reading
        low, high = self._stop_readings(control)
        beyond = reading < low
        beyond |= reading > high
        if not beyond.any():  # within the stops (or NaN, which stays NaN): the reading as it is
            return reading
        self._flag_stopped(control, beyond)
        return np.minimum(np.maximum(reading, low), high)  # np.clip's values, less overhead

    def _stop_readings(self, control: ScrewName) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The readings of the two stops of a lead screw (low, high), cached."""
        stops = self._stops.get(control)
        if stops is None:
            lo, hi = self.inst.travel_mm(control)
            margin = 1e-9
            r_lo, r_hi = (
                self.v(self.inst.reading_of(control, v)) for v in (lo + margin, hi - margin)
            )
            stops = np.minimum(r_lo, r_hi), np.maximum(r_lo, r_hi)
            self._stops[control] = stops
        return stops

    def _flag_stopped(self, control: str, beyond: NDArray[np.bool_]) -> None:
        if beyond.any():
            self.stopped[control] = self.stopped.get(control, np.zeros_like(beyond)) | beyond

    # --- turning while looking ---------------------------------------------------------------

    def physical(self, control: DrivenControl) -> NDArray[np.float64]:
        """Where a control physically is (what the eye judges in the eyepiece)."""
        if control in SCREWS:
            now: Any = self.inst.position(control)  # a copy of the carriages
            return now if self.trials and np.shape(now) == (self.trials,) else self.v(now)
        if control_kind(control) == "cassette":
            return self.v(self.inst.unit(control_side(control)).kappa)
        if control in KNOBS:
            axis, side = control_axis(control), control_side(control)
            unit = self.inst.unit(side)
            return self.v(unit.tan_alpha if axis == "alpha" else unit.tan_omega)
        raise StereoplotterError(f"cannot drive {control!r}")

    def drive(
        self,
        control: DrivenControl,
        target: ArrayLike,
        active: NDArray[np.bool_] | None = None,
    ) -> None:
        """Turn a handwheel, knob or cassette until the control is physically at ``target``.

        A fixed number of look-and-correct passes: with the habit of finishing from one side
        the backlash is a constant offset, removed by the second pass.
        """
        active = self.all() if active is None else active
        if not np.any(active):
            return
        if self.trials and control in SCREWS:  # a lead screw over T trials: the fast path
            screw = control
            target = np.asarray(target, float)  # only read: no copy of a (T,) target
            if target.shape != (self.trials,):
                target = self.v(target)
            side = self.model.finish_side
            if self.inst.drive_screw(
                screw, target, active, self.passes, lambda r: self._at_stop(screw, r), side
            ):
                return
        target = self.v(target)
        for _ in range(self.passes):
            now = self.physical(control)
            err = np.where(active, target - now, 0.0)
            if control in SCREWS:
                cmd = self._at_stop(control, self.v(self.inst.read(control, exact=True)) + err)
                self.inst.set(control, cmd, side=self.model.finish_side)
            elif control in KNOBS:
                cmd = self.commanded.get(control, now) + err
                self.inst.turn_knob(control, cmd)
                self.commanded[control] = cmd
            else:
                cmd = self.commanded.get(control, now) + err
                self.inst.set(cast(CassetteName, control), cmd)
                self.commanded[control] = cmd

    # --- looking ------------------------------------------------------------------------------

    def units(self) -> tuple[CorrectionUnit, CorrectionUnit]:
        """The correction units of the left and right photo as they are."""
        return self.inst.unit("left"), self.inst.unit("right")

    def unit_map(self, side: Side, unit: CorrectionUnit | None = None) -> UnitMap:
        """The UnitMap of ``unit`` (default: the present unit of ``side``), cached by the
        instrument while that unit is in place."""
        if unit is None or unit is self.inst.unit(side):
            return self.inst.unit_map(side)
        return UnitMap(unit)

    def mark_on(
        self,
        side: Side,
        photo_point_mm: ArrayLike,
        key: KeyLike,
        active: NDArray[np.bool_] | None = None,
        free: str = "XY",
    ) -> NDArray[np.float64]:
        """Monocular pointing: move X and/or Y until the mark of ``side`` is on a photo point.

        ``free`` names the handwheels turned ("XY", "X": onto the fiducial line x = const with
        Y as set, "Y": onto y = const). Returns the judgment error, shape (..., 2); on one line
        only its component across the line is judged, the other is 0 (its act not drawn unless
        :attr:`draws_unused`). [mm]
        """
        mono = as_key(key).by("mono")
        sigma = self.model.monocular_sigma_mm
        parts = []
        for handwheel, name in (("X", "x"), ("Y", "y")):
            if handwheel in free:
                parts.append(self.noise.draw(mono.at(name), sigma))
            else:
                if self.draws_unused:
                    self.noise.draw(mono.at(name), sigma)
                parts.append(self.v(0.0))
        e = np.stack(parts, axis=-1)
        target = np.asarray(photo_point_mm, float) + e
        umap = self.unit_map(side)
        setting = self.inst.setting
        car = {c: self.physical(c) for c in ("X", "Y", "Z")}
        # the rod of ``side`` (kinematics.rod_from_counters / counters_from_photo, split so that
        # the unit's invariants and the rod frame are computed once per pointing)
        sx, sy, n = rod_frame(setting, side, car["Z"])
        if free == "XY":  # both handwheels: the closed-form monocular setting (§3.4)
            xi, eta = umap.rod_xy(target[..., 0], target[..., 1])
            car["X"], car["Y"] = sx + n * xi, sy + n * eta
            free_solve = ""
        else:
            free_solve = free
        for axis in free_solve:
            comp = 0 if axis == "X" else 1
            if axis == "X":
                eta = (np.asarray(car["Y"], float) - sy) / n

                def seen(value: Any, other: Any = eta, comp: int = comp) -> Any:
                    return umap.photo_xy((np.asarray(value, float) - sx) / n, other)[comp]
            else:
                xi = (np.asarray(car["X"], float) - sx) / n

                def seen(value: Any, other: Any = xi, comp: int = comp) -> Any:
                    return umap.photo_xy(other, (np.asarray(value, float) - sy) / n)[comp]

            car[axis] = solve_1d(seen, car[axis], target[..., comp], iterations=4, h=1e-3)
        for axis in free:
            self.drive(cast(ScrewName, axis), car[axis], active)
        return e

    def fuse(
        self,
        points_m: ArrayLike,
        images: tuple[NDArray[np.float64], NDArray[np.float64]],
        key: KeyLike,
        active: NDArray[np.bool_] | None = None,
        move: bool = True,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Stereo pointing on a ground point: clear the x-parallax (σ_p) with the floating mark
        on the point (σ_mono); return the y-parallax seen there (σ_q) and the true one. [mm]"""
        key = as_key(key)
        q_true = self._fused(images, key, active, move)
        eq = self.noise.draw(key.by("q"), self.model.y_parallax_sigma_mm)
        return q_true + eq, q_true

    def fuse_mark(
        self,
        points_m: ArrayLike,
        images: tuple[NDArray[np.float64], NDArray[np.float64]],
        key: KeyLike,
        active: NDArray[np.bool_] | None = None,
    ) -> NDArray[np.float64]:
        """:meth:`fuse` where no y-parallax is judged (the mark fused on a point to read a
        counter or the height scale): the same pointing, without the act σ_q, whose keyed draw
        is then not made (unless :attr:`draws_unused`). Returns the true y-parallax. [mm]"""
        key = as_key(key)
        q_true = self._fused(images, key, active, True)
        if self.draws_unused:
            self.noise.draw(key.by("q"), self.model.y_parallax_sigma_mm)
        return q_true

    def _fused(
        self,
        images: tuple[NDArray[np.float64], NDArray[np.float64]],
        key: NoiseKey,
        active: NDArray[np.bool_] | None,
        move: bool,
    ) -> NDArray[np.float64]:
        """The pointing of :meth:`fuse` (σ_mono, σ_p), the carriages moved there when ``move``;
        the true y-parallax at the mark. [mm]"""
        mono = key.by("mono")
        ex = self.noise.draw(mono.at("x"), self.model.monocular_sigma_mm)
        ey = self.noise.draw(mono.at("y"), self.model.monocular_sigma_mm)
        ep = self.noise.draw(key.by("stereo"), self.model.stereo_sigma_mm)
        pl, pr = (np.asarray(p, float) for p in images)
        # the marks at the photo points shifted by (ex, ey) on both photos and by ep in x on the
        # left: by component (the y of the left mark + 0·ep is that y, to the bit)
        r = rods_intersection_xy(
            self.unit_map("left").rod_xy(pl[..., 0] + ex + ep, pl[..., 1] + ey),
            self.unit_map("right").rod_xy(pr[..., 0] + ex, pr[..., 1] + ey),
            self.inst.setting,
        )
        if move:
            self.drive("X", r.x_mm, active)
            self.drive("Y", r.y_mm, active)
            self.drive("Z", r.depth_mm, active)
        return r.y_parallax_mm

    def q_turning(
        self, control: CassetteName | KnobName, images: tuple[ArrayLike, ArrayLike]
    ) -> Look:
        """q at homologous points as a function of where ``control`` (a cassette κ or a
        correction knob) would be, the rest of the instrument as it is now: the operator's 1-D
        look for :func:`solve_1d`.

        The same arithmetic as ``counters_from_homologous_points(...).y_parallax_mm`` on the
        units with the control turned; the other photo's rod and cos κ, sin κ of a knob's unit
        are computed once.
        """
        side = control_side(control)
        other: Side = "right" if side == "left" else "left"
        pts = {"left": np.asarray(images[0], float), "right": np.asarray(images[1], float)}
        setting = self.inst.setting
        fixed = self.unit_map(other).rod_xy(pts[other][..., 0], pts[other][..., 1])
        base = self.unit_map(side)
        x, y = pts[side][..., 0], pts[side][..., 1]
        cassette = control_kind(control) == "cassette"
        if cassette:

            def turned(value: Any) -> UnitMap:
                return base.with_kappa(value)
        else:
            axis = control_axis(control)
            linkage = self.inst.variant.linkage

            def turned(value: Any) -> UnitMap:
                return base.with_knob(axis, value, linkage)

        def q(value: Any) -> Any:
            moving = turned(value).rod_xy(x, y)
            if side == "left":
                return rods_y_parallax(moving, fixed, setting)
            return rods_y_parallax(fixed, moving, setting)

        # a turn at one point is element-wise arithmetic and square roots (the mechanisms' scales
        # too) and, for a cassette, cos κ and sin κ, element-wise ufuncs whose every element a
        # vectorised run already needs to be the one of the trial alone (the per-trial oracle):
        # x, x ± h at once
        return Look(q, stacked=np.ndim(x) == 0 and np.ndim(y) == 0)

    def y_parallax(
        self, points_m: ArrayLike, images: tuple[NDArray[np.float64], NDArray[np.float64]]
    ) -> Any:
        """The true y-parallax of the present model at ground points (no judgment). [mm]"""
        left, right = self.units()
        setting = self.inst.setting
        if self.trials:  # one row per trial, one column per point
            left, right, setting = (_column(o) for o in (left, right, setting))
        pl, pr = (np.asarray(p, float) for p in images)
        return rods_y_parallax(
            UnitMap(left).rod_xy(pl[..., 0], pl[..., 1]),
            UnitMap(right).rod_xy(pr[..., 0], pr[..., 1]),
            setting,
        )

    def knob_for(
        self,
        knob: KnobName,
        unit: CorrectionUnit,
        photo_point: ArrayLike,
        rod: ArrayLike,
        comp: int,
        target: ArrayLike,
    ) -> NDArray[np.float64]:
        """T of ``knob`` that puts ``photo_point`` under the rod coordinate ``rod`` (axis comp).

        A 1-D Newton solve on the unit model with the instrument's own linkage (D1).
        """
        axis, side = control_axis(knob), control_side(knob)
        linkage = self.inst.variant.linkage
        trig = self.unit_map(side, unit).trig  # κ stays while the knob turns
        rod = np.asarray(rod, float)
        xi, eta = rod[..., 0], rod[..., 1]

        def seen(t: Any) -> Any:
            u = turn_correction_knob(unit, axis, t, linkage=linkage)
            return UnitMap(u, trig).photo_xy(xi, eta)[comp]

        t0 = self.physical(knob)
        return solve_1d(seen, t0, target, iterations=6, h=1e-6)


def _given(value: float | None, derived: float) -> float:
    """A σ given as a number, else the derived one."""
    return derived if value is None else value


def _column(obj: Any) -> Any:
    """A frozen unit/setting with every per-trial field (T,) turned into a column (T, 1)."""
    changes = {}
    for f in fields(obj):
        v = getattr(obj, f.name)
        if isinstance(v, np.ndarray) and v.ndim == 1:
            changes[f.name] = v[:, None]
    return replace(obj, **changes)
