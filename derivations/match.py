"""Matching an MSS stiffness matrix against an FEM element stiffness matrix.

``match_exact`` equates the two matrices entry by entry and solves for the unknown MSS coefficients
*together with* condition symbols (Poisson's ratio, free node coordinates, ...): the conditions under
which an exact match exists come out of the equations instead of being assumed. ``least_squares``
minimises the squared Frobenius distance (Lloyd et al.'s criterion) and reports the residual.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp


def _equations(K_fem: sp.Matrix, K_mss: sp.Matrix):
    if K_fem.shape != K_mss.shape:
        raise ValueError(f"shape mismatch {K_fem.shape} vs {K_mss.shape}")
    eqs = []
    for i in range(K_fem.rows):
        for j in range(i, K_fem.cols):
            for e in {K_fem[i, j] - K_mss[i, j], K_fem[j, i] - K_mss[j, i]}:
                num = sp.numer(sp.together(sp.expand(e)))
                num = sp.expand(num)
                if num != 0 and num not in eqs and -num not in eqs:
                    eqs.append(num)
    return eqs


@dataclass
class ExactMatch:
    """Exact solutions of K_fem = K_mss. ``solutions`` lists dicts over unknowns and condition symbols;
    an empty list proves that no exact match exists."""

    unknowns: tuple
    conditions: tuple
    equations: list
    solutions: list = field(default_factory=list)

    @property
    def exists(self) -> bool:
        return bool(self.solutions)


def match_exact(K_fem, K_mss, unknowns, conditions=(), accept=None) -> ExactMatch:
    """Solve K_fem == K_mss for ``unknowns`` and ``conditions``.

    ``accept(solution) -> bool`` filters solutions (e.g. positive stiffness, a node above the x-axis).
    """
    eqs = _equations(K_fem, K_mss)
    syms = list(unknowns) + list(conditions)
    sols = sp.solve(eqs, syms, dict=True) if eqs else [{}]
    out = []
    for s in sols:
        s = {k: sp.simplify(v) for k, v in s.items()}
        if any(sym not in s for sym in syms):
            # free symbols left: keep, they are part of the family of solutions
            pass
        if accept is None or accept(s):
            out.append(s)
    return ExactMatch(tuple(unknowns), tuple(conditions), eqs, out)


@dataclass
class LeastSquares:
    """Least-squares optimum of sum_ij (K_fem - K_mss)_ij^2 over ``unknowns``."""

    unknowns: tuple
    solution: dict
    residual: sp.Expr  # the minimised sum of squares
    relative_residual: sp.Expr  # residual / sum_ij K_fem_ij^2
    gradient: list  # gradient at the optimum (simplifies to zero)
    hessian: sp.Matrix  # Hessian of the objective (positive definite at a strict minimum)


def least_squares(K_fem, K_mss, unknowns) -> LeastSquares:
    """Minimise sum_ij (K_fem - K_mss)_ij^2. When K_mss is linear in the unknowns (springs and
    volume terms at rest are), this is solved through the normal equations G theta = b with
    G_pq = <dK/dp, dK/dq> and b_p = <dK/dp, K_fem - K_mss(0)> (Frobenius products), exactly."""
    unknowns = list(unknowns)
    zero = {u: 0 for u in unknowns}
    basis = [K_mss.applyfunc(lambda e, u=u: sp.diff(e, u)) for u in unknowns]
    linear = all(sp.simplify(sp.diff(b, u)) == sp.zeros(*b.shape) for b in basis for u in unknowns)
    if not linear:
        raise NotImplementedError("least squares is implemented for MSS stiffness linear in the unknowns")
    R0 = (K_fem - K_mss.subs(zero))

    def dot(A, B):
        return sp.simplify(sum(a * b for a, b in zip(A, B)))

    G = sp.Matrix(len(unknowns), len(unknowns), lambda p, q: dot(basis[p], basis[q]))
    b = sp.Matrix([dot(B, R0) for B in basis])
    theta = G.LUsolve(b).applyfunc(sp.simplify)
    sol = dict(zip(unknowns, theta))
    R = (K_fem - K_mss.subs(sol)).applyfunc(sp.simplify)
    res = dot(R, R)
    ref = dot(K_fem, K_fem)
    # gradient of the objective at the optimum: -2 <dK/dp, R>
    grad = [sp.simplify(-2 * dot(B, R)) for B in basis]
    return LeastSquares(tuple(unknowns), sol, res, sp.simplify(res / ref), grad, 2 * G)


def frobenius(A, B):
    """<A, B> = sum_ij A_ij B_ij, cancelled to one rational function (products with a zero left out)."""
    return sp.factor(sp.cancel(sum(x * y for x, y in zip(A, B) if x != 0 and y != 0)))


def normal_equations(basis, K_fem):
    """``(G, b)`` of the least-squares fit ``sum_p k_p basis_p`` to ``K_fem``: ``G_pq = <basis_p, basis_q>``
    (symmetric, each pair once), ``b_p = <basis_p, K_fem>``, each entry cancelled to one rational
    function; left unsolved (with a symbolic shape :func:`least_squares`, which simplifies the whole
    solution, takes minutes)."""
    n = len(basis)
    G = sp.Matrix(n, n, lambda p, q: frobenius(basis[p], basis[q]) if p <= q else 0)
    G = G + G.T - sp.diag(*[G[p, p] for p in range(n)])
    b = sp.Matrix([frobenius(B, K_fem) for B in basis])
    return G, b


def is_positive_definite(H: sp.Matrix) -> bool:
    """Sylvester's criterion, exactly (for numeric or sign-determined symbolic minors)."""
    for n in range(1, H.rows + 1):
        m = sp.simplify(H[:n, :n].det())
        if not (m.is_positive):
            return False
    return True
