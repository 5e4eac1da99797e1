"""Linear solves of the Newton systems: the solver the policy chooses
(:func:`msslib.solvers.policy.choose_linear_solver`), AMG-preconditioned CG with a kept
hierarchy, the direct fallback."""

from __future__ import annotations

import warnings

import numpy as np

from .amg import _preconditioner
from .amg_cycle import _matvec_of, _VCycle
from .direct import _direct_solve
from .policy import as_symmetric, banded_cholesky_is_cheap, choose_factorisation, choose_linear_solver
from .protocol import NewtonFailure


def solve_linear_system(A, b, method, symmetric, messages, context=None, rtol=1e-10, truncate=False):
    """Solve ``A x = b``; raise NewtonFailure when the matrix is singular or the solve fails.

    The solver is the one :func:`~msslib.solvers.policy.choose_linear_solver` chooses; a matrix
    declared non-symmetric that is symmetric to round-off is solved as symmetric
    (:func:`~msslib.solvers.policy.as_symmetric`).
    ``context`` (optional dict) holds ``dim`` and ``coords`` (free nodes) for the AMG near-null
    space and a ``cache`` where the AMG hierarchy is kept and reused for the next matrices
    (Newton iterations, load steps, later static solves of the same problem, time steps) as long
    as CG converges fast with it (a kept one is given up as soon as CG passes that limit); a kept
    compiled V-cycle smooths with each new matrix's values and diagonal blocks
    (:meth:`_VCycle.update`, :meth:`_VCycle.refresh_diagonal`).  ``rtol`` is the CG tolerance
    (relative to ``||b||``).  With ``truncate``, a CG run that meets negative
    curvature returns its last iterate (truncated Newton: used under an energy line search)
    instead of falling back to sparse LU."""
    A, symmetric = as_symmetric(A, symmetric)  # symmetric to round-off: the symmetric way
    indefinite = (not truncate and context is not None and bool(context.get("indefinite"))
                  and choose_factorisation(A.shape[0], symmetric) == "pardiso")
    choice = choose_linear_solver(method, A.shape[0], symmetric, lambda: banded_cholesky_is_cheap(A, context),
                                  indefinite)
    if choice == "user":
        x = np.asarray(method(A, b), dtype=float)
        if not np.all(np.isfinite(x)):
            raise NewtonFailure("user linear solver returned non-finite values")
        return x
    n = A.shape[0]
    if choice == "cg":
        cache = context.setdefault("cache", {}) if context is not None else {}
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                maxiter = max(1000, int(20 * np.sqrt(n)))
                M = cache.get("M") if cache.get("shape") == A.shape else None
                reused = M is not None
                if reused and isinstance(M, _VCycle) and M.update(A):  # smooth with this matrix
                    M.refresh_diagonal()
                if M is None:
                    M = _preconditioner(A, context)
                # iterations per decade of residual reduction: comparable across tolerances
                decades = max(1.0, -np.log10(max(rtol, 1e-300)))
                limit = 2.0 * cache.get("per_decade", maxiter) * decades + 10
                # a kept hierarchy is given up as soon as CG exceeds the limit, not at maxiter
                x, info, its = _pcg(A, b, M, rtol, min(maxiter, int(limit) + 1) if reused else maxiter)
                total = its
                if reused and (info > 0 or its > limit):
                    # the kept hierarchy no longer fits the matrix: rebuild it and solve again
                    M = _preconditioner(A, context)
                    reused = False
                    x, info, its = _pcg(A, b, M, rtol, maxiter)
                    total += its
                if not reused and info == 0:
                    cache.update(M=M, shape=A.shape, per_decade=its / decades)
                if context is not None:
                    context["cg_iterations"] = context.get("cg_iterations", 0) + total
            if np.all(np.isfinite(x)):
                if info == 0:
                    return x
                if info < 0 and truncate:
                    # negative curvature: the CG iterate reached so far (a descent direction of
                    # the energy); the line search and the Newton test decide what it is worth
                    if context is not None:
                        context["negative_curvature"] = context.get("negative_curvature", 0) + 1
                    return x
            cache.clear()
            if info < 0 and context is not None:
                context["indefinite"] = True  # a symmetric indefinite factorisation takes the next ones
            what = "met negative curvature" if info < 0 else f"did not converge in {maxiter} iterations"
            messages.append(f"CG {what}; falling back to a direct solve")
        except (RuntimeError, ValueError, ArithmeticError) as exc:
            cache.clear()
            messages.append(f"preconditioned CG failed ({exc}); falling back to a direct solve")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            x = _direct_solve(A, b, symmetric, context, choose_factorisation(n, symmetric))
    except RuntimeError as exc:  # "Factor is exactly singular"
        raise NewtonFailure(f"singular stiffness matrix ({exc})") from None
    if not np.all(np.isfinite(x)):
        raise NewtonFailure("linear solve produced non-finite values (singular stiffness?)")
    return x


def _pcg(A, b, M, rtol, maxiter):
    """Preconditioned conjugate gradients from zero, stopping at ``||b - A x|| <= rtol ||b||``.

    Returns ``(x, info, iterations)``: ``info`` 0 when converged, 1 when ``maxiter`` was reached,
    -1 when a search direction of non-positive curvature ``p.A p <= 0`` was met (``A`` or the
    preconditioner is not positive definite); ``x`` is then the last iterate, or the
    preconditioned residual direction scaled by ``r.z / |p.A p|`` if that happens at the first
    iteration (for an SPD preconditioner, both are descent directions of ``x.A x / 2 - b.x``)."""
    b = np.asarray(b, dtype=float)
    n = b.shape[0]
    x = np.zeros(n)
    bnorm = float(np.linalg.norm(b))
    if bnorm == 0.0:
        return x, 0, 0
    tol = rtol * bnorm
    matvec = _matvec_of(A)
    r = b.copy()
    z = np.asarray(M @ r, dtype=float).ravel()
    rz = float(r @ z)
    p = z.copy()
    for k in range(1, maxiter + 1):
        Ap = matvec(p)
        pAp = float(p @ Ap)
        if not (pAp > 0.0 and rz > 0.0):
            if k == 1:
                scale = rz / abs(pAp) if pAp != 0.0 and np.isfinite(pAp) and rz > 0 else 1.0
                x = p * scale
            return x, -1, k
        alpha = rz / pAp
        x += alpha * p
        r -= alpha * Ap
        if float(np.linalg.norm(r)) <= tol:
            return x, 0, k
        z = np.asarray(M @ r, dtype=float).ravel()
        rz_new = float(r @ z)
        p *= rz_new / rz
        p += z
        rz = rz_new
    return x, 1, maxiter
