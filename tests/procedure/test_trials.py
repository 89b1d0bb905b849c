"""Long runs in chunks: chunk-size invariance, summary statistics, the per-trial file."""

from __future__ import annotations

import itertools
import json
import math
import zipfile
import zlib

import numpy as np
import pytest

from stereoplotter import random_streams
from stereoplotter.cli import main
from stereoplotter.io.instrument_file import load_instrument
from stereoplotter.io.scenario_file import load_scenario
from stereoplotter.io.trial_store import TrialStore
from stereoplotter.procedure.arrays import max_abs_last
from stereoplotter.procedure.simulate import prepare_run, simulate
from stereoplotter.procedure.trials import (
    chunk_trials_for,
    iter_chunk_columns,
    iter_trial_chunks,
    summarise_result,
    trial_columns,
)
from stereoplotter.random_streams import BLOCK, keyed_draws, keyed_standard_normal
from stereoplotter.statistics import scale_summary, summarise_flags, summarise_values


@pytest.fixture(scope="module")
def pair():
    return load_scenario("scenarios/pair60.yaml"), load_instrument("sc1")


def _normal(rng, n):
    return rng.standard_normal(n)


def test_keyed_streams_do_not_depend_on_the_cut():
    whole = keyed_draws(9, "k", 0, 2 * BLOCK + 10, _normal)
    cuts = [0, 3, BLOCK - 1, BLOCK + 5, 2 * BLOCK + 10]
    parts = [keyed_draws(9, "k", a, b, _normal) for a, b in itertools.pairwise(cuts)]
    assert np.array_equal(whole, np.concatenate(parts))
    # block 0 is the stream a run of ≤ BLOCK trials drew before chunking existed
    before = np.random.default_rng([9, zlib.crc32(b"k")]).standard_normal(50)
    assert np.array_equal(whole[:50], before)


def test_keyed_normals_go_on_from_where_a_range_stopped():
    """Consecutive ranges (the chunks of a run, which go on with a block's generator where the
    previous range left it), the same range twice and ranges out of order give the numbers of
    the block drawn whole, by ``Generator.standard_normal`` of a generator of their own."""
    whole = keyed_draws(11, "k/n", 0, 3 * BLOCK, _normal)
    cuts = [0, 1, 2, BLOCK + 7, 2 * BLOCK - 1, 2 * BLOCK + 100, 3 * BLOCK]
    ranges = list(itertools.pairwise(cuts))
    for order in (ranges, ranges[::-1], [*ranges, *ranges]):
        for a, b in order:
            assert np.array_equal(keyed_standard_normal(11, "k/n", a, b), whole[a:b]), (a, b)


def test_keyed_normals_of_known_keys_from_states_seeded_together():
    """The keys drawn before in this process have their blocks' generator states computed all
    at once for a new range (``random_streams.seeded_states``); their numbers, and those of a
    block going on from a kept state, are those of the block drawn whole by a generator of its
    own."""
    keys = [f"k/together/{i}" for i in range(5)]
    whole = {k: keyed_draws(2**32 - 1, k, 0, 3 * BLOCK, _normal) for k in keys}
    cuts = [0, 5, BLOCK + 7, 2 * BLOCK + 100, 2 * BLOCK + 101, 3 * BLOCK]
    for a, b in itertools.pairwise(cuts):
        for k in keys:
            got = keyed_standard_normal(2**32 - 1, k, a, b)
            assert np.array_equal(got, whole[k][a:b]), (k, a, b)


def test_largest_absolute_value_of_rows_by_columns_is_numpys():
    rng = np.random.default_rng(5)
    for n in (1, 2, 6, 16, 17, 81):
        v = rng.normal(size=(300, n))
        v[rng.random(v.shape) < 0.05] = -0.0
        v[rng.random(v.shape) < 0.05] = 0.0
        v[rng.random(v.shape) < 0.01] = np.nan
        v[7] = -0.0  # a row of zeros of either sign
        got, want = max_abs_last(v), np.max(np.abs(v), axis=-1)
        np.testing.assert_array_equal(got, want, err_msg=str(n))
        assert not np.signbit(got).any()


def test_block_states_seeded_together_are_numpys():
    rng = np.random.default_rng(4)
    codes = rng.integers(0, 2**32, 200).astype(np.uint32)
    blocks = rng.integers(0, 60, 200).astype(np.uint32)
    blocks[:20] = 0
    for seed in (0, 1, 2**32 - 1):
        got = random_streams.seeded_states(seed, codes, blocks)
        for c, b, state in zip(codes.tolist(), blocks.tolist(), got, strict=True):
            entropy = [seed, c] if b == 0 else [seed, c, b]
            want = np.random.default_rng(entropy).bit_generator.state["state"]
            assert state == (want["state"], want["inc"]), (seed, c, b)


@pytest.mark.parametrize("method", ["setup", "conventional"])
def test_chunked_run_equals_one_vectorised_run(pair, method):
    """Trials 0…11 in chunks of 5 give the values of one run of 12 (rtol 1e-10: the
    elementary functions may round the last bit differently for arrays of other lengths, and
    the procedure's iterations and least-squares fits carry that on: 4.3e-12 measured in
    ``height_error_after_plane_max_m``, seed 4, once b_x and the decentrations drew 0.01 mm
    zero errors; far below any printed figure)."""
    sc, spec = pair
    one = trial_columns(simulate(sc, spec, method, seed=4, trials=12))
    prep = prepare_run(sc, spec, method, seed=4)
    chunks = [trial_columns(r) for r in iter_trial_chunks(prep, 12, 5)]
    assert [len(next(iter(c.values()))) for c in chunks] == [5, 5, 2]
    for name, want in one.items():
        got = np.concatenate([c[name] for c in chunks])
        np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-15, err_msg=name)


def test_single_run_is_trial_zero_of_a_vectorised_run(pair):
    sc, spec = pair
    single = simulate(sc, spec, seed=6, evaluate=False)
    many = simulate(sc, spec, seed=6, trials=3, evaluate=False)
    for name, c in single.checks.items():
        assert float(c.residual) == pytest.approx(float(many.checks[name].residual[0]))


def test_chunk_size_follows_the_memory_budget():
    assert chunk_trials_for(256, "setup") == 8000
    assert chunk_trials_for(512, "conventional") == 24576  # 25 600 cut to whole keyed blocks
    assert chunk_trials_for(256, "conventional") == 12288
    assert chunk_trials_for(150, "conventional") == 7500  # under two blocks: not cut
    assert chunk_trials_for(1, "setup") == 256  # the smallest useful chunk
    with pytest.raises(ValueError):
        chunk_trials_for(0, "setup")


def test_mean_and_rms_standard_errors_match_their_spread():
    """Over 400 independent samples of 500 normal values, the reported SEs equal the observed
    spread of the estimates (within the ±10 % that 400 repetitions allow), and the 95 % quantile
    intervals cover the true median in 95 % ± 3.3 % (3 binomial σ) of the samples."""
    rng = np.random.default_rng(2024)
    sums = [summarise_values(rng.normal(1.0, 2.0, 500)) for _ in range(400)]
    means = np.array([s["mean"] for s in sums])
    rmss = np.array([s["rms"] for s in sums])
    assert np.mean([s["mean_se"] for s in sums]) == pytest.approx(np.std(means), rel=0.10)
    assert np.mean([s["rms_se"] for s in sums]) == pytest.approx(np.std(rmss), rel=0.10)
    assert np.mean(means) == pytest.approx(1.0, abs=3 * 2.0 / math.sqrt(500 * 400))
    covered = [lo <= 1.0 <= hi for lo, hi in (s["quantiles"]["p50"]["ci95"] for s in sums)]
    assert np.mean(covered) == pytest.approx(0.95, abs=3 * math.sqrt(0.95 * 0.05 / 400))


@pytest.mark.parametrize("n", [2, 3, 19, 20, 21, 400, 4001])
def test_quantiles_are_the_order_statistics_of_the_sorted_values(n):
    """Each quantile and its interval as from the whole sample sorted (``np.quantile`` on it,
    ranks k = T·p ± 1.96·√(T·p(1−p))), also with ties."""
    rng = np.random.default_rng(n)
    for x in (rng.exponential(size=n), rng.integers(0, 4, size=n).astype(float)):
        if np.all(x == x[0]):
            continue
        s = np.sort(x)
        got = summarise_values(x)["quantiles"]
        for p in (0.05, 0.5, 0.95):
            q = got[f"p{round(100 * p):02d}"]
            assert q["value"] == np.quantile(s, p)
            lo = math.floor(n * p - 1.959963984540054 * math.sqrt(n * p * (1 - p)))
            hi = math.ceil(n * p + 1.959963984540054 * math.sqrt(n * p * (1 - p)))
            if 0 <= lo and hi <= n - 1:
                assert q["ci95"] == [s[lo], s[hi]]
            else:
                assert q["ci95"] is None


def test_pass_rate_and_unit_change():
    assert summarise_flags([True] * 3 + [False])["rate"] == 0.75
    s = summarise_values([1.0, 2.0, np.nan, 4.0])
    assert s["n"] == 3 and s["not_finite"] == 1
    assert s["mean"] == pytest.approx(7.0 / 3.0)
    scaled = scale_summary(s, 1000.0)
    assert scaled["mean"] == pytest.approx(7000.0 / 3.0)
    assert scaled["quantiles"]["p50"]["value"] == pytest.approx(2000.0)
    assert summarise_values([0.5, 0.5]) == {"n": 2, "constant": 0.5}


def test_summary_of_a_run_holds_statistics_not_trial_arrays(pair):
    sc, spec = pair
    s = summarise_result(simulate(sc, spec, seed=2, trials=40))
    rate = s["checks"]["stage 5: corner 4"]["pass_rate"]
    assert rate["n"] == 40 and 0.0 <= rate["rate"] <= 1.0
    text = json.dumps(s)

    def longest_list(node):
        if isinstance(node, dict):
            return max((longest_list(v) for v in node.values()), default=0)
        if isinstance(node, list):
            return max([len(node), *(longest_list(v) for v in node)])
        return 0

    assert longest_list(s) <= 2  # only the [lo, hi] of a quantile interval
    assert "height_error_rms_permille" in s["evaluation"]["control"]
    assert len(text) < 100_000


def test_trial_store_round_trip_and_npz(tmp_path):
    rng = np.random.default_rng(1)
    chunks = [
        {"a/x": rng.normal(size=n), "b/passed": rng.random(n) < 0.5} for n in (4, 7, 1)
    ]
    with TrialStore() as store:
        for c in chunks:
            store.append(c)
        store.write_npz(tmp_path / "trials.npz")
        assert store.trials == 12
    with np.load(tmp_path / "trials.npz") as npz:
        assert sorted(npz.files) == ["a/x", "b/passed"]
        np.testing.assert_array_equal(npz["a/x"], np.concatenate([c["a/x"] for c in chunks]))
        assert npz["b/passed"].dtype == bool


def test_interrupted_npz_leaves_no_file(tmp_path):
    with TrialStore() as store:
        store.append({"x": np.arange(3.0), "y": np.arange(3.0)})
        (store.folder / "column0001.bin").unlink()  # the failure comes mid-file
        with pytest.raises(FileNotFoundError):
            store.write_npz(tmp_path / "trials.npz")
    assert list(tmp_path.iterdir()) == []


def test_many_chunks_on_workers_give_the_columns_of_one_process():
    sc = load_scenario("pair60")
    prep = prepare_run(sc, load_instrument("sc1"), "setup", seed=3)
    one = list(iter_chunk_columns(prep, 27, 3, workers=1, evaluate=False))
    two = list(iter_chunk_columns(prep, 27, 3, workers=2, evaluate=False))
    assert len(one) == len(two) == 9
    for (_, a), (_, b) in zip(one, two, strict=True):
        for name in a:
            np.testing.assert_array_equal(a[name], b[name], err_msg=name)


def test_cli_simulate_trials_writes_summary_and_columns(tmp_path, capsys):
    out = tmp_path / "run"
    code = main(
        ["simulate", "pair60", "--instrument", "sc1", "--trials", "30", "--json", "-o", str(out)]
    )
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["trials"] == 30 and summary["chunks"] == {"trials": 8000, "count": 1}
    with zipfile.ZipFile(out / "trials.npz") as z:
        assert "check/stage 1: |L − L′|/residual.npy" in z.namelist()
    with np.load(out / "trials.npz") as npz:
        assert npz["residual_y_parallax/grid_rms_um"].shape == (30,)
        # the summary is the statistics of the written columns
        rms = npz["evaluation/control/height_error_rms_m"]
    got = summary["evaluation"]["control"]["height_error_rms_m"]["mean"]
    assert got == pytest.approx(float(np.mean(rms)), rel=1e-12)
