"""Command-line interface: ``stereoplotter`` and ``python -m stereoplotter``.

Thin: each subcommand parses, calls one library function and formats the result. Every expected
failure (bad input file, degenerate geometry) is printed as one ``error:`` line and exit code 1;
a usage error exits with 2. No traceback reaches the user.

Each subcommand's handler imports the layers it needs inside the handler: `stereoplotter --help`
and a bad argument answer without loading matplotlib or fpdf2.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import math
import os
import platform
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, NoReturn

import numpy as np

from stereoplotter import __version__
from stereoplotter.errors import StereoplotterError
from stereoplotter.io.job_file import is_job_file
from stereoplotter.io.paths import (
    DEFAULT_SCENARIO,
    DataFile,
    data_files,
    resolve_data_file,
    set_user_folders,
    shipped_root,
    user_folders,
)
from stereoplotter.io.yaml_files import atomic_write_bytes, load_yaml_mapping
from stereoplotter.procedure.trials import DEFAULT_MEMORY_BUDGET_MB
from stereoplotter.progress import configure_logging
from stereoplotter.verification.budget import DEFAULT_BUDGET_TRIALS

__all__ = ["main"]


def _json(data: Any) -> str:
    return json.dumps(data, indent=2, ensure_ascii=False, default=_json_default) + "\n"


def _json_default(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


# --- info -------------------------------------------------------------------------------------


def _versions() -> dict[str, str]:
    import matplotlib
    import pymunk
    import pyproj
    import scipy
    import yaml

    return {
        "stereoplotter": __version__,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "pymunk": pymunk.version,
        "matplotlib": matplotlib.__version__,
        "pyyaml": yaml.__version__,
        "pyproj": pyproj.__version__,
        "proj": pyproj.proj_version_str,
    }


def _count_status(node: Any, counts: dict[str, int]) -> None:
    if isinstance(node, dict):
        status = node.get("status")
        if status in ("documented", "assumed"):
            counts[status] += 1
        for value in node.values():
            _count_status(value, counts)
    elif isinstance(node, list):
        for value in node:
            _count_status(value, counts)


def _data_entry(found: DataFile) -> dict[str, Any]:
    """The name, file and origin of a data file for ``info``."""
    entry: dict[str, Any] = {"key": found.name, "file": str(found.path), "from": found.origin}
    if found.hides:
        entry["hides"] = [str(p) for p in found.hides]
    return entry


def _info() -> dict[str, Any]:
    from stereoplotter.io.scenario_file import load_scenario

    instruments = []
    for found in data_files("instruments"):
        counts = {"documented": 0, "assumed": 0}
        entry = _data_entry(found)
        try:
            data, _ = load_yaml_mapping(found.path)
            _count_status(data, counts)
            entry.update(values_documented=counts["documented"], values_assumed=counts["assumed"])
        except StereoplotterError as exc:
            entry["error"] = str(exc)
        instruments.append(entry)
    scenarios = []
    for found in data_files("scenarios"):
        entry = _data_entry(found)
        try:
            s = load_scenario(found.path)
            entry.update(name=s.name, photos=len(s.photos), points=len(s.points))
        except StereoplotterError as exc:
            entry["error"] = str(exc)
        scenarios.append(entry)
    # in the order names are looked up: user folders first, the shipped data last
    folders = [{"folder": str(f.path), "from": f.origin} for f in user_folders()]
    folders.append({"folder": str(shipped_root()), "from": "shipped"})
    return {
        "versions": _versions(),
        "data_folders": folders,
        "instruments": instruments,
        "scenarios": scenarios,
    }


def _format_info(info: dict[str, Any]) -> str:
    lines = ["stereoplotter " + info["versions"]["stereoplotter"], "", "versions:"]
    lines += [f"  {k:<14}{v}" for k, v in info["versions"].items()]
    lines += ["", "data folders (a name is looked up in this order):"]
    lines += [f"  {f['from']:<20}{f['folder']}" for f in info["data_folders"]]
    for kind in ("instruments", "scenarios"):
        lines += ["", f"{kind} ({len(info[kind])} found):"]
        if not info[kind]:
            lines.append("  none")
        width = max((len(e["key"]) for e in info[kind]), default=0) + 2
        for entry in info[kind]:
            head = f"  {entry['key']:<{width}}[{entry['from']}] {entry['file']}"
            if "error" in entry:
                lines.append(f"{head}: INVALID: {entry['error']}")
            elif kind == "instruments":
                lines.append(
                    f"{head}: {entry['values_documented']} documented, "
                    f"{entry['values_assumed']} assumed values"
                )
            else:
                lines.append(
                    f"{head}: {entry['name']} ({entry['photos']} photo(s), "
                    f"{entry['points']} points)"
                )
            if "hides" in entry:
                lines.append(f"  {'':<{width}}hides {', '.join(entry['hides'])}")
    return "\n".join(lines) + "\n"


# --- scenario check --------------------------------------------------------------------------


def _format_summary(s: dict[str, Any]) -> str:
    lines = [f"scenario {s['name']} ({s['file']}): valid", f"  {s['description']}".rstrip(), ""]
    cam = s["camera"]
    lines.append(
        f"camera: f = {cam['focal_length_mm']} mm, format {cam['format_mm']} mm, "
        f"principal point {cam['principal_point_mm']} mm, fiducials given as "
        f"{cam['fiducials_given_as']}"
    )
    lines.append(f"frame: {s['frame']}")
    for p in s["photos"]:
        lines.append(
            f"photo {p['name']}: S = {p['projection_centre_m']} m, α = {p['alpha_deg']}°, "
            f"ω = {p['omega_deg']}°, κ = {p['kappa_deg']}° ({p['exterior_source']}); "
            f"H = {p['flying_height_m']} m, photo scale 1:{p['photo_scale_denominator']:.0f}; "
            f"{p['points_imaged']} points imaged"
        )
    if "base" in s:
        b = s["base"]
        lines.append(
            f"base: B = {b['horizontal_m']} m (components {b['components_m']} m), "
            f"B/H = {b['base_to_height']}, overlap {b['overlap_percent']} %"
        )
    r = s["relief"]
    lines.append(
        f"relief: {r['working_area_min_m']} … {r['working_area_max_m']} m over the "
        f"working area ({r['working_area_range_m']} m = "
        f"{r['range_over_flying_height'] * 100:.1f} % of H); points "
        f"{r['points_min_m']} … {r['points_max_m']} m"
    )
    pts = s["points"]
    lines.append(
        "points: control "
        + ", ".join(f"{v} {k}" for k, v in pts["control"].items())
        + "; check "
        + str(sum(pts["check"].values()))
    )
    if "map_sheet" in s:
        m = s["map_sheet"]
        lines.append(
            f"map sheet: 1:{m['scale_denominator']}"
            + (f" {m['nomenclature']}" if m["nomenclature"] else " (corners given)")
        )
    return "\n".join(lines) + "\n"


# --- demo ------------------------------------------------------------------------------------


def _measurements_csv(scenario, measurements) -> str:
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["photo", "kind", "id", "x_true_mm", "y_true_mm", "x_mm", "y_mm"])
    for pm in measurements.photos:
        for name, t, m in zip(
            ("1", "2", "3", "4"), pm.fiducials_true_mm, pm.fiducials_mm, strict=True
        ):
            writer.writerow([pm.photo, "fiducial", name, *(f"{v:.6f}" for v in (*t, *m))])
        for pid, t, m, ok in zip(
            measurements.point_ids, pm.points_true_mm, pm.points_mm, pm.points_imaged, strict=True
        ):
            if ok:
                role = scenario.points[measurements.point_ids.index(pid)].role
                writer.writerow([pm.photo, role, pid, *(f"{v:.6f}" for v in (*t, *m))])
        for i, (t, m) in enumerate(zip(pm.grid_true_mm, pm.grid_mm, strict=True)):
            writer.writerow([pm.photo, "grid", f"G{i + 1}", *(f"{v:.6f}" for v in (*t, *m))])
    return out.getvalue()


def _format_demo(result: dict[str, Any]) -> str:
    s = result["summary"]
    lines = [
        f"# stereoplotter demo: {s['name']}",
        "",
        _format_summary(s).rstrip(),
        "",
        f"f′ of the pair from the measured fiducials: "
        f"{result['focal_length_corrected_mm']} mm "
        f"(per photo {result['focal_length_corrected_per_photo_mm']} mm)",
        "",
    ]
    for e in result["exterior"]:
        lines.append(
            f"photo {e['photo']}: exterior orientation {e['source']}; error against "
            f"the truth: angles {e['error_angles_arcsec']}″, centre "
            f"{e['error_centre_m']} m"
        )
    inter = result.get("intersection")
    if inter:
        lines += [
            "",
            "space intersection of the measured points (error = intersected − true):",
            "",
            "| point | role | dX m | dY m | dZ m | dZ ‰H | ray miss m |",
            "|---|---|---|---|---|---|---|",
        ]
        for row in inter["points"]:
            dx, dy, dz = row["error_m"]
            lines.append(
                f"| {row['id']} | {row['role']} | {dx:+.3f} | {dy:+.3f} | {dz:+.3f} | "
                f"{row['error_height_permille_H']:+.3f} | {row['ray_miss_m']:.3f} |"
            )
        lines.append("")
        for role, st in inter["statistics"].items():
            lines.append(
                f"{role} points ({st['count']}): RMS plan {st['rms_plan_m']} m, "
                f"RMS height {st['rms_height_m']} m, max |dZ| {st['max_abs_height_m']} m"
            )
    sim = result.get("similarity")
    if sim:
        lines += [
            "",
            f"similarity (6.8) Gauss–Krüger → photogrammetric: a = {sim['a']:.4e}, "
            f"b = {sim['b']:.9f}, c_X = {sim['cx_m']:.3f} m, c_Y = {sim['cy_m']:.3f} m, "
            f"det = {sim['determinant']:.9f}; RMS residual {sim['rms_m']} m",
        ]
    return "\n".join(lines) + "\n"


def _render(args: argparse.Namespace) -> int:
    from stereoplotter.io.images import write_render
    from stereoplotter.io.scenario_file import load_scenario

    scenario = load_scenario(args.scenario)
    sides = (args.side,) if args.side else tuple(p.name for p in scenario.photos)
    written = write_render(
        scenario,
        args.output,
        sides=sides,
        at_m=tuple(args.at) if args.at else None,
        magnification=args.magnification,
        pixel_mm=args.pixel,
        seed=args.seed,
    )
    for path in written:
        print(path)
    return 0


def _demo(args: argparse.Namespace) -> int:
    from stereoplotter.progress import step_progress

    with step_progress("demo") as step:
        return _demo_steps(args, step)


def _demo_steps(args: argparse.Namespace, step) -> int:
    """The demo's work, reporting ``step(done, 4, what)`` as it goes."""
    from stereoplotter.io.instrument_file import load_instrument
    from stereoplotter.io.scenario_file import load_scenario
    from stereoplotter.plotting.figures import plot_scenario_layout
    from stereoplotter.report.sheet import sheet_to_dict
    from stereoplotter.scenario.foundation import run_foundation
    from stereoplotter.setup.sheet import SetupRefusal, compute_setup_sheet

    path = Path(args.scenario)  # main() has resolved a name (default: the shipped pair60)
    scenario = load_scenario(path)
    spec = load_instrument(args.instrument)
    seed = scenario.seed if args.seed is None else args.seed
    result = run_foundation(scenario, np.random.default_rng(seed))
    measurements = result.pop("measurements")
    result["seed"] = seed
    text = _format_demo(result)
    step(1, 4, "setup sheet")
    files: dict[str, bytes] = {}
    try:
        sheet = compute_setup_sheet(scenario, spec, rng=np.random.default_rng(seed))
    except SetupRefusal as exc:
        result["setup_sheet"] = {"refused": str(exc)}
        text += f"\nsetup sheet on {spec.title}: refused: {exc}\n"
    else:
        data = sheet_to_dict(sheet)
        data["seed"] = seed
        result["setup_sheet"] = data
        files.update(_sheet_files(sheet, data))
        text += f"\n{_sheet_summary(sheet)} (sheet.md, sheet.pdf)\n"
    step(2, 4, "simulated operator")
    if scenario.is_stereopair and "refused" not in result["setup_sheet"]:
        from stereoplotter.report.simulation import run_simulation_command, tolerance_note

        sim = run_simulation_command(
            path, instrument=args.instrument, seed=seed, output=Path(args.output) / "simulate"
        )
        result["simulation"] = sim.summary
        # name the sub-folder, not the output path: the summary stays the same wherever written
        text += "\n" + sim.text.replace(str(Path(args.output) / "simulate"), "simulate/")
        text += "\n" + tolerance_note(sim.summary) + "\n"
    step(3, 4, "figures")
    figure = plot_scenario_layout(scenario, result)
    png = io.BytesIO()
    figure.savefig(png, format="png", dpi=110, metadata={"Software": None})
    step(4, 4, "done")
    files.update(
        {
            "result.json": _json(result).encode("utf-8"),
            "summary.md": text.encode("utf-8"),
            "measurements.csv": _measurements_csv(scenario, measurements).encode("utf-8"),
            "layout.png": png.getvalue(),
        }
    )
    out = Path(args.output)
    for name, content in files.items():
        atomic_write_bytes(out / name, content)
    if args.json:
        sys.stdout.write(_json(result))
    else:
        sys.stdout.write(text)
        sys.stdout.write(f"\nwritten: {', '.join(sorted(files))} in {out}\n")
    return 0


# --- instruments and setup sheets -----------------------------------------------------------


def _instrument(args: argparse.Namespace) -> int:
    from stereoplotter.instrument.spec import format_instrument, instrument_to_dict
    from stereoplotter.io.instrument_file import load_instrument

    spec = load_instrument(args.name)
    if args.instrument_command == "test":
        from stereoplotter.procedure.selftest import format_selftest, run_kinematic_selftest

        tilts = [math.radians(t) for t in args.tilts]
        result = run_kinematic_selftest(tilts=tilts, variants=tuple(args.variants), instrument=spec)
        result["instrument"] = spec.key
        sys.stdout.write(_json(result) if args.json else format_selftest(result))
        return 0
    sys.stdout.write(_json(instrument_to_dict(spec)) if args.json else format_instrument(spec))
    return 0


def _sheet_files(sheet: Any, data: dict[str, Any]) -> dict[str, bytes]:
    """sheet.yaml, sheet.md, sheet.pdf and sheet.png of a setup sheet, rendered in memory."""
    import yaml

    from stereoplotter.plotting.figures import plot_setup_sheet
    from stereoplotter.report.sheet import sheet_markdown

    text = yaml.safe_dump(json.loads(_json(data)), sort_keys=False, allow_unicode=True, width=100)
    figure = plot_setup_sheet(sheet)
    pdf, png = io.BytesIO(), io.BytesIO()
    figure.savefig(
        pdf, format="pdf", metadata={"Creator": None, "Producer": None, "CreationDate": None}
    )
    figure.savefig(png, format="png", dpi=110, metadata={"Software": None})
    return {
        "sheet.yaml": text.encode("utf-8"),
        "sheet.md": sheet_markdown(sheet).encode("utf-8"),
        "sheet.pdf": pdf.getvalue(),
        "sheet.png": png.getvalue(),
    }


def _sheet_summary(sheet: Any) -> str:
    return (
        f"setup sheet of {sheet.scenario} on {sheet.instrument_title}: M_г = "
        f"1:{sheet.horizontal_scale_denominator}, M_в = 1:{sheet.vertical_scale_denominator}, "
        f"f_пр = {sheet.f_instrument_mm:.3f} mm, n_л = {sheet.n_left:.5f}, "
        f"n_п = {sheet.n_right:.5f}"
    )


def _check_sheet(args: argparse.Namespace) -> int:
    """check-sheet: exit 0 when every value is within its tolerance, 1 otherwise."""
    from stereoplotter.io.instrument_file import load_instrument
    from stereoplotter.io.scenario_file import load_scenario
    from stereoplotter.io.trainee_sheet import load_trainee_sheet
    from stereoplotter.report.sheet_check import check_dict, check_text
    from stereoplotter.setup.sheet import compute_setup_sheet
    from stereoplotter.setup.sheet_check import check_sheet

    trainee = load_trainee_sheet(args.sheet)
    spec = load_instrument(args.instrument)
    scenario = load_scenario(args.scenario)
    seed = scenario.seed if args.seed is None else args.seed
    sheet = compute_setup_sheet(scenario, spec, rng=np.random.default_rng(seed))
    result = check_sheet(sheet, spec, trainee)
    sys.stdout.write(_json(check_dict(result)) if args.json else check_text(result))
    return 0 if result.passed else 1


def _setup(args: argparse.Namespace) -> int:
    from stereoplotter.io.instrument_file import load_instrument
    from stereoplotter.io.scenario_file import load_scenario
    from stereoplotter.report.sheet import sheet_to_dict
    from stereoplotter.setup.sheet import SetupOptions, compute_setup_sheet

    data, _ = load_yaml_mapping(args.scenario)
    if is_job_file(data):
        return _setup_job(args)
    if args.instrument is None:
        raise StereoplotterError(
            f"{args.scenario}: --instrument: expected sc1, spr3, sd3 or a YAML path, found "
            "nothing (only a job file names its own instrument)"
        )
    spec = load_instrument(args.instrument)
    if "models" in data or "models_csv" in data:
        return _setup_block(args, spec)
    scenario = load_scenario(args.scenario)
    options = SetupOptions(
        book_sign_n_right=args.book_sign,
        horizontal_scale_denominator=args.horizontal_scale,
        vertical_scale_denominator=args.vertical_scale,
        bz_scale_sense=args.bz_scale_sense,
    )
    seed = scenario.seed if args.seed is None else args.seed
    sheet = compute_setup_sheet(scenario, spec, options, np.random.default_rng(seed))
    data = sheet_to_dict(sheet)
    data["seed"] = seed
    if args.json:
        sys.stdout.write(_json(data))
    if args.output is None and args.json:
        return 0
    out = Path(args.output or "stereoplotter-setup")
    files = _sheet_files(sheet, data)  # everything rendered before anything is written
    for name, content in files.items():
        atomic_write_bytes(out / name, content)
    if not args.json:
        sys.stdout.write(f"{_sheet_summary(sheet)}\nwritten: {', '.join(files)} in {out}\n")
    return 0


def _setup_job(args: argparse.Namespace) -> int:
    """A production job: every pair's sheet and printable form (``stereoplotter.report.job``)."""
    from stereoplotter.io.instrument_file import load_instrument
    from stereoplotter.io.job_file import load_job
    from stereoplotter.report.job import compute_job, pair_dict, write_job

    given = [
        o
        for o, v in (
            ("--seed", args.seed),
            ("--horizontal-scale", args.horizontal_scale),
            ("--vertical-scale", args.vertical_scale),
        )
        if v is not None
    ]
    if given:
        raise StereoplotterError(
            f"{args.scenario}: {given[0]}: expected nothing for a job file, found a value (a job "
            "draws no random numbers and sets its scales in its own 'scales' field)"
        )
    job = load_job(args.scenario)
    result = compute_job(job, load_instrument(args.instrument) if args.instrument else None)
    if args.json:
        pairs = [pair_dict(job, p) for p in result.pairs]
        sys.stdout.write(_json({"job": job.name, "instrument": result.spec.key, "pairs": pairs}))
        if args.output is None:
            return 0
    out = Path(args.output or "stereoplotter-setup")
    names = write_job(result, out)
    if args.json:
        return 0
    accepted = sum(p.accepted for p in result.pairs)
    lines = [
        f"job {job.name} on {result.spec.title}: {accepted} of {len(result.pairs)} pairs set up"
    ]
    for p in result.pairs:
        s = p.sheet
        lines.append(
            f"  {p.pair.name}: M_г = 1:{s.horizontal_scale_denominator}, M_в = "
            f"1:{s.vertical_scale_denominator}, f_пр = {s.f_instrument_mm:.3f} mm, n_л = "
            f"{s.n_left:.5f}, n_п = {s.n_right:.5f}"
            if s is not None
            else f"  {p.pair.name}: REFUSED: {p.reason}"
        )
    pdfs = sum(n.endswith("/sheet.pdf") for n in names)
    lines.append(
        f"written: <pair>/sheet.yaml, sheet.md, sheet.pdf ({pdfs} forms), forms.pdf, "
        f"block.csv, refused.md in {out}"
    )
    sys.stdout.write("\n".join(lines) + "\n")
    return 0


def _setup_block(args: argparse.Namespace, spec: Any) -> int:
    """Block mode: one sheet per model of a block file (``stereoplotter.setup.block``)."""
    from stereoplotter.report.block import model_sheet, run_block

    if args.horizontal_scale is not None or args.vertical_scale is not None or args.seed:
        raise StereoplotterError(
            f"{args.scenario}: a block file sets its scales in its own 'scales' field; "
            "--horizontal-scale, --vertical-scale and --seed apply to single pairs only"
        )
    out = (
        None if (args.json and args.output is None) else Path(args.output or "stereoplotter-setup")
    )
    result = run_block(args.scenario, spec, out, book_sign=args.book_sign)
    sheets = [model_sheet(result, i) for i in range(len(result))]
    if args.json:
        sys.stdout.write(_json({"block": result.name, "instrument": spec.key, "models": sheets}))
        return 0
    accepted = int(np.sum(result.accepted))
    lines = [f"block {result.name} on {spec.title}: {accepted} of {len(result)} models set up"]
    for i, sheet in enumerate(sheets):
        if result.accepted[i]:
            lines.append(
                f"  {result.model_names[i]}: M_г = 1:{sheet['scale_horizontal']}, "
                f"M_в = 1:{sheet['scale_vertical']}, n_л = {sheet['n_left']:.5f}, "
                f"n_п = {sheet['n_right']:.5f}"
            )
        else:
            lines.append(f"  {result.model_names[i]}: REFUSED: {result.reason(i)}")
    lines.append(f"written: <model>/sheet.yaml and block.csv in {out}")
    sys.stdout.write("\n".join(lines) + "\n")
    return 0


def _job(args: argparse.Namespace) -> int:
    """``job to-scenario``: one pair of a job as a scenario (``stereoplotter.io.job_scenario``)."""
    from stereoplotter.io.job_file import load_job
    from stereoplotter.io.job_scenario import write_job_scenario

    doc, fit = write_job_scenario(load_job(args.job), args.pair, args.output)
    sys.stdout.write(
        f"scenario {doc['name']}: {len(doc['points'])} points, terrain {fit.kind} fitted to "
        f"{fit.points} control heights (rms {fit.rms_m:.3f} m, max {fit.max_m:.3f} m)\n"
        f"written: {args.output}\n"
    )
    return 0


def _simulate(args: argparse.Namespace) -> int:
    from stereoplotter.progress import progress_bar
    from stereoplotter.report.simulation import run_simulation_command

    with progress_bar(args.trials or 1, "simulate") as advance:
        outcome = run_simulation_command(
            args.scenario,
            instrument=args.instrument,
            method=args.method,
            errors=args.errors,
            operator=args.operator,
            practice=args.practice,
            options=args.option,
            seed=args.seed,
            trials=args.trials,
            backend=args.backend,
            output=args.output,
            memory_mb=args.memory_mb,
            progress=advance,
        )
    sys.stdout.write(_json(outcome.summary) if args.json else outcome.text)
    return 0


def _verify(args: argparse.Namespace) -> int:
    from stereoplotter.io.geometry_file import geometry_from_file
    from stereoplotter.progress import step_progress
    from stereoplotter.report.verification import start_procedure_mc, verify

    geometry, scenarios = None, None
    if args.geometry:
        geometry, scenarios = geometry_from_file(args.geometry)
    # the procedure MC once, shared by the table and the histograms; its runs go on in worker
    # processes while the linear rows are computed
    t0 = time.perf_counter()
    pending = start_procedure_mc(args.procedure_trials, args.seed, scenarios, args.instrument)
    with step_progress("verify") as progress:
        rows, seconds = verify(
            trials=args.trials,
            seed=args.seed,
            out_dir=None,
            geometry=geometry,
            progress=progress,
            procedure_trials=0,
        )
    with step_progress("procedure MC") as progress:
        proc = pending.result(progress)
    seconds = time.perf_counter() - t0  # the table and the procedure MC (running alongside)
    if proc:
        from stereoplotter.verification.table import attach_procedure_mc

        attach_procedure_mc(rows, proc)
    if args.output:
        from stereoplotter.report.verification import write_verification

        out = Path(args.output)
        # Figures first, in memory: every file is written whole or not at all.
        from stereoplotter.plotting.accuracy import (
            plot_error_maps,
            plot_mc_histograms,
            plot_verification_chart,
        )

        figures = {}
        for name, figure in (
            ("error_maps.png", plot_error_maps()),
            ("verification_chart.png", plot_verification_chart(rows).figure),
            (
                "mc_histograms.png",
                plot_mc_histograms(rows, proc, seed=args.seed, geometry=geometry),
            ),
        ):
            buffer = io.BytesIO()
            figure.savefig(buffer, format="png", dpi=100, metadata={"Software": None})
            figures[name] = buffer.getvalue()
        write_verification(
            rows,
            out,
            trials=args.trials,
            seed=args.seed,
            seconds=seconds,
            procedure_trials=args.procedure_trials,
        )
        for name, content in figures.items():
            atomic_write_bytes(out / name, content)
    if args.json:
        sys.stdout.write(_json(rows))
        return 0
    lines = [
        f"verification of Eqs. (6.28)–(6.61): {len(rows)} rows, {args.trials} trials, "
        f"seed {args.seed}, {seconds:.1f} s",
        "",
        f"{'eq':<14}{'printed':>10}{'rigorous':>10}{'MC':>10}{'proc. MC':>10}  verdict",
    ]
    for r in rows:

        def f(v):
            return f"{v:10.4g}" if isinstance(v, int | float) else f"{'—':>10}"

        lines.append(
            f"{r['eq']:<14}{f(r['printed'])}{f(r['rigorous'])}{f(r['mc_linear'])}"
            f"{f(r['mc_procedure'])}  {r['verdict']}"
        )
    if args.output:
        lines.append(
            f"\nwritten: verification.md, .csv, .json, closing_comparison.json, "
            f"error_maps.png, verification_chart.png, mc_histograms.png in {args.output}"
        )
    sys.stdout.write("\n".join(lines) + "\n")
    return 0


def _budget(args: argparse.Namespace) -> int:
    from stereoplotter.progress import progress_bar
    from stereoplotter.report.budget import (
        budget_json,
        budget_markdown,
        run_budget_command,
        write_budget,
    )

    def bar(total: int) -> Any:
        return progress_bar(total, "budget", unit="trial")

    budget = run_budget_command(
        args.scenario, args.instrument, args.method, args.trials, args.seed, bar
    )
    written = write_budget(budget, args.output) if args.output else []
    sys.stdout.write(budget_json(budget) if args.json else budget_markdown(budget))
    if written and not args.json:
        sys.stdout.write(f"written: {', '.join(written)} in {args.output}\n")
    return 0


# --- parser ----------------------------------------------------------------------------------

#: The largest seed, as in scenario files (``seed``); numpy itself takes any integer ≥ 0.
MAX_SEED = 2**63 - 1
#: Trials of one verification row are held in memory at once (8 bytes each, per row).
MAX_VERIFY_TRIALS = 1_000_000
#: Trials per configuration of ``budget``: one configuration's trials run in one chunk of the
#: default memory budget (``procedure.trials.chunk_trials_for``: 8 000 setup, 6 400 conventional).
MAX_BUDGET_TRIALS = 6000
#: Scale denominators as the instrument gear sets allow (``gears.vertical_scale_denominators``).
MAX_SCALE_DENOMINATOR = 10_000_000
#: Tilts of the kinematic self-test: near-vertical photos, as in scenario files.
MAX_TILT_DEG = 15.0


def bounded_int(low: int, high: int | None = None) -> Callable[[str], int]:
    """An argparse ``type=``: an integer in [low, high] (``high=None``: no upper end).

    The message names what was expected and what was found; argparse adds the option.
    """
    expected = f"an integer ≥ {low}" if high is None else f"an integer in [{low}, {high}]"

    def parse(text: str) -> int:
        try:
            value = int(text, 10)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {expected}, found {text!r}") from None
        if value < low or (high is not None and value > high):
            raise argparse.ArgumentTypeError(f"expected {expected}, found {value}")
        return value

    parse.__name__ = f"integer in [{low}, {high}]"
    return parse


def bounded_float(low: float, high: float) -> Callable[[str], float]:
    """An argparse ``type=``: a finite number in [low, high]."""
    expected = f"a number in [{low:g}, {high:g}]"

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {expected}, found {text!r}") from None
        if not (math.isfinite(value) and low <= value <= high):
            raise argparse.ArgumentTypeError(f"expected {expected}, found {text}")
        return value

    parse.__name__ = f"number in [{low:g}, {high:g}]"
    return parse


positive_int = bounded_int(1)
non_negative_int = bounded_int(0)
seed_int = bounded_int(0, MAX_SEED)
scale_denominator = bounded_int(1, MAX_SCALE_DENOMINATOR)


class _Parser(argparse.ArgumentParser):
    """An argument parser whose usage errors are one line, ``error: …``, exit code 2."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"error: {self.prog}: {message} (see {self.prog} --help)\n")


def _add_budget_parser(sub: Any) -> None:
    """``budget``: the per-part error budget (``verification.budget``)."""
    p = sub.add_parser(
        "budget",
        help="per-part error budget: each instrument and operator error's contribution to the "
        "residual y-parallax, height and plan RMS of the simulated procedure",
    )
    p.add_argument("scenario", help="a stereopair scenario: a name (pair60) or a YAML file")
    p.add_argument("--instrument", required=True, help="sc1, spr3, sd3 or a YAML path")
    p.add_argument("--method", choices=("setup", "conventional"), default="setup")
    p.add_argument(
        "--trials",
        type=bounded_int(2, MAX_BUDGET_TRIALS),
        default=DEFAULT_BUDGET_TRIALS,
        help="trials per configuration, the same trials in every configuration "
        f"(2 to {MAX_BUDGET_TRIALS}; default: %(default)s)",
    )
    p.add_argument("--seed", type=seed_int, help="override the scenario's seed")
    p.add_argument("--json", action="store_true", help="print the budget as JSON")
    p.add_argument("-o", "--output", help="write budget.md, budget.json and budget.png here")


def _parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="stereoplotter",
        description="Virtual SC-1, SPR-3 and SD-3 stereoplotters and their setup data "
        "(Kushtin & Lyskov 1984, ch. 6).",
    )
    parser.add_argument("--version", action="version", version=f"stereoplotter {__version__}")
    parser.add_argument(
        "--data",
        action="append",
        default=[],
        metavar="DIR",
        help="a folder of your own instruments/ and scenarios/, searched by name before the "
        "shipped ones (may be repeated; also $STEREOPLOTTER_DATA, separated by os.pathsep)",
    )
    _add_verbosity(parser, argparse.SUPPRESS)
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser("info", help="versions, instruments and scenarios found")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")

    p = sub.add_parser("scenario", help="work with scenario files")
    scen = p.add_subparsers(dest="scenario_command", required=True, metavar="ACTION")
    c = scen.add_parser(
        "check",
        help="validate a scenario file and summarise it: photo scale, overlap, base, B/H, relief",
    )
    c.add_argument("file", help="a scenario name (pair60) or YAML file")
    c.add_argument("--json", action="store_true", help="print JSON instead of text")

    p = sub.add_parser("instrument", help="instrument specifications")
    inst = p.add_subparsers(dest="instrument_command", required=True, metavar="ACTION")
    s = inst.add_parser("show", help="print an instrument's parameters, documented or assumed")
    s.add_argument("name", help="sc1, spr3, sd3 or a path to an instrument YAML")
    s.add_argument("--json", action="store_true", help="print JSON instead of text")
    t = inst.add_parser(
        "test",
        help="kinematic acceptance on a synthetic grid pair (kinematics.md §5–§6): residual "
        "y-parallax per decentration variant and tilt",
    )
    t.add_argument("name", help="sc1, spr3, sd3 or a path to an instrument YAML")
    t.add_argument(
        "--tilts",
        type=bounded_float(-MAX_TILT_DEG, MAX_TILT_DEG),
        nargs="+",
        default=[0.5, 1.0, 3.0],
        metavar="DEG",
        help="tilt magnitudes [deg] (default: 0.5 1 3)",
    )
    t.add_argument(
        "--variants",
        nargs="+",
        default=["L", "A", "B", "B2", "S"],
        choices=["L", "A", "B", "B2", "S"],
        help="decentration variants",
    )
    t.add_argument("--json", action="store_true", help="print JSON instead of text")

    p = sub.add_parser(
        "render", help="render synthetic photos and eyepiece views as PNG (docs/imagery.md)"
    )
    p.add_argument("scenario", help="a scenario name (pair60) or YAML file")
    p.add_argument("--side", choices=["left", "right"], help="one photo only (default: both)")
    p.add_argument(
        "--at",
        type=bounded_float(-1e7, 1e7),
        nargs=2,
        metavar=("X", "Y"),
        help="ground point [m] the views centre on (default: below the centres' midpoint)",
    )
    p.add_argument(
        "--magnification",
        type=bounded_float(0.5, 60.0),
        default=6.0,
        help="eyepiece magnification of the views (default: 6)",
    )
    p.add_argument(
        "--pixel",
        type=bounded_float(0.02, 0.5),
        default=0.08,
        metavar="MM",
        help="pixel of the photo files [mm] (default 0.08: 3.6 s a photo; 0.02 takes a minute)",
    )
    p.add_argument("--seed", type=seed_int, help="texture seed (default: the scenario's)")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="folder for the PNG files")

    p = sub.add_parser("setup", help="compute the setup sheet (Table 24) of a stereopair")
    p.add_argument(
        "scenario",
        help="a stereopair scenario (a name such as pair60, or a YAML file), a block file "
        "listing many stereopairs of one camera (one sheet per model), or a production job file "
        "(format: stereoplotter-job/1: one sheet and printable form per pair)",
    )
    p.add_argument(
        "--instrument",
        help="sc1, spr3, sd3 or a YAML path (required, except for a job file, which names its "
        "own instrument; given, it overrides the job's)",
    )
    p.add_argument(
        "-o",
        "--output",
        help="output folder for sheet.yaml, sheet.md, sheet.pdf, "
        "sheet.png (default: stereoplotter-setup; with --json "
        "nothing is written unless -o is given)",
    )
    p.add_argument(
        "--book-sign",
        action="store_true",
        help="use the printed sign of (6.4) for n_п (default: the geometric sign)",
    )
    p.add_argument(
        "--bz-scale-sense",
        type=int,
        choices=(1, -1),
        default=1,
        help="+1: the b_z scale grows when the right pivot rises (default); -1: the other way, "
        "as the printed minus of (6.11) implies",
    )
    p.add_argument("--horizontal-scale", type=scale_denominator, metavar="M", help="force M_г = M")
    p.add_argument("--vertical-scale", type=scale_denominator, metavar="M", help="force M_в = M")
    p.add_argument("--seed", type=seed_int, help="override the scenario's seed")
    p.add_argument("--json", action="store_true", help="print the sheet as JSON")

    p = sub.add_parser(
        "check-sheet",
        help="check a trainee's own setup sheet against the program's and name the mistakes",
    )
    p.add_argument("sheet", help="the trainee's sheet (YAML in the layout of sheet.yaml)")
    p.add_argument("--scenario", required=True, help="the stereopair (a name or a YAML file)")
    p.add_argument("--instrument", required=True, help="sc1, spr3, sd3 or a YAML path")
    p.add_argument("--seed", type=seed_int, help="override the scenario's seed")
    p.add_argument("--json", action="store_true", help="print the check as JSON")

    p = sub.add_parser("job", help="work with production job files (docs/production.md)")
    jobs = p.add_subparsers(dest="job_command", required=True, metavar="ACTION")
    j = jobs.add_parser(
        "to-scenario",
        help="write one pair of a job as a scenario for simulation: the job's orientation, "
        "points and map sheet, a terrain fitted to the control heights (said in the YAML)",
    )
    j.add_argument("job", help="a job file (format: stereoplotter-job/1)")
    j.add_argument("pair", help="the pair as LEFT-RIGHT photo numbers, e.g. 101-102")
    j.add_argument("-o", "--output", required=True, metavar="FILE", help="the scenario YAML")

    p = sub.add_parser(
        "simulate",
        help="run the simulated operator on a virtual instrument and evaluate the model",
    )
    p.add_argument("scenario", help="a stereopair scenario: a name (pair60) or a YAML file")
    p.add_argument("--instrument", required=True, help="sc1, spr3, sd3 or a YAML path")
    p.add_argument(
        "--method",
        choices=("setup", "conventional"),
        default="setup",
        help="the setup-data method (five stages) or the conventional method",
    )
    p.add_argument(
        "--errors",
        help="injected errors: a YAML of overrides, or 'zero' "
        "(default: the instrument's own, all assumed)",
    )
    p.add_argument(
        "--operator",
        help="the operator: 'zero' (no judgment, reading or setting error, no rounding) or a "
        "YAML of OperatorModel fields (default: the assumed operator)",
    )
    p.add_argument(
        "--practice",
        choices=("operator", "book"),
        default="operator",
        help="'operator' (default): after a failed check the operator applies the book's "
        "remedies (repeat the setting, refine the relative orientation, refine scaling and "
        "levelling on control), bounded and logged; 'book': §27's task 1, each element set "
        "once, failed checks only recorded (both methods)",
    )
    p.add_argument(
        "--option",
        action="append",
        default=[],
        choices=("correction_unit", "automatic_coordinatograph"),
        help="fit an option of the SC complex to the SC-1 (repeatable; off by default): "
        "'correction_unit' corrects the image errors within ±100 µm to 3 µm RMS, "
        "'automatic_coordinatograph' drives the needle by a tracking servo (to 10 ×)",
    )
    p.add_argument("--seed", type=seed_int, help="override the scenario's seed")
    p.add_argument(
        "--trials", type=positive_int, help="run T trials at once (closed-form back-end)"
    )
    p.add_argument("--backend", choices=("closed-form", "pymunk"), default="closed-form")
    p.add_argument(
        "-o",
        "--output",
        help="write the transcript, the evaluation, a parallax map and (with --trials) the "
        "per-trial measures trials.npz into this folder (default: write nothing)",
    )
    p.add_argument(
        "--memory-mb",
        type=bounded_float(16.0, 1e6),  # below 16 MB no useful chunk fits
        default=DEFAULT_MEMORY_BUDGET_MB,
        metavar="MB",
        help="memory budget of one chunk of trials (default: %(default)s MB)",
    )
    p.add_argument("--json", action="store_true", help="print the summary as JSON")

    p = sub.add_parser(
        "verify",
        help="verify the accuracy formulas (6.28)–(6.61) against rigorous forms and Monte Carlo",
    )
    p.add_argument(
        "--trials",
        type=bounded_int(2, MAX_VERIFY_TRIALS),
        default=60000,
        help=f"Monte Carlo trials per row, 2 to {MAX_VERIFY_TRIALS} (default: %(default)s)",
    )
    p.add_argument("--seed", type=seed_int, default=20240601, help="seed of the Monte Carlo")
    p.add_argument("-o", "--output", help="write Markdown, CSV, JSON and plots into this folder")
    p.add_argument("--json", action="store_true", help="print the rows as JSON")
    p.add_argument(
        "--procedure-trials",
        type=bounded_int(0, MAX_VERIFY_TRIALS),
        default=None,
        help="trials of each procedure MC run (simulated operator); default: per configuration, "
        "enough for a 1 %% CI; 0 disables",
    )
    p.add_argument(
        "--instrument",
        default="sc1",
        help="instrument of the procedure MC, ideal and with its error terms (default: "
        "%(default)s, the book's SC-1)",
    )
    p.add_argument(
        "--geometry",
        metavar="FILE",
        help="YAML: a scenario (f, l, n, photo base p, overlap; also runs the procedure MC on it) "
        "or a mapping of f, l, n, c, p60, a60, p80, a80",
    )

    _add_budget_parser(sub)

    p = sub.add_parser(
        "demo",
        help="run the main job on the default scenario (or --scenario) "
        "and write its results into a folder",
    )
    p.add_argument(
        "-o", "--output", default="stereoplotter-demo", help="output folder (default: %(default)s)"
    )
    p.add_argument(
        "--scenario",
        default=DEFAULT_SCENARIO,
        help="scenario name or file (default: the shipped %(default)s)",
    )
    p.add_argument("--seed", type=seed_int, help="override the scenario's seed")
    p.add_argument(
        "--instrument", default="sc1", help="instrument of the setup sheet (default: %(default)s)"
    )
    p.add_argument("--json", action="store_true", help="print JSON instead of text")

    p = sub.add_parser("exercise", help="trainer exercises (docs/trainer.md)")
    exs = p.add_subparsers(dest="exercise_command", required=True, metavar="ACTION")
    e = exs.add_parser("list", help="the exercises found, easiest first")
    e.add_argument("--json", action="store_true", help="print JSON instead of text")
    e = exs.add_parser("show", help="an exercise's settings")
    e.add_argument("name", help="an exercise name (e01-setup-stage1) or YAML file")
    e.add_argument("--json", action="store_true", help="print JSON instead of text")

    p = sub.add_parser("session", help="run a trainee's session without a browser")
    ses = p.add_subparsers(dest="session_command", required=True, metavar="ACTION")
    r = ses.add_parser(
        "run",
        help="carry out the actions of a file (JSON lines or a JSON list; 'operator' for the "
        "simulated operator's own) and write the session log",
    )
    r.add_argument("exercise", help="an exercise name or YAML file")
    r.add_argument("--actions", required=True, metavar="FILE", help="actions file, or 'operator'")
    r.add_argument("-o", "--output", required=True, metavar="LOG", help="session log to write")
    r.add_argument("--trainee", default="trainee", help="trainee's name (per-trainee seeds)")
    r.add_argument("--seed", type=seed_int, help="seed when the exercise has none fixed")
    r.add_argument(
        "--keep-going", action="store_true", help="log a refused action and go on (default: stop)"
    )

    p = sub.add_parser("grade", help="grade a session log (Markdown and JSON)")
    p.add_argument("log", metavar="SESSION_LOG", help="a session log (JSON lines)")
    p.add_argument("--json", action="store_true", help="print JSON instead of Markdown")
    p.add_argument("-o", "--output", metavar="DIR", help="also write grade.md and grade.json here")
    p.add_argument(
        "--population",
        type=non_negative_int,
        default=10_000,
        help="simulated operators for the percentile (0: none; default: %(default)s)",
    )

    p = sub.add_parser(
        "trainer",
        help="serve the browser trainer (needs the extra stereoplotter[trainer]; docs/trainer.md)",
    )
    p.add_argument(
        "--host", default="127.0.0.1", help="address to listen on (default: %(default)s)"
    )
    p.add_argument(
        "--port",
        type=non_negative_int,
        default=0,
        help="port (default: 0, a free port chosen by the system; the address is printed)",
    )
    p.add_argument("--token", help="the instructor's token (default: a random one, printed)")
    p.add_argument(
        "--data-dir",
        metavar="DIR",
        help="folder of the trainer's SQLite file: sessions, logs, grades (default: "
        "~/.local/share/stereoplotter/trainer, or $XDG_DATA_HOME/stereoplotter/trainer)",
    )
    return parser


# --- trainer: exercises, sessions, grades ----------------------------------------------------


def _exercise_row(ex: Any) -> dict[str, Any]:
    return {
        "name": ex.name,
        "level": ex.level,
        "title": ex.title,
        "instrument": ex.instrument,
        "scenario": ex.scenario_name,
        "method": ex.method,
        "stages": list(ex.stages),
        "preset_stages": list(ex.preset_stages),
        "terrain": ex.terrain,
        "model": ex.model,
        "unusable_points": list(ex.unusable_points),
        "errors": ex.errors,
        "tilt": ex.tilt,
        "assists": ex.assists,
        "mode": ex.mode,
        "seed": ex.seed if ex.seed is not None else "per-trainee",
        "description": ex.description,
    }


def _exercise(args: argparse.Namespace) -> int:
    from stereoplotter.io.exercise_file import load_exercise, shipped_exercises

    if args.exercise_command == "list":
        rows = sorted(
            (_exercise_row(load_exercise(p)) for p in shipped_exercises()),
            key=lambda r: (r["level"], r["name"]),
        )
        if args.json:
            sys.stdout.write(_json(rows))
            return 0
        for r in rows:
            stages = ",".join(r["stages"])
            print(
                f"{r['level']:>2}  {r['name']:<30} {r['instrument']:<5} {r['method']:<12} "
                f"stages {stages:<11} {r['mode']:<8} {r['title']}"
            )
        return 0
    row = _exercise_row(load_exercise(args.name))
    if args.json:
        sys.stdout.write(_json(row))
        return 0
    for key, value in row.items():
        print(f"{key}: {value}")
    return 0


def _read_actions(path: str) -> list[dict[str, Any]]:
    """Actions from a JSON list or JSON lines file (one line: file, line, what is wrong)."""
    from stereoplotter.errors import ConfigError

    text = Path(path).read_text(encoding="utf-8")
    try:
        data = json.loads(text)
        rows = data if isinstance(data, list) else [data]
    except json.JSONDecodeError:
        rows = []
        for number, line in enumerate(text.splitlines(), 1):
            if line.strip():
                try:
                    rows.append(json.loads(line))
                except json.JSONDecodeError as exc:
                    raise ConfigError(path, f"line {number}", "a JSON action", exc.msg) from None
    return rows


def _session(args: argparse.Namespace) -> int:
    from stereoplotter.errors import TrainerError
    from stereoplotter.io.exercise_file import load_exercise
    from stereoplotter.io.session_log import write_log
    from stereoplotter.trainer.session import Session

    session = Session.start(load_exercise(args.exercise), trainee=args.trainee, seed=args.seed)
    actions = (
        session.operator_script() if args.actions == "operator" else _read_actions(args.actions)
    )
    refused = 0
    try:
        for action in actions:
            try:
                session.act(action)
            except TrainerError as exc:
                refused += 1
                if not args.keep_going:
                    print(f"error: {exc}", file=sys.stderr)
                    return 1
                print(f"refused: {exc}", file=sys.stderr)
    finally:
        write_log(args.output, session)
    state = session.state()
    print(
        f"{len(session.log)} actions ({refused} refused), stage {state['stage'] or 'all done'}; "
        f"log: {args.output}"
    )
    return 0


def _grade(args: argparse.Namespace) -> int:
    from stereoplotter.io.session_log import read_log
    from stereoplotter.progress import progress_bar
    from stereoplotter.report.grade import grade_json, grade_markdown, write_grade
    from stereoplotter.trainer.grading import grade

    records = read_log(args.log)
    with progress_bar(args.population, "simulated operators", unit="operator") as advance:
        result = grade(records, population=args.population, progress=advance)
    if args.output:
        write_grade(result, args.output)
    sys.stdout.write(grade_json(result) if args.json else grade_markdown(result))
    return 0


def _trainer(args: argparse.Namespace) -> int:
    try:
        from stereoplotter.web.server import serve
    except ImportError as exc:
        print(
            f"error: the browser trainer needs the extra stereoplotter[trainer] "
            f"(pip install 'stereoplotter[trainer]'); missing module {exc.name}",
            file=sys.stderr,
        )
        return 1
    try:
        serve(args.host, args.port, args.token, args.data_dir)
    except OSError as exc:
        print(
            f"error: trainer: cannot listen on {args.host}:{args.port} ({exc.strerror or exc})",
            file=sys.stderr,
        )
        return 1
    return 0


def _resolve_data_arguments(args: argparse.Namespace) -> None:
    """Apply ``--data`` and turn scenario names (``pair60``) into files; instrument names are
    resolved by :func:`~stereoplotter.io.instrument_file.load_instrument` itself."""
    set_user_folders(args.data)
    for attribute in ("scenario", "file", "geometry"):  # setup/simulate/demo, check, verify
        if getattr(args, attribute, None):
            setattr(args, attribute, str(resolve_data_file("scenarios", getattr(args, attribute))))


def _add_verbosity(parser: argparse.ArgumentParser, default: Any) -> None:
    parser.add_argument(
        "-v",
        "--verbose",
        action="count",
        default=default,
        help="log what is done on stderr (-v: steps, -vv: details)",
    )
    parser.add_argument(
        "-q",
        "--quiet",
        action="store_true",
        default=default,
        help="no progress bar, warnings and errors only",
    )


def _all_subparsers(parser: argparse.ArgumentParser) -> list[argparse.ArgumentParser]:
    found = []
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for child in action.choices.values():
                found += [child, *_all_subparsers(child)]
    return found


def _full_parser() -> argparse.ArgumentParser:
    """The parser with -v/--quiet accepted before or after the command."""
    parser = _parser()
    for child in _all_subparsers(parser):
        _add_verbosity(child, argparse.SUPPRESS)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``stereoplotter`` command. Returns the exit code."""
    args = _full_parser().parse_args(argv)
    configure_logging(getattr(args, "verbose", 0), getattr(args, "quiet", False))
    try:
        _resolve_data_arguments(args)
        if args.command == "info":
            info = _info()
            sys.stdout.write(_json(info) if args.json else _format_info(info))
            return 0
        if args.command == "scenario":
            from stereoplotter.io.scenario_file import load_scenario
            from stereoplotter.scenario import summarize_scenario

            summary = summarize_scenario(load_scenario(args.file))
            sys.stdout.write(_json(summary) if args.json else _format_summary(summary))
            return 0
        if args.command == "demo":
            return _demo(args)
        if args.command == "instrument":
            return _instrument(args)
        if args.command == "setup":
            return _setup(args)
        if args.command == "check-sheet":
            return _check_sheet(args)
        if args.command == "render":
            return _render(args)
        if args.command == "job":
            return _job(args)
        if args.command == "simulate":
            return _simulate(args)
        if args.command == "verify":
            return _verify(args)
        if args.command == "budget":
            return _budget(args)
        if args.command == "exercise":
            return _exercise(args)
        if args.command == "session":
            return _session(args)
        if args.command == "grade":
            return _grade(args)
        if args.command == "trainer":
            return _trainer(args)
    except StereoplotterError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    except OSError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    except Exception as exc:  # a bug: say so in one line, the traceback only on request
        if os.environ.get("STEREOPLOTTER_DEBUG"):
            raise
        print(
            f"error: internal error ({type(exc).__name__}: {exc}); this is a bug in "
            "stereoplotter: please report it with the command you ran (set "
            "STEREOPLOTTER_DEBUG=1 to see the traceback)",
            file=sys.stderr,
        )
        return 3
    return 2  # pragma: no cover - argparse requires a command


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
