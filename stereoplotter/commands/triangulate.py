"""``stereoplotter triangulate`` and ``stereoplotter block synth``: phototriangulation of a block.

``block synth -o DIR`` makes a synthetic block measurements file from an invented ground truth
(:mod:`stereoplotter.triangulation.synth`) and writes the truth beside it (``truth.csv`` and the
production job of the true orientations, ``truth/job.yaml``). ``triangulate BLOCK.yaml --method
bundle|strip|polygon -o DIR`` writes each photo's orientation with its σ (``orientations.csv``),
the residuals at control and check points (``residuals.csv``), a report (``report.md`` with
``residuals.png``) and, when the block has a ``production`` section, the production job
``job.yaml`` that ``stereoplotter setup`` turns into forms (``docs/triangulation.md``).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
from pathlib import Path
from typing import Any

from stereoplotter.commands.arguments import bounded_float, bounded_int, seed_int

__all__ = ["add_arguments", "run", "run_synth"]

METHODS = ("bundle", "strip", "polygon")


#: Largest plausible antenna offset from the camera in any axis [m] (assumed: an antenna on the
#: fuselage above the camera hatch of a survey aircraft sits a few metres from it at most).
MAX_LEVER_ARM_M = 5.0


def add_arguments(sub: Any) -> None:
    """Add ``triangulate`` and ``block`` (action ``synth``) to the CLI's subparsers."""
    _add_triangulate(sub)
    _add_block_synth(sub)


def _add_triangulate(sub: Any) -> None:
    """``triangulate BLOCK -o DIR`` with its method and the bundle's options."""
    p = sub.add_parser(
        "triangulate",
        help="analytic phototriangulation of a block: orientations, residuals, report, job file",
    )
    p.add_argument("block", help="block measurements file (stereoplotter-block-measurements/1)")
    p.add_argument(
        "--method",
        choices=METHODS,
        default="bundle",
        help="bundle block adjustment (default), strip triangulation by independent "
        "models with polynomials, or the polygon block adjustment",
    )
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="output folder")
    p.add_argument(
        "--models",
        choices=("independent", "dependent"),
        default="independent",
        help="strip method: how a strip is formed (default independent)",
    )
    p.add_argument(
        "--degree",
        type=int,
        choices=(1, 2, 3),
        default=3,
        help="strip method: degree of the strip polynomials (default 3)",
    )
    p.add_argument(
        "--reject",
        action="store_true",
        help="bundle: remove the observations data snooping flags and readjust (default: "
        "flag them in report.md and flagged.csv, keep them in the solution)",
    )
    p.add_argument(
        "--alpha0",
        type=bounded_float(1e-12, 0.5),
        default=None,
        metavar="A",
        help="bundle: level of one w-test (default: family-wise 5 %% over all observations "
        "by Šidák; Baarda's classical value is 0.001)",
    )
    p.add_argument(
        "--robust",
        choices=("huber", "danish"),
        default=None,
        help="bundle: robust re-weighting instead of data snooping (Danish: weight × "
        "exp(1 − |t|/k) beyond the critical value k; Huber: × k/|t|); the solution is the "
        "re-weighted one, flagged.csv the observations it down-weighted",
    )
    p.add_argument(
        "--self-calibrate",
        default="",
        metavar="PARAMS",
        help="bundle: adjust camera parameters with the block, comma-separated among "
        "f,x0,y0,k1,k2,p1,p2 or 'all' (default none: the certificate holds)",
    )
    p.set_defaults(func=run)


def _add_block_synth(sub: Any) -> None:
    """``block synth -o DIR``: the synthetic block's size, control, errors and production."""
    b = sub.add_parser("block", help="blocks of comparator measurements (docs/triangulation.md)")
    acts = b.add_subparsers(dest="block_command", required=True, metavar="ACTION")
    s = acts.add_parser("synth", help="a synthetic block from an invented ground truth")
    s.add_argument("-o", "--output", required=True, metavar="DIR", help="output folder")
    s.add_argument(
        "--strips", type=bounded_int(1, 200), default=4, help="number of strips (default 4)"
    )
    s.add_argument(
        "--photos", type=bounded_int(2, 500), default=10, help="photos per strip (default 10)"
    )
    s.add_argument("--seed", type=seed_int, default=1, help="seed of the truth and the errors")
    s.add_argument(
        "--control-every",
        type=bounded_int(1, 100),
        default=4,
        metavar="BASES",
        help="control spacing along the block edges in bases (default 4)",
    )
    s.add_argument(
        "--control-degree",
        type=int,
        choices=(2, 3),
        metavar="N",
        help="instead: N + 1 control stations along the strips, spaced for polynomials of "
        "degree N (the control spacing chosen from the residual variances)",
    )
    s.add_argument(
        "--sigma-photo",
        type=bounded_float(1e-9, 0.1),
        default=0.005,
        metavar="MM",
        help="σ of a comparator coordinate [mm] (default 0.005: a stereocomparator)",
    )
    s.add_argument(
        "--centres",
        type=bounded_float(1e-6, 100.0),
        default=None,
        metavar="SIGMA_M",
        help="also measure every photo's projection centre (GNSS antenna) with this σ [m]",
    )
    s.add_argument(
        "--lever-arm",
        type=bounded_float(-MAX_LEVER_ARM_M, MAX_LEVER_ARM_M),
        nargs=3,
        default=(0.0, 0.0, 0.0),
        metavar=("X", "Y", "Z"),
        help="the antenna in the camera system [m] (with --centres; default 0 0 0; each within "
        f"±{MAX_LEVER_ARM_M:g} m, assumed: an antenna a few metres from the camera at most)",
    )
    s.add_argument("--name", default="synthetic", help="name of the block")
    s.add_argument("--instrument", default="sc1", help="instrument of the production job")
    s.add_argument(
        "--date",
        default="2026-11-26",
        help="date printed on the forms, YYYY-MM-DD (the clock is never read)",
    )
    s.set_defaults(func=run_synth)


def _calibrated(block: Any, snooping: Any, args: argparse.Namespace) -> Any:
    """The block whose camera the job carries: with self-calibration the adjusted f and
    principal point (x₀, y₀ added to the certificate's); the distortion has no place in a job
    and is reported only."""
    if snooping is None:
        return block
    last = args.reject or args.robust is not None
    prob = snooping.problem_last if last else snooping.problem_first
    if not prob.camera_free:
        return block
    cam = (snooping.last if last else snooping.first).camera
    x0, y0 = block.camera.principal_point_mm
    camera = dataclasses.replace(
        block.camera,
        focal_length_mm=float(cam[0]),
        principal_point_mm=(float(x0 + cam[1]), float(y0 + cam[2])),
    )
    return dataclasses.replace(block, camera=camera)


def _camera_parameters(text: str) -> tuple[str, ...]:
    """``--self-calibrate``'s list: names of the camera model, or ``all``."""
    # imported here: the CLI loads no library module until a command runs (it starts fast)
    from stereoplotter.triangulation.camera_model import CAMERA_PARAMETERS

    names = tuple(n.strip() for n in text.split(",") if n.strip())
    if names == ("all",):
        return CAMERA_PARAMETERS
    bad = [n for n in names if n not in CAMERA_PARAMETERS]
    if bad:
        from stereoplotter.errors import ConfigError  # a command's top imports argparse only

        raise ConfigError(
            "--self-calibrate", "(option)", "names among " + ",".join(CAMERA_PARAMETERS), bad[0]
        )
    return names


def _solve(block: Any, args: argparse.Namespace) -> tuple[Any, Any]:
    """The solution and, for the bundle, its data snooping (else None)."""
    if args.method == "bundle":
        # imported here: the CLI starts without loading scipy's sparse solvers
        from stereoplotter.triangulation.reliability import snooped_block

        return snooped_block(
            block,
            reject=args.reject,
            alpha0=args.alpha0,
            self_calibration=_camera_parameters(args.self_calibrate),
            robust_method=args.robust,
        )
    from stereoplotter.triangulation import strip  # only the method asked for is loaded

    if args.method == "strip":
        return strip.strip_block(block, args.models, args.degree), None
    from stereoplotter.triangulation.polygon_block import polygon_block  # as above

    return polygon_block(block), None


def run(args: argparse.Namespace) -> int:
    # imported here: the CLI starts fast (no pyproj, matplotlib or pydantic until a command runs)
    from stereoplotter.io.atomic_write import write_files
    from stereoplotter.io.block_measurements_file import load_block_measurements
    from stereoplotter.triangulation.solution import catalogue_residuals

    block, production = load_block_measurements(args.block)
    solution, snooping = _solve(block, args)
    residuals = catalogue_residuals(block, solution)
    files = _job_files(block, production, solution, snooping, args)
    files.update(_result_files(block, solution, residuals, snooping, args))
    out = Path(args.output)
    encoded = {n: c if isinstance(c, bytes) else c.encode("utf-8") for n, c in files.items()}
    write_files(out, encoded)  # every file whole or not at all
    print(_summary_line(block, solution, residuals, snooping, args, production is not None))
    if production is None:
        print("no production section in the block file: no job file written", file=sys.stderr)
    return 0


def _job_files(
    block: Any, production: Any, solution: Any, snooping: Any, args: argparse.Namespace
) -> dict[str, str | bytes]:
    """The production job's files (none without a ``production`` section); made first, so a
    photo number the job cannot take stops everything."""
    if production is None:
        return {}
    # imported here: the CLI starts fast (pyproj and pydantic load only when a command runs)
    from stereoplotter.io.triangulated_job import job_files

    description = (
        f"Exterior orientation of block {block.name} by stereoplotter triangulate "
        f"--method {args.method} from {Path(args.block).name}."
    )
    return dict(
        job_files(
            _calibrated(block, snooping, args),
            production,
            solution.orientations,
            source=args.block,
            description=description,
        )
    )


def _result_files(
    block: Any, solution: Any, residuals: Any, snooping: Any, args: argparse.Namespace
) -> dict[str, str | bytes]:
    """Orientations, residuals, points, figures, the snooping tables and the report."""
    # imported here: the CLI starts fast (matplotlib loads only when a command runs)
    from stereoplotter.plotting.triangulation import (
        photo_residual_figure_png,
        precision_figure_png,
        residual_figure_png,
    )
    from stereoplotter.report.triangulation import (
        catalogue_observations_csv,
        flagged_csv,
        observations_csv,
        orientation_csv,
        points_csv,
        report_markdown,
        residual_csv,
    )

    files: dict[str, str | bytes] = {}
    files["orientations.csv"] = orientation_csv(block, solution)
    files["residuals.csv"] = residual_csv(block, residuals)
    files["points.csv"] = points_csv(block, solution)
    files["residuals.png"] = residual_figure_png(block, solution, residuals)
    files["photo_residuals.png"] = photo_residual_figure_png(block, solution)
    if solution.point_covariances is not None:
        files["precision.png"] = precision_figure_png(block, solution)
    if snooping is not None:
        files["flagged.csv"] = flagged_csv(snooping.flags)
        last = args.reject or args.robust is not None
        prob = snooping.problem_last if last else snooping.problem_first
        rel = snooping.reliability if last else snooping.reliability_first
        files["observations.csv"] = observations_csv(block, prob, rel)
        files["catalogue_observations.csv"] = catalogue_observations_csv(prob, rel)
    files["report.md"] = report_markdown(
        block, solution, residuals, args.block, snooping, args.reject or args.robust is not None
    )
    return files


def _summary_line(
    block: Any,
    solution: Any,
    residuals: Any,
    snooping: Any,
    args: argparse.Namespace,
    has_job: bool,
) -> str:
    """The one line printed on success: method, iterations, σ₀, RMS at check points, flags."""
    out = Path(args.output)
    rms = residuals.rms(block, "check")
    job = f"; job file {out / 'job.yaml'}" if has_job else ""
    flagged = ""
    if snooping is not None:
        what = (
            "down-weighted"
            if args.robust
            else "removed"
            if args.reject
            else "kept; --reject removes them"
        )
        flagged = f"; {len(snooping.flags)} observations flagged ({what})"
    return (
        f"block {block.name}: {len(block.photos)} photos by {args.method} in "
        f"{solution.iterations} iterations, σ₀ = {solution.sigma0:.3f}; RMS at check points "
        f"X {rms[0]:.3f}, Y {rms[1]:.3f}, Z {rms[2]:.3f} m{flagged}; report "
        f"{out / 'report.md'}{job}"
    )


def _production(block: Any, orientations: Any, instrument: str, date: str) -> dict[str, Any]:
    """The ``production:`` section: instrument, date and the 1:10 000 sheets of the pairs."""
    # imported here: the CLI starts fast (pyproj and pydantic load only when a command runs)
    from stereoplotter.io.block_measurements_file import production_data
    from stereoplotter.io.triangulated_job import sheets_of_pairs

    return production_data(instrument, date, sheets_of_pairs(block, orientations))


def run_synth(args: argparse.Namespace) -> int:
    # imported here: the CLI starts fast (numpy, pyproj, pydantic load only when a command runs)
    import numpy as np

    from stereoplotter.io.atomic_write import atomic_write_text
    from stereoplotter.io.block_measurements_file import (
        load_block_measurements,
        write_block_measurements,
    )
    from stereoplotter.io.triangulated_job import write_triangulated_job
    from stereoplotter.random_streams import key_code
    from stereoplotter.triangulation.synth import (
        SynthSpec,
        control_stations_for_degree,
        synthesize_block,
    )

    stations = None
    if args.control_degree is not None:
        stations = control_stations_for_degree(args.photos - 1, args.control_degree)
    spec = SynthSpec(
        control_stations=stations,
        strips=args.strips,
        photos_per_strip=args.photos,
        name=args.name,
        control_every_bases=args.control_every,
        sigma_photo_mm=args.sigma_photo,
        centre_sigma_m=args.centres,
        lever_arm_m=tuple(args.lever_arm),
    )
    rng = np.random.default_rng([args.seed, key_code("block synth")])
    block, truth = synthesize_block(spec, rng)
    out = Path(args.output)
    production = _production(block, truth.orientations, args.instrument, args.date)
    description = (
        f"Synthetic block of {spec.strips} × {spec.photos_per_strip} photos made by stereoplotter "
        f"block synth --seed {args.seed} (the truth in truth.csv)."
    )
    write_block_measurements(out, block, description=description, production=production)
    rows = ["photo,alpha_deg,omega_deg,kappa_deg,X_m,Y_m,Z_m"]
    for p, o in zip(block.photos, truth.orientations, strict=True):
        a, w, k = (math.degrees(float(v)) for v in o[:3])
        rows.append(f"{p},{a:.8f},{w:.8f},{k:.8f},{o[3]:.4f},{o[4]:.4f},{o[5]:.4f}")
    atomic_write_text(out / "truth.csv", "\n".join(rows) + "\n")
    pts = ["point,X_m,Y_m,Z_m"] + [
        f"{pid},{x:.4f},{y:.4f},{z:.4f}"
        for pid, (x, y, z) in zip(block.point_ids, truth.points_m, strict=True)
    ]
    atomic_write_text(out / "truth_points.csv", "\n".join(pts) + "\n")
    _, prod = load_block_measurements(out / "block.yaml")  # the file as triangulate reads it
    assert prod is not None
    write_triangulated_job(
        out / "truth",
        block,
        prod,
        truth.orientations,
        source=str(out / "block.yaml"),
        description="The TRUE exterior orientation of the synthetic block "
        "(for comparison with the triangulated one).",
    )
    print(
        f"block {block.name}: {len(block.photos)} photos, {block.obs_photo.size} point "
        f"measurements, {len(block.catalogue)} catalogue points written to {out / 'block.yaml'}"
        f"; truth in {out / 'truth.csv'} and {out / 'truth' / 'job.yaml'}"
    )
    return 0
