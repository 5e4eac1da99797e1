"""A one-line text progress bar for long runs, and the line that says numba kernels are being
compiled (:func:`compile_notice`)."""

from __future__ import annotations

import math
import sys
import time
from contextlib import contextmanager


class TextProgress:
    """A one-line text progress bar on ``stream`` (default stderr), ``callable(fraction, text)``.

    Nothing is shown during the first ``delay`` seconds (short runs stay quiet); then the line is
    redrawn at most every ``interval`` seconds on a terminal, and written as a whole line at most
    every 5 s elsewhere (a log file gets no carriage returns).  :meth:`close` ends the line.

    The line shows the elapsed time, the rate since the first report and the time left at that
    rate: ``(3.1 s, 12.3 steps/s, 0:42 left)`` when ``total`` (the number of ``unit`` in the whole
    run) is given, ``(3.1 s, 2.5 %/s, 0:42 left)`` otherwise.  :meth:`restart_rate` measures the
    rate from the next report on (after a compile, which is no part of the pace of the run);
    :meth:`note` writes a line of its own.
    """

    def __init__(self, label: str = "", stream=None, width: int = 30, delay: float = 0.5, interval: float = 0.1,
                 total: float | None = None, unit: str = "steps"):
        self.label = label
        self.total = total
        self.unit = unit
        self.first = None  # (time, fraction) of the first report: the rate is measured from there
        self.drawn = 0  # length of the line on a terminal
        self.stream = stream
        self.width = width
        self.delay = delay
        self.interval = interval
        self.start = time.perf_counter()
        self.last = -math.inf
        self.shown = False
        self.fraction = 0.0
        self.text = ""

    def __call__(self, fraction: float, text: str = "") -> None:
        self.fraction = min(max(float(fraction), 0.0), 1.0)
        self.text = text
        now = time.perf_counter()
        if self.first is None:
            self.first = (now, self.fraction)
        interval = self.interval if self._tty() else max(self.interval, 5.0)
        if now - self.start < self.delay or now - self.last < interval:
            return
        self.last = now
        self._draw(now)

    def restart_rate(self) -> None:
        """Measure the rate (and the time left) from the next report on."""
        self.first = None

    def note(self, text: str) -> None:
        """Write ``text`` as a line of its own (below the bar when it is drawn on a terminal)."""
        stream = self._stream()
        if self.shown and self._tty() and self.drawn:
            stream.write("\n")
            self.drawn = 0
        stream.write(text + "\n")
        stream.flush()

    def _stream(self):
        return self.stream if self.stream is not None else sys.stderr

    def _tty(self) -> bool:
        try:
            return bool(self._stream().isatty())
        except (AttributeError, ValueError):
            return False

    def _draw(self, now):
        stream = self._stream()
        filled = int(round(self.fraction * self.width))
        bar = "#" * filled + "." * (self.width - filled)
        line = f"{self.label} [{bar}] {100 * self.fraction:5.1f}% {self.text} ({now - self.start:.1f} s{self._pace(now)})"
        if self._tty():
            stream.write("\r" + line.ljust(max(99, self.drawn)))
            self.drawn = len(line)
        else:  # a log file: whole lines, no carriage returns
            stream.write(line + "\n")
        stream.flush()
        self.shown = True

    def _pace(self, now) -> str:
        """``", 12.3 steps/s, 0:42 left"``, or "" before any progress."""
        if self.first is None:
            return ""
        t0, f0 = self.first
        if self.fraction <= f0 or now <= t0:
            return ""
        rate = (self.fraction - f0) / (now - t0)  # fraction per second
        pace = f"{rate * self.total:.3g} {self.unit}/s" if self.total else f"{100 * rate:.3g} %/s"
        if self.fraction >= 1.0:
            return f", {pace}"
        minutes, seconds = divmod(math.ceil((1.0 - self.fraction) / rate), 60)
        hours, minutes = divmod(minutes, 60)
        left = f"{hours}:{minutes:02d}:{seconds:02d}" if hours else f"{minutes}:{seconds:02d}"
        return f", {pace}, {left} left"

    def close(self, fraction: float | None = None) -> None:
        if self.shown:
            if fraction is not None:
                self.fraction = fraction
            self._draw(time.perf_counter())
            if self._tty():
                self._stream().write("\n")
                self._stream().flush()
            self.shown = False



@contextmanager
def compile_notice(bar: TextProgress, what: str):
    """Within the block, the first compile of numba kernels (a cache miss: the first run of a model
    family; loading compiled kernels from the cache says nothing) is said in one line on the
    bar's stream, ``msslib: compiling the WHAT kernels (first run only, cached afterwards) ...``,
    and after each compile the bar's rate starts again (the time left does not count the
    compile)."""
    from msslib.terms.jit import cached_on_disk, watch_compiles

    said = False

    def start(dispatcher):
        nonlocal said
        if not said:
            said = True
            cached = cached_on_disk(dispatcher) is not False
            why = "first run only, cached afterwards" if cached else "not cached: numba's cache directory is read-only"
            bar.note(f"msslib: compiling the {what} kernels ({why}) ...")

    with watch_compiles(start, lambda seconds: bar.restart_rate()):
        yield
