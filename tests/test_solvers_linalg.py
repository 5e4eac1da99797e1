"""Tests of the linear algebra of msslib.solvers: free-dof extraction, banded direct solves, CG, the
forcing term and the node-block matrices."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from solver_problems import SpringNetwork

from msslib.models.golec import golec_cube_springs
from msslib.solvers import (
    static_solve,
)

# ---------------------------------------------------------------------------------------------
# linear algebra of the static solver: free-dof extraction, banded direct, CG, forcing term
# ---------------------------------------------------------------------------------------------


def lattice_block(nx, ny, nz, *, k3=2.0, g=0.05):
    """3D lattice of nodes joined to their 26 neighbours (springs), bottom layer fixed, a uniform
    downward load; dofs interleaved by node (``dim = 3``), so the AMG path sees node blocks."""
    idx = np.arange(nx * ny * nz).reshape(nx, ny, nz)
    pts = np.stack(np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij"), -1).reshape(-1, 3)
    edges = []
    for di in (0, 1):
        for dj in (-1, 0, 1):
            for dk in (-1, 0, 1):
                if (di, dj, dk) <= (0, 0, 0):
                    continue
                a = idx[max(0, -di):nx - max(0, di), max(0, -dj):ny - max(0, dj), max(0, -dk):nz - max(0, dk)]
                b = idx[max(0, di):nx - max(0, -di) or None, max(0, dj):ny - max(0, -dj) or None,
                        max(0, dk):nz - max(0, -dk) or None]
                edges.append(np.column_stack([a.ravel(), b.ravel()]))
    edges = np.concatenate(edges)
    f = np.zeros(pts.size)
    f[2::3] = -g
    fixed = np.flatnonzero(pts[:, 2] == 0)
    return SpringNetwork(pts.astype(float), edges, 1.0, k3=k3, fixed_nodes=fixed, f_ext=f)


def test_submatrix_plan_matches_fancy_indexing_and_is_reused():
    from msslib.solvers import PlanCache
    from msslib.solvers.submatrices import submatrix

    rng = np.random.default_rng(4)
    plans = PlanCache()
    for t in range(30):
        K = sp.random(40, 40, 0.08, random_state=t, format="csr") + (sp.eye(40) if t % 2 else 0)
        K = sp.csr_matrix(K)
        K.sum_duplicates()
        free = rng.random(40) < 0.7
        idx = np.flatnonzero(free)
        for _ in range(2):  # the second call goes through the cached plan
            A = submatrix(K, free, plans=plans)
            A.check_format(full_check=True)
            assert A.shape == (len(idx), len(idx))
            assert abs(A - K[idx][:, idx]).max() == 0 if A.nnz else K[idx][:, idx].nnz == 0
        K2 = K.copy()
        K2.data = rng.standard_normal(K2.nnz)  # same pattern, new values
        assert abs(submatrix(K2, free, plans=plans) - K2[idx][:, idx]).max() == 0 if K2[idx][:, idx].nnz else True
        assert plans.entries[0]["free"].tolist() == free.tolist()  # the plan was kept


def clamped_golec_block(nx, ny, nz, nu=0.3):
    """Golec cube lattice of nx x ny x nz 1 cm cells, clamped at x = 0."""
    from msslib import mesh as M
    from msslib.system import Model

    mesh = M.hex_grid(0.01 * nx, 0.01 * ny, 0.01 * nz, nx, ny, nz)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[mesh.points[:, 0] < 1e-12] = True
    return Model(mesh, golec_cube_springs(mesh, [(1e4, nu)], 1.0), fixed=fixed)


def test_submatrix_refill_in_place_equals_fresh_extraction():
    from msslib.solvers import PlanCache
    from msslib.solvers.submatrices import submatrix

    model = clamped_golec_block(3, 2, 2)
    free = model.free
    idx = np.flatnonzero(free)
    rng = np.random.default_rng(5)
    K = model.stiffness(model.x0)
    plans = PlanCache()
    A = submatrix(K, free, plans=plans)
    for _ in range(2):
        x = model.x0 + 1e-3 * rng.standard_normal(model.n_dof)
        K = model.stiffness(x, out=K)
        A2 = submatrix(K, free, out=A, plans=plans)
        assert A2 is A  # values overwritten in place
        ref = K.tocsc()[idx][:, idx]
        assert abs(A2 - ref).max() == 0.0
    # a matrix of another pattern is not reused
    other = sp.csr_matrix(np.eye(len(idx)))
    assert submatrix(K, free, out=other, plans=plans) is not other
    # without a plan cache the plan is made for the call: the result is not refilled in place
    assert submatrix(K, free, out=A) is not A


@pytest.mark.parametrize("shift", [0.0, -0.5])  # SPD (banded Cholesky) and indefinite (banded LU)
def test_banded_direct_solve_matches_dense(shift):
    from msslib.solvers.direct import _direct_solve
    from msslib.solvers.context import linear_solve_context

    prob = lattice_block(3, 3, 6)
    x = prob.x0()
    free = prob.free
    from msslib.solvers.submatrices import submatrix

    A = submatrix(prob.stiffness(x) + shift * sp.eye(prob.n_dof, format="csr"), free)
    A = sp.csr_matrix(A)
    A.sum_duplicates()
    b = np.random.default_rng(0).standard_normal(A.shape[0])
    ctx = linear_solve_context(prob, x, free)
    sol = _direct_solve(A, b, True, ctx)
    ref = np.linalg.solve(A.toarray(), b)
    np.testing.assert_allclose(sol, ref, rtol=1e-8, atol=1e-10 * np.abs(ref).max())
    assert bool(ctx.get("band_indefinite")) == (np.linalg.eigvalsh(A.toarray()).min() < 0)
    # the band arrays kept in the context are refilled for new values of the same pattern
    A2 = A.copy()
    A2.data *= np.random.default_rng(1).uniform(0.9, 1.1, A2.nnz)
    A2 = sp.csr_matrix(0.5 * (A2 + A2.T))
    A2.sum_duplicates()
    sol2 = _direct_solve(A2, b, True, ctx)
    ref2 = np.linalg.solve(A2.toarray(), b)
    np.testing.assert_allclose(sol2, ref2, rtol=1e-8, atol=1e-10 * np.abs(ref2).max())


def test_pcg_converges_and_detects_negative_curvature():
    from msslib.solvers.linear import _pcg

    n = 100
    K = sp.diags([-np.ones(n - 1), 2.05 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1], format="csr")
    b = np.random.default_rng(2).standard_normal(n)
    identity = sp.eye(n, format="csr")
    x, info, its = _pcg(K, b, identity, 1e-10, 1000)
    assert info == 0 and 0 < its <= n and np.linalg.norm(K @ x - b) <= 1e-10 * np.linalg.norm(b)
    # indefinite: a negative-curvature direction is reported, and what is returned still descends
    # the quadratic model 1/2 x.A x - b.x (direction of positive b.x)
    Kn = K - 1.0 * identity
    x, info, its = _pcg(Kn, b, identity, 1e-10, 1000)
    assert info == -1 and np.all(np.isfinite(x)) and float(b @ x) > 0


def test_forcing_term_loose_far_tight_near():
    from msslib.solvers.statics import _ETA_MAX, _forcing_term

    threshold = 1e-8
    assert _forcing_term(1.0, None, None, threshold) == _ETA_MAX
    # quadratic convergence phase: eta follows (r_k / r_k-1)^2
    assert _forcing_term(1e-3, 1e-1, 1e-2, threshold) == pytest.approx(0.9e-4)
    # close to the threshold it never asks more than needed (0.1 threshold / r), nor < 1e-10
    assert _forcing_term(1e-6, 1e-3, 1e-4, threshold) == pytest.approx(1e-3)
    assert _forcing_term(1e-20, 1e-3, 1e-4, 1e-30) == 1e-10


def test_static_solve_cg_and_direct_agree_on_a_nonlinear_lattice():
    prob = lattice_block(4, 4, 7)
    x0 = prob.x0()
    direct = static_solve(prob, x0, linear_solver="direct", tol=1e-10)
    iterative = static_solve(prob, x0, linear_solver="cg", tol=1e-10)
    assert direct.cg_iterations == 0 and iterative.cg_iterations > 0
    for r in (direct, iterative):
        assert r.residuals[-1][-1] <= 1e-10 * r.force_scale
        assert np.linalg.norm(prob.force(r.x)[prob.free]) <= 1e-10 * r.force_scale
    u = direct.x - x0
    assert np.abs(u).max() > 0.05  # a genuinely deformed state
    np.testing.assert_allclose(iterative.x, direct.x, rtol=0, atol=1e-7 * np.abs(u).max())
    # the inexact Newton (loose CG early on) does not cost many more Newton iterations
    assert iterative.total_iterations <= direct.total_iterations + 3


def test_free_node_blocks_as_bsr_equal_the_csr_block_and_refill_in_place():
    from msslib.solvers.submatrices import _is_node_blocked, _submatrix_bsr
    from msslib.solvers.context import linear_solve_context

    model = clamped_golec_block(3, 2, 2)
    free = model.free
    idx = np.flatnonzero(free)
    ctx = linear_solve_context(model, model.x0, free)
    rng = np.random.default_rng(6)
    K = model.stiffness(model.x0)
    B = _submatrix_bsr(K, ctx["node_free"], 3, plans=ctx)
    assert B.format == "bsr" and B.blocksize == (3, 3)
    B.check_format(full_check=True)
    for _ in range(2):
        K = model.stiffness(model.x0 + 1e-3 * rng.standard_normal(model.n_dof), out=K)
        B2 = _submatrix_bsr(K, ctx["node_free"], 3, out=B, plans=ctx)
        assert B2 is B  # values overwritten in place
        np.testing.assert_array_equal(B2.toarray(), K.toarray()[np.ix_(idx, idx)])
    # patterns that are not whole node blocks are refused (the caller then extracts a CSR block)
    assert not _is_node_blocked(sp.csr_matrix(np.eye(6)).indptr, sp.csr_matrix(np.eye(6)).indices, 3)
    assert _submatrix_bsr(sp.csr_matrix(np.eye(6)), np.ones(2, dtype=bool), 3) is None
    full = sp.csr_matrix(np.ones((6, 6)))
    assert _is_node_blocked(full.indptr, full.indices, 3)
    holed = sp.csr_matrix(np.ones((6, 6)) - np.eye(6)[::-1])  # one entry missing per row
    assert _submatrix_bsr(holed, np.ones(2, dtype=bool), 3) is None
    assert _submatrix_bsr(full, np.ones(3, dtype=bool), 3) is None  # mask of the wrong size


def test_cg_newton_systems_go_through_node_blocks(monkeypatch):
    import msslib.solvers as S

    prob = lattice_block(4, 4, 7)
    x0 = prob.x0()
    calls = []
    real = S.submatrices._submatrix_bsr

    def spy(*a, **kw):
        out = real(*a, **kw)
        calls.append(None if out is None else out.format)
        return out

    monkeypatch.setattr(S.statics, "_submatrix_bsr", spy)  # where the Newton iteration looks it up
    iterative = static_solve(prob, x0, linear_solver="cg", tol=1e-10)
    assert calls and set(calls) == {"bsr"}
    direct = static_solve(prob, x0, linear_solver="direct", tol=1e-10)
    assert len(calls) == iterative.total_iterations  # the direct solver keeps the CSR block
    u = direct.x - x0
    np.testing.assert_allclose(iterative.x, direct.x, rtol=0, atol=1e-7 * np.abs(u).max())


@pytest.mark.parametrize("shape", [(16, 4, 4), (12, 12, 12), (30, 2, 2), (8, 8, 3)])
def test_band_width_bound_never_exceeds_the_bandwidth_found(shape, monkeypatch):
    """The breadth-first bound that skips the band orderings is a lower bound of the bandwidth
    of every ordering, so it never rejects a body the banded Cholesky would take."""
    from msslib.solvers import BAND_AUTO_COST
    from msslib.solvers.direct import _band_plan
    from msslib.solvers.policy import _band_surely_wide
    from msslib.solvers.submatrices import _bsr_entry, _eccentricity, submatrix
    from msslib.solvers.context import linear_solve_context

    nx, ny, nz = shape
    model = clamped_golec_block(nx, ny, nz)
    K = model.stiffness(model.x0)
    ctx = linear_solve_context(model, model.x0, model.free)
    entry = _bsr_entry(K, ctx["node_free"], 3)
    e = _eccentricity(entry["bptr"], entry["bind"])
    # 26-neighbour lattice: Chebyshev distance from the first free node (a corner of layer x = 1)
    assert e == max(nx - 1, ny, nz)
    A = submatrix(K, model.free)
    import msslib.solvers as S

    monkeypatch.setattr(S.direct, "BAND_COST_MAX", float("inf"))  # a plan whatever the bandwidth
    plan = _band_plan(sp.csr_matrix(A.toarray()), ctx)
    n = A.shape[0]
    assert plan["bw"] >= (n - 1) / (2.0 * e)
    cheap = n * (plan["bw"] + 1.0) ** 2 <= BAND_AUTO_COST
    assert not (cheap and _band_surely_wide(entry, 3))
    if shape == (12, 12, 12):
        assert _band_surely_wide(entry, 3)
    if shape in ((16, 4, 4), (30, 2, 2)):
        assert cheap and not _band_surely_wide(entry, 3)


def test_linear_solver_policy_decides_every_case_in_one_place():
    """choose_linear_solver: explicit choices pass through, "auto" is direct up to
    ITERATIVE_THRESHOLD or for non-symmetric systems, CG above BAND_PLAN_MAX_DOFS, and between
    the two asks whether the band is cheap (only then)."""
    from msslib.solvers import BAND_PLAN_MAX_DOFS, ITERATIVE_THRESHOLD, choose_linear_solver

    def never():
        raise AssertionError("band cost asked for")

    assert choose_linear_solver(lambda A, b: b, 10, True, never) == "user"
    assert choose_linear_solver("cg", 10, False, never) == "cg"
    assert choose_linear_solver("direct", 10**6, True, never) == "direct"
    assert choose_linear_solver("auto", ITERATIVE_THRESHOLD, True, never) == "direct"
    assert choose_linear_solver("auto", 10**6, False, never) == "direct"
    assert choose_linear_solver("auto", BAND_PLAN_MAX_DOFS + 1, True, never) == "cg"
    mid = ITERATIVE_THRESHOLD + 1
    assert choose_linear_solver("auto", mid, True, lambda: True) == "direct"
    assert choose_linear_solver("auto", mid, True, lambda: False) == "cg"
    with pytest.raises(ValueError, match="linear_solver"):
        choose_linear_solver("lu", 10, True)


def test_solver_errors_are_defined_once_and_fem_failures_are_convergence_errors():
    import msslib.errors as E
    import msslib.solvers as S
    from msslib import fem
    from msslib import mesh as M

    assert S.ConvergenceError is E.ConvergenceError and S.DivergenceError is E.DivergenceError
    assert E.ConvergenceError.__module__ == "msslib.errors"
    mesh = M.hex_grid(2.0, 1.0, 1.0, 2, 1, 1)
    fixed = np.zeros((mesh.n_nodes, 3), bool)
    fixed[np.isclose(mesh.points[:, 0], 0.0)] = True
    f = np.zeros((mesh.n_nodes, 3))
    f[np.isclose(mesh.points[:, 0], 2.0), 0] = 50.0
    with pytest.raises(E.ConvergenceError, match=r"static_solve did not converge: load step \d+ \(nominal step 1 of 1\)"):
        fem.solve_nonlinear(mesh, 1.0, 0.3, fixed=fixed, nodal_forces=f, steps=1, max_iter=2, max_halvings=1)
