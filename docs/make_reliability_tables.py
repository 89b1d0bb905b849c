"""The figures of docs/triangulation.md on blunders, point σ, self-calibration and centres.

Run from the repository root: ``python docs/make_reliability_tables.py``; prints Markdown. The
blocks are synthetic (``triangulation/synth.py``) with the seeds the tests use
(``tests/triangulation/test_reliability.py``, ``test_self_calibration.py``, ``test_centres.py``,
``test_strip.py``).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from stereoplotter.triangulation.bundle import bundle_adjust, bundle_adjusted, problem
from stereoplotter.triangulation.camera_model import CAMERA_PARAMETERS
from stereoplotter.triangulation.reliability import snoop
from stereoplotter.triangulation.self_calibration import camera_calibration
from stereoplotter.triangulation.solution import catalogue_residuals
from stereoplotter.triangulation.strip import strip_block
from stereoplotter.triangulation.synth import SynthSpec, synthesize_block


def _check_z(block, truth, s):
    check = {c.id for c in block.catalogue if c.role == "check"}
    se = s.point_standard_errors
    idx = [
        i
        for i, pid in enumerate(block.point_ids)
        if pid in check and np.all(np.isfinite(s.points_m[i])) and np.all(np.isfinite(se[i]))
    ]
    return (s.points_m[idx] - truth.points_m[idx]) / se[idx]


def _check_err(block, truth, s):
    check = {c.id for c in block.catalogue if c.role == "check"}
    se = s.point_standard_errors
    idx = [
        i
        for i, pid in enumerate(block.point_ids)
        if pid in check and np.all(np.isfinite(s.points_m[i])) and np.all(np.isfinite(se[i]))
    ]
    return s.points_m[idx] - truth.points_m[idx]


def blunders() -> None:
    block, _ = synthesize_block(
        SynthSpec(strips=6, photos_per_strip=15), np.random.default_rng([0, 39])
    )
    rays = np.bincount(block.obs_point)
    strip = block.strip_of_photo
    three = [
        o
        for o in np.flatnonzero(rays[block.obs_point] == 3)
        if np.unique(strip[block.obs_photo[block.obs_point == block.obs_point[o]]]).size == 1
    ]
    clean = catalogue_residuals(block, bundle_adjust(problem(block))).rms(block, "check")
    print("| blunders | flagged (round: photo, point, observation, w, MDB) | RMS check X, Y, Z "
          "[m]: blundered → after --reject (clean block: "
          f"{clean[0]:.3f}, {clean[1]:.3f}, {clean[2]:.3f}) |")  # fmt: skip
    print("|---|---|---|")
    for coordinate in (1, 0):
        o = three[len(three) // 2]
        comparator = block.comparator_mm.copy()
        comparator[o, coordinate] += 0.5
        cat = list(block.catalogue)
        k = [i for i, c in enumerate(cat) if c.role == "control" and c.kind == "height"][2]
        north, east, h = cat[k].sk42_m
        cat[k] = dataclasses.replace(cat[k], sk42_m=(north, east, h + 2.0))
        bad = dataclasses.replace(block, comparator_mm=comparator, catalogue=tuple(cat))
        r = snoop(problem(bad))
        flags = "; ".join(
            f"{f.round}: {f.photo or '—'}, {f.point or '—'}, {f.observation}, {f.w:+.1f}, "
            f"{f.mdb * 1000 if f.observation.endswith('_mm') else f.mdb:.3g}"
            f"{' µm' if f.observation.endswith('_mm') else ' m'}"
            + (f" (not separable from {', '.join(f.inseparable)})" if f.inseparable else "")
            for f in r.flags
        )
        before = catalogue_residuals(block, r.first.solution).rms(block, "check")
        after = catalogue_residuals(block, r.last.solution).rms(block, "check")
        what = (
            f"+0.5 mm on {'y' if coordinate else 'x'} of {block.photos[block.obs_photo[o]]}/"
            f"{block.point_ids[block.obs_point[o]]}, +2 m on the height of {cat[k].id}"
        )
        print(
            f"| {what} | {flags} | {before[0]:.3f}, {before[1]:.3f}, {before[2]:.3f} → "
            f"{after[0]:.3f}, {after[1]:.3f}, {after[2]:.3f} |"
        )
    print(f"\nk = {r.reliability.k:.2f} (α₀ = {r.reliability.alpha0:.2e}), δ₀ = "
          f"{r.reliability.delta0:.2f}; σ₀ of the blundered block {r.first.solution.sigma0:.3f}, "
          f"after rejection {r.last.solution.sigma0:.3f} (global test: "
          f"{'accepted' if r.global_test.passed else 'rejected'}, interval "
          f"{r.global_test.low:.3f}–{r.global_test.high:.3f})")  # fmt: skip


def robust_weights() -> None:
    from stereoplotter.triangulation.reliability import robust

    block, _ = synthesize_block(
        SynthSpec(strips=6, photos_per_strip=15), np.random.default_rng([0, 39])
    )
    clean = catalogue_residuals(block, bundle_adjust(problem(block))).rms(block, "check")
    rays = np.bincount(block.obs_point)
    strip = block.strip_of_photo
    three = [
        o
        for o in np.flatnonzero(rays[block.obs_point] == 3)
        if np.unique(strip[block.obs_photo[block.obs_point == block.obs_point[o]]]).size == 1
    ]
    o = three[len(three) // 2]
    comparator = block.comparator_mm.copy()
    comparator[o, 1] += 0.5
    cat = list(block.catalogue)
    k = [i for i, c in enumerate(cat) if c.role == "control" and c.kind == "height"][2]
    north, east, h = cat[k].sk42_m
    cat[k] = dataclasses.replace(cat[k], sk42_m=(north, east, h + 2.0))
    bad = dataclasses.replace(block, comparator_mm=comparator, catalogue=tuple(cat))
    print("\n| robust method | rounds | down-weighted | RMS check X, Y, Z / clean block |")
    print("|---|---:|---:|---|")
    for method in ("danish", "huber"):
        r = robust(problem(bad), method)
        got = catalogue_residuals(block, r.adjusted.solution).rms(block, "check") / clean
        print(f"| {method} | {r.iterations} | {len(r.flags)} | {got[0]:.3f}, {got[1]:.3f}, "
              f"{got[2]:.3f} |")  # fmt: skip


def fiducials() -> None:
    print("\n| fiducial marks read with | σ₀ of the clean 6 × 15 block |")
    print("|---|---:|")
    for sf, name in ((None, "σ of a point (5 µm)"), (0.0, "no error")):
        block, _ = synthesize_block(
            SynthSpec(strips=6, photos_per_strip=15, sigma_fiducial_mm=sf),
            np.random.default_rng([0, 39]),
        )
        print(f"| {name} | {bundle_adjust(problem(block), covariance=False).sigma0:.3f} |")


def point_sigma() -> None:
    print(
        "\n| method | blocks | check points | RMS(error/σ) X | Y | Z | SD of the blocks' values |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|")
    runs = (
        ("bundle, 6 × 15", SynthSpec(strips=6, photos_per_strip=15), 39,
         lambda b: bundle_adjust(problem(b))),
        ("strip (independent, degree 3), 4 × 10", SynthSpec(), 7, strip_block),
    )  # fmt: skip
    for name, spec, key, method in runs:
        z = []
        for seed in range(4):
            block, truth = synthesize_block(spec, np.random.default_rng([seed, key]))
            z.append(_check_z(block, truth, method(block)))
        per_block = np.array([np.sqrt(np.mean(b**2, axis=0)) for b in z])
        z = np.vstack(z)
        rms = np.sqrt(np.mean(z**2, axis=0))
        print(f"| {name} | 4 | {len(z)} | {rms[0]:.3f} | {rms[1]:.3f} | {rms[2]:.3f} | "
              f"{np.mean(np.std(per_block, axis=0, ddof=1)):.3f} |")  # fmt: skip


def self_calibration() -> None:
    planted = (0.5, 0.1, -0.08, 5e-8, 0.0, 0.0, 0.0)
    print("\n| block | parameter | planted | adjusted − certificate | σ | (adjusted − planted)/σ |")
    print("|---|---|---:|---:|---:|---:|")
    for name, error in (("planted", planted), ("as certified", (0.0,) * 7)):
        block, _ = synthesize_block(SynthSpec(camera_error=error), np.random.default_rng([0, 5]))
        p = problem(block, CAMERA_PARAMETERS)
        c = camera_calibration(p, bundle_adjusted(p))
        for k, n in enumerate(c.names):
            delta = c.values[k] - c.certificate[k]
            print(f"| {name} | {n} [{c.units[k]}] | {error[k]:.3g} | {delta:.3g} | "
                  f"{c.sigma[k]:.3g} | {(delta - error[k]) / c.sigma[k]:+.2f} |")  # fmt: skip
        print(f"| {name} | group F | | {c.f_statistic:.2f} | critical {c.f_critical:.2f} | "
              f"{'significant' if c.group_significant else 'not significant'} |")  # fmt: skip


def centres() -> None:
    print("\n| block (control only at both strip ends) | RMS check X, Y, Z [m] | RMS(error/σ) |"
          " RMS error against the truth, with/without centres |")  # fmt: skip
    print("|---|---|---:|---:|")
    for seed in range(3):
        without = None
        for sigma in (None, 0.1):
            spec = SynthSpec(
                strips=4,
                photos_per_strip=10,
                control_stations=(0, 9),
                centre_sigma_m=sigma,
                lever_arm_m=(0.2, -0.5, 1.5) if sigma else (0.0, 0.0, 0.0),
            )
            block, truth = synthesize_block(spec, np.random.default_rng([seed, 6]))
            s = bundle_adjust(problem(block))
            rms = catalogue_residuals(block, s).rms(block, "check")
            z = _check_z(block, truth, s)
            what = "centres σ 0.1 m, lever arm 1.6 m" if sigma else "no centres"
            err = float(np.sqrt(np.mean(_check_err(block, truth, s) ** 2)))
            ratio = "" if without is None else f"{err / without:.2f}"
            without = err if without is None else without
            print(f"| seed {seed}, {what} | {rms[0]:.3f}, {rms[1]:.3f}, {rms[2]:.3f} | "
                  f"{np.sqrt(np.mean(z**2)):.3f} | {ratio} |")  # fmt: skip


def lever_arm() -> None:
    block, _ = synthesize_block(
        SynthSpec(strips=2, photos_per_strip=6, centre_sigma_m=0.05, lever_arm_m=(0.2, -0.5, 1.5)),
        np.random.default_rng(3),
    )
    p = problem(block)
    good = bundle_adjust(p, covariance=False).sigma0
    bad = bundle_adjust(dataclasses.replace(p, lever_arm_m=np.zeros(3)), covariance=False).sigma0
    print(f"\n2 × 6 block, centres to 5 cm, lever arm (0.2, −0.5, 1.5) m: σ₀ {good:.2f} with the "
          f"lever arm, {bad:.2f} without")  # fmt: skip


if __name__ == "__main__":
    import sys

    if sys.argv[1:] == ["centres"]:
        centres()
        lever_arm()
        raise SystemExit(0)
    blunders()
    robust_weights()
    fiducials()
    point_sigma()
    self_calibration()
    centres()
    lever_arm()
