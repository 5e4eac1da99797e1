"""``python -m benchmarks [--quick] [--out results/benchmarks.json]``."""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

from msslib.results import write_text


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m benchmarks", description=__doc__)
    ap.add_argument("--quick", action="store_true", help="reduced sizes (< 60 s)")
    ap.add_argument("--out", default="results/benchmarks.json", help="JSON output file")
    ap.add_argument("--only", default="", help="comma-separated sections: springs,scaling,cantilever,dynamics,scenes,stepping,reference,gpu (gpu: by default only when JAX sees a GPU)")
    args = ap.parse_args(argv)

    os.environ.setdefault("NUMBA_NUM_THREADS", "1")
    import numba
    import numpy as np
    import scipy.linalg  # noqa: F401 - load BLAS before pinning its pool
    import scipy.sparse.linalg  # noqa: F401
    from threadpoolctl import threadpool_info, threadpool_limits

    try:
        import pyamg  # noqa: F401
    except ImportError:
        pass
    _limits = threadpool_limits(1)  # noqa: F841 - kept alive for the whole run

    numba.set_num_threads(1)
    from .common import Results

    pools = ", ".join(f"{p['internal_api']}={p['num_threads']}" for p in threadpool_info()) or "none loaded"
    print(f"threads: BLAS/OpenMP pools pinned to 1 ({pools}); numba threads {numba.get_num_threads()}; "
          f"cpu count {os.cpu_count()}; load average {os.getloadavg()[0]:.1f}", flush=True)
    res = Results()
    sections = [s for s in args.only.split(",") if s] or ["springs", "cantilever", "dynamics", "scaling", "scenes", "stepping",
                                                           "reference"]
    if not args.only:  # the GPU figures of the JAX backend, when JAX sees a GPU
        try:
            from msslib.stepping.jax_backend import has_gpu

            if has_gpu():
                sections.append("gpu")
        except Exception as exc:  # noqa: BLE001 - a broken JAX install: say so, run the CPU sections
            print(f"no GPU figures: {type(exc).__name__}: {exc}", flush=True)
    from . import dynamics, fem_solvers, gpu, scenes, springs, statics, stepping

    t0 = time.perf_counter()
    for sec in sections:
        {"springs": springs.run, "scaling": statics.run_scaling, "cantilever": statics.run_cantilever,
         "dynamics": dynamics.run, "scenes": scenes.run,
         "stepping": stepping.run, "reference": fem_solvers.run_reference, "gpu": gpu.run}[sec](res, args.quick)
    try:
        import pyamg
        amg = pyamg.__version__
    except ImportError:
        amg = None
    meta = {"quick": args.quick, "threads_blas": 1, "threads_numba": numba.get_num_threads(),
            "thread_pools": pools, "cpu_count": os.cpu_count(), "load_average": os.getloadavg()[0],
            "python": platform.python_version(), "numpy": np.__version__, "numba": numba.__version__,
            "pyamg": amg, "wall_s": time.perf_counter() - t0}
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    write_text(out, json.dumps({"meta": meta, "figures": res.figures}, indent=2))  # atomic: no partial file
    print(f"wrote {out} ({len(res.figures)} figures, {meta['wall_s']:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
