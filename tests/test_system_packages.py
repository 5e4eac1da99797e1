"""The tests that install Debian packages install one at a time (a file lock shared by all test
processes) and let apt-get wait for dpkg's lock: two processes contending for an apt-get that
records when it runs never overlap, and every call carries DPkg::Lock::Timeout."""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from pathlib import Path

import pytest

import system_packages

HERE = Path(__file__).resolve().parent

FAKE_APT = """#!/bin/sh
# records its arguments, its start and its end
echo "start $$ $*" >> {log}
sleep 1.5
echo "end $$" >> {log}
exit 0
"""

CHILD = """
import sys
sys.path.insert(0, {here!r})
import system_packages
run = system_packages.apt_install(["chromium"], lock={lock!r})
sys.exit(run.returncode)
"""


def _contend(tmp_path, lock):
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    log = tmp_path / "apt.log"
    (bin_dir / "apt-get").write_text(FAKE_APT.format(log=log))
    (bin_dir / "apt-get").chmod(0o755)
    env = {**os.environ, "PATH": f"{bin_dir}{os.pathsep}{os.environ['PATH']}"}
    child = CHILD.format(here=str(HERE), lock=str(lock))
    procs = [subprocess.Popen([sys.executable, "-c", child], env=env) for _ in range(2)]
    assert [p.wait(timeout=60) for p in procs] == [0, 0]
    return log.read_text().splitlines()


def test_two_installing_processes_take_turns(tmp_path):
    lines = _contend(tmp_path, tmp_path / "apt.lock")
    # each run ends before the next starts: start, end, start, end
    assert [line.split()[0] for line in lines] == ["start", "end", "start", "end"]
    assert lines[0].split()[1] == lines[1].split()[1] and lines[2].split()[1] == lines[3].split()[1]
    for line in lines[::2]:
        assert line.split(None, 2)[2] == f"-o DPkg::Lock::Timeout={system_packages.DPKG_LOCK_TIMEOUT} install -y -q chromium"


def test_without_the_shared_lock_they_would_overlap(tmp_path):
    """The check above can fail: with a lock file per process the two runs overlap."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    log = tmp_path / "apt.log"
    (bin_dir / "apt-get").write_text(FAKE_APT.format(log=log))
    (bin_dir / "apt-get").chmod(0o755)
    env = {**os.environ, "PATH": f"{bin_dir}{os.pathsep}{os.environ['PATH']}"}
    procs = [subprocess.Popen([sys.executable, "-c", CHILD.format(here=str(HERE), lock=str(tmp_path / f"own{k}.lock"))],
                              env=env) for k in range(2)]
    assert [p.wait(timeout=60) for p in procs] == [0, 0]
    assert [line.split()[0] for line in log.read_text().splitlines()] == ["start", "start", "end", "end"]


def test_the_lock_is_one_file_in_the_system_temporary_folder():
    import tempfile

    assert system_packages.LOCK.parent == Path(tempfile.gettempdir())


def test_installing_tests_go_through_the_lock():
    """tests/test_docs.py installs chromium with system_packages.apt_install (no apt-get of its own);
    tests/test_slurm.py starts the cluster (which may install slurm and munge) under install_lock."""
    docs = (HERE / "test_docs.py").read_text(encoding="utf-8")
    assert '["apt-get"' not in docs and "apt_install([\"chromium\"])" in docs
    slurm = HERE / "test_slurm.py"
    assert any(isinstance(node, ast.With) and any(isinstance(item.context_expr, ast.Call)
                                                  and getattr(item.context_expr.func, "id", "") == "install_lock"
                                                  for item in node.items)
               and "'up'" in ast.unparse(node)
               for node in ast.walk(ast.parse(slurm.read_text(encoding="utf-8"))))


@pytest.mark.skipif(os.geteuid() != 0, reason="needs root to run a process as another user")
def test_another_users_lock_file_serves(tmp_path):
    """The lock file made by root (0644): a test process of another user (nobody) takes the lock
    instead of failing with PermissionError."""
    import pwd
    import shutil
    import tempfile

    folder = Path(tempfile.mkdtemp(prefix="msslib-lock-"))
    try:
        folder.chmod(0o755)
        lock = folder / "apt.lock"
        lock.write_text("")
        lock.chmod(0o644)
        nobody = pwd.getpwnam("nobody")
        # the module beside the lock: the tests' folder may lie where nobody may not enter
        shutil.copy(HERE / "system_packages.py", folder / "system_packages.py")
        (folder / "system_packages.py").chmod(0o644)
        child = (f"import sys; sys.path.insert(0, {str(folder)!r}); import system_packages\n"
                 f"with system_packages.install_lock({str(lock)!r}): print('held')")
        python = shutil.which("python3", path="/usr/bin:/bin")  # one that another user may run
        if python is None:
            pytest.skip("no system python3 in /usr/bin or /bin")
        r = subprocess.run([python, "-c", child], capture_output=True, text=True, timeout=60, cwd="/",
                           user=nobody.pw_uid, group=nobody.pw_gid, extra_groups=[],
                           env={**os.environ, "HOME": "/", "PYTHONDONTWRITEBYTECODE": "1"})
        assert r.returncode == 0 and r.stdout == "held\n", r.stderr[-500:]
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def test_a_lock_file_that_is_not_writable_still_locks(tmp_path):
    """A lock file left read-only (made by another user) is opened read-only: flock still holds."""
    import fcntl

    lock = tmp_path / "apt.lock"
    lock.write_text("")
    lock.chmod(0o444)
    with system_packages.install_lock(lock):
        with open(lock) as other:  # a second open file description: flock excludes it
            try:
                fcntl.flock(other, fcntl.LOCK_EX | fcntl.LOCK_NB)
                taken = True
            except BlockingIOError:
                taken = False
    assert not taken
    with open(lock) as other:  # released afterwards
        fcntl.flock(other, fcntl.LOCK_EX | fcntl.LOCK_NB)
