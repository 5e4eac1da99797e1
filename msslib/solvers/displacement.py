"""Displacement-based problems with dead loads (the finite-strain FEM references) for the solvers.

:class:`DisplacementProblem` presents an internal-force assembly ``u -> (f_int, K, energy,
f_abs)`` through the problem protocol of :mod:`msslib.solvers`, and :func:`solve_displacement`
solves it with :func:`~msslib.solvers.static_solve`: the Newton iteration, the convergence test
``||r|| <= max(tol F_ref, floor)``, the load stepping and step halving and the failure
messages of the mass-spring models.  The state is the displacement ``u``; the round-off floor
is taken at every iterate from ``|| |K| |u| + sum_e |f_e| + load |f_ext| ||`` (protocol
``force_magnitude``: the forces are computed from displacement gradients, and each element force
sums stresses, so the size of what they sum grows with the deformation).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .roundoff import _abs_times
from .statics import static_solve

SOLVER = "Newton (msslib.solvers.static_solve), banded Cholesky or SuperLU (MMD_AT_PLUS_A ordering)"


class DisplacementProblem:
    """``internal(u, tangent)`` -> ``(f_int, K, energy, f_abs)``: internal forces, tangent
    stiffness (None without ``tangent``), strain energy and ``sum_e |f_e|`` (per dof) at the
    displacement ``u``.  ``f_ext``: dead external forces at load factor 1; ``constrained``: mask
    of the prescribed dofs, ``prescribed``: their values at load factor 1.  An internal force
    that raises ``FloatingPointError`` or ``LinAlgError`` (an inverted element) reads as a
    non-finite force, which fails the Newton step (and halves the load increment)."""

    symmetric = True

    def __init__(self, internal: Callable, f_ext, constrained, prescribed):
        self.internal = internal
        self.f_ext = np.asarray(f_ext, dtype=float)
        self.constrained = np.asarray(constrained, dtype=bool)
        self.free = ~self.constrained
        self.prescribed = np.asarray(prescribed, dtype=float)
        self.n_dof = self.f_ext.size
        self._last = None  # (u, f_int, K, energy, f_abs) of the last evaluation

    def _eval(self, u):
        u = np.asarray(u, dtype=float)
        last = self._last
        if last is None or not np.array_equal(last[0], u):
            try:
                fint, K, energy, fabs = self.internal(u, True)
            except (FloatingPointError, np.linalg.LinAlgError):
                nan = np.full(self.n_dof, np.nan)
                fint, K, energy, fabs = nan, None, float("nan"), nan
            last = self._last = (u.copy(), fint, K, energy, fabs)
        return last

    def force(self, u, load=1.0):
        return load * self.f_ext - self._eval(u)[1]

    def stiffness(self, u, load=1.0):
        K = self._eval(u)[2]
        if K is None:
            raise FloatingPointError("no tangent at a non-finite state")
        return K

    def energy(self, u, load=1.0):
        return float(self._eval(u)[3] - load * (self.f_ext @ np.asarray(u, dtype=float)))

    def apply_prescribed(self, u, load):
        out = np.array(u, dtype=float)
        out[self.constrained] = load * self.prescribed[self.constrained]
        return out

    def force_magnitude(self, u, load=1.0):
        """``|K| |u| + sum_e |f_e| + load |f_ext|`` per dof: the size of what the force sums."""
        _, _, K, _, fabs = self._eval(u)
        if K is None:
            return np.full(self.n_dof, np.inf)
        return _abs_times(K, np.abs(np.asarray(u, dtype=float))) + fabs + abs(load) * np.abs(self.f_ext)


def solve_displacement(problem: DisplacementProblem, *, steps: int, tol: float, max_iter: int,
                       max_halvings: int, progress: Callable[[int, int], None] | None = None):
    """Solve ``problem`` from ``u = 0`` by :func:`~msslib.solvers.static_solve` (plain Newton:
    no line search; direct linear solves) in ``steps`` equal load increments, each halved at most
    ``max_halvings`` times in a row.  ``progress(step, steps)`` after every converged nominal
    step.  Returns ``(u, stats)``: ``stats`` holds ``iterations``, ``residuals`` (relative to
    ``F_ref``), ``load_factors``, ``n_halvings``, ``force_scale``, ``tol``, ``roundoff_floor``,
    ``threshold``, ``roundoff_steps`` and ``messages``.  Raises
    :class:`~msslib.errors.ConvergenceError` (a RuntimeError) when an increment fails."""
    reported = [1]

    def on_load_step(_count, lam):
        while progress is not None and reported[0] <= steps and lam >= reported[0] / steps - 1e-12:
            progress(reported[0], steps)
            reported[0] += 1

    res = static_solve(problem, np.zeros(problem.n_dof), load_steps=steps, tol=tol, max_iter=max_iter,
                       line_search=False, linear_solver="direct", max_cuts=max_halvings,
                       on_load_step=on_load_step)
    stats = {"iterations": list(res.iterations), "residuals": [[r / res.force_scale for r in h] for h in res.residuals],
             "load_factors": list(res.loads), "n_halvings": res.n_cuts, "force_scale": res.force_scale,
             "tol": float(tol), "roundoff_floor": float(res.roundoff_floor), "threshold": float(res.threshold),
             "roundoff_steps": list(res.roundoff_steps), "messages": list(res.messages)}
    return res.x, stats
