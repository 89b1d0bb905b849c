"""The results of an evaluation (:mod:`stereoplotter.procedure.evaluation`): the errors of a
built model per point set, their summaries and their JSON form.

Shapes: with a single instrument every per-point array has shape (n,) and every summary value
is a float; with T trials they have shapes (T, n) and (T,).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from stereoplotter.constants import MM_PER_M
from stereoplotter.procedure.arrays import max_abs_last

__all__ = ["ModelEvaluation", "PointSetEvaluation"]

_F = NDArray[np.float64]


def _rms(v: _F) -> _F:
    rms: _F = np.sqrt(np.mean(np.square(v), axis=-1))
    return rms


def _max_abs(v: _F) -> _F:
    return max_abs_last(np.asarray(v, float))


def _plain(v: Any) -> Any:
    """JSON-ready: ndarrays to (nested) lists, numpy scalars to float."""
    if isinstance(v, dict):
        return {k: _plain(x) for k, x in v.items()}
    if isinstance(v, list | tuple):
        return [_plain(x) for x in v]
    if isinstance(v, np.ndarray):
        return v.tolist()
    if isinstance(v, np.floating | np.integer):
        return v.item()
    return v


def _out(v: _F, trials: int | None) -> Any:
    """Summary value: a float for a single instrument, an array (T,) for T trials."""
    v = np.asarray(v, float)
    return float(v) if trials is None else v


@dataclass(frozen=True, slots=True)
class PointSetEvaluation:
    r"""Errors of the built model at one set of ground points (grid, standard, control or check).

    Attributes
    ----------
    ids : tuple of str
        Point ids (grid points "g0", "g1", … in row-major order from low Y, low X).
    ground_m : ndarray, shape (n, 3)
        The points in the instrument frame (origin S_л, base along +X). [m]
    model_mm : ndarray, shape (n, 3)
        Ideal model (X − MO_X, Y − MO_Y, D). [mm]
    x_parallax_error_mm, y_parallax_mm : ndarray, shape (n,) or (T, n)
        δp and q at the ideal position (module docstring). [photo mm]
    x_error_m, y_error_m : ndarray, shape (n,) or (T, n)
        Plan error of the built point along the instrument-frame axes. [m]
    height_error_m : ndarray, shape (n,) or (T, n)
        ΔH of the built point, + = too high. [m]
    y_parallax_seen_mm : ndarray, shape (n,) or (T, n)
        The y-parallax the operator sees at the built point (``kinematics.md`` §3.4 sign). [mm]
    height_error_after_plane_m, x_parallax_error_after_plane_mm : ndarray or None
        The same after removing the plane fitted at the plane control points. [m], [mm]
    """

    ids: tuple[str, ...]
    ground_m: _F
    model_mm: _F
    x_parallax_error_mm: _F
    y_parallax_mm: _F
    x_error_m: _F
    y_error_m: _F
    height_error_m: _F
    y_parallax_seen_mm: _F
    height_error_after_plane_m: _F | None = None
    x_parallax_error_after_plane_mm: _F | None = None

    @property
    def plan_error_m(self) -> _F:
        """|ΔX, ΔY| of the built point. [m]"""
        return np.hypot(self.x_error_m, self.y_error_m)

    def summary(
        self,
        flying_height_m: float,
        map_scale_denominator: int | None,
        trials: int | None,
        permille: bool = True,
    ) -> dict[str, Any]:
        """Max |·| and RMS over the points of every error (floats, or arrays (T,) for T trials).

        Keys end in their unit: ``_mm`` photo mm (parallaxes), ``_m`` ground metres,
        ``_map_mm`` mm on the map, ``_permille`` ‰ of the mean flying height H̄ (left out
        unless ``permille``).
        """
        if not self.ids:
            return {}
        out: dict[str, Any] = {"n_points": len(self.ids)}
        per_h = MM_PER_M / float(flying_height_m)

        def put(name: str, v: _F | None, unit: str) -> None:
            if v is None:
                return
            out[f"{name}_max_{unit}"] = _out(_max_abs(v), trials)
            out[f"{name}_rms_{unit}"] = _out(_rms(v), trials)

        put("x_parallax_error", self.x_parallax_error_mm, "mm")
        put("y_parallax", self.y_parallax_mm, "mm")
        put("x_parallax_error_after_plane", self.x_parallax_error_after_plane_mm, "mm")
        plan = self.plan_error_m  # computed once for both units
        put("plan_error", plan, "m")
        if map_scale_denominator:
            put("plan_error", plan * MM_PER_M / map_scale_denominator, "map_mm")
        put("height_error", self.height_error_m, "m")
        if permille:
            put("height_error", self.height_error_m * per_h, "permille")
        if self.height_error_after_plane_m is not None:
            put("height_error_after_plane", self.height_error_after_plane_m, "m")
            if permille:
                after = self.height_error_after_plane_m * per_h
                put("height_error_after_plane", after, "permille")
        return out

    def per_point(
        self, flying_height_m: float, map_scale_denominator: int | None
    ) -> dict[str, Any]:
        """Per-point values (arrays (n,) or (T, n)) with derived units, keyed like ``summary``."""
        per_h = MM_PER_M / float(flying_height_m)
        out: dict[str, Any] = {
            "ids": list(self.ids),
            "ground_m": self.ground_m,
            "model_mm": self.model_mm,
            "x_parallax_error_mm": self.x_parallax_error_mm,
            "y_parallax_mm": self.y_parallax_mm,
            "y_parallax_seen_mm": self.y_parallax_seen_mm,
            "x_error_m": self.x_error_m,
            "y_error_m": self.y_error_m,
            "plan_error_m": self.plan_error_m,
            "height_error_m": self.height_error_m,
            "height_error_permille": self.height_error_m * per_h,
        }
        if map_scale_denominator:
            scale = MM_PER_M / map_scale_denominator
            out["x_error_map_mm"] = self.x_error_m * scale
            out["y_error_map_mm"] = self.y_error_m * scale
            out["plan_error_map_mm"] = self.plan_error_m * scale
        if self.height_error_after_plane_m is not None:
            out["height_error_after_plane_m"] = self.height_error_after_plane_m
            out["height_error_after_plane_permille"] = self.height_error_after_plane_m * per_h
        if self.x_parallax_error_after_plane_mm is not None:
            out["x_parallax_error_after_plane_mm"] = self.x_parallax_error_after_plane_mm
        return out


@dataclass(frozen=True, slots=True)
class ModelEvaluation:
    r"""The evaluation of a built model against the ground truth (see the module docstring).

    Attributes
    ----------
    trials : int or None
        T for a vectorised evaluation, None for a single instrument.
    horizontal_scale_denominator, vertical_scale_denominator : int
        M_г, M_в of the sheet (the ideal model). [—]
    map_scale_denominator : int or None
        M_map (plan errors on the map). [—]
    flying_height_m : float
        H̄ = Z_Sл − mean Z over the working-area grid (the H of ‰ H). [m]
    height_zero_m : float or ndarray
        The height-scale reading at D = 0 used to read the built heights. [m]
    standard_points_c_mm : float
        c of the standard points 3–6. [mm]
    plane_point_ids : tuple of str
        Control points the plane is fitted at (empty: no plane removal).
    grid, standard_points, control, check : PointSetEvaluation
        The uniform working-area grid, the six standard points (ids "1"–"6"), the control and the
        independent check points imaged on both photos.
    not_imaged : tuple of str
        Control/check points outside the format of a photo (not evaluated).
    corner4_misclosure_mm : float, ndarray or None
        Passed through from the procedure (stage 5, Eq. (6.18) of [1]_). [mm on the sheet]
    """

    trials: int | None
    horizontal_scale_denominator: int
    vertical_scale_denominator: int
    map_scale_denominator: int | None
    flying_height_m: float
    height_zero_m: Any
    standard_points_c_mm: float
    plane_point_ids: tuple[str, ...]
    grid: PointSetEvaluation
    standard_points: PointSetEvaluation
    control: PointSetEvaluation
    check: PointSetEvaluation
    not_imaged: tuple[str, ...] = ()
    corner4_misclosure_mm: Any = None

    def sets(self) -> dict[str, PointSetEvaluation]:
        """The four point sets by name."""
        return {
            "grid": self.grid,
            "standard_points": self.standard_points,
            "control": self.control,
            "check": self.check,
        }

    def summary(self, permille: bool = True) -> dict[str, dict[str, Any]]:
        """Max |·| and RMS per point set (see :meth:`PointSetEvaluation.summary`)."""
        return {
            name: s.summary(self.flying_height_m, self.map_scale_denominator, self.trials, permille)
            for name, s in self.sets().items()
        }

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (lists and floats): settings, summaries and per-point values."""
        out: dict[str, Any] = {
            "trials": self.trials,
            "horizontal_scale_denominator": self.horizontal_scale_denominator,
            "vertical_scale_denominator": self.vertical_scale_denominator,
            "map_scale_denominator": self.map_scale_denominator,
            "flying_height_m": self.flying_height_m,
            "height_zero_m": self.height_zero_m,
            "standard_points_c_mm": self.standard_points_c_mm,
            "plane_point_ids": list(self.plane_point_ids),
            "not_imaged": list(self.not_imaged),
            "corner4_misclosure_mm": self.corner4_misclosure_mm,
            "summary": self.summary(),
            "points": {
                name: s.per_point(self.flying_height_m, self.map_scale_denominator)
                for name, s in self.sets().items()
            },
        }
        plain: dict[str, Any] = _plain(out)
        return plain
