"""Stopping a command when asked: SIGINT and SIGTERM end it within seconds, also inside a long C
call (see :class:`StopWhenAsked`)."""

from __future__ import annotations

import os
import sys


#: seconds a command has, after SIGINT or SIGTERM, to stop by itself before it is ended at once
STOP_GRACE_S = 1.5


class StopWhenAsked:
    """SIGINT and SIGTERM stop a command within seconds, also during a long C call (a sparse
    factorisation, a numba loop) in which Python's handlers cannot run.

    Python's own handlers stay: the signal raises ``KeyboardInterrupt`` (``Terminated``) in the
    main thread as soon as it runs Python again, and the command unwinds, removing its temporary
    files.  Besides, the signal is written to a wake-up pipe that a watching thread reads; if the
    command has not ended :data:`STOP_GRACE_S` seconds later (it is inside a C call that releases
    the GIL, as SciPy's factorisations and msslib's numba kernels do), the watching thread removes
    every staged temporary file (:func:`msslib.results.staging.abandon_staged`, which waits for a
    commit under way to end: outputs stay all or nothing) and ends the process with ``os._exit``,
    exit code 130 (SIGINT) or 143 (SIGTERM).  Only in the main thread, where signals are received."""

    def __init__(self):
        self._done = None
        self._previous_fd = None
        self._fds = None

    def __enter__(self):
        import signal
        import threading

        if threading.current_thread() is not threading.main_thread() or not hasattr(signal, "set_wakeup_fd"):
            return self
        r, w = os.pipe()
        os.set_blocking(w, False)
        try:
            self._previous_fd = signal.set_wakeup_fd(w, warn_on_full_buffer=False)
        except (ValueError, OSError):
            os.close(r)
            os.close(w)
            return self
        self._fds = (r, w)
        self._done = threading.Event()
        threading.Thread(target=self._watch, args=(r, self._done), name="msslib-stop", daemon=True).start()
        return self

    @staticmethod
    def _watch(fd, done):
        import signal

        from msslib.results.staging import abandon_staged

        try:
            while True:
                data = os.read(fd, 64)
                if not data:  # the write end was closed: the command ended
                    return
                signums = {int(b) for b in data} & {int(signal.SIGINT), int(signal.SIGTERM)}
                if signums:  # (not another signal, such as an alarm of plan's per-run budget)
                    break
            if done.wait(STOP_GRACE_S):
                return  # the command stopped by itself
        except OSError:
            return
        finally:
            os.close(fd)
        abandon_staged()
        term = int(signal.SIGTERM) in signums
        try:
            sys.stderr.write("msslib: terminated\n" if term else "msslib: interrupted\n")
            sys.stderr.flush()
            sys.stdout.flush()
        except Exception:
            pass
        os._exit(143 if term else 130)

    def __exit__(self, *exc):
        import signal

        if self._fds is None:
            return False
        self._done.set()
        try:
            signal.set_wakeup_fd(self._previous_fd)
        except (ValueError, OSError):
            pass
        os.close(self._fds[1])  # the watching thread reads the end of the pipe and closes it
        self._fds = None
        return False
