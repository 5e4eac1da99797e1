"""Debian packages installed by the tests (chromium for the rendered site, slurm and munge for the
cluster): one installation at a time, waiting for the package manager.

Two locks.  ``apt-get`` waits up to :data:`DPKG_LOCK_TIMEOUT` seconds for dpkg's own lock
(``-o DPkg::Lock::Timeout``) when something outside the tests holds it (an unattended upgrade);
and the tests that install take :func:`install_lock`, an exclusive ``flock`` on one file in the
system's temporary folder, so that the workers of ``pytest -n 2`` install one after the other
instead of the second failing with "Unable to acquire the dpkg frontend lock"."""

from __future__ import annotations

import contextlib
import fcntl
import os
import subprocess
import tempfile
from pathlib import Path

#: the file every installing test locks (shared by all test processes on the machine)
LOCK = Path(tempfile.gettempdir()) / "msslib-tests-apt-get.lock"
#: seconds apt-get waits for dpkg's lock held by another program
DPKG_LOCK_TIMEOUT = 600


@contextlib.contextmanager
def install_lock(path=None):
    """Hold the installing tests' lock (exclusive; blocks until no other test process holds it).  The
    file is opened read-only when it exists (flock needs no more), so a lock file made by another user
    in a sticky temporary folder (where O_CREAT on another's file is refused) still serves."""
    path = os.fspath(path or LOCK)
    try:
        fd = os.open(path, os.O_RDONLY)
    except FileNotFoundError:
        fd = os.open(path, os.O_RDONLY | os.O_CREAT, 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fd, fcntl.LOCK_UN)
    finally:
        os.close(fd)


def apt_get(*args) -> list[str]:
    """The command line of ``apt-get ARGS`` that waits for dpkg's lock."""
    return ["apt-get", "-o", f"DPkg::Lock::Timeout={DPKG_LOCK_TIMEOUT}", *args]


def apt_install(packages, *, timeout=900, lock=None) -> subprocess.CompletedProcess:
    """``apt-get install -y PACKAGES`` under the lock; after a failure, ``apt-get update`` and once
    more (a fresh machine's package lists may be missing or stale).  Returns the last run."""
    env = {**os.environ, "DEBIAN_FRONTEND": "noninteractive"}
    install = apt_get("install", "-y", "-q", *packages)
    with install_lock(lock):
        run = subprocess.run(install, capture_output=True, text=True, timeout=timeout, env=env)
        if run.returncode != 0:
            update = subprocess.run(apt_get("update", "-q"), capture_output=True, text=True, timeout=timeout, env=env)
            if update.returncode != 0:
                return update
            run = subprocess.run(install, capture_output=True, text=True, timeout=timeout, env=env)
    return run
