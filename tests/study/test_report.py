"""`study report` on a Dataset whose ratios are set by hand: the validity counts and the files."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("xarray")

from stereoplotter import load_instrument, load_scenario
from stereoplotter.io.atomic_write import write_files
from stereoplotter.plotting.study_figures import study_figures
from stereoplotter.report.study import study_report_files, study_summary
from stereoplotter.study.design import Axis, StudyDesign
from stereoplotter.study.results import STATUS, empty_dataset

RATIOS = [0.97, 1.04, 1.08, 0.85, 1.00, 1.20]  # within 5 %: 0.97, 1.04, 1.00; 10 %: + 1.08


@pytest.fixture(scope="module")
def dataset():
    design = StudyDesign(
        name="hand",
        base=load_scenario("pair60"),
        instruments={"sc1": load_instrument("sc1")},
        axes=(
            Axis("f_mm", (70.0, 140.0)),
            Axis("overlap", (0.6, 0.7, 0.8)),
            Axis("method", ("setup",)),
        ),
        trials=10,
        chunk_trials=10,
        measures=("checks", "heights", "procedure", "budget"),
        seed=1,
        procedure_trials=10,
        budget_trials=10,
    )
    cells = design.cells()
    ds = empty_dataset(design, cells, ("stage 1: |L − L′|",), ("instrument.a", "operator.b"))
    ds["status"][:] = STATUS["done"]
    ds["ratio"].loc[{"row": "setup"}] = RATIOS
    ds["ratio_se"].loc[{"row": "setup"}] = 0.01
    ds["pass_rate"][:] = np.linspace(0.5, 1.0, 6)[:, None]
    ds["height_rms_permille"][:] = np.arange(1.0, 7.0)
    delta = np.zeros((6, 2, 3))
    delta[:4, 1, :] = 2.0  # operator.b dominates in the first four cells
    delta[4:, 0, :] = 3.0
    ds["budget_delta_ms"][:] = delta
    return ds


def test_summary_counts_the_cells_within_5_and_10_percent(dataset):
    v = study_summary(dataset)["validity"]["setup"]
    assert v["cells"] == 6
    assert v["within_5"] == pytest.approx(3 / 6)
    assert v["within_10"] == pytest.approx(4 / 6)
    assert (v["min"], v["max"]) == (0.85, 1.20)


def test_dominant_term_per_cell_from_the_one_at_a_time_runs(dataset):
    counts = study_summary(dataset)["dominant_terms"]["height_error_rms_permille"]
    assert counts == {"instrument.a": 2, "operator.b": 4}


def test_report_writes_the_figures_and_the_markdown(dataset, tmp_path):
    figures, note = study_figures(dataset)
    written = list(write_files(tmp_path, study_report_files(dataset, figures, note)).values())
    names = {p.name for p in written}
    assert {"ratio_maps.png", "pass_rates.png", "dominant_terms.png", "study.md"} <= names
    for p in written:
        if p.suffix == ".png":
            assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    text = (tmp_path / "study.md").read_text(encoding="utf-8")
    assert "| setup | (6.39)–(6.44) | 6 | 50% | 67% | 0.850 | 1.020 | 1.200 |" in text
    assert "stage 1: \\|L − L′\\|" in text  # the bars of a check name escaped in its table
