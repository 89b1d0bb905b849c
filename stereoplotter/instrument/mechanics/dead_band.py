"""The dead band of a lead-screw axis: its half-width and centre offset (``mechanics.md`` §2, §7).

Pure formulas shared by the axis parameters (:mod:`.base`) and the play operator (:mod:`.play`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["G_MM_S2", "half_play_mm", "play_offset_mm"]

#: Standard gravity. [mm/s²]
G_MM_S2: float = 9810.0


def half_play_mm(
    backlash_mm: ArrayLike,
    friction: ArrayLike,
    mass_kg: ArrayLike,
    stiffness_kg_s2: ArrayLike,
    *,
    vertical: bool = False,
    g_mm_s2: float = G_MM_S2,
) -> np.ndarray:
    """Half-width h of the dead band of a lead-screw axis.

    Parameters
    ----------
    backlash_mm : array_like
        Axial play b. [mm]
    friction : array_like
        Coulomb coefficient μ. [—]
    mass_kg : array_like
        Carriage mass m. [kg]
    stiffness_kg_s2 : array_like
        Axial stiffness k, ``inf`` for a rigid screw (1 N/µm = 10⁶). [kg/s²]
    vertical : bool
        A column under gravity: the play is taken up by the load (see :func:`play_offset_mm`).
    g_mm_s2 : float
        Gravity. [mm/s²]

    Returns
    -------
    numpy.ndarray
        h = b/2 + μ·m·g/k, or μ·m·g/k for a vertical column. [mm]

    Examples
    --------
    >>> round(float(half_play_mm(0.020, 0.1, 2.0, 1e6)) * 1e3, 4)  # µm, mechanics.md §8
    11.962
    >>> half_play_mm([0.02, 0.03], 0.1, 2.0, np.inf)
    array([0.01 , 0.015])
    """
    f_over_k = np.asarray(friction, float) * np.asarray(mass_kg, float) * g_mm_s2
    f_over_k = f_over_k / np.asarray(stiffness_kg_s2, float)
    if vertical:
        return f_over_k + 0.0 * np.asarray(backlash_mm, float)
    return 0.5 * np.asarray(backlash_mm, float) + f_over_k


def play_offset_mm(
    backlash_mm: ArrayLike,
    mass_kg: ArrayLike,
    stiffness_kg_s2: ArrayLike,
    follower_mass_kg: ArrayLike = 0.5,
    *,
    vertical: bool = False,
    g_mm_s2: float = G_MM_S2,
) -> np.ndarray:
    """Centre c of the dead band relative to the nut: 0, or the sag of a vertical column.

    Parameters
    ----------
    backlash_mm, mass_kg, stiffness_kg_s2 : array_like
        b [mm], m [kg], k [kg/s²] as in :func:`half_play_mm`.
    follower_mass_kg : array_like
        Mass m_f hanging on the spring with the carriage (none for a rigid screw). [kg]
    vertical : bool
        A column with gravity along −axis.
    g_mm_s2 : float
        Gravity. [mm/s²]

    Returns
    -------
    numpy.ndarray
        0 for a horizontal axis; −(b/2 + (m + m_f)·g/k) for a vertical one. [mm]

    Examples
    --------
    >>> round(float(play_offset_mm(0.020, 3.0, 1e6, 0.5, vertical=True)) * 1e3, 2)  # §7, µm
    -44.34
    """
    b = np.asarray(backlash_mm, float)
    if not vertical:
        return 0.0 * b
    k = np.asarray(stiffness_kg_s2, float)
    load = (np.asarray(mass_kg, float) + np.where(np.isinf(k), 0.0, follower_mass_kg)) * g_mm_s2
    return -(0.5 * b + load / k)
