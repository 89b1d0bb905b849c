"""The web layer's only door to the trainer core: exercises, sessions, grades, logs.

Every call the server makes into :mod:`stereoplotter.trainer`, :mod:`stereoplotter.io` and
:mod:`stereoplotter.report` goes through here, so a change of the core's contract
(``notes: trainer_contract``) is met in one module.
"""

from __future__ import annotations

import json
import re
from typing import Any

from stereoplotter.errors import StereoplotterError, TrainerError
from stereoplotter.imagery.cache import EAGER_PIXEL_MM, ViewCache
from stereoplotter.imagery.eyepiece import SCREEN_PIXEL_MM
from stereoplotter.instrument.virtual import CONTROL_INFO
from stereoplotter.io.exercise_file import (
    exercise_from_mapping,
    load_exercise,
    shipped_exercises,
)
from stereoplotter.io.images import png_bytes
from stereoplotter.io.paths import available_names
from stereoplotter.io.session_log import log_bytes
from stereoplotter.report.exercise_sheet import exercise_sheet
from stereoplotter.report.grade import grade_markdown
from stereoplotter.trainer.actions import ACTION_CATALOGUE
from stereoplotter.trainer.exercise import Exercise, resolve_exercise
from stereoplotter.trainer.grading import grade
from stereoplotter.trainer.panel import checklist, overview, show_me_actions
from stereoplotter.trainer.session import Session, json_finite

__all__ = [
    "COARSE_MAG",
    "SCREEN_PIXEL_MM",
    "Catalogue",
    "CoreError",
    "NameInUse",
    "TrainerError",
    "action_catalogue",
    "build_view_cache",
    "checklist_of",
    "format_mm",
    "grade_records",
    "grade_text",
    "log_bytes",
    "log_of",
    "operator_script",
    "overview_of",
    "photo_key",
    "photo_patch",
    "replay",
    "replay_frames",
    "replay_json",
    "sheet_of",
    "show_me",
    "start",
]

#: Any refusal the core raises (a trainee's action, a bad exercise name, a bad log).
CoreError = StereoplotterError

#: Grading population (Monte Carlo runs of the simulated operator) used by the server; the
#: core's default is 10 000; 256 gives the percentile to ±3 points at a fraction of a second.
GRADE_POPULATION = 256
#: Magnification of the page's coarse-first patch: its screen pixel is the pyramid's coarsest
#: level rendered whole when the photos are built (``imagery.cache.EAGER_PIXEL_MM``), so the
#: patch is answered without rendering a tile. [—]
COARSE_MAG = SCREEN_PIXEL_MM / EAGER_PIXEL_MM
#: An uploaded exercise's name.
UPLOAD_NAME = re.compile(r"[a-z0-9][a-z0-9_-]{0,63}")


class Catalogue:
    """The exercises the server knows: the shipped ones (by name, read once) and those the
    instructor uploaded (validated, kept in the store); a retired upload is offered no more
    but still known to its sessions. Nothing else is ever opened."""

    def __init__(
        self,
        uploaded: dict[str, dict[str, Any]] | None = None,
        retired: dict[str, dict[str, Any]] | None = None,
    ):
        self.by_name: dict[str, Exercise] = {}
        self.retired: dict[str, Exercise] = {}
        self.shipped: set[str] = set()
        for path in shipped_exercises():
            ex = load_exercise(path)
            self.by_name[ex.name] = ex
            self.shipped.add(ex.name)
        for target, found in ((self.by_name, uploaded), (self.retired, retired)):
            for name, source in (found or {}).items():
                if name not in self.shipped:
                    target[name] = exercise_from_mapping(source, f"uploaded exercise {name}")

    def get(self, name: Any) -> Exercise | None:
        """An exercise offered (a session may start on it)."""
        return self.by_name.get(name) if isinstance(name, str) else None

    def known(self, name: Any) -> Exercise | None:
        """An exercise offered or retired (its sessions resume)."""
        if not isinstance(name, str):
            return None
        return self.by_name.get(name) or self.retired.get(name)

    def listing(self) -> list[dict[str, Any]]:
        """The exercises, easiest first: name, title, level, mode, description."""
        out = [
            {
                "name": ex.name,
                "title": ex.title,
                "level": ex.level,
                "mode": ex.mode,
                "instrument": ex.spec.key,
                "description": ex.description,
                "assists": dict(ex.assists),
                "uploaded": ex.name not in self.shipped,
            }
            for ex in self.by_name.values()
        ]
        return sorted(out, key=lambda e: (e["level"], e["name"]))

    def check_upload(self, data: dict[str, Any]) -> Exercise:
        """Validate an uploaded exercise's content: its name new and plain, its instrument and
        scenario shipped names (never a path), the rest as an exercise file, an exam's seed the
        server's, and a session can start on it. Does not add it (:meth:`add`)."""
        name = data.get("name")
        if not isinstance(name, str) or not UPLOAD_NAME.fullmatch(name):
            raise CoreError(
                "uploaded exercise: name: expected 1 to 64 of a-z, 0-9, '-', '_', "
                f"found {_quote(name)}"
            )
        if name in self.shipped:
            raise NameInUse(f"uploaded exercise: name: {name} is a shipped exercise")
        if name in self.by_name or name in self.retired:
            raise NameInUse(
                f"uploaded exercise: name: {name} is in use (its sessions replay from it): "
                "upload under a new name"
            )
        for kind, field in (("instruments", "instrument"), ("scenarios", "scenario")):
            value = data.get(field)
            if value not in available_names(kind):
                raise CoreError(
                    f"uploaded exercise: {field}: expected one of "
                    f"{', '.join(available_names(kind))}, found {_quote(value)}"
                )
        ex = exercise_from_mapping(data, "uploaded exercise")
        if ex.mode == "exam" and ex.seed is not None:
            raise CoreError(
                "uploaded exercise: seed: an exam's seed is per-trainee (the server's own); "
                f"a fixed seed is known to anyone who sees the file, found {ex.seed}"
            )
        try:  # every session starts as this one would (the operator's run on a seed)
            Session.start(ex, trainee="upload check", seed=0 if ex.seed is None else None)
        except StereoplotterError as exc:
            raise CoreError(f"uploaded exercise: no session can start on it: {exc}") from None
        except (ArithmeticError, ValueError) as exc:  # numpy's LinAlgError is a ValueError
            raise CoreError(
                f"uploaded exercise: no session can start on it ({type(exc).__name__}: {exc})"
            ) from None
        return ex

    def add(self, ex: Exercise) -> None:
        self.by_name[ex.name] = ex

    def retire(self, name: str) -> Exercise | None:
        """Offer an uploaded exercise no more (its sessions still resume); the exercise, or
        None when no upload of that name is offered."""
        if name in self.shipped or name not in self.by_name:
            return None
        ex = self.by_name.pop(name)
        self.retired[name] = ex
        return ex


class NameInUse(CoreError):
    """An uploaded exercise's name is taken (answered 409)."""


def _quote(value: Any, limit: int = 42) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 1] + "…"


def start(exercise: Exercise, trainee: str, seed: int | None = None) -> Session:
    """A new session on a known exercise."""
    return Session.start(exercise, trainee=trainee, seed=seed)


def operator_script(session: Session) -> list[dict[str, Any]]:
    """The simulated operator's actions for the session's exercise (demonstration mode)."""
    return session.operator_script()


def log_of(session: Session) -> list[dict[str, Any]]:
    """The session log as records: the header, then one record per action."""
    return [session.header(), *session.log]


def replay(records: list[dict[str, Any]]) -> Session:
    """A session run again from its log."""
    return Session.replay(records, read_exercise=exercise_from_mapping)


def grade_text(grade_dict: dict[str, Any]) -> str:
    """The grade as Markdown."""
    return grade_markdown(grade_dict)


def replay_json(records: list[dict[str, Any]], trainee: str, exercise: str) -> bytes:
    """The instructor's replay as JSON bytes (run in a worker process: the frames of a long log
    are megabytes of JSON, encoded off the server's event loop)."""
    head = records[0]
    ex = resolve_exercise(head["exercise"], exercise_from_mapping)
    view = {"screen_pixel_mm": SCREEN_PIXEL_MM, "format_mm": format_mm(ex), "patch_px": 768}
    frames = replay_frames(records)
    body = {"trainee": trainee, "exercise": exercise, "view": view, "frames": frames}
    return json.dumps(body, allow_nan=False, separators=(",", ":")).encode()


def replay_frames(records: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The log stepped through: for each action, the action and the state after it (the
    instructor's replay). The session is started afresh from the header and fed each recorded
    action at its recorded time; refused actions stay refused."""
    head = records[0]
    exercise = resolve_exercise(head["exercise"], exercise_from_mapping)
    session = Session(exercise, str(head["trainee"]), int(head["seed"]), clock=False)
    frames = [{"action": None, "state": session.state(), "refused": None}]
    for rec in records[1:]:
        action = dict(rec["action"], t=rec["t"])
        refused = None
        try:
            session.act(action)
        except TrainerError as exc:
            refused = str(exc)
        frames.append({"action": rec["action"], "t": rec["t"], "state": session.state(),
                       "refused": refused})
    return frames


#: Both photos of an exercise's scenario as the imagery's tile pyramid, built once (in a worker,
#: about 4 s for pair60) and shared by every session of the exercise: the ground texture's seed
#: is the exercise's fixed seed, or the scenario's own for a per-trainee exercise (a trainee's
#: seed draws the instrument's errors, not the ground), so the photos are ready before the
#: first trainee starts.
def photo_key(exercise: Exercise) -> tuple[str, str, str, int | None]:
    """What a session's photos depend on: the scenario, terrain and tilt classes, the seed."""
    return (exercise.scenario_name, exercise.terrain, exercise.tilt, exercise.seed)


def build_view_cache(source: dict[str, Any]) -> ViewCache:
    """The view cache of an exercise's photos (run in a worker process: picklable in and out)."""
    ex = resolve_exercise(source, exercise_from_mapping)
    return ViewCache(ex.scenario, ex.seed)


def format_mm(exercise: Exercise) -> float:
    """The photos' format side (the mark is off the photo beyond ±format/2). [mm]"""
    return float(exercise.scenario.camera.format_mm)


def grade_records(records: list[dict[str, Any]]) -> dict[str, Any]:
    """The grade of a session log (run in a worker process)."""
    result = grade(records, population=GRADE_POPULATION, read_exercise=exercise_from_mapping)
    return json.loads(json.dumps(result, allow_nan=False))


def photo_patch(
    cache: ViewCache, side: str, x_mm: float, y_mm: float, magnification: float, size_px: int
) -> bytes:
    """PNG of the photo ``side`` around photo point x, y [mm], unrotated (κ = 0), one pixel
    = SCREEN_PIXEL_MM / magnification mm of photo, x to the right, y up: the page turns and
    places it under the mark itself, so a move needs no new image."""
    return png_bytes(cache.view(side, x_mm, y_mm, 0.0, magnification, size_px))


def sheet_of(exercise: Exercise) -> dict[str, Any]:
    """The exercise's own setup sheet as the page shows it (run in a worker thread): the data of
    :func:`stereoplotter.report.exercise_sheet.exercise_sheet`, as ``stereoplotter exercise
    sheet --json`` (the sheet depends on the exercise, not on a trainee's seed)."""
    return _jsonable(exercise_sheet(exercise))


#: Grid of the overview's point positions where the parallax read-out is hidden (an exam, or
#: practice with the read-out off): a glance finds a point to 0.5 mm, the eye sets the mark on
#: it, and the exact images (which with the marks would give the parallax to 0.1 µm) are not
#: sent. [mm]
HIDDEN_GRID_MM = 0.5


def overview_of(session: Session) -> dict[str, Any]:
    """Both photos at a glance (``trainer.panel.overview``; run on the actor thread). Where
    the parallax read-out is hidden, the points are given on a :data:`HIDDEN_GRID_MM` grid and
    the fiducials as the camera's certificate gives them (not where they lie on the photo)."""
    body = _jsonable(overview(session))
    if session.exercise.allows("parallax_readout"):
        return body
    certificate = session.prep.scene.camera.fiducial_array_mm()
    for photo in body["photos"].values():
        for k, fid in enumerate(photo["fiducials"]):
            fid["x_mm"], fid["y_mm"] = (float(v) for v in certificate[k])
        for key in ("standard_points", "control_points", "check_points"):
            for point in photo[key]:
                for axis in ("x_mm", "y_mm"):
                    point[axis] = _on_grid(point[axis])
    return body


def _on_grid(value: float | None) -> float | None:
    if value is None:
        return None
    return round(round(value / HIDDEN_GRID_MM) * HIDDEN_GRID_MM, 3)


#: What a step's words say that the operator found on this instrument or that names its
#: control, removed where the exercise gives no hints: a number with a decimal point (a common
#: tilt, a pass's RMS, an over-correction: the operator's answers), the control a step turns.
_FOUND_NUMBER = re.compile(r"[+\-−]?\d+\.\d+")
#: The controls a step's words name, by their identifiers: every one but the carriages' X, Y,
#: Z and the height scale H (single letters the words use for their coordinates too).
_CONTROL_ID = "(?:{})".format(
    "|".join(
        re.escape(name)
        for name, info in CONTROL_INFO.items()
        if info.part not in ("carriage", "height counter")
    )
)
_NAMED_CONTROL = (
    (re.compile(r"\s*\(by turning [^)]*\)"), ""),
    (re.compile(r" by turning \S+"), ""),
    (re.compile(r"(?<=y-parallax) with \S+( \([^)]*\))?"), ""),
    (re.compile(rf"[;:,] turn {_CONTROL_ID}$"), ""),
    (re.compile(rf"\bturn {_CONTROL_ID} by\b"), "turn an element by"),
    (re.compile(rf"\s*\({_CONTROL_ID}\)"), ""),
)


def bare_words(text: str | None) -> str | None:
    """A step's words without the controls they name or the operator's numbers (an exam's
    checklist: naming the controls is hint 2; the numbers are this instrument's answers)."""
    if text is None:
        return None
    for pattern, instead in _NAMED_CONTROL:
        text = pattern.sub(instead, text)
    return _FOUND_NUMBER.sub("…", text)


def checklist_of(session: Session) -> dict[str, Any] | None:
    """The stage in hand's steps with their done flags (``trainer.panel.checklist``; the state
    carries only the flags on every action; run on the actor thread). Where the read-out is
    hidden, no tick depends on a hidden quantity and no step carries its targets (blind);
    where the exercise gives no hints, the steps are those of the operator's run on the
    error-free instrument (the same for every trainee), name no controls (that is hint 2)
    and carry none of the operator's numbers (:func:`bare_words`)."""
    reference = session.shows_reference_steps()
    blind = session.hides_readout() or reference
    body = _jsonable(checklist(session, blind=blind, reference=reference))
    if body is not None and not session.exercise.allows("hints"):
        for step in body["steps"]:
            for key in ("controls", "control_names", "sheet_rows"):
                step.pop(key, None)
            step["text"] = bare_words(step["text"])
            step["note"] = bare_words(step.get("note"))
    return body


def show_me(session: Session, stage: str | None = None) -> list[dict[str, Any]]:
    """The simulated operator's actions of a stage (default: the stage in hand; what hint 3
    applies at once), for the page to play one by one at its chosen speed ("show me",
    animated)."""
    return show_me_actions(session, stage)


def action_catalogue() -> list[dict[str, Any]]:
    """Every action the core accepts with its fields (``trainer.actions.ACTION_CATALOGUE``),
    for the page to make one control per kind."""
    return ACTION_CATALOGUE


def _jsonable(value: Any) -> Any:
    """``value`` through JSON (numpy scalars and arrays as numbers, non-finite as null)."""
    return json_finite(json.loads(json.dumps(value, default=_plain)))


def _plain(value: Any) -> Any:
    if hasattr(value, "tolist"):
        return value.tolist()
    return str(value)
