"""Performance benchmarks of msslib (``python -m benchmarks [--quick] [--out results/benchmarks.json]``).

Every figure is printed as ``name: value unit (ratio to baseline: x)``, the baseline being measured
in the same run, and written to a JSON file.  BLAS/OpenMP pools are pinned to one thread with
threadpoolctl and numba runs single-threaded; timings are medians of repeats.
"""
