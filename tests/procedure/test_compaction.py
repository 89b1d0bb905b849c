"""Remedies and loops at array speed: a round run on the failing trials alone
(``procedure.compaction``) gives the masked round's values, and the chunks of a long run give
the same columns in worker processes as here."""

from __future__ import annotations

import numpy as np
import pytest

from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.procedure import compaction
from stereoplotter.procedure.simulate import prepare_run, run_trials_chunk
from stereoplotter.procedure.trials import iter_chunk_columns, split_chunk, trial_columns

#: Trials of the compared runs: above COMPACT_MIN_TRIALS, so that the rounds are compacted.
TRIALS = 96


@pytest.fixture(scope="module")
def pair():
    return load_scenario("scenarios/pair60.yaml"), load_instrument("sc1")


def _run(prep, monkeypatch, compact: bool):
    limit = compaction.COMPACT_MIN_TRIALS if compact else 10**9
    monkeypatch.setattr(compaction, "COMPACT_MIN_TRIALS", limit)
    result = run_trials_chunk(prep, 0, TRIALS)
    return trial_columns(result), result.transcript.to_text()


@pytest.mark.parametrize("method", ["setup", "conventional"])
def test_compacted_rounds_give_the_masked_values(pair, monkeypatch, method):
    """Every per-trial measure (checks, remedies with their rounds, iterations, zero readings,
    the true y-parallax, the evaluation) and trial 0's transcript as with masks alone. The
    arithmetic of a trial is the same elementwise arithmetic either way; rtol 1e-12 leaves the
    last bit to the elementary functions on arrays of other lengths (as test_trials)."""
    sc, spec = pair
    prep = prepare_run(sc, spec, method, seed=11)
    masked, masked_text = _run(prep, monkeypatch, compact=False)
    compact, compact_text = _run(prep, monkeypatch, compact=True)
    assert compact.keys() == masked.keys()
    applied = [k for k in masked if k.startswith("remedy/") and k.endswith("/applied")]
    assert applied and all(0 < masked[k].mean() < 1 for k in applied[:1])  # some failed
    for name, want in masked.items():
        np.testing.assert_allclose(compact[name], want, rtol=1e-12, atol=1e-15, err_msg=name)
    assert compact_text == masked_text


def test_scatter_puts_the_sub_run_back_and_broadcasts_a_common_value():
    index = np.array([1, 3])
    assert compaction.scatter(np.arange(5.0), np.array([10.0, 30.0]), index, 5).tolist() == [
        0.0,
        10.0,
        2.0,
        30.0,
        4.0,
    ]
    # a value common to all trials that the sub-run made per trial
    assert compaction.scatter(7.0, np.array([1.0, 2.0]), index, 5).tolist() == [
        7.0,
        1.0,
        7.0,
        2.0,
        7.0,
    ]


def test_chunks_in_worker_processes_give_the_columns_of_this_process(pair):
    sc, spec = pair
    prep = prepare_run(sc, spec, "setup", seed=2)
    here = list(iter_chunk_columns(prep, 12, 4, workers=1, evaluate=False))
    forked = list(iter_chunk_columns(prep, 12, 4, workers=2, evaluate=False))
    assert here[0][0] is not None and all(r is None for r, _ in here[1:] + forked[1:])
    for (_, a), (_, b) in zip(here, forked, strict=True):
        assert a.keys() == b.keys()
        for name in a:
            np.testing.assert_array_equal(a[name], b[name], err_msg=name)


def test_chunk_cut_gives_each_process_a_chunk():
    assert split_chunk(10_000, 8000, 2) == 5000
    assert split_chunk(100_000, 8000, 2) == 8000
    assert split_chunk(10_000, 8000, 1) == 8000
