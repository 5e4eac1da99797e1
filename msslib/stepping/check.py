"""The stability check of an explicit run behind the :class:`~msslib.stepping.Simulator`: decided
at once when the cheap stages (the cheap bound, an estimate kept for the state, a few passes of
the directional bound) decide the step, else run on a second thread while the first call's steps
run.

:func:`msslib.solvers.check_time_step` first tries a bound that costs about one force evaluation,
then, on a spring model, the directional bound (about one force evaluation a pass; two passes
decide a step at 0.9 of the limit on the benchmark's networks); a step closer to the limit needs
the certificates (tens of products with the stiffness, about as many as steps of the fused
kernel).  Inside :func:`deferred_checks` (the Simulator builds its engines there), a model of at
least :data:`DEFER_MIN_DOFS` free dofs whose step the cheap stages cannot decide gets a
:class:`PendingCheck`: the whole check runs on a thread (its compiled kernels release the GIL)
and the engine waits for it at the first divergence check of the first call that steps (:meth:`msslib.stepping.generic.Integrator.observe`), after the first kernel call.  A
refusal then puts the state back as it was before that call and raises the
:class:`msslib.errors.StabilityError` the check raised, from that call and from every later one.
"""

from __future__ import annotations

import contextvars
import threading
import time
from contextlib import contextmanager

import numpy as np

from msslib.solvers.stability import check_time_step

# below this many free dofs the whole check is short (dense or a few milliseconds): decided at once
DEFER_MIN_DOFS = 20_000

_DEFER = contextvars.ContextVar("msslib_defer_stability_check", default=False)


@contextmanager
def deferred_checks():
    """Engines built inside may run their stability check on a second thread."""
    token = _DEFER.set(True)
    try:
        yield
    finally:
        _DEFER.reset(token)


class PendingCheck:
    """:func:`msslib.solvers.check_time_step` on a thread; :meth:`result` waits for it."""

    def __init__(self, problem, x, dt, kw):
        self._out = self._exc = None
        self._thread = threading.Thread(target=self._run, args=(problem, np.array(x, dtype=float), dt, kw),
                                        name="msslib stability check", daemon=True)
        self._thread.start()

    def _run(self, problem, x, dt, kw):
        t0 = time.perf_counter()
        try:
            with np.errstate(all="ignore"):
                out = check_time_step(problem, x, dt, **kw)
            out["stability_check_time"] = time.perf_counter() - t0
            self._out = out
        except BaseException as exc:  # noqa: BLE001 - raised again by result()
            self._exc = exc

    def result(self) -> dict:
        """The check's information, with ``stability_check_wait`` (s, how long the caller waited);
        raises what the check raised."""
        t0 = time.perf_counter()
        self._thread.join()
        if self._exc is not None:
            raise self._exc
        return dict(self._out, stability_check_wait=time.perf_counter() - t0)


def stability_check(problem, x, dt, *, free, method, damping, load, allow_unstable):
    """The check's information (a dict with ``stability_check_time``), or a :class:`PendingCheck`
    (inside :func:`deferred_checks`, see the module docstring)."""
    kw = {"method": method, "damping": damping, "load": load, "allow_unstable": allow_unstable}
    defer = _DEFER.get() and not allow_unstable and int(np.count_nonzero(free)) >= DEFER_MIN_DOFS
    t0 = time.perf_counter()
    with np.errstate(all="ignore"):
        info = check_time_step(problem, x, dt, cheap_only=defer, **kw)
    if info is None:
        return PendingCheck(problem, x, dt, kw)
    info["stability_check_time"] = time.perf_counter() - t0
    return info


def remember(stepper):
    """Keep the state a refused first call of ``stepper`` returns to (the engine calls it when its
    detector restarts: the last thing a build does before the first call)."""
    stepper._restore_to = (np.array(stepper.x, dtype=float), np.array(stepper.v, dtype=float), stepper.t,
                           stepper.n_taken, stepper.a_in)


def settle(stepper):
    """Wait for ``stepper``'s pending check; on a refusal put back the state :func:`remember` kept
    and raise the check's error (the check stays pending: every later call ends the same way)."""
    try:
        stepper.stats.update(stepper._pending.result())
    except BaseException:
        x, v, stepper.t, stepper.n_taken, stepper.a_in = stepper._restore_to
        stepper.x[...] = x.reshape(np.shape(stepper.x))
        stepper.v[...] = v
        stepper.stats["n_steps"] = stepper.n_taken
        stepper.evaluate()
        stepper.restart_detector()
        raise
    stepper._pending = None
    stepper._use_check()
