"""Staged outputs: files written to hidden temporaries and committed together.

:class:`StagedOutputs` writes several files as one (all are replaced, or none is): each is written
to a hidden temporary file beside its target, flushed to disk and renamed over it only when every
file was written; on any error, on SIGINT and on SIGTERM the temporaries are removed and the targets
are left as they were. :class:`msslib.io.StagedOutputs` adds NetCDF results to it; every write of
msslib goes through that class.
"""

from __future__ import annotations

import errno
import os
import re
import secrets
import signal
import threading
from contextlib import contextmanager
from pathlib import Path

__all__ = ["TEMP_TAG", "StagedOutputs", "Terminated", "terminate_raises", "remove_stale_temporaries"]


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


def remove_stale_temporaries(path: str | os.PathLike) -> list[Path]:
    """Remove the temporary files that runs killed while writing ``path`` left beside it (those
    whose process id is no longer alive); returns the paths removed. Errors are ignored."""
    path = Path(path)
    pattern = _temp_pattern(path.name)
    removed = []
    try:
        names = os.listdir(path.parent if str(path.parent) else ".")
    except OSError:
        return removed
    for name in names:
        match = pattern.match(name)
        if match is None or _pid_alive(int(match.group(1))):
            continue
        stale = path.parent / name
        try:
            if stale.is_file() and not stale.is_symlink():
                stale.unlink()
                removed.append(stale)
        except OSError:
            pass
    return removed


def _unlink(path: Path) -> None:
    try:
        os.unlink(path)
    except FileNotFoundError:
        pass


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


def _rename_error(exc: BaseException, tmp: Path, dest: Path, what: str) -> BaseException:
    """``exc`` raised while writing ``tmp``, re-made to name ``dest`` (not the temporary file)."""
    pattern = re.compile(r"\.?" + re.escape(tmp.name) + r"(?:\.[0-9a-f]+\.tmp)?")
    if isinstance(exc, OSError) and exc.errno is not None:  # shown as "[Errno N] message: 'dest'"
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


class StagedOutputs:
    """Several output files written as one: every file is replaced, or none is.

    .. code-block:: python

        with StagedOutputs() as out:  # msslib.io.StagedOutputs adds out.write_result(path, dataset)
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
        self._staged: list[tuple[Path, Path]] = []  # (destination, temporary file)
        self._installed = False
        self._previous = None

    # -- staging

    def stage(self, dest: str | os.PathLike, what: str = "output file") -> Path:
        """Reserve (create, empty) a temporary file for ``dest`` and return its path; it becomes
        ``dest`` at :meth:`commit`."""
        dest = Path(dest)
        for other, _ in self._staged:
            if os.path.abspath(other) == os.path.abspath(dest):
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
        remove_stale_temporaries(dest)
        tmp = _temp_path(dest)
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)  # mode honours the umask
        except OSError as exc:
            raise type(exc)(exc.errno, f"cannot write {what}, no temporary file in {str(directory)!r}: "
                                       f"{exc.strerror}", str(dest)) from exc
        os.close(fd)
        self._staged.append((dest, tmp))
        return tmp

    def write(self, dest: str | os.PathLike, writer, what: str = "output file") -> Path:
        """Stage ``dest`` and call ``writer(temporary_path)`` to fill it; an error of the writer
        is re-raised naming ``dest``."""
        dest = Path(dest)
        tmp = self.stage(dest, what)
        try:
            writer(tmp)
        except BaseException as exc:
            self._staged.remove((dest, tmp))
            _unlink(tmp)
            if isinstance(exc, Exception):
                raise _rename_error(exc, tmp, dest, what) from exc
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
        staged, self._staged = self._staged, []
        for _, tmp in staged:
            _unlink(tmp)

    def commit(self) -> list[Path]:
        """Rename every temporary file over its destination (all, or none); returns the
        destinations."""
        staged = self._staged
        backups: dict[Path, Path | None] = {}
        replaced: list[Path] = []
        existed = {dest: os.path.lexists(dest) for dest, _ in staged}
        try:
            for _, tmp in staged:
                _fsync(tmp)
            for dest, _ in staged:  # keep the files about to be replaced, to put them back on failure
                backups[dest] = None
                if existed[dest]:
                    backup = _temp_path(dest, _BACKUP_TAG)
                    try:
                        os.link(dest, backup, follow_symlinks=False)
                        backups[dest] = backup
                    except OSError:  # no hard links here: that file cannot be put back
                        pass
            for dest, tmp in staged:
                try:
                    os.replace(tmp, dest)
                except Exception as exc:
                    raise _rename_error(exc, tmp, dest, "output file") from exc
                replaced.append(dest)
        except BaseException:
            for dest in reversed(replaced):  # put the old files back
                try:
                    if backups.get(dest) is not None:
                        os.replace(backups.pop(dest), dest)
                    elif not existed[dest]:
                        os.unlink(dest)
                except OSError:
                    pass
            raise
        finally:
            for backup in backups.values():
                if backup is not None:
                    _unlink(backup)
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
                self.commit()
            else:
                self.discard()
        finally:
            if self._installed:
                self._installed = False
                signal.signal(signal.SIGTERM, self._previous)
                if exc_type is not None and issubclass(exc_type, Terminated):
                    os.kill(os.getpid(), signal.SIGTERM)  # end as the default disposition would
        return False
