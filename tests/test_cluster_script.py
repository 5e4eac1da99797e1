"""profiles/slurm/cluster.sh without SLURM: its usage line for every wrong call, its checks of DIR
before anything is installed, apt-get waiting for dpkg's lock, and `down` signalling only the daemons
it started for DIR (a stale pid file naming a reused pid leaves that process alone)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
CLUSTER = ROOT / "profiles" / "slurm" / "cluster.sh"
USAGE = f"cluster.sh: error: usage: {CLUSTER} up [DIR] | down DIR"


def _fake_apt(folder: Path) -> tuple[Path, Path]:
    """A folder holding an apt-get that records its arguments and fails; returns (folder, record)."""
    bin_dir = folder / "fakebin"
    bin_dir.mkdir()
    record = folder / "apt-get.calls"
    apt = bin_dir / "apt-get"
    apt.write_text(f'#!/bin/sh\necho "$*" >> {record}\necho "E: no network here"\nexit 100\n')
    apt.chmod(0o755)
    return bin_dir, record


def _cluster(*args, path=None, timeout=60):
    env = dict(os.environ)
    if path is not None:
        env["PATH"] = path
    return subprocess.run(["bash", str(CLUSTER), *args], capture_output=True, text=True, timeout=timeout, env=env)


@pytest.mark.parametrize("args", [[], ["down"], ["down", ""], ["down", "a", "b"], ["up", "a", "b"], ["start"],
                                  ["up", "--help"], ["up", "-x"], ["down", "-h"],
                                  ["--help"]])
def test_every_wrong_call_prints_the_usage_line(args):
    r = _cluster(*args)
    assert r.returncode == 1 and r.stdout == "" and r.stderr.splitlines() == [USAGE], r.stderr


def test_up_checks_dir_before_it_installs_anything(tmp_path, request):
    bin_dir, record = _fake_apt(tmp_path)
    path = f"{bin_dir}{os.pathsep}/usr/bin{os.pathsep}/bin"
    a_file = tmp_path / "a file.txt"
    a_file.write_text("keep me")
    plain = tmp_path / "plain"
    plain.write_text("keep me too")
    held = tmp_path / "held"
    held.mkdir()
    (held / "slurm.conf").write_text("ClusterName=other\n")
    deep = tmp_path / ("x" * 100)
    # a short folder of mode 700 (mkdtemp's): under a long temporary path the length check, which
    # comes first, would answer instead
    locked = Path(tempfile.mkdtemp(prefix="lk", dir="/tmp"))
    request.addfinalizer(lambda: shutil.rmtree(locked, ignore_errors=True))
    for dir_, says in [(plain, f"DIR '{plain}' exists and is not a folder; give a folder to make or one without a cluster"),
                       (plain / "sub", f"DIR '{plain / 'sub'}' cannot be made: '{plain}' is not a folder"),
                       (held, f"{held} already holds a cluster (run: {CLUSTER} down {held})"),
                       (tmp_path / "two words", "contains white space, which slurm.conf cannot hold"),
                       (deep, "characters long; at most 94"),
                       (locked / "c", f"DIR '{locked / 'c'}' is inside '{locked}', which not every user may enter "
                                      "(mode 700); munged needs that for its socket")]:
        r = _cluster("up", str(dir_), path=path)
        lines = r.stderr.strip().splitlines()
        assert r.returncode == 1 and len(lines) == 1 and lines[0].startswith("cluster.sh: error: "), r.stderr
        assert says in lines[0], lines[0]
    env_tmp = {"TMPDIR": str(locked)}  # without DIR: the folder it would make in TMPDIR is checked too
    r = subprocess.run(["bash", str(CLUSTER), "up"], capture_output=True, text=True, timeout=60,
                       env={**os.environ, "PATH": path, **env_tmp})
    assert r.returncode == 1 and r.stderr.splitlines() == [
        f"cluster.sh: error: DIR '{locked}/slurm-cluster.XXXXXX' is inside '{locked}', which not every user may "
        f"enter (mode 700); munged needs that for its socket: choose another folder or chmod o+x '{locked}'"], r.stderr
    assert not any(locked.iterdir())
    assert not record.exists()  # apt-get never ran
    assert plain.read_text() == "keep me too" and a_file.read_text() == "keep me"
    assert not deep.exists() and not (tmp_path / "two words").exists() and not (locked / "c").exists()
    assert (held / "slurm.conf").read_text() == "ClusterName=other\n"


@pytest.mark.skipif(os.geteuid() != 0, reason="cluster.sh up installs only as root")
def test_up_installs_with_apt_get_waiting_for_the_dpkg_lock(tmp_path):
    """munged and the slurm daemons out of PATH: up asks apt-get, with DPkg::Lock::Timeout on every
    call, and stops in one line when it fails, having made no DIR."""
    bin_dir, record = _fake_apt(tmp_path)
    path = f"{bin_dir}{os.pathsep}/usr/bin{os.pathsep}/bin"
    if shutil.which("munged", path=path):
        pytest.skip("munged is on /usr/bin or /bin here")
    searchable = Path(tempfile.mkdtemp(prefix="msslib-cluster-"))  # (tmp_path's folders are 0700)
    searchable.chmod(0o755)
    new = searchable / "cluster"
    try:
        r = _cluster("up", str(new), path=path)
    finally:
        made = new.exists()
        shutil.rmtree(searchable)
    lines = r.stderr.strip().splitlines()
    assert r.returncode == 1 and lines == ["cluster.sh: error: apt-get could not install slurmctld slurmd "
                                           "slurm-client munge: E: no network here"], r.stderr
    calls = record.read_text().splitlines()
    assert [c.split()[2] for c in calls] == ["install", "update"]
    assert all(c.startswith("-o DPkg::Lock::Timeout=600 ") for c in calls), calls
    assert not made


def _start(argv, **kw):
    return subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, **kw)


def test_down_signals_only_the_daemons_it_started(tmp_path):
    """The pid files name: a process that is not a daemon at all (a pid reused after a reboot), a
    'slurmctld' of another folder, a file that is not a pid, and a 'munged' started for DIR. Only the
    last is stopped; each other pid file gets one note."""
    folder = tmp_path / "cluster"
    folder.mkdir()
    (folder / "munge.key").write_bytes(b"k" * 1024)
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    for name in ("munged", "slurmctld"):
        (bin_dir / name).symlink_to(sys.executable)
    sleep = "import time; time.sleep(120)"
    reused = _start([sys.executable, "-c", sleep])
    # another cluster's slurmctld, in a sub-folder of DIR: its command line names a path under DIR
    other = _start([str(bin_dir / "slurmctld"), "-c", sleep, "-f", str(folder / "inner" / "slurm.conf")])
    ours = _start([str(bin_dir / "munged"), "-c", sleep, f"--pid-file={folder}/munged.pid"])
    try:
        time.sleep(0.5)
        (folder / "slurmd.pid").write_text(f"{reused.pid}\n")
        (folder / "slurmctld.pid").write_text(f"{other.pid}\n")
        (folder / "munged.pid").write_text(f"{ours.pid}\n")
        r = _cluster("down", str(folder))
        assert r.returncode == 0, r.stderr
        assert ours.wait(timeout=20) is not None
        assert reused.poll() is None and other.poll() is None
        assert r.stderr.splitlines() == [
            f"cluster.sh: note: {folder}/slurmd.pid names pid {reused.pid}, not slurmd of {folder}; left alone",
            f"cluster.sh: note: {folder}/slurmctld.pid names pid {other.pid}, not slurmctld of {folder}; left alone"]
        (folder / "slurmd.pid").write_text("garbage; rm -rf /\n")
        r = _cluster("down", str(folder))
        assert r.returncode == 0 and reused.poll() is None and other.poll() is None
    finally:
        for proc in (reused, other, ours):
            if proc.poll() is None:
                proc.kill()
                proc.wait()


def test_down_refuses_a_folder_without_a_cluster(tmp_path):
    r = _cluster("down", str(tmp_path))
    assert r.returncode == 1 and r.stderr.splitlines() == [f"cluster.sh: error: {tmp_path} holds no cluster (no munge.key)"]
    r = _cluster("down", str(tmp_path / "none"))
    assert r.returncode == 1 and r.stderr.splitlines() == [
        f"cluster.sh: error: {tmp_path / 'none'} is not a folder (give the DIR that up printed)"]
