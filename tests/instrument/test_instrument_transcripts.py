"""Issue 11, deliverable 6: the simulated operator names each instrument's own controls."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from stereoplotter.commands.simulation import run_simulation_command
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.report.sheet import sheet_markdown
from stereoplotter.setup.sheet import compute_setup_sheet

PAIR60 = Path(__file__).parents[2] / "stereoplotter" / "data" / "scenarios" / "pair60.yaml"


def _transcript(tmp_path: Path, name: str) -> str:
    run_simulation_command(PAIR60, instrument=name, seed=None, output=tmp_path / name)
    return (tmp_path / name / "transcript.txt").read_text(encoding="utf-8")


def test_spr3_and_sd3_transcripts_differ_and_spr3_moves_the_photo(tmp_path):
    spr3 = _transcript(tmp_path, "spr3")
    sd3 = _transcript(tmp_path, "sd3")
    assert spr3 != sd3
    assert "the photo carriage brings mark 3 under the fixed measuring mark" in spr3
    assert "lens-shift mechanism δ_ω (k_omega_left)" in spr3
    assert "fixed measuring mark" not in sd3
    assert "correction plane kω (follower) (k_omega_left)" in sd3


def test_sheet_names_the_instrument_controls():
    scenario = load_scenario(PAIR60)
    texts = {
        name: sheet_markdown(
            compute_setup_sheet(scenario, load_instrument(name), rng=np.random.default_rng(1))
        )
        for name in ("sc1", "spr3", "sd3")
    }
    assert "lens-shift mechanism δ_α (k_alpha_left)" in texts["spr3"]
    assert "correction plane kα (follower) (k_alpha_left)" in texts["sd3"]
    assert "photo-carrier tilt α (gimbal) (k_alpha_left)" in texts["sc1"]


def test_spr3_sets_its_three_decentrations_from_the_tables(tmp_path):
    spr3 = _transcript(tmp_path, "spr3")
    sd3 = _transcript(tmp_path, "sd3")
    assert spr3.count("from the tables:") == 4  # dx, dy of each photo
    assert "follower decentration x (correction plate) u_x" in spr3
    assert "from the tables:" not in sd3
