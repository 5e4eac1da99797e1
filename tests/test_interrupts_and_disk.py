"""Staged outputs (msslib.results.staging) under interrupts and on a full disk: an interrupt landing at
any point of a write leaves no temporary file and the outputs all old or all new; a full disk is
said to be one (``no space left on device``, one ``msslib: error:`` line naming the output), also
when the NetCDF library reports it as ``NetCDF: HDF error``."""

from __future__ import annotations

import errno
import os
import signal
import sys
from collections import namedtuple
from pathlib import Path

import pytest
import xarray as xr
import yaml

from msslib import cli
from msslib.results import staging
from msslib.results import StagedOutputs
from scene_helpers import pulled_sheet

OLD, NEW_KEPT, NEW_FRESH = "the user's file\n", "new content of kept.txt\n", "new content of fresh.txt\n"


def _write_two(directory: Path) -> None:
    with StagedOutputs() as out:
        out.write_text(directory / "kept.txt", NEW_KEPT)
        out.write_text(directory / "fresh.txt", NEW_FRESH)


def _state(directory: Path) -> dict:
    return {name: (directory / name).read_text() for name in sorted(os.listdir(directory))}


ALL_OLD = {"kept.txt": OLD}
ALL_NEW = {"fresh.txt": NEW_FRESH, "kept.txt": NEW_KEPT}


def _settle():
    """A few calls: a pending signal handler runs here at the latest."""
    for _ in range(3):
        sorted([3, 2, 1])


def _interrupted_at(n: int, action) -> tuple[bool, int]:
    """Run ``action`` with SIGINT sent to this process at the ``n``-th line run in
    msslib/results/staging.py; returns (interrupted, lines run there)."""
    count = 0
    source = staging.__file__

    def local(frame, event, arg):
        nonlocal count
        if event == "line":
            count += 1
            if count == n:
                os.kill(os.getpid(), signal.SIGINT)
        return local

    def calls(frame, event, arg):
        return local if frame.f_code.co_filename == source else None

    try:
        sys.settrace(calls)
        try:
            action()
        finally:
            sys.settrace(None)
        _settle()
    except KeyboardInterrupt:
        return True, count
    return False, count


@pytest.mark.skipif(not hasattr(signal, "SIGINT") or sys.gettrace() is not None, reason="needs SIGINT and no tracer")
def test_sigint_at_every_line_of_a_staged_write_leaves_nothing_behind(tmp_path):
    # Python's own handler (a process started in the background by a shell inherits SIGINT ignored)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        _sigint_at_every_line(tmp_path)
    finally:
        signal.signal(signal.SIGINT, previous)


def _sigint_at_every_line(tmp_path):
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    outcomes = set()
    n = 0
    while True:
        n += 1
        directory = tmp_path / f"try{n}"
        directory.mkdir()
        (directory / "kept.txt").write_text(OLD)
        interrupted, lines = _interrupted_at(n, lambda: _write_two(directory))
        state = _state(directory)  # every temporary file and backup would show here
        assert state in (ALL_OLD, ALL_NEW), (n, state)
        if n > lines:  # the signal came after the write: it ran through
            assert not interrupted and state == ALL_NEW
            break
        assert interrupted, n  # an interrupt is held for a moment at most, never lost
        outcomes.add("old" if state == ALL_OLD else "new")
        assert n < 5000
    assert n > 50 and outcomes == {"old", "new"}  # both ends were reached: interrupted before and after the commit
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def _raises_after(monkeypatch, name: str, exc: type[BaseException]):
    """``os.NAME`` does its work, then raises ``exc`` (an interrupt landing just after it)."""
    real = getattr(os, name)

    def call(*args, **kwargs):
        result = real(*args, **kwargs)
        if name == "open":
            os.close(result)
        raise exc()

    monkeypatch.setattr(os, name, call)


@pytest.mark.parametrize("name", ["open", "link", "replace"])
def test_interrupt_just_after_creating_a_temporary_file(tmp_path, monkeypatch, name):
    (tmp_path / "kept.txt").write_text(OLD)
    _raises_after(monkeypatch, name, KeyboardInterrupt)
    with pytest.raises(KeyboardInterrupt):
        _write_two(tmp_path)
    monkeypatch.undo()
    assert _state(tmp_path) == ALL_OLD  # no temporary file, no backup, the user's file as it was


def test_stale_temporaries_of_dead_runs_are_removed_once_per_directory(tmp_path, monkeypatch):
    dead = 2**22 + 12345  # above the usual pid_max of 4194304: no such process
    for name in ("a.txt", "b.txt"):
        (tmp_path / f".{name}.{staging.TEMP_TAG}-{dead}-0123abcd").write_text("left by a killed run\n")
    (tmp_path / f".c.txt.{staging.TEMP_TAG}-{os.getpid()}-0123abcd").write_text("ours, alive\n")
    listings = []
    real = os.listdir
    monkeypatch.setattr(os, "listdir", lambda d=".": listings.append(d) or real(d))
    with StagedOutputs() as out:
        for name in ("a.txt", "b.txt"):
            out.write_text(tmp_path / name, name)
    monkeypatch.undo()
    assert len(listings) == 1
    assert sorted(os.listdir(tmp_path)) == [f".c.txt.{staging.TEMP_TAG}-{os.getpid()}-0123abcd", "a.txt", "b.txt"]


# ---- a full disk ------------------------------------------------------------------------------

StatVfs = namedtuple("StatVfs", "f_bsize f_frsize f_blocks f_bfree f_bavail f_files f_ffree f_favail f_flag f_namemax")


def _statvfs(free_blocks: int):
    return lambda path: StatVfs(4096, 4096, 1000, free_blocks, free_blocks, 100, 10, 10, 0, 255)


def _hdf_error(monkeypatch):
    """The NetCDF writer writes part of the file, then fails as netCDF4 does when the disk fills."""
    def to_netcdf(self, path, *args, **kwargs):
        Path(path).write_bytes(b"\x89HDF\r\n\x1a\n" + bytes(4096))
        raise RuntimeError("NetCDF: HDF error")

    monkeypatch.setattr(xr.Dataset, "to_netcdf", to_netcdf)


SCENE = pulled_sheet()


def _run(capsys, tmp_path):
    code = cli.main(["run", str(tmp_path / "sheet.yaml"), "--out", str(tmp_path / "out.nc"), "--quiet"])
    return code, capsys.readouterr().err


def test_full_disk_is_said_in_one_line_naming_the_output(tmp_path, capsys, monkeypatch):
    (tmp_path / "sheet.yaml").write_text(yaml.safe_dump(SCENE))
    (tmp_path / "out.nc").write_text("an older result\n")
    _hdf_error(monkeypatch)
    monkeypatch.setattr(os, "statvfs", _statvfs(0))
    code, err = _run(capsys, tmp_path)
    lines = err.splitlines()
    assert code == 1 and len(lines) == 1 and lines[0].startswith("msslib: error:"), err
    assert "no space left on device" in lines[0] and "out.nc" in lines[0], err
    assert "msslib-tmp" not in err
    monkeypatch.undo()
    assert _state(tmp_path) == {"out.nc": "an older result\n", "sheet.yaml": yaml.safe_dump(SCENE)}


def test_hdf_error_with_space_left_is_not_called_a_full_disk(tmp_path, capsys, monkeypatch):
    (tmp_path / "sheet.yaml").write_text(yaml.safe_dump(SCENE))
    _hdf_error(monkeypatch)
    monkeypatch.setattr(os, "statvfs", _statvfs(10**6))  # 4 GB free
    code, err = _run(capsys, tmp_path)
    lines = err.splitlines()
    assert code == 1 and len(lines) == 1 and "NetCDF: HDF error" in lines[0] and "out.nc" in lines[0], err
    assert "no space" not in err.lower()
    monkeypatch.undo()
    assert sorted(os.listdir(tmp_path)) == ["sheet.yaml"]


def test_enospc_from_a_writer_is_said_as_it_is(tmp_path):
    def full(tmp):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(tmp))

    with pytest.raises(OSError, match="No space left on device") as info:
        with StagedOutputs() as out:
            out.write(tmp_path / "big.vtu", full, what="VTU file")
    assert info.value.errno == errno.ENOSPC and info.value.filename == str(tmp_path / "big.vtu")
    assert os.listdir(tmp_path) == []
