"""Timing helpers and the result registry of the benchmarks."""

from __future__ import annotations

import time

import numpy as np


def median_time(fn, repeat: int = 5, warmup: int = 1) -> float:
    """Median wall time (s) of ``fn()`` over ``repeat`` runs after ``warmup`` runs."""
    for _ in range(warmup):
        fn()
    ts = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t)
    return float(np.median(ts))


class Results:
    """Collects figures, prints them as ``name: value unit (ratio to baseline: x)``."""

    def __init__(self):
        self.figures: dict[str, dict] = {}

    def add(self, name: str, value: float, unit: str, ratio: float | None = None, baseline: str | None = None,
            note: str = "", target: tuple[str, float, str] | None = None):
        """Record and print one figure.  ``target``: ``(op, threshold, on)`` with ``op`` one of
        ``"<="``/``">="`` and ``on`` ``"value"`` or ``"ratio"``; whether it is met is stored and
        printed."""
        value = float(value)
        met = None
        if target is not None:
            op, thr, on = target
            if op not in ("<=", ">=") or on not in ("value", "ratio"):
                raise ValueError(f"bad target {target!r}")
            v = value if on == "value" else ratio
            met = None if v is None else bool(v <= thr if op == "<=" else v >= thr)
        self.figures[name] = {"value": value, "unit": unit,
                              "ratio_to_baseline": None if ratio is None else float(ratio),
                              "baseline": baseline, "note": note,
                              "target": None if target is None else
                              f"{'ratio' if target[2] == 'ratio' else ''} {target[0]} {target[1]:g}".strip()
                              + ("" if target[2] == "ratio" or not unit else f" {unit}"),
                              "met": met}
        r = "n/a" if ratio is None else f"{ratio:.3g}"
        b = f" vs {baseline}" if baseline else ""
        n = f"  [{note}]" if note else ""
        t = "" if target is None else f"  target {self.figures[name]['target']}: {'MET' if met else 'NOT MET'}"
        print(f"{name}: {value:.4g} {unit} (ratio to baseline: {r}{b}){t}{n}", flush=True)
