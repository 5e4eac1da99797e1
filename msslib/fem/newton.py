"""The FEM references on the solver stack of the mass-spring models (:mod:`msslib.solvers`).

A linear solve (:func:`linear_solve`) goes through the same policy as a Newton system of an MSS
model (:func:`msslib.solvers.choose_linear_solver`): up to ``ITERATIVE_THRESHOLD`` free dofs the
direct solver (banded Cholesky when a narrow band exists, else SuperLU), above it banded
Cholesky while it is cheap, else conjugate gradients preconditioned by the library's
smoothed-aggregation AMG with the rigid-body modes of the dofs' locations as near-null space.

A finite-strain solve (:func:`newton_solve`) is :func:`msslib.solvers.static_solve` on a
:class:`~msslib.solvers.displacement.DisplacementProblem` (the state is the displacement ``u``,
the round-off floor from ``|K| |u| + sum_e |f_e| + |f_ext|``) that also names where its dofs sit,
so that the solver context has the AMG near-null space and the band orderings of the dofs.
"""

from __future__ import annotations

from collections.abc import Callable
from types import SimpleNamespace

import numpy as np

#: what the FEM solves run on
SOLVER = ("msslib.solvers (the policy of the mass-spring models: banded Cholesky, SuperLU or "
          "AMG-preconditioned CG)")
NEWTON = "Newton (msslib.solvers.static_solve, no line search), linear solves by " + SOLVER
#: relative residual of an iterative linear solve of linear elasticity
LINEAR_RTOL = 1e-12


def linear_solve(K, rhs, free, points, dim: int, linear_solver="auto", symmetric: bool = True):
    """``K[free][:, free]^-1 rhs`` by the linear-solver policy of :mod:`msslib.solvers`.

    ``points`` ``(n_scalar, dim)``: the location of every scalar dof (for the AMG near-null
    space). Returns ``(x, how)``, ``how`` naming the solver taken (``"direct"`` or ``"cg"``).
    ``symmetric``: whether ``K`` is (CG is chosen for symmetric systems only); a ``K`` declared
    non-symmetric that is symmetric to round-off is solved as symmetric.
    Raises :class:`numpy.linalg.LinAlgError` for a singular matrix."""
    from msslib.solvers import context as _context
    from msslib.solvers.linear import solve_linear_system
    from msslib.solvers.submatrices import submatrix
    from msslib.solvers.policy import as_symmetric, banded_cholesky_is_cheap, choose_linear_solver
    from msslib.solvers.protocol import NewtonFailure

    ctx = _context.linear_solve_context(SimpleNamespace(dim=dim), np.asarray(points, dtype=float).ravel(), free)
    A, symmetric = as_symmetric(submatrix(K.tocsr(), free, plans=ctx), symmetric)  # round-off asymmetry
    how = choose_linear_solver(linear_solver, A.shape[0], symmetric, lambda: banded_cholesky_is_cheap(A, ctx))
    messages: list = []
    try:
        x = solve_linear_system(A, np.asarray(rhs, dtype=float), linear_solver, symmetric, messages, ctx,
                                rtol=LINEAR_RTOL)
    except NewtonFailure as exc:
        raise np.linalg.LinAlgError(f"singular stiffness matrix (are rigid-body modes constrained?): {exc}") from None
    if not np.all(np.isfinite(x)):
        raise np.linalg.LinAlgError("singular stiffness matrix (are rigid-body modes constrained?)")
    if how == "cg" and any("falling back" in m for m in messages):
        how = "direct (after CG failed)"
    return x, how


def _problem_class():
    from msslib.solvers.displacement import DisplacementProblem

    class LocatedProblem(DisplacementProblem):
        """A :class:`~msslib.solvers.displacement.DisplacementProblem` that names where its dofs
        sit (``coordinates``, ``(n_scalar, dim)``) and its dimension, for the AMG near-null space
        and the band orderings of the solver context; the state stays the displacement (a
        position ``X + u`` would round a small ``u`` to the precision of ``X``)."""

        def __init__(self, internal: Callable, f_ext, constrained, prescribed, points, followers=()):
            super().__init__(internal, f_ext, constrained, prescribed)
            self.coordinates = np.asarray(points, dtype=float)
            self.dim = int(self.coordinates.shape[1])
            self.followers = list(followers)
            # a follower pressure's load stiffness is not symmetric in general: LU, never Cholesky/CG
            self.symmetric = not self.followers

        def force(self, u, load=1.0):
            self.state = u  # the last state evaluated: after a converged load step, its solution
            return self._force(u, load)

        def _follower(self, u):
            return sum((load.forces(u) for load in self.followers), np.zeros(self.n_dof))

        def _force(self, u, load=1.0):
            f = super().force(u, load)
            return f + load * self._follower(u) if self.followers and load != 0.0 else f

        def stiffness(self, u, load=1.0):
            K = super().stiffness(u, load)
            for f in self.followers:  # K = -d force / d u
                K = K - load * f.stiffness(u)
            return K

        def force_magnitude(self, u, load=1.0):
            m = super().force_magnitude(u, load)
            return m + abs(load) * np.abs(self._follower(u)) if self.followers else m

    return LocatedProblem


def newton_solve(internal, f_ext, constrained, prescribed, points, *, steps: int, tol: float, max_iter: int,
                 max_halvings: int, progress: Callable[[int, int], None] | None = None, linear_solver="auto",
                 initial=None, followers=(), check=None):
    """Solve ``f_int(u) = f_ext`` from ``u = 0`` by :func:`msslib.solvers.static_solve` (Newton
    without line search, ``steps`` load increments each halved at most ``max_halvings`` times in a
    row, the convergence test of the mass-spring models) with the linear solver chosen by the
    policy of :mod:`msslib.solvers`. ``internal(u, tangent)`` -> ``(f_int, K, energy, f_abs)``.
    ``initial``: the first iterate (all dofs, flat; default zero). ``followers``: loads at load
    factor 1 with ``forces(u)`` and ``stiffness(u)`` (``d forces / d u``), e.g.
    :class:`msslib.fem.pressure.FacetPressure`, scaled by the load factor; with any, the tangent
    is treated as non-symmetric. ``check(u, load)``: called with the solution of every converged
    load increment (all dofs, flat) and its load factor, before the next increment; it may raise
    to stop the solve (e.g. on an inverted element).
    Returns ``(u, stats)`` as :func:`msslib.solvers.displacement.solve_displacement`."""
    from msslib.solvers import static_solve

    problem = _problem_class()(internal, f_ext, constrained, prescribed, points, followers)
    reported = [1]

    def on_load_step(_count, lam):
        if check is not None:
            check(problem.state, lam)
        while progress is not None and reported[0] <= steps and lam >= reported[0] / steps - 1e-12:
            progress(reported[0], steps)
            reported[0] += 1

    x0 = np.zeros(problem.n_dof) if initial is None else np.asarray(initial, dtype=float).ravel()
    res = static_solve(problem, x0, load_steps=steps, tol=tol, max_iter=max_iter, line_search=False,
                       linear_solver=linear_solver, max_cuts=max_halvings, on_load_step=on_load_step)
    stats = {"iterations": list(res.iterations), "residuals": [[r / res.force_scale for r in h] for h in res.residuals],
             "load_factors": list(res.loads), "n_halvings": res.n_cuts, "force_scale": res.force_scale,
             "tol": float(tol), "roundoff_floor": float(res.roundoff_floor), "threshold": float(res.threshold),
             "roundoff_steps": list(res.roundoff_steps), "messages": list(res.messages)}
    return res.x, stats
