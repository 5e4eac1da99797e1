"""Solver contexts: the state a solve keeps between its linear solves, owned by the problem.

A :class:`SolverContext` holds what the Newton systems of one problem have in common: the
spatial dimension and the coordinates of the free nodes (AMG near-null space, band orderings),
the plans of the free-dof submatrices and band orderings (:class:`~msslib.solvers.submatrices.PlanCache`,
backed by the process-wide memo of plans :data:`msslib.solvers.memo.PLANS`),
the kept AMG hierarchy (``cache``), the matrix of the Newton systems whose values are refilled
(``K``) and the banded factorisation arrays.  It is a dict (its entries are the state) with the
plan cache as attribute ``plans``.

The context of the last static solve of a problem is kept by the problem itself (attribute
:data:`ATTRIBUTE`; a problem that takes no attributes keeps none): the next solve of the same
problem with the same free nodes, initial coordinates and linear solver starts with it, as the
Newton iterations of one solve do: the hierarchy is kept while CG converges fast with it (load
steps, parameter sweeps and repeated solves of one model keep their tangent's pattern and,
largely, its values), rebuilt otherwise.  It goes with the problem.
"""

from __future__ import annotations

import threading

import numpy as np

from .submatrices import PlanCache

ATTRIBUTE = "_msslib_solver_context"  # where a problem keeps the context of its last static solve


class SolverContext(dict):
    """The state of the linear solves of one problem (see the module docstring)."""

    def __init__(self, *args, plans: PlanCache | None = None, **kw):
        super().__init__(*args, **kw)
        self.plans = PlanCache(share=plans)  # its own view of the shared plans (with its geometry)

    def __reduce__(self):  # copies and pickles of a problem start afresh (a lock cannot be copied)
        return (SolverContext, ())


def _kept_context(problem):
    """The context kept by ``problem`` from its last static solve, or None."""
    ctx = getattr(problem, "__dict__", {}).get(ATTRIBUTE)
    return ctx if isinstance(ctx, SolverContext) else None


def _keep_context(problem, ctx) -> bool:
    try:
        setattr(problem, ATTRIBUTE, ctx)
    except (AttributeError, TypeError):  # slots, frozen or read-only objects keep nothing
        return False
    return True


def linear_solve_context(problem, x, free, plans: PlanCache | None = None):
    """Context of :func:`msslib.solvers.linear.solve_linear_system`: spatial dimension and coordinates
    of the free nodes when the free dofs are whole nodes (all or none of a node's dofs free); the
    coordinates are ``x``, or the problem's ``coordinates`` attribute when it has one.
    ``plans``: a plan cache to share (default: the one of the context the problem keeps, if
    any; plans depend only on the sparsity pattern)."""
    if plans is None:
        kept = _kept_context(problem)
        plans = kept.plans if kept is not None else None
    dim = getattr(problem, "dim", None)
    ctx = SolverContext({"cache": {}}, plans=plans)
    try:
        dim = int(dim) if dim else 0
    except (TypeError, ValueError):
        dim = 0
    if dim in (2, 3) and free.size % dim == 0:
        f = free.reshape(-1, dim)
        whole = f.all(axis=1)
        if np.array_equal(whole, f.any(axis=1)):
            ctx["dim"] = dim
            ctx["node_free"] = whole
            # a problem whose state is no position (FEM displacements) names its dofs' locations
            where = getattr(problem, "coordinates", None)
            ctx["coords"] = np.asarray(x if where is None else where, dtype=float).reshape(-1, dim)[whole]
    return ctx


def _static_context(problem, x, free, linear_solver):
    """The solver context of a static solve (see :func:`linear_solve_context`): the one left by the
    previous solve of ``problem`` when it is compatible and not in use (another thread), else a
    new one (sharing the old one's plans), kept for the next solve.  Release it with
    :func:`_release_context`."""
    old = _kept_context(problem)
    ctx = linear_solve_context(problem, x, free, old.plans if old is not None else None)
    if not isinstance(linear_solver, str):  # a user solver: nothing to keep
        return ctx
    ctx["linear_solver"] = linear_solver
    if (old is not None and old.get("linear_solver") == linear_solver and old.get("dim") == ctx.get("dim")
            and "lock" in old and old["free"].shape == free.shape and np.array_equal(old["free"], free)
            and np.array_equal(old.get("coords"), ctx.get("coords")) and old["lock"].acquire(blocking=False)):
        old["cg_iterations"] = 0
        old.pop("negative_curvature", None)
        old.pop("band_indefinite", None)  # judged afresh by each solve
        old.pop("indefinite", None)
        return old
    if old is not None and old.get("lock") is not None and old["lock"].locked():  # in use: keep its own
        return ctx
    ctx["free"] = free.copy()
    ctx["lock"] = threading.Lock()
    ctx["lock"].acquire()
    _keep_context(problem, ctx)
    return ctx


def _release_context(ctx):
    lock = ctx.get("lock")
    if lock is not None and lock.locked():
        lock.release()
