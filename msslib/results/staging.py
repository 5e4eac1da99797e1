"""Staged outputs: files written to hidden temporaries and committed together.

:class:`StagedOutputs` writes several files as one (all are replaced, or none is): each is written
to a hidden temporary file beside its target, flushed to disk and renamed over it only when every
file was written; on any error, on SIGINT and on SIGTERM the temporaries are removed and the targets
are left as they were (an interrupt landing anywhere, even between creating a temporary file and
registering it, leaves nothing behind: the few steps that create, rename or remove files run with
the signals held for that moment).  A write that fails on a full disk says ``no space left on
device``, also when the writer's library says otherwise (NetCDF's ``HDF error``).
:func:`msslib.results.netcdf.stage_result` stages a NetCDF result in it; every write of msslib goes
through that class.  Staging and committing take a time linear in the number of files.
"""

from __future__ import annotations

import errno
import os
import re
import secrets
import signal
import threading
import weakref
from contextlib import contextmanager
from pathlib import Path

__all__ = ["TEMP_TAG", "StagedOutputs", "Terminated", "abandon_staged", "terminate_raises",
           "remove_stale_temporaries"]


def _to_text(text: str):
    def write(tmp: Path) -> None:
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)
    return write

# --------------------------------------------------------------------------------------------------
# staged outputs: temporary files committed together


#: marks the temporary files of msslib: ``.NAME.msslib-tmp-PID-RANDOM`` beside the target ``NAME``
#: (``msslib-bak`` for the copy of a replaced file kept while several files are committed)
TEMP_TAG = "msslib-tmp"
_BACKUP_TAG = "msslib-bak"


class Terminated(KeyboardInterrupt):
    """Raised by the SIGTERM handler of :func:`terminate_raises` (and of :class:`StagedOutputs`).

    A :class:`KeyboardInterrupt`, so that code which lets an interrupt pass (solvers catching
    ``Exception``) lets a termination pass too, and ``finally`` blocks remove temporary files."""


def _raise_terminated(signum, frame):
    raise Terminated(f"terminated by signal {signum}")


def _in_main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


@contextmanager
def terminate_raises():
    """Within the block, SIGTERM raises :class:`Terminated` in the main thread (as SIGINT raises
    :class:`KeyboardInterrupt`), so that ``finally`` blocks run and temporary files are removed;
    the previous handler is restored afterwards. Outside the main thread it does nothing."""
    if not _in_main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


@contextmanager
def _interrupts_held():
    """Within the block, SIGINT and SIGTERM are held and take effect when it ends (the previous
    handlers are restored and the signals sent again): a file created in the block and registered
    for removal in the same block cannot be left behind by an interrupt landing in between.  The
    blocks are short (a file created, renamed or removed).  In every thread the block holds
    :data:`_CRITICAL`, so that :func:`abandon_staged` (called on a signal by another thread) runs
    before or after it, never in the middle.  Outside the main thread (which receives no signals
    in Python) no handler is changed."""
    with _CRITICAL:
        if not _in_main_thread():
            yield
            return
        with _held_in_main_thread():
            yield


@contextmanager
def _held_in_main_thread():
    held: list[int] = []

    def hold(signum, frame):
        held.append(signum)

    previous = {}
    try:
        for sig in (signal.SIGINT, signal.SIGTERM):
            handler = signal.getsignal(sig)
            if handler is not None:  # None: a handler installed outside Python, left alone
                previous[sig] = signal.signal(sig, hold)
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        for sig in dict.fromkeys(held):
            signal.raise_signal(sig)  # the restored handler acts on it now


def _temp_path(dest: Path, tag: str = TEMP_TAG) -> Path:
    return dest.parent / f".{dest.name}.{tag}-{os.getpid()}-{secrets.token_hex(4)}"


def _temp_pattern(name: str) -> re.Pattern:
    # ``..NAME.msslib-tmp-PID-RANDOM.<hex>.tmp`` too: the temporary of a writer (write_vtu) that
    # itself writes beside the path it is given
    return re.compile(r"^\.{1,2}" + re.escape(name) + rf"\.(?:{TEMP_TAG}|{_BACKUP_TAG})-(\d+)-[0-9a-f]+(?:\..+)?$")


def _pid_alive(pid: int) -> bool:
    if pid <= 0:
        return True  # not one of ours: never remove
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (OSError, OverflowError):  # PermissionError: a process of another user is alive
        return True
    return True


#: any temporary file of msslib: (leading dots, the text before the tag, the process id)
_ANY_TEMP = re.compile(rf"^(\.{{1,2}})(.*)\.(?:{TEMP_TAG}|{_BACKUP_TAG})-(\d+)-[0-9a-f]+(?:\..+)?$")


def _stale_index(directory: Path) -> dict[str, list[str]]:
    """The temporary files of runs no longer alive in ``directory``, by the name of their target
    (one listing of the directory, however many targets are looked up)."""
    index: dict[str, list[str]] = {}
    try:
        names = os.listdir(directory if str(directory) else ".")
    except OSError:
        return index
    for name in names:
        match = _ANY_TEMP.match(name)
        if match is None or _pid_alive(int(match.group(3))):
            continue
        dots, core = match.group(1), match.group(2)
        for target in ({core, "." + core} if dots == ".." else {core}):
            index.setdefault(target, []).append(name)
    return index


def _remove_stale(path: Path, names) -> list[Path]:
    """Remove the entries ``names`` beside ``path`` that are temporaries of ``path`` (regular
    files, not links); returns the paths removed. Errors are ignored."""
    removed = []
    if not names:
        return removed
    pattern = _temp_pattern(path.name)
    for name in names:
        if pattern.match(name) is None:
            continue
        stale = path.parent / name
        try:
            if stale.is_file() and not stale.is_symlink():
                stale.unlink()
                removed.append(stale)
        except OSError:
            pass
    return removed


def remove_stale_temporaries(path: str | os.PathLike) -> list[Path]:
    """Remove the temporary files that runs killed while writing ``path`` left beside it (those
    whose process id is no longer alive); returns the paths removed. Errors are ignored."""
    path = Path(path)
    return _remove_stale(path, _stale_index(path.parent).get(path.name, []))


def _unlink(path: Path) -> None:
    try:
        os.unlink(path)
    except FileNotFoundError:
        pass


def _remove_all(staged: list) -> None:
    """Remove the temporary files of ``staged`` (pairs ``(destination, temporary)``) and empty it."""
    for _, tmp in staged:
        _unlink(tmp)
    staged.clear()


def _replace_all(staged: list) -> list[Path]:
    """Rename every temporary file of ``staged`` over its destination, or (on any error) none:
    the files already replaced get their old content back from a hard link kept until the end.
    Each step is registered before it is done, so an error raised by the step itself is undone
    too. Returns the destinations."""
    backups: dict[Path, Path | None] = {}
    replaced: list[Path] = []
    existed = {dest: os.path.lexists(dest) for dest, _ in staged}
    try:
        for dest, _ in staged:  # keep the files about to be replaced, to put them back on failure
            backups[dest] = None
            if existed[dest]:
                backups[dest] = _temp_path(dest, _BACKUP_TAG)
                try:
                    os.link(dest, backups[dest], follow_symlinks=False)
                except OSError:  # no hard links here: that file cannot be put back
                    backups[dest] = None
        for dest, tmp in staged:
            replaced.append(dest)
            try:
                os.replace(tmp, dest)
            except Exception as exc:
                raise _rename_error(exc, tmp, dest, "output file") from exc
    except BaseException:
        for dest in reversed(replaced):  # put the old files back
            try:
                if backups.get(dest) is not None:
                    os.replace(backups[dest], dest)
                    backups[dest] = None  # it is the destination again: not to be removed
                elif not existed[dest]:
                    os.unlink(dest)
            except OSError:
                pass
        raise
    finally:
        for backup in backups.values():
            if backup is not None:
                _unlink(backup)
    return replaced


def _fsync(path: Path, flags: int = os.O_RDONLY) -> None:
    try:
        fd = os.open(path, flags)
    except OSError:
        return  # directories cannot be opened on every platform
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


#: a directory with less free space than this (bytes) is full: a write that failed there failed for it
FULL_BELOW = 1 << 20


def _free_bytes(directory: Path) -> int | None:
    """Bytes this process may still write in ``directory`` (the reserved blocks count for root),
    None when unknown."""
    try:
        st = os.statvfs(directory if str(directory) else ".")
    except (OSError, AttributeError, ValueError):  # no statvfs (Windows)
        return None
    if not st.f_blocks:  # a file system that reports no sizes
        return None
    blocks = st.f_bfree if hasattr(os, "geteuid") and os.geteuid() == 0 else st.f_bavail
    return int(blocks) * int(st.f_frsize)


def _disk_full(exc: BaseException, tmp: Path) -> bool:
    """Whether the write of ``tmp`` that raised ``exc`` failed for want of space: ``ENOSPC`` or
    ``EDQUOT``, or (libraries that report it otherwise, such as NetCDF's ``HDF error``) less than
    :data:`FULL_BELOW` bytes left in its directory."""
    if isinstance(exc, OSError) and exc.errno in (errno.ENOSPC, getattr(errno, "EDQUOT", errno.ENOSPC)):
        return True
    free = _free_bytes(tmp.parent)
    return free is not None and free < FULL_BELOW


def _rename_error(exc: BaseException, tmp: Path, dest: Path, what: str, disk_full: bool = False) -> BaseException:
    """``exc`` raised while writing ``tmp``, re-made to name ``dest`` (not the temporary file);
    ``disk_full``: the device was full, said as ``no space left on device``."""
    pattern = re.compile(r"\.?" + re.escape(tmp.name) + r"(?:\.[0-9a-f]+\.tmp)?")
    said = isinstance(exc, OSError) and exc.errno in (errno.ENOSPC, getattr(errno, "EDQUOT", errno.ENOSPC))
    if disk_full and not said:  # e.g. "NetCDF: HDF error": say what it means
        detail = pattern.sub(dest.name, " ".join(str(exc).split())) or type(exc).__name__
        new = OSError(errno.ENOSPC, f"cannot write {what}: no space left on device in {str(dest.parent)!r} "
                                    f"(the writer said: {detail})", str(dest))
    elif isinstance(exc, OSError) and exc.errno is not None:  # shown as "[Errno N] message: 'dest'"
        message = f"cannot write {what}: {pattern.sub(dest.name, str(exc.strerror or exc))}"
        try:
            new = type(exc)(exc.errno, message, str(dest))
        except Exception:  # an OSError subclass with another signature
            new = OSError(exc.errno, message, str(dest))
    elif isinstance(exc, OSError):
        new = type(exc)(f"cannot write {what} {str(dest)!r}: {pattern.sub(dest.name, str(exc))}")
    else:
        message = f"cannot write {what} {str(dest)!r}: {pattern.sub(dest.name, ' '.join(str(exc).split()))}"
        try:
            new = type(exc)(message)
        except Exception:
            new = OSError(errno.EIO, message, str(dest))
    new.msslib_output = str(dest)  # the command line reports such errors as one line
    return new


#: held by every step that creates, renames or removes a staged file (:func:`_interrupts_held`)
_CRITICAL = threading.RLock()
#: every :class:`StagedOutputs` alive, for :func:`abandon_staged`
_LIVE: "weakref.WeakSet[StagedOutputs]" = weakref.WeakSet()


def abandon_staged(timeout: float = 2.0) -> None:
    """Remove the temporary files of every :class:`StagedOutputs` alive (and the temporaries their
    writers made beside them); no destination is touched.  For a process about to end at once
    (``os._exit``) on a signal, from a thread other than the one writing: it waits up to
    ``timeout`` seconds for a create, rename or remove under way to end, so that a commit is
    either whole or not begun.  The caller must not let the writing thread go on afterwards."""
    got = _CRITICAL.acquire(timeout=timeout)
    try:
        for outputs in list(_LIVE):
            for _, tmp in list(outputs._staged):
                _unlink(tmp)
                try:  # a writer's own temporary beside the path it was given
                    for extra in tmp.parent.glob(f".{tmp.name}.*"):
                        _unlink(extra)
                except OSError:
                    pass
    finally:
        if got:
            _CRITICAL.release()


class StagedOutputs:
    """Several output files written as one: every file is replaced, or none is.

    .. code-block:: python

        with StagedOutputs() as out:  # msslib.results.netcdf.stage_result(out, path, dataset) stages a result
            out.write_text("run.md", table)
            out.write("run.vtu", lambda tmp: write_vtu(tmp, mesh), what="VTU file")
        # here both files are in place; had anything in the block failed, neither would be touched

    Each output is first written to a temporary file in its destination directory, named
    ``.NAME.msslib-tmp-PID-RANDOM``; when the block ends without an error, every temporary file is
    flushed to disk and renamed over its destination (:func:`os.replace`). Should a rename fail
    half-way, the files already replaced get their old content back (a hard link to each replaced
    file is kept until the end). On any error, ``KeyboardInterrupt`` included, every temporary file
    is removed and the error re-raised, naming the destination rather than the temporary file.

    SIGTERM: when the process has the default SIGTERM disposition, the block installs a handler
    that raises :class:`Terminated`; after the clean-up the default is restored and the signal
    re-sent, so that the process still ends as killed by SIGTERM (another handler, such as the
    command line's :func:`terminate_raises`, is left alone). Temporary files of runs killed
    outright (SIGKILL, power loss) are removed the next time the same destination is written, once
    their process id is no longer alive (:func:`remove_stale_temporaries`).

    Without ``with``, call :meth:`commit` or :meth:`discard` yourself.
    """

    def __init__(self):
        self._staged: list[tuple[Path, Path]] = []  # (destination, temporary file), changed in place
        # the last resort, alive while files are staged: temporary files still staged when the
        # object goes (an interrupt that landed where no clean-up of ours could run, e.g. as the
        # with block ends) are removed then
        self._finalizer = weakref.finalize(self, _remove_all, self._staged)
        self._finalizer.detach()
        self._names: set[str] = set()  # the absolute destinations staged: a second one is refused
        self._stale: dict[str, dict[str, list[str]]] = {}  # directory -> target -> temporaries of dead runs
        self._installed = False
        self._previous = None
        _LIVE.add(self)

    # -- staging

    def _remove_stale(self, dest: Path) -> None:
        """Remove the temporaries dead runs left for ``dest``; each directory is listed once."""
        key = os.path.abspath(dest.parent)
        if key not in self._stale:
            self._stale[key] = _stale_index(dest.parent)
        _remove_stale(dest, self._stale[key].pop(dest.name, []))

    def stage(self, dest: str | os.PathLike, what: str = "output file") -> Path:
        """Reserve (create, empty) a temporary file for ``dest`` and return its path; it becomes
        ``dest`` at :meth:`commit`."""
        dest = Path(dest)
        name = os.path.abspath(dest)
        if name in self._names:
            raise ValueError(f"{what} {str(dest)!r} is staged twice")
        directory = dest.parent
        if not directory.is_dir():
            code = errno.ENOTDIR if directory.exists() else errno.ENOENT
            raise (NotADirectoryError if code == errno.ENOTDIR else FileNotFoundError)(
                code, f"cannot write {what}, directory {str(directory)!r} does not exist", str(dest))
        if dest.is_dir():
            raise IsADirectoryError(errno.EISDIR, f"cannot write {what}, it is a directory", str(dest))
        if dest.exists() and not dest.is_file():  # a device or a pipe: os.replace would replace it
            raise OSError(errno.EINVAL, f"cannot write {what}, it exists and is not a regular file", str(dest))
        self._remove_stale(dest)
        tmp = _temp_path(dest)
        # registered before it is created, with the interrupts held: it cannot be left behind
        with _interrupts_held():
            if not self._finalizer.alive:
                self._finalizer = weakref.finalize(self, _remove_all, self._staged)
            self._staged.append((dest, tmp))
            self._names.add(name)
            try:
                fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)  # mode honours the umask
            except OSError as exc:  # not created (or not ours): forgotten, never removed
                self._staged.remove((dest, tmp))
                self._names.discard(name)
                raise type(exc)(exc.errno, f"cannot write {what}, no temporary file in {str(directory)!r}: "
                                           f"{exc.strerror}", str(dest)) from exc
            os.close(fd)
        return tmp

    def _unstage(self, dest: Path, tmp: Path) -> None:
        with _interrupts_held():  # removed and forgotten together
            _unlink(tmp)
            self._staged.remove((dest, tmp))
            self._names.discard(os.path.abspath(dest))

    def write(self, dest: str | os.PathLike, writer, what: str = "output file") -> Path:
        """Stage ``dest`` and call ``writer(temporary_path)`` to fill it; an error of the writer
        is re-raised naming ``dest`` (a full disk is said to be one: ``no space left on device``,
        also when the writer's library reports it otherwise, e.g. NetCDF's ``HDF error``)."""
        dest = Path(dest)
        tmp = self.stage(dest, what)
        try:
            writer(tmp)
        except BaseException as exc:
            full = isinstance(exc, Exception) and _disk_full(exc, tmp)  # before the partial file is removed
            self._unstage(dest, tmp)
            if isinstance(exc, Exception):
                raise _rename_error(exc, tmp, dest, what, disk_full=full) from exc
            raise
        return dest

    def write_text(self, dest: str | os.PathLike, text: str, what: str = "text file") -> Path:
        """Stage a UTF-8 text file."""
        return self.write(dest, _to_text(text), what)

    @property
    def destinations(self) -> list[Path]:
        return [dest for dest, _ in self._staged]

    # -- ending

    def discard(self) -> None:
        """Remove every temporary file; no destination is touched."""
        with _interrupts_held():  # an interrupt cannot stop the clean-up half-way
            _remove_all(self._staged)
            self._names.clear()
            self._finalizer.detach()  # nothing left to remove

    def commit(self) -> list[Path]:
        """Rename every temporary file over its destination (all, or none); returns the
        destinations.  The renames (and the links kept to put the replaced files back) run with
        SIGINT and SIGTERM held: an interrupt lands before them (nothing is replaced) or after them
        (everything is), never half-way; they take a moment even for thousands of files."""
        staged = self._staged
        try:
            for _, tmp in staged:
                _fsync(tmp)
            with _interrupts_held():
                replaced = _replace_all(staged)
        finally:
            self.discard()
        for directory in {dest.parent for dest in replaced}:  # make the renames durable
            _fsync(directory)
        return replaced

    def __enter__(self):
        if _in_main_thread() and signal.getsignal(signal.SIGTERM) == signal.SIG_DFL:
            self._previous = signal.signal(signal.SIGTERM, _raise_terminated)
            self._installed = True
        return self

    def __exit__(self, exc_type, exc, tb):
        try:
            if exc_type is None:
                try:
                    self.commit()
                except BaseException:  # an interrupt before commit's own clean-up could run
                    self.discard()
                    raise
            else:
                self.discard()
        finally:
            if self._installed:
                self._installed = False
                signal.signal(signal.SIGTERM, self._previous)
                if exc_type is not None and issubclass(exc_type, Terminated):
                    os.kill(os.getpid(), signal.SIGTERM)  # end as the default disposition would
        return False
