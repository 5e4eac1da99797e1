"""Functions of time for the stepping API and the scene's time-varying loads.

A value may be a constant (a number or a vector), a callable ``f(t)``, or a table of points
``[[t0, y0...], [t1, y1...], ...]`` (times increasing), read as the piecewise-linear curve through
them, held at its first and last values outside.
"""

from __future__ import annotations

from bisect import bisect_right
from collections.abc import Callable

import numpy as np

__all__ = ["Curve", "time_function"]


class Curve:
    """Piecewise-linear function of time through ``points`` (rows ``[t, y_1, ..., y_k]``);
    ``curve(t)`` is a float for one column of values, else a ``(k,)`` array."""

    def __init__(self, points, name: str = "curve"):
        p = np.asarray(points, dtype=float)
        if p.ndim != 2 or p.shape[0] < 1 or p.shape[1] < 2:
            raise ValueError(f"{name}: expected rows [t, value...] (at least one), got shape {p.shape}")
        if not np.all(np.isfinite(p)):
            raise ValueError(f"{name}: times and values must be finite")
        if np.any(np.diff(p[:, 0]) <= 0):
            raise ValueError(f"{name}: times must increase strictly, got {p[:, 0].tolist()}")
        self.t = p[:, 0].copy()
        self.y = p[:, 1:].copy()
        self.name = name
        self._times = self.t.tolist()  # bisect on a list: a call costs about a microsecond

    def __call__(self, t: float):
        t = float(t)
        times = self._times
        if len(times) == 1 or t <= times[0]:
            y = self.y[0]
        elif t >= times[-1]:
            y = self.y[-1]
        else:
            i = bisect_right(times, t) - 1
            s = (t - times[i]) / (times[i + 1] - times[i])
            y = (1.0 - s) * self.y[i] + s * self.y[i + 1]
        return float(y[0]) if y.size == 1 else y.copy()

    def __repr__(self) -> str:
        return f"Curve({np.column_stack([self.t, self.y]).tolist()})"


def time_function(value, name: str = "value", size: int | None = None) -> tuple[Callable[[float], object], bool]:
    """``(f, varies)``: ``value`` as a function of time and whether it varies.  ``size``: the
    length a vector value must have (None: a scalar)."""
    if callable(value):
        return value, True
    a = np.asarray(value, dtype=float)
    if a.ndim == 2:
        curve = Curve(a, name)
        if size is not None and curve.y.shape[1] != size:
            raise ValueError(f"{name}: rows must be [t, {size} values], got {curve.y.shape[1]} value(s)")
        if size is None and curve.y.shape[1] != 1:
            raise ValueError(f"{name}: rows must be [t, value], got {curve.y.shape[1]} values")
        return curve, len(curve.t) > 1
    expected = () if size is None else (size,)
    if a.shape != expected or not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: expected {'a number' if size is None else f'{size} numbers'} or a table "
                         f"[[t, ...], ...], got {value!r}")
    const = float(a) if size is None else a.copy()
    return (lambda t: const), False
