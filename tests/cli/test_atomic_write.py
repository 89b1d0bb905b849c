"""Output files: whole or not at all, and with the mode the user's umask gives (0644 under 022)."""

from __future__ import annotations

import os
import stat
from contextlib import contextmanager

import pytest

from stereoplotter.cli import main
from stereoplotter.io import atomic_write as yamlio


@contextmanager
def umask(mask: int):
    old = os.umask(mask)
    try:
        yield
    finally:
        os.umask(old)


def mode(path) -> int:
    return stat.S_IMODE(os.stat(path).st_mode)


@pytest.mark.parametrize(("mask", "expected"), [(0o022, 0o644), (0o077, 0o600), (0o002, 0o664)])
def test_files_get_the_mode_of_the_umask(tmp_path, mask, expected):
    with umask(mask):
        yamlio.atomic_write_text(tmp_path / "new.txt", "a")
        (tmp_path / "old.txt").write_text("x", encoding="utf-8")
        os.chmod(tmp_path / "old.txt", 0o600)
        yamlio.atomic_write_text(tmp_path / "old.txt", "b")  # a replaced file too
    assert mode(tmp_path / "new.txt") == expected
    assert mode(tmp_path / "old.txt") == expected
    assert sorted(p.name for p in tmp_path.iterdir()) == ["new.txt", "old.txt"]


def test_setup_sheet_files_are_0644_under_umask_022(tmp_path, capsys):
    """The report: every output came out -rw------- (the mode of tempfile.mkstemp)."""
    with umask(0o022):
        assert main(["setup", "pair60", "--instrument", "sc1", "-o", str(tmp_path)]) == 0
    capsys.readouterr()
    modes = {p.name: mode(p) for p in tmp_path.iterdir()}
    assert modes == dict.fromkeys(["sheet.yaml", "sheet.md", "sheet.pdf", "sheet.png"], 0o644)


@pytest.mark.parametrize("interruption", [KeyboardInterrupt, OSError])
def test_interrupted_write_leaves_no_file_under_the_final_name(tmp_path, interruption):
    with pytest.raises(interruption, match="mid-write"):
        with yamlio.atomic_stream(tmp_path / "sheet.pdf") as f:
            f.write(b"%PDF" + b"x" * 10)
            f.flush()  # part of the file is on disk under the temporary name
            assert len(list(tmp_path.iterdir())) == 1
            raise interruption("interrupted mid-write")
    assert list(tmp_path.iterdir()) == []  # neither the final name nor the temporary file


def test_interrupted_write_keeps_the_previous_file(tmp_path, monkeypatch):
    target = tmp_path / "sheet.yaml"
    yamlio.atomic_write_text(target, "old: 1\n")

    def interrupted_fsync(fd):
        raise KeyboardInterrupt

    monkeypatch.setattr(yamlio.os, "fsync", interrupted_fsync)
    with pytest.raises(KeyboardInterrupt):
        yamlio.atomic_write_text(target, "new: 2\n")
    assert target.read_text(encoding="utf-8") == "old: 1\n"
    assert [p.name for p in tmp_path.iterdir()] == ["sheet.yaml"]


def test_a_temporary_file_of_someone_else_is_not_touched(tmp_path, monkeypatch):
    """The temporary name is taken with O_EXCL: a clash tries another name."""
    names = iter(["aaaaaaaaaaaa", "aaaaaaaaaaaa", "bbbbbbbbbbbb"])
    monkeypatch.setattr(yamlio.secrets, "token_hex", lambda n: next(names))
    (tmp_path / ".out.txt.aaaaaaaaaaaa.tmp").write_text("theirs", encoding="utf-8")
    yamlio.atomic_write_text(tmp_path / "out.txt", "mine")
    assert (tmp_path / ".out.txt.aaaaaaaaaaaa.tmp").read_text(encoding="utf-8") == "theirs"
    assert (tmp_path / "out.txt").read_text(encoding="utf-8") == "mine"
