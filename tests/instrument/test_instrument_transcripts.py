"""Issue 11, deliverable 6: the simulated operator names each instrument's own controls."""

from __future__ import annotations

from pathlib import Path

from stereoplotter.report.simulation import run_simulation_command

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
