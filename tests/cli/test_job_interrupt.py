"""A job's output folder is all old or all new: ``setup JOB --force`` interrupted by a signal
after each of its file writes, and inside the swap, leaves the previous complete run or the new
complete run (the operator's own file kept), no staging folder and no temporary file; a killed
run's leftovers are undone by the next run; Ctrl-C ends the command in one line."""

from __future__ import annotations

import hashlib
import os
import shutil
import signal
from pathlib import Path

import pytest

from stereoplotter.cli import main
from stereoplotter.commands.setup_job import compute_job
from stereoplotter.errors import raise_keyboard_interrupt
from stereoplotter.io import atomic_write, output_folder
from stereoplotter.io.job_file import load_job
from stereoplotter.io.output_folder import write_outputs
from stereoplotter.report.job import job_files, manifest_about

JOB = Path(__file__).resolve().parents[2] / "jobs" / "strip8" / "job.yaml"


@pytest.fixture(autouse=True)
def _no_fsync(monkeypatch):
    """Durability on a power cut is not what is tested here: no waiting for the disk."""
    monkeypatch.setattr(os, "fsync", lambda fd: None)


def _snapshot(folder: Path) -> dict[str, str]:
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}  # fmt: skip


def _hidden(top: Path) -> list[str]:
    """Staging folders, folders moved aside and temporary files anywhere under ``top``."""
    return [str(p) for p in top.rglob(".*")]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """The previous run (English, with the operator's notes) and the new run's files (Russian)."""
    result = compute_job(load_job(JOB))
    about = manifest_about(result)
    top = tmp_path_factory.mktemp("runs")
    old = top / "old"
    write_outputs(old, job_files(result, "en"), about)
    (old / "notes.txt").write_text("the operator's own notes\n")
    new_files = job_files(result, "ru")
    new = top / "new"
    shutil.copytree(old, new)
    write_outputs(new, new_files, about, force=True)
    return old, new, new_files, about


def _signal_after(monkeypatch, target, name: str, k: int, signum: int, before: bool = False):
    """Patch ``target.name`` to send ``signum`` to this process at its k-th call (before or
    after the call itself); returns the list of calls."""
    real = getattr(target, name)
    calls = []

    def patched(*args, **kwargs):
        calls.append(args[0])
        if before and len(calls) == k:
            os.kill(os.getpid(), signum)
        out = real(*args, **kwargs)
        if not before and len(calls) == k:
            os.kill(os.getpid(), signum)
        return out

    monkeypatch.setattr(target, name, patched)
    return calls


def test_an_interrupt_after_any_write_leaves_the_old_or_the_new_run(runs, tmp_path, monkeypatch):
    old, new, files, about = runs
    states = {"old": _snapshot(old), "new": _snapshot(new)}
    assert states["old"] != states["new"] and "notes.txt" in states["new"]
    previous = signal.signal(signal.SIGTERM, raise_keyboard_interrupt)
    seen = []
    try:
        k, writes = 1, len(files) + 1 + 1  # the files, the manifest, one past the last
        while k <= writes:
            work = tmp_path / f"w{k}"
            out = work / "out"
            shutil.copytree(old, out)
            with monkeypatch.context() as m:
                signum = signal.SIGINT if k % 2 else signal.SIGTERM
                calls = _signal_after(m, atomic_write, "atomic_write_bytes", k, signum)
                try:
                    write_outputs(out, files, about, force=True)
                    outcome = "finished"
                except KeyboardInterrupt:
                    outcome = "interrupted"
            state = [name for name, snap in states.items() if _snapshot(out) == snap]
            assert state, (k, outcome)
            assert _hidden(work) == [], k
            seen.append((k, len(calls), outcome, state[0]))
            k += 1
        for before in (True, False):  # a signal inside the swap waits for it: the new run
            out = tmp_path / f"swap{before}" / "out"
            shutil.copytree(old, out)
            with monkeypatch.context() as m:
                _signal_after(m, output_folder, "_exchange", 1, signal.SIGINT, before=before)
                with pytest.raises(KeyboardInterrupt):
                    write_outputs(out, files, about, force=True)
            assert _snapshot(out) == states["new"]
            assert _hidden(out.parent) == []
    finally:
        signal.signal(signal.SIGTERM, previous)
    interrupted = [s for s in seen if s[2] == "interrupted"]
    assert len(interrupted) == len(files) + 1  # after every file and after the manifest
    assert all(s[3] == "old" for s in interrupted)
    assert seen[-1][2:] == ("finished", "new")


def test_a_killed_runs_leftovers_are_undone_by_the_next_run(runs, tmp_path):
    old, new, files, about = runs
    out = tmp_path / "out"
    shutil.copytree(old, out)
    (tmp_path / ".out.staging-dead1").mkdir()  # killed while writing
    (tmp_path / ".out.staging-dead1" / ".sheet.pdf.0123.tmp").write_bytes(b"%PDF half")
    write_outputs(out, files, about, force=True)
    assert _snapshot(out) == _snapshot(new) and _hidden(tmp_path) == []
    os.rename(out, tmp_path / ".out.old-dead2")  # killed between the two renames of a swap
    with pytest.raises(Exception, match="new or empty"):
        write_outputs(out, files, about)  # the previous run is back first: refused as usual
    assert _snapshot(out) == _snapshot(new) and _hidden(tmp_path) == []


def test_ctrl_c_ends_the_command_in_one_line(runs, tmp_path, monkeypatch, capsys):
    old, _, _, _ = runs
    out = tmp_path / "out"
    shutil.copytree(old, out)
    _signal_after(monkeypatch, atomic_write, "atomic_write_bytes", 3, signal.SIGINT)
    code = main(["setup", str(JOB), "-o", str(out), "--force", "--lang", "ru"])
    err = capsys.readouterr().err
    assert code == 130 and err.count("\n") == 1 and err.startswith(f"error: {out}: interrupted")
    assert _snapshot(out) == _snapshot(old) and _hidden(tmp_path) == []
