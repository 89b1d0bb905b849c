"""Seeded mutations of a block measurements file: `triangulate` answers, or fails in one line.

Every mutated file must give exit 0 or exit 1 with exactly one ``error:`` line naming a file;
never an internal error (exit 3) or a traceback.
"""

from __future__ import annotations

import numpy as np
import pytest

from stereoplotter.cli import main
from stereoplotter.io.block_measurements_file import write_block_measurements
from stereoplotter.triangulation.synth import SynthSpec, synthesize_block

JUNK = ["", "x", "-1", "1e400", "nan", "0", "1e-300", '"', "101", "P1.1", "fiducial", "5"]


def _mutate(text: str, rng: np.random.Generator) -> str:
    lines = text.splitlines()
    i = int(rng.integers(len(lines)))
    action = int(rng.integers(4))
    if action == 0:  # drop a line
        del lines[i]
    elif action == 1:  # duplicate a line
        lines.insert(i, lines[i])
    elif action == 2 and "," in lines[i]:  # one CSV field replaced
        fields = lines[i].split(",")
        fields[int(rng.integers(len(fields)))] = JUNK[int(rng.integers(len(JUNK)))]
        lines[i] = ",".join(fields)
    else:  # one YAML value (after the first ": ") replaced
        head, sep, _ = lines[i].partition(": ")
        lines[i] = head + (sep or ": ") + JUNK[int(rng.integers(len(JUNK)))]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("seed", range(30))  # 300 seeds ran clean once
def test_mutated_block_gives_a_result_or_one_error_line(seed, tmp_path, capsys):
    block, _ = synthesize_block(
        SynthSpec(strips=2, photos_per_strip=3, control_every_bases=1), np.random.default_rng(1)
    )
    write_block_measurements(tmp_path, block)
    rng = np.random.default_rng(seed)
    name = ["block.yaml", "measurements.csv", "control.csv"][seed % 3]
    path = tmp_path / name
    path.write_text(_mutate(path.read_text(encoding="utf-8"), rng), encoding="utf-8")
    code = main(["triangulate", str(tmp_path / "block.yaml"), "-o", str(tmp_path / "out")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code in (0, 1), err
    if code == 1:
        assert len(err) == 1 and err[0].startswith("error: ") and "internal error" not in err[0]
