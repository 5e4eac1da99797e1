"""One BLAS thread for the banded factorisations of the static solver.

LAPACK's banded Cholesky and LU (``pbtrf``/``gbtrf``) split a band of a few hundred columns into
many small level-3 BLAS calls; a threaded BLAS (OpenBLAS) synchronises its threads at each of
them.  On an idle machine that costs little, but when the cores are shared (other processes, a
parallel build) a waiting thread is descheduled at every synchronisation and the same
factorisation became up to a thousand times slower (the Newton matrix of the cylinder scene at
level 2, 924 dofs, bandwidth 242: up to 2.4 s with the default two threads on two busy cores,
1.7 ms with one).  One thread costs at most the parallel speed-up on an idle machine (at most the
number of cores, for the largest bands allowed, ``BAND_COST_MAX``).

:func:`one_blas_thread` limits the BLAS pools of the process to one thread for the duration of a
``with`` block and restores them after; without ``threadpoolctl`` it does nothing.
"""

from __future__ import annotations

import contextlib

_CONTROLLER: list = []  # [BLAS pools or None], filled on first use (the libraries loaded by then)


def _controller():
    if not _CONTROLLER:
        try:
            from threadpoolctl import ThreadpoolController

            pools = ThreadpoolController().select(user_api="blas")
            _CONTROLLER.append(pools if pools.lib_controllers else None)
        except Exception:  # noqa: BLE001 - no threadpoolctl, or it cannot inspect this process
            _CONTROLLER.append(None)
    return _CONTROLLER[0]


def blas_threads() -> int:
    """Largest thread count of the BLAS pools of this process (1 when unknown)."""
    pools = _controller()
    if pools is None:
        return 1
    return max([lib.num_threads for lib in pools.lib_controllers] or [1])


# LAPACK's banded factorisations (DPBTRF, DGBTRF) run their blocked level-3 code from this
# bandwidth on (ILAENV gives them block size 1 up to 64 sub-diagonals, 32 above); below it,
# unblocked level-2 code on vectors of at most the bandwidth: no thread synchronisation to stall
BLOCKED_BANDWIDTH = 65


def one_blas_thread(active: bool = True):
    """Context manager: the BLAS pools at one thread inside the block, restored on exit; a no-op
    when not ``active`` or when the pools cannot be controlled."""
    pools = _controller() if active else None
    return contextlib.nullcontext() if pools is None else pools.limit(limits=1)
