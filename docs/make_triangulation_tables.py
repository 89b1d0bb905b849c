"""The tables of docs/triangulation.md: the methods on the 10 × 4 block, the chain to the forms.

Run from the repository root: ``python docs/make_triangulation_tables.py``; prints Markdown.
The 10 × 4 block is ``stereoplotter block synth --seed 7`` (4 strips × 10 photos, control every
4 bases); the chain is the worked example ``jobs/block3x6`` triangulated by the bundle method.
Times are wall-clock on the machine that ran it (shared, 2 cores): read them as ratios.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

from stereoplotter.cli import main
from stereoplotter.commands.triangulation_chain import chain_comparison, chain_markdown
from stereoplotter.errors import GeometryError
from stereoplotter.io.block_measurements_file import load_block_measurements
from stereoplotter.triangulation.bundle import bundle_block
from stereoplotter.triangulation.polygon_block import polygon_block
from stereoplotter.triangulation.solution import catalogue_residuals
from stereoplotter.triangulation.strip import strip_block

ROOT = Path(__file__).resolve().parents[1]


def _truth(folder: Path) -> np.ndarray:
    rows = np.genfromtxt(folder / "truth.csv", delimiter=",", skip_header=1, dtype=float)
    out = rows[:, 1:].copy()
    out[:, :3] = np.radians(out[:, :3])
    return out


def methods_table(folder: Path) -> str:
    block, _ = load_block_measurements(folder / "block.yaml")
    truth = _truth(folder)
    runs = [("bundle", lambda: bundle_block(block))]
    for models in ("independent", "dependent"):
        for degree in (2, 3):
            runs.append(
                (
                    f"strip, {models} models, degree {degree}",
                    lambda m=models, d=degree: strip_block(block, m, d),
                )
            )
    runs.append(("polygon (least squares)", lambda: polygon_block(block)))
    lines = [
        "| method | RMS X | RMS Y | RMS Z | centres vs truth X, Y, Z | iterations | time |",
        "|---|---:|---:|---:|---|---:|---:|",
    ]
    for name, run in runs:
        start = time.perf_counter()
        try:
            s = run()
        except GeometryError as exc:
            lines.append(f"| {name} | — | — | — | {exc} | | |")
            continue
        seconds = time.perf_counter() - start
        rms = catalogue_residuals(block, s).rms(block, "check")
        c = np.sqrt(np.mean((s.orientations[:, 3:] - truth[:, 3:]) ** 2, axis=0))
        lines.append(
            f"| {name} | {rms[0]:.3f} | {rms[1]:.3f} | {rms[2]:.3f} | "
            f"{c[0]:.3f}, {c[1]:.3f}, {c[2]:.3f} | {s.iterations} | {seconds:.2f} s |"
        )
    n = sum(1 for c in block.catalogue if c.role == "check")
    return "\n".join(lines) + f"\n\nRMS at the {n} check points [m].\n"


def main_tables() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        assert main(["block", "synth", "-o", str(tmp / "b10x4"), "--seed", "7"]) == 0
        print("## 10 × 4 block\n")
        print(methods_table(tmp / "b10x4"))
        example = ROOT / "jobs" / "block3x6"
        print("## Worked example jobs/block3x6\n")
        print(methods_table(example))
        assert main(["triangulate", str(example / "block.yaml"), "-o", str(tmp / "tri")]) == 0
        block, _ = load_block_measurements(example / "block.yaml")
        rows = chain_comparison(
            tmp / "tri" / "job.yaml", example / "truth" / "job.yaml", block, bundle_block(block)
        )
        print("## Chain: forms from the triangulated against the true orientations\n")
        print(chain_markdown(rows, 4.0))


if __name__ == "__main__":
    main_tables()
