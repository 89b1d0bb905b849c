"""Burshtynskaya's tables reproduced beside the printed ones (text report).

``python -m stereoplotter.triangulation.spacing_report [--trials N]`` prints Table 1 and Table 2
(printed | |σ_η² − σ_p²| of the paper's Eq. (1) | variance of the actual residual), the m² column,
the recommended link lengths and a Monte Carlo check of actual strips. The figures of
``docs/triangulation-papers.md`` §1 are this output.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass

import numpy as np

from stereoplotter.triangulation.control_spacing import (
    PAPER_PER_BASE_VARIANCE,
    choose_control_spacing,
    link_lengths,
    mean_square,
    paper_residual_variance,
    residual_variance,
    simulate_residual_variance,
)
from stereoplotter.triangulation.spacing_printed import (
    OCR_READINGS,
    RECOMMENDED_LINKS,
    TABLE_1,
    TABLE_1_MEAN_SQUARE,
    TABLE_2,
)

__all__ = ["Cell", "main", "table_cells"]

#: Half a unit of the printed last digit (0.01) plus float slack.
PRINTED_HALF_UNIT = 0.005 + 1e-9
#: The line between rounding and misprint: half a unit of the printed 0.01 plus half a unit of
#: the next digit (0.0005), the most a value carried to three decimals before its rounding to two
#: can move it. A cell off by more than half a unit but not more than this is "rounding" (the
#: paper's arithmetic at a rounding boundary), beyond it a "misprint".
ROUNDING_LIMIT = 0.0055 + 1e-9


@dataclass(frozen=True)
class Cell:
    """One table entry: paper control numbers, paper point number, printed and reproduced values."""

    control: tuple[int, ...]
    point: int
    printed: float | None
    paper: float  # |σ_η² − σ_p²|·σ_ε² (the paper's Eq. (1))
    signed: float  # σ_η² − σ_p², signed
    actual: float  # var(η − p)·σ_ε²
    read: float | None = None  # the printed value as read (an OCR reading), else the printed

    @property
    def value(self) -> float | None:
        """The printed value as read."""
        return self.printed if self.read is None else self.read

    @property
    def agrees(self) -> bool:
        """Within half a unit of the printed 0.01 (after the OCR reading)."""
        return self.value is None or abs(self.value - self.paper) <= PRINTED_HALF_UNIT

    @property
    def kind(self) -> str:
        """``agrees``, ``rounding`` (≤ :data:`ROUNDING_LIMIT` off) or ``misprint``."""
        if self.agrees:
            return "agrees"
        return "rounding" if abs(self.value - self.paper) <= ROUNDING_LIMIT else "misprint"


def table_cells(table: dict, degree: int) -> list[Cell]:
    """Every entry of a printed table beside its reproduction (σ_ε² = 0.01), OCR readings of
    :data:`~stereoplotter.triangulation.spacing_printed.OCR_READINGS` applied."""
    out = []
    for control, printed in table.items():
        n_bases = control[-1] - 1
        base = np.array(control) - 1
        signed = paper_residual_variance(n_bases, base, degree) * PAPER_PER_BASE_VARIANCE
        actual = residual_variance(n_bases, base, degree) * PAPER_PER_BASE_VARIANCE
        for b in range(n_bases + 1):
            read = OCR_READINGS.get((control, b + 1))
            out.append(
                Cell(
                    control,
                    b + 1,
                    printed[b],
                    abs(signed[b]),
                    float(signed[b]),
                    float(actual[b]),
                    read,
                )
            )
    return out


def _print_table(name: str, table: dict, degree: int) -> None:
    print(
        f"\n{name} (degree {degree}): printed | |σ_η²−σ_p²| (Eq. 1) | var(η−p); "
        "r rounding, * misprint"
    )
    cells = table_cells(table, degree)
    for control in table:
        row = [c for c in cells if c.control == control]
        text = " ".join(
            ("  —  " if c.printed is None else f"{c.printed:5.2f}")
            + f"|{c.paper:5.3f}|{c.actual:5.3f}"
            + {"agrees": " ", "rounding": "r", "misprint": "*"}[c.kind]
            for c in row
        )
        print(f"  {'-'.join(map(str, control)):>10}: {text}")
    legible = sum(c.printed is not None for c in cells)
    kinds = [c.kind for c in cells if c.printed is not None]
    print(
        f"  {kinds.count('agrees')} of {legible} printed cells agree within half a unit (0.005), "
        f"{kinds.count('rounding')} more within {ROUNDING_LIMIT:.4f} (rounding, 'r'), "
        f"{kinds.count('misprint')} misprints ('*'):"
    )
    for c in cells:
        if c.read is not None:
            print(
                f"    {'-'.join(map(str, c.control))} point {c.point}: printed {c.printed:.3f} "
                f"read {c.read:.2f} (OCR), Eq. (1) {c.signed:+.4f}: {c.kind}"
            )
    for c in cells:
        if c.kind != "agrees":
            print(
                f"    {'-'.join(map(str, c.control))} point {c.point}: printed {c.value:.2f}, "
                f"Eq. (1) {c.signed:+.4f}, off {abs(c.value - c.paper):.4f}: {c.kind}; actual "
                f"residual {c.actual:.4f}"
            )


def _print_mean_square() -> None:
    print(
        "\nTable 1, m² = Σ(σ_Δ²)²/(N−3): printed | from reproduced entries rounded to 0.01 |"
        " unrounded | of the actual residual"
    )
    for control, printed in TABLE_1_MEAN_SQUARE.items():
        n_bases = control[-1] - 1
        base = np.array(control) - 1
        paper = np.abs(paper_residual_variance(n_bases, base, 2)) * PAPER_PER_BASE_VARIANCE
        actual = residual_variance(n_bases, base, 2) * PAPER_PER_BASE_VARIANCE
        rounded = mean_square(np.round(paper, 2), base)
        print(
            f"  {'-'.join(map(str, control)):>8}: {printed:.4f} | {rounded:.4f} | "
            f"{mean_square(paper, base):.5f} | {mean_square(actual, base):.6f}"
        )


def _print_recommendations() -> None:
    print("\nDegree-2 link lengths (first, second): printed | paper's criterion | actual residual")
    for n_bases, printed in RECOMMENDED_LINKS.items():
        paper = link_lengths(choose_control_spacing(n_bases, 2, criterion="paper"))
        actual = link_lengths(choose_control_spacing(n_bases, 2, criterion="residual"))
        print(f"  {n_bases:2d} bases: {printed} | {paper} | {actual}")
    print("Degree-3 links: paper's criterion | actual residual")
    for n_bases in (9, 12, 15, 18, 21):
        paper = link_lengths(choose_control_spacing(n_bases, 3, criterion="paper"))
        actual = link_lengths(choose_control_spacing(n_bases, 3, criterion="residual"))
        print(f"  {n_bases:2d} bases: {paper} | {actual}")


def _print_monte_carlo(trials: int, seed: int) -> None:
    print(
        f"\nMonte Carlo of actual strips ({trials} trials, seed {seed}), units σ_ε²:"
        " point: simulated ± SE | var(η−p) | Eq. (1)"
    )
    rng = np.random.default_rng(seed)
    for control, degree in (((1, 8, 16), 2), ((1, 10, 16), 2), ((1, 6, 11, 16), 3)):
        n_bases = control[-1] - 1
        base = np.array(control) - 1
        mean, se = simulate_residual_variance(n_bases, base, degree, trials, rng)
        actual = residual_variance(n_bases, base, degree)
        paper = paper_residual_variance(n_bases, base, degree)
        z = np.abs(mean - actual) / np.where(se > 0, se, 1.0)
        print(f"  {'-'.join(map(str, control))} (max |z| vs var(η−p) = {z.max():.2f}):")
        for b in range(0, n_bases + 1, 3):
            print(
                f"    {b + 1:2d}: {mean[b]:7.3f} ± {se[b]:.3f} | {actual[b]:7.3f} | "
                f"{paper[b]:+8.3f}"
            )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=200_000, help="Monte Carlo strips")
    parser.add_argument("--seed", type=int, default=29, help="Monte Carlo seed")
    args = parser.parse_args(argv)
    _print_table("Table 1", TABLE_1, 2)
    _print_mean_square()
    _print_table("Table 2", TABLE_2, 3)
    _print_recommendations()
    _print_monte_carlo(args.trials, args.seed)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
