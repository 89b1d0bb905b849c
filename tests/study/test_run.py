"""`study run` on a reduced grid of the shipped formula-validity study: the Dataset of 2 Dask
workers (one of them killed mid-run; or forked by the embedded cluster) is identical to the
serial run, bit for bit, and so is a run resumed after its process was killed."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

pytest.importorskip("distributed")
xr = pytest.importorskip("xarray")
zarr = pytest.importorskip("zarr")

from stereoplotter.commands.study import run_into_store  # noqa: E402
from stereoplotter.errors import StereoplotterError  # noqa: E402
from stereoplotter.io.study_store import open_results  # noqa: E402

SHIPPED = Path(__file__).parents[2] / "studies" / "formula-validity.yaml"


def reduced_study(cells_f=(70.0, 140.0), trials=32) -> dict:
    """The shipped formula-validity study on a grid of two cells (f = 70, 140 mm at 60 %),
    SC-1, setup data, two chunks of 16 trials and the procedure MC per cell: every kind of task
    and measure of the full study, in seconds (a chunk costs ≈ 1 s whatever its size)."""
    data = yaml.safe_load(SHIPPED.read_text(encoding="utf-8"))
    data["axes"] = {
        "f_mm": list(cells_f),
        "overlap": [0.6],
        "instrument": ["sc1"],
        "method": ["setup"],
    }
    data.update(trials=trials, chunk_trials=16, procedure_trials=12)
    return data


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    out = tmp_path_factory.mktemp("study") / "serial.zarr"
    run_into_store(reduced_study(), "reduced", str(out))
    return open_results(out)


def assert_same_bits(a: xr.Dataset, b: xr.Dataset) -> None:
    assert a.identical(b)
    for name in a.data_vars:  # identical() compares NaN as equal; floats bit for bit too
        x, y = a[name].values, b[name].values
        if x.dtype.kind == "f":
            assert np.array_equal(x.view(np.int64), y.view(np.int64)), name


def test_serial_run_fills_every_cell_with_finite_measures(serial):
    assert (serial.status.values == 1).all()
    assert np.isfinite(serial.y_parallax_rms_um.values).all()
    assert np.isfinite(serial.ratio.sel(row="setup").values).all()
    assert serial.sizes["cell"] == 2


def test_two_workers_one_killed_give_the_serial_dataset(serial, tmp_path):
    # imported here: the extra `study`, present once the module's importorskip has passed
    from distributed import Client, LocalCluster

    cluster = LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    )
    client = Client(cluster)
    killed = []

    def kill_one_worker(n):
        if not killed:  # after the first task: kill a worker process; the nanny restarts it
            pids = client.run(os.getpid)
            pid = next(iter(pids.values()))
            os.kill(pid, signal.SIGKILL)
            killed.append(pid)

    try:
        out = tmp_path / "two.zarr"
        run_into_store(reduced_study(), "reduced", str(out), client, progress=kill_one_worker)
    finally:
        client.close()
        cluster.close()
    assert killed
    assert_same_bits(open_results(out), serial)


def _done(store: Path) -> int:
    try:
        return int((np.asarray(zarr.open_group(str(store), mode="r")["status"][:]) != 0).sum())
    except Exception:  # not created yet
        return 0


def test_run_killed_then_resumed_gives_the_serial_dataset(serial, tmp_path):
    study = tmp_path / "reduced.yaml"
    study.write_text(yaml.safe_dump(reduced_study(), allow_unicode=True), encoding="utf-8")
    out = tmp_path / "resumed.zarr"
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).parents[2])}
    cmd = [
        sys.executable,
        "-m",
        "stereoplotter",
        "study",
        "run",
        str(study),
        "-o",
        str(out),
        "--workers",
        "0",
    ]
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while _done(out) < 1 and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    first = _done(out)
    assert 1 <= first < 2, "killed too late: the run had finished"
    data = yaml.safe_load(study.read_text(encoding="utf-8"))
    cells, ran = run_into_store(data, str(study), str(out))
    assert ran == cells - first
    assert_same_bits(open_results(out), serial)


def test_a_store_of_another_study_is_refused(serial, tmp_path):
    out = tmp_path / "s.zarr"
    first = {**reduced_study(cells_f=(70.0,), trials=2), "measures": ["y_parallax"]}
    run_into_store(first, "a", str(out))
    with pytest.raises(StereoplotterError, match="another study"):
        run_into_store({**first, "trials": 3}, "b", str(out))


def _has_pytest() -> bool:
    return "_pytest" in sys.modules


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="workers are forked on Linux")
def test_embedded_cluster_forks_its_workers_and_gives_the_serial_dataset(serial, tmp_path):
    from stereoplotter.study.runner import start_local_client, started_client

    started = start_local_client(2, dashboard=False)
    client = started_client(started)
    assert client is not None
    try:
        # forked from this process: a worker holds what only this process imported
        assert list(client.run(_has_pytest).values()) == [True, True]
        out = tmp_path / "forked.zarr"
        run_into_store(reduced_study(), "reduced", str(out), started)
    finally:
        cluster = client.cluster
        client.close()
        cluster.close()
    assert_same_bits(open_results(out), serial)


def _fork_and_reap() -> None:
    pid = os.fork()
    if pid == 0:
        os._exit(0)
    os.waitpid(pid, 0)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="workers are forked on Linux")
def test_the_study_is_prepared_only_once_the_workers_are_forked():
    # start_local_client waits for the cluster's forks (made by other threads), not its own
    import threading

    from stereoplotter.study.runner import ForkCounter

    forks = ForkCounter(2)
    _fork_and_reap()  # this thread's fork: not one of the cluster's
    assert not forks.done.is_set()
    for seen in (1, 2):
        thread = threading.Thread(target=_fork_and_reap)
        thread.start()
        thread.join()
        assert forks.seen == seen
    assert forks.done.is_set()
    _fork_and_reap()  # counted no more once done
    assert forks.seen == 2


class _UnusedClient:
    """A Dask client that fails the test if the study hands it any work."""

    def __getattr__(self, name):
        raise AssertionError(f"client.{name} used")


def test_a_store_that_cannot_be_written_fails_before_any_task_is_submitted(tmp_path):
    blocker = tmp_path / "a-file"
    blocker.write_text("", encoding="utf-8")
    with pytest.raises(NotADirectoryError):
        run_into_store(reduced_study(), "reduced", str(blocker / "out.zarr"), _UnusedClient())
