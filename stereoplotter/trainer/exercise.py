"""An exercise: what a trainee does on which instrument, with which help.

:class:`Exercise` is the validated content of an exercise file
(:func:`stereoplotter.io.exercise_file.load_exercise` reads and checks the file and resolves the
scenario and the instrument into objects); the trainer never reads files. The per-trainee seed is
derived from the trainee's name (:func:`trainee_seed`), so two trainees get different instruments
and the same trainee always the same one.
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from stereoplotter.errors import TrainerError
from stereoplotter.scenario.model import Scenario
from stereoplotter.spec.instrument_spec import InstrumentSpec

__all__ = [
    "ASSISTS",
    "ERROR_MODES",
    "EXERCISE_FORMAT",
    "MODES",
    "STAGES",
    "TERRAINS",
    "TILTS",
    "Exercise",
    "resolve_exercise",
    "trainee_seed",
]

EXERCISE_FORMAT = "stereoplotter-exercise/1"
#: Stages of each method: the setup-data method's five (§27) and the conventional C1–C4.
STAGES = {"setup": ("1", "2", "3", "4", "5"), "conventional": ("C1", "C2", "C3", "C4")}
TERRAINS = ("flat", "hilly", "mountainous")
#: Injected instrument errors: none, drawn and shown to the trainee, drawn and not shown.
ERROR_MODES = ("off", "announced", "hidden")
#: Tilt size classes of the photos (the io loader scales the scenario's α, ω to the class:
#: ``stereoplotter.io.exercise_file.TILT_TARGET_DEG``).
TILTS = ("small", "medium", "large")
MODES = ("practice", "exam")
#: What the trainee may use: the numeric y/x-parallax read-out, undo/redo, hints.
ASSISTS = ("parallax_readout", "undo", "hints")


@dataclass(frozen=True)
class Exercise:
    """One exercise (all fields as in the file; ``scenario`` and ``spec`` resolved).

    Attributes
    ----------
    name, title : str
    level : int
        Difficulty, 1 (easiest) upwards; the shipped set is graded by it.
    instrument, scenario_name : str
        Names of the instrument and scenario files.
    method : {"setup", "conventional"}
    stages : tuple of str
        The stages the trainee does, in order; earlier stages of the method are preset by the
        simulated operator (same instrument, errors and seed).
    terrain : {"flat", "hilly", "mountainous"}
    model : {"complete", "incomplete"}
    unusable_points : tuple of int
        Incomplete model: the standard points (1–6, Fig. 39) on water or outside the overlap;
        the trainee records a substitute for each (``record`` "substitute N").
    errors : {"off", "announced", "hidden"}
    tilt : {"small", "medium", "large"}
    assists : dict
        ``parallax_readout``, ``undo``, ``hints`` → bool.
    mode : {"practice", "exam"}
        Exam: no undo, no hints and no parallax read-out whatever ``assists`` says.
    seed : int or None
        Fixed seed, or None: per trainee (:func:`trainee_seed`).
    description : str
    spec : InstrumentSpec
    scenario : Scenario
    source : dict
        The file's content as read (written into the session log's header).
    """

    name: str
    title: str
    level: int
    instrument: str
    scenario_name: str
    method: str
    stages: tuple[str, ...]
    terrain: str
    model: str
    unusable_points: tuple[int, ...]
    errors: str
    tilt: str
    assists: dict[str, bool]
    mode: str
    seed: int | None
    description: str
    spec: InstrumentSpec = field(repr=False, compare=False)
    scenario: Scenario = field(repr=False, compare=False)
    source: dict[str, Any] = field(default_factory=dict, repr=False, compare=False)

    def allows(self, assist: str) -> bool:
        """Whether the trainee may use an assist (exam mode: no undo, no hints and no numeric
        parallax read-out: the eyepieces are the read-out)."""
        if self.mode == "exam" and assist in ASSISTS:
            return False
        return bool(self.assists.get(assist, False))

    @property
    def preset_stages(self) -> tuple[str, ...]:
        """The method's stages before the first one the trainee does."""
        all_stages = STAGES[self.method]
        return all_stages[: all_stages.index(self.stages[0])]

    def seed_for(self, trainee: str) -> int:
        """The seed of a trainee's instrument: fixed, or derived from the name."""
        return self.seed if self.seed is not None else trainee_seed(self.name, trainee)


def trainee_seed(exercise: str, trainee: str) -> int:
    """A per-trainee seed: the first 8 bytes of SHA-256 of ``exercise/trainee`` (deterministic,
    differs between trainees and exercises), as a non-negative int below 2**63."""
    digest = hashlib.sha256(f"{exercise}/{trainee}".encode()).digest()
    return int.from_bytes(digest[:8], "big") >> 1


def resolve_exercise(
    source: dict[str, Any],
    read_exercise: Callable[[dict[str, Any]], Exercise] | None = None,
) -> Exercise:
    """The :class:`Exercise` of a file content (a session log's header), read by
    ``read_exercise`` (the io layer's ``exercise_from_mapping``, passed by the caller: the
    trainer cannot import io, and nothing registers itself on import)."""
    if read_exercise is None:
        raise TrainerError(
            "no exercise reader given: pass read_exercise "
            "(stereoplotter.io.exercise_file.exercise_from_mapping) or the exercise itself"
        )
    return read_exercise(source)
