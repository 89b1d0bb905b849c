"""Measured projection centres (GNSS antenna with a lever arm) in the bundle adjustment."""

from __future__ import annotations

import dataclasses

import numpy as np

from stereoplotter.io.block_measurements_file import (
    load_block_measurements,
    write_block_measurements,
)
from stereoplotter.triangulation.bundle import bundle_adjust, problem
from stereoplotter.triangulation.reliability import snoop
from stereoplotter.triangulation.synth import SynthSpec, synthesize_block

LEVER = (0.2, -0.5, 1.5)


def _check_errors(block, truth, s):
    check = {c.id for c in block.catalogue if c.role == "check"}
    idx = [
        i for i, pid in enumerate(block.point_ids) if pid in check and np.isfinite(s.points_m[i, 0])
    ]
    err = s.points_m[idx] - truth.points_m[idx]
    return err, err / s.point_standard_errors[idx]


def test_centres_and_control_at_the_strip_ends_recover_check_points_within_their_sigma():
    # control only at both ends of the strips (10 points for 40 photos); centres to 0.1 m with
    # a lever arm of 1.6 m. RMS(error/σ) pooled over 3 blocks × 3 axes; the blocks' values
    # spread by ≈ 0.1 per axis, so 0.8–1.25 (a factor 1.25 either way) is > 3 SE
    z_all, gain = [], []
    for seed in range(3):
        spec = dict(strips=4, photos_per_strip=10, control_stations=(0, 9))
        rng = [seed, 6]
        block, truth = synthesize_block(
            SynthSpec(**spec, centre_sigma_m=0.1, lever_arm_m=LEVER), np.random.default_rng(rng)
        )
        plain, truth0 = synthesize_block(SynthSpec(**spec), np.random.default_rng(rng))
        err, z = _check_errors(block, truth, bundle_adjust(problem(block)))
        err0, _ = _check_errors(plain, truth0, bundle_adjust(problem(plain)))
        z_all.append(z)
        gain.append(np.sqrt(np.mean(err**2)) / np.sqrt(np.mean(err0**2)))
    rms = float(np.sqrt(np.mean(np.vstack(z_all) ** 2)))
    assert 0.8 < rms < 1.25, rms
    assert max(gain) < 0.9  # the centres make every block better


def test_a_wrong_lever_arm_shows_in_sigma0():
    # the antenna 1.6 m from the centre: adjusting without the lever arm leaves it in the
    # centre residuals (σ₀ well above 1); with it σ₀ is that of the photo measurements
    block, _ = synthesize_block(
        SynthSpec(strips=2, photos_per_strip=6, centre_sigma_m=0.05, lever_arm_m=LEVER),
        np.random.default_rng(3),
    )
    p = problem(block)
    good = bundle_adjust(p)
    bad = bundle_adjust(dataclasses.replace(p, lever_arm_m=np.zeros(3)))
    assert good.sigma0 < 1.3 < 3.0 < bad.sigma0


def test_centres_and_lever_arm_round_trip_through_the_block_file(tmp_path):
    block, _ = synthesize_block(
        SynthSpec(strips=2, photos_per_strip=3, centre_sigma_m=0.1, lever_arm_m=LEVER),
        np.random.default_rng(2),
    )
    write_block_measurements(tmp_path, block)
    again, _ = load_block_measurements(tmp_path / "block.yaml")
    assert again.lever_arm_m == LEVER and [c[0] for c in again.centres] == list(block.photos)
    np.testing.assert_allclose(
        [c[1] for c in again.centres], [c[1] for c in block.centres], atol=5e-4
    )
    assert again.sigmas.centre_plan_m == 0.1


def test_a_blunder_on_a_measured_centre_is_flagged_by_photo():
    block, _ = synthesize_block(
        SynthSpec(strips=3, photos_per_strip=6, centre_sigma_m=0.1, lever_arm_m=LEVER),
        np.random.default_rng(4),
    )
    centres = list(block.centres)
    photo, (north, east, h) = centres[7]
    centres[7] = (photo, (north, east, h + 1.0))  # 10 σ
    r = snoop(problem(dataclasses.replace(block, centres=tuple(centres))))
    assert [(f.photo, f.point, f.observation) for f in r.flags] == [(photo, "", "centre_Z_m")]
    rel = r.reliability_first
    total = rel.photo_r.sum() + np.nansum(rel.control_r) + np.nansum(rel.centre_r)
    assert total == np.float64(total) and abs(total - r.first.redundancy) < 1e-6 * total
