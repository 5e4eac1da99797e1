"""numba decorators of the compiled loops of :mod:`msslib.terms`, and their on-disk cache.

The loops are compiled on first use with ``cache=True`` (seconds; the hexahedron Hessian about ten
seconds); later processes load them from ``msslib/terms/__pycache__``.  numba's cache is keyed on
the source file of each jitted loop only, not on the generated kernels of
:mod:`msslib.generated.kernels` that the loops of :mod:`msslib.terms.loops` inline:
:func:`_drop_stale_numba_cache` (run when this module is imported, before any loop of the package
is compiled or loaded) drops the package's cache when the generated kernels change.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from msslib.generated import kernels as _K


def _drop_stale_numba_cache() -> None:
    """numba's on-disk cache of the loops of this package is keyed on their own source files, not
    on the generated kernels they inline: when ``msslib/generated/kernels.py`` changes
    (re-derived), drop the cache of every module of the package."""
    import hashlib
    from pathlib import Path

    try:
        cache_dir = Path(__file__).resolve().parent / "__pycache__"
        digest = hashlib.sha256(Path(_K.__file__).read_bytes()).hexdigest()
        stamp = cache_dir / "generated-kernels.sha256"
        if stamp.is_file() and stamp.read_text() == digest:
            return
        for f in cache_dir.glob("*.nb[ic]"):
            f.unlink(missing_ok=True)
        cache_dir.mkdir(exist_ok=True)
        stamp.write_text(digest)
    except OSError:  # read-only installation: numba falls back to compiling in memory
        pass


_drop_stale_numba_cache()

njit_cached = njit(cache=True, error_model="numpy", nogil=True)

# fastmath without reassociation: results stay deterministic and agree with the plain loops to
# round-off
_FAST = {"nnan", "ninf", "nsz", "arcp", "contract", "afn"}
_jit_fast = njit(cache=True, error_model="numpy", nogil=True, fastmath=_FAST)

# Indexing with an unsigned integer: numba wraps negative signed indices around (a compare, a
# shift and a conditional move per access), which doubles the instruction count of the scatter
# loops (fast spring force, Hessian assembly); our indices are never negative, so the hot loops
# index through ``UINT(i)``.
UINT = np.uint64



def watch_compiles(on_start, on_end):
    """A context manager: within it, ``on_start(dispatcher)`` is called when numba starts
    compiling a kernel (a cache miss, as on the first run of a model family; loading a kernel
    from the on-disk cache is no compile) and ``on_end(seconds)`` when that compile ends, the
    kernels it compiles on the way (callees) included.  Uses numba's event API
    (``numba:compile``); a numba without it watches nothing."""
    import time
    from contextlib import nullcontext

    try:
        from numba.core import event
    except ImportError:  # pragma: no cover - numba before 0.53
        return nullcontext()

    class CompileListener(event.Listener):
        depth, t0 = 0, 0.0

        def on_start(self, ev):
            if self.depth == 0:
                self.t0 = time.perf_counter()
                on_start((ev.data or {}).get("dispatcher"))
            self.depth += 1

        def on_end(self, ev):
            self.depth = max(self.depth - 1, 0)
            if self.depth == 0:
                on_end(time.perf_counter() - self.t0)

    return event.install_listener("numba:compile", CompileListener())


def cached_on_disk(dispatcher) -> bool | None:
    """Whether numba can save what it compiles for ``dispatcher`` in its on-disk cache (the
    cache directory is writable); None when unknown."""
    import os

    path = getattr(getattr(dispatcher, "_cache", None), "_cache_path", None)
    if not path:
        return None
    return os.access(path, os.W_OK)
