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
            note: str = ""):
        value = float(value)
        self.figures[name] = {"value": value, "unit": unit,
                              "ratio_to_baseline": None if ratio is None else float(ratio),
                              "baseline": baseline, "note": note}
        r = "n/a" if ratio is None else f"{ratio:.3g}"
        b = f" vs {baseline}" if baseline else ""
        n = f"  [{note}]" if note else ""
        print(f"{name}: {value:.4g} {unit} (ratio to baseline: {r}{b}){n}", flush=True)
