"""Tests of the algebraic multigrid of msslib.solvers: set-up, smoothers, V-cycle and compiled
kernels against pyamg and dense products, and the hierarchy kept between solves."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from solver_problems import lattice_system

from msslib.models.golec import golec_cube_springs
from msslib.solvers import (
    static_solve,
)

# ---------------------------------------------------------------------------------------------
# linear algebra of the static solver: free-dof extraction, banded direct, CG, forcing term
# ---------------------------------------------------------------------------------------------


_lattice_system = lattice_system


def test_block_jacobi_radius_is_the_largest_eigenvalue():
    from scipy.linalg import eigh

    from msslib.solvers.amg_kernels import _block_diag_inverse
    from msslib.solvers.amg import _block_jacobi_radius

    A, _, _ = _lattice_system(5)
    dinv = _block_diag_inverse(A.indptr, A.indices, A.data)
    D = sp.block_diag(list(np.linalg.inv(dinv))).toarray()
    lam = eigh(A.toarray(), D, eigvals_only=True)[-1]
    rho = _block_jacobi_radius(A, dinv)
    assert 0.97 * lam <= rho <= lam * (1 + 1e-10)  # a Ritz value: from below, close


def test_finest_level_prolongator_is_the_jacobi_smoothed_tentative_one():
    from pyamg.aggregation import fit_candidates, standard_aggregation
    from pyamg.strength import symmetric_strength_of_connection

    from msslib.solvers.amg import _SA_OPTIONS, _block_jacobi_radius, _sa_solver
    from msslib.solvers.amg_kernels import _block_diag_inverse

    A, B, _ = _lattice_system(8)
    ml = _sa_solver(A, B, 3)
    assert ml is not None and len(ml.levels) >= 2
    T, _ = fit_candidates(standard_aggregation(symmetric_strength_of_connection(A, 0.0))[0], B)
    dinv = _block_diag_inverse(A.indptr, A.indices, A.data)
    Dinv = sp.block_diag(list(dinv)).toarray()
    omega = _SA_OPTIONS["smooth"][1]["omega"]
    P_ref = T.toarray() - omega / _block_jacobi_radius(A, dinv) * Dinv @ A.toarray() @ T.toarray()
    np.testing.assert_allclose(ml.levels[0].P.toarray(), P_ref, rtol=0, atol=1e-12 * np.abs(P_ref).max())
    A_c = ml.levels[1].A.toarray()
    np.testing.assert_allclose(A_c, P_ref.T @ A.toarray() @ P_ref, rtol=0, atol=1e-10 * np.abs(A_c).max())


def test_own_finest_level_preconditions_as_well_as_pyamg():
    import pyamg

    from msslib.solvers.amg import _SA_OPTIONS, _sa_solver
    from msslib.solvers.linear import _pcg

    A, B, _ = _lattice_system(9)
    b = np.random.default_rng(8).standard_normal(A.shape[0])
    its = {}
    for name, ml in (("own", _sa_solver(A, B, 3)), ("pyamg", pyamg.smoothed_aggregation_solver(A, B=B, **_SA_OPTIONS))):
        x, info, its[name] = _pcg(A, b, ml.aspreconditioner(cycle="V"), 1e-10, 500)
        assert info == 0
        assert np.linalg.norm(A @ x - b) <= 1e-10 * np.linalg.norm(b) * 1.0001
    assert its["own"] <= its["pyamg"] + 1


@pytest.mark.parametrize("d", [3, 6])
def test_compiled_block_gauss_seidel_sweeps_equal_pyamg(d):
    from pyamg.relaxation.relaxation import block_gauss_seidel

    from msslib.solvers.amg_kernels import _block_diag_inverse
    from msslib.solvers.amg_cycle import _BlockGaussSeidel

    rng = np.random.default_rng(d)
    nb = 40
    pattern = sp.random(nb, nb, 0.15, random_state=d, format="csr") + sp.eye(nb)
    pattern = (pattern + pattern.T).tocsr()
    M = sp.kron(pattern, np.ones((d, d))).toarray() * rng.standard_normal((nb * d, nb * d))
    M = M + M.T + 4 * d * np.eye(nb * d)  # symmetric, blocks on a symmetric node pattern
    A = sp.bsr_matrix(M, blocksize=(d, d))
    A.sort_indices()
    dinv = _block_diag_inverse(A.indptr, A.indices, A.data)
    np.testing.assert_allclose(dinv[3], np.linalg.inv(M[3 * d:4 * d, 3 * d:4 * d]), rtol=1e-12, atol=1e-14)
    b = rng.standard_normal(nb * d)
    for forward, sweep in ((True, "forward"), (False, "backward")):
        x0 = rng.standard_normal(nb * d)
        x_ref, x = x0.copy(), x0.copy()
        block_gauss_seidel(A, x_ref, b, iterations=1, sweep=sweep, blocksize=d, Dinv=dinv)
        _BlockGaussSeidel(dinv, forward)(A, x, b)
        np.testing.assert_allclose(x, x_ref, rtol=1e-12, atol=1e-12 * np.abs(x_ref).max())
    with pytest.raises(TypeError):
        _BlockGaussSeidel(dinv, True)(A, np.zeros((nb * d, 1)), b)


def _count_tangent_fills(monkeypatch, model):
    """Count the calls of ``model.stiffness_blocks`` ("blocks") and ``model.stiffness``
    ("full"); returns the live dict of counts."""
    calls = {"blocks": 0, "full": 0}

    def count(name, fn):
        def wrapped(*a, **kw):
            calls[name] += 1
            return fn(*a, **kw)
        return wrapped

    monkeypatch.setattr(model, "stiffness_blocks", count("blocks", model.stiffness_blocks))
    monkeypatch.setattr(model, "stiffness", count("full", model.stiffness))
    return calls


def test_model_newton_systems_filled_as_free_node_blocks(monkeypatch):
    """With CG, a Model's Newton systems come from ``stiffness_blocks`` (no full tangent is
    formed); the solution equals the direct solve's."""
    from msslib import mesh as M
    from msslib import terms as T
    from msslib.system import Model

    mesh = M.hex_grid(0.05, 0.02, 0.02, 5, 2, 2)
    masses = M.lumped_masses(mesh, 1000.0)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[mesh.points[:, 0] < 1e-12] = True
    model = Model(mesh, golec_cube_springs(mesh, [(1e3, 0.3)], 1.0) + [T.Gravity(masses, [0, 0, -9.81])],
                  fixed=fixed)
    calls = _count_tangent_fills(monkeypatch, model)
    iterative = static_solve(model, model.x0, linear_solver="cg", tol=1e-10)
    assert calls == {"blocks": iterative.total_iterations, "full": 0}
    direct = static_solve(model, model.x0, linear_solver="direct", tol=1e-10)
    assert calls["blocks"] == iterative.total_iterations and calls["full"] == direct.total_iterations
    u = direct.x - model.x0
    assert np.abs(u).max() > 1e-3
    np.testing.assert_allclose(iterative.x, direct.x, rtol=0, atol=1e-7 * np.abs(u).max())


def test_galerkin_product_equals_the_dense_one():
    import msslib.solvers as S

    A, B, _ = _lattice_system(8)
    ml = S.amg._sa_solver(A, B, 3)
    P = ml.levels[0].P
    A_c = S.amg._galerkin(A, P)
    assert A_c.format == "bsr" and A_c.blocksize == (B.shape[1], B.shape[1])
    ref = (P.T @ A @ P).toarray()
    np.testing.assert_allclose(A_c.toarray(), ref, rtol=0, atol=1e-12 * np.abs(ref).max())
    # generic block sizes (the unrolled loops are for 3 x d blocks of A)
    rng = np.random.default_rng(5)
    for d, m in ((2, 3), (6, 6), (3, 2)):
        nb, nc = 25, 7
        pattern = sp.random(nb, nb, 0.2, random_state=d + m, format="csr") + sp.eye(nb)
        pattern = (pattern + pattern.T).tocsr()
        M = sp.kron(pattern, np.ones((d, d))).toarray() * rng.standard_normal((nb * d, nb * d))
        M = M + M.T
        Pd = sp.kron(sp.random(nb, nc, 0.3, random_state=m, format="csr"), np.ones((d, m))).toarray()
        Pd *= rng.standard_normal(Pd.shape)
        C = S.amg._galerkin(sp.bsr_matrix(M, blocksize=(d, d)), sp.bsr_matrix(Pd, blocksize=(d, m)))
        ref = Pd.T @ M @ Pd
        np.testing.assert_allclose(C.toarray(), ref, rtol=0, atol=1e-12 * np.abs(ref).max())


def test_compiled_v_cycle_equals_pyamg_cycle():
    """The compiled V-cycle (forward sweep from zero on the lower blocks, residual on the others
    fused with the restriction, prolongation, backward sweep) is pyamg's V-cycle with the same
    smoothers, on a hierarchy with 3 x 3 and 6 x 6 block levels and on the own finest level."""
    import pyamg

    import msslib.solvers as S

    A, B, _ = _lattice_system(8)
    b = np.random.default_rng(3).standard_normal(A.shape[0])
    deep = S.amg_cycle._compiled_smoothers(pyamg.smoothed_aggregation_solver(A, B=B, **dict(S.amg._SA_OPTIONS, max_coarse=8)))
    assert len(deep.levels) >= 3 and deep.levels[1].A.blocksize == (6, 6)
    for ml in (deep, S.amg._sa_solver(A, B, 3)):
        cycle = S.amg_cycle._VCycle.build(ml, single=False)
        assert cycle is not None
        ref = ml.aspreconditioner(cycle="V") @ b
        for _ in range(2):  # work vectors are reused: a second application gives the same
            z = cycle @ b
            np.testing.assert_allclose(z, ref, rtol=0, atol=1e-12 * np.abs(ref).max())
        # a symmetric operator (CG needs it)
        c = np.random.default_rng(4).standard_normal(A.shape[0])
        assert abs(c @ (cycle @ b) - b @ (cycle @ c)) <= 1e-10 * abs(c @ (cycle @ b))
    # single precision on the finest level: the exact V-cycle of the rounded matrix and
    # prolongator; after update(), of the rounded new matrix
    ml = S.amg._sa_solver(A, B, 3)
    cycle = S.amg_cycle._VCycle.build(ml, single=True)
    assert cycle.levels[0]["a_data"].dtype == np.float32 and cycle.levels[0]["p_data"].dtype == np.float32
    v = np.random.default_rng(6).standard_normal(A.shape[0])
    np.testing.assert_allclose(ml.levels[0].R @ v, ml.levels[0].P.T @ v, rtol=1e-14, atol=0)  # lazy R
    A2 = A.copy()
    A2.data *= 1.0 + 0.1 * np.random.default_rng(5).random(A2.data.shape[0])[:, None, None]
    approx = cycle @ b
    assert cycle.update(A2)
    updated = cycle @ b
    assert not cycle.update(A.tocsr()[:30, :30].tobsr(blocksize=(3, 3)))  # another pattern: ignored
    assert not cycle.update(sp.bsr_matrix(sp.identity(A.shape[0]), blocksize=(3, 3)))  # same shape
    for mat, z in ((A, approx), (A2, updated)):
        lvl = ml.levels[0]
        keep = lvl.A, lvl.P, lvl.R
        lvl.A = sp.bsr_matrix((mat.data.astype(np.float32).astype(float), mat.indices, mat.indptr), shape=mat.shape)
        lvl.P = sp.bsr_matrix((keep[1].data.astype(np.float32).astype(float), keep[1].indices, keep[1].indptr),
                              shape=keep[1].shape)
        lvl.R = lvl.P.T.tobsr()
        ref = ml.aspreconditioner(cycle="V") @ b
        lvl.A, lvl.P, lvl.R = keep
        np.testing.assert_allclose(z, ref, rtol=0, atol=1e-12 * np.abs(ref).max())
    assert np.abs(approx - S.amg_cycle._VCycle.build(ml, single=False) @ b).max() <= 1e-5 * np.abs(approx).max()
    # the preconditioner that CG gets is the compiled cycle
    ctx = {"dim": 3, "coords": _lattice_system(8)[2]["coords"]}
    assert isinstance(S.amg._amg_preconditioner(A, ctx), S.amg_cycle._VCycle)
    # a level without the compiled smoother: no compiled cycle (pyamg's is used)
    plain = pyamg.smoothed_aggregation_solver(A, B=B, **S.amg._SA_OPTIONS)
    assert S.amg_cycle._VCycle.build(plain) is None


def _random_spd_bsr(nb, d, rng):
    """A random symmetric positive definite BSR matrix of nb x nb blocks of size d (sparse block
    pattern, sorted indices, diagonally dominant) and its dense array."""
    pattern = sp.random(nb, nb, 0.2, random_state=d, format="csr") + sp.eye(nb)
    pattern = (pattern + pattern.T).tocsr()
    M = sp.kron(pattern, np.ones((d, d))).toarray() * rng.standard_normal((nb * d, nb * d))
    M = M + M.T + 4 * d * np.eye(nb * d)
    A = sp.bsr_matrix(M, blocksize=(d, d))
    A.sort_indices()
    return A, M


@pytest.mark.parametrize("d,m", [(3, 3), (3, 6), (6, 6), (2, 2)])
def test_compiled_bsr_kernels_equal_dense_products(d, m):
    import msslib.solvers as S

    rng = np.random.default_rng(d * 10 + m)
    nb, nc = 30, 12
    A, M = _random_spd_bsr(nb, d, rng)
    Pd = sp.kron(sp.random(nb, nc, 0.3, random_state=m, format="csr"), np.ones((d, m))).toarray()
    Pd *= rng.standard_normal(Pd.shape)
    P = sp.bsr_matrix(Pd, blocksize=(d, m))
    v = rng.standard_normal(nb * d)
    np.testing.assert_allclose(S.amg_cycle._matvec_of(A)(v), M @ v, rtol=0, atol=1e-12 * np.abs(M @ v).max())
    vc = rng.standard_normal(nc * m)
    np.testing.assert_allclose(S.amg_cycle._matvec_of(P)(vc), Pd @ vc, rtol=0, atol=1e-12 * np.abs(Pd @ vc).max())
    dinv = S.amg_kernels._block_diag_inverse(A.indptr, A.indices, A.data)
    L = np.tril(M, -1) * (np.abs(np.subtract.outer(np.arange(nb * d) // d, np.arange(nb * d) // d)) > 0)
    D = M - L - (np.triu(M, 1) * (np.subtract.outer(np.arange(nb * d) // d, np.arange(nb * d) // d) < 0))
    kernels = ((S.amg_kernels._gs3_forward_from_zero, S.amg_kernels._residual3_restrict),) if d == 3 else ()
    for fwd, res in kernels + ((S.amg_kernels._gs_forward_from_zero, S.amg_kernels._residual_restrict),):
        x, s, bc = np.empty(nb * d), np.empty(nb * d), np.zeros(nc * m)
        fwd(A.indptr, A.indices, A.data, dinv, v, x, s)
        x_ref = np.linalg.solve(D + L, v)  # block forward substitution
        np.testing.assert_allclose(x, x_ref, rtol=0, atol=1e-10 * np.abs(x_ref).max())
        res(A.indptr, A.indices, A.data, x, s, P.indptr, P.indices, P.data, bc)
        ref = Pd.T @ (v - M @ x)
        np.testing.assert_allclose(bc, ref, rtol=0, atol=1e-10 * np.abs(ref).max())
    x0 = rng.standard_normal(nb * d)
    x_ref = x0.copy()
    S.amg_kernels._block_gauss_seidel_sweep(A.indptr, A.indices, A.data, dinv, x_ref, v, False)
    if d == 3:
        x = x0.copy()
        S.amg_kernels._gs3_backward(A.indptr, A.indices, A.data, dinv, x, v)
        np.testing.assert_allclose(x, x_ref, rtol=0, atol=1e-12 * np.abs(x_ref).max())
    x = x0.copy()
    S.amg_kernels._prolong_add(P.indptr, P.indices, P.data, vc, x)
    np.testing.assert_allclose(x, x0 + Pd @ vc, rtol=0, atol=1e-12 * np.abs(Pd @ vc).max())


def _gravity_cube(n, E=1e4):
    from msslib import mesh as M
    from msslib import terms as T
    from msslib.system import Model

    mesh = M.hex_grid(0.1, 0.1, 0.1, n, n, n)
    masses = M.lumped_masses(mesh, 1000.0)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[mesh.points[:, 2] < 1e-12] = True
    return Model(mesh, golec_cube_springs(mesh, [(E, 0.25)], 1.0) + [T.Gravity(masses, [0, 0, -9.81])],
                 fixed=fixed, masses=masses)


def test_repeated_solves_of_a_problem_keep_the_amg_hierarchy(monkeypatch):
    """A second solve of the same model starts with the hierarchy and matrix left by the first
    (no new set-up) and gives the same result; another start, another linear solver or a model
    whose values changed still solve correctly; the state goes with the model."""
    import gc
    import weakref

    import msslib.solvers as S

    builds = []
    original = S.amg._preconditioner

    def counting(A, context=None):
        builds.append(A.shape)
        return original(A, context)

    monkeypatch.setattr(S.linear, "_preconditioner", counting)  # where the linear solve looks it up
    model = _gravity_cube(6)
    direct = static_solve(model, model.x0, linear_solver="direct", tol=1e-10)  # the reference
    first = static_solve(model, model.x0, linear_solver="cg", tol=1e-10)
    assert len(builds) == 1 and first.cg_iterations > 0
    ctx = S.context._kept_context(model)
    K = ctx["K"]
    second = static_solve(model, model.x0, linear_solver="cg", tol=1e-10)
    assert len(builds) == 1  # kept: CG converged as fast with it
    assert S.context._kept_context(model) is ctx and ctx["K"] is K  # the matrix refilled in place
    assert second.cg_iterations == first.cg_iterations
    scale = np.abs(first.x - model.x0).max()
    np.testing.assert_allclose(second.x, first.x, rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(second.x, direct.x, rtol=0, atol=1e-7 * scale)
    # another initial configuration: new context (rigid-body modes of other coordinates)
    x0 = model.x0 + 1e-4 * np.random.default_rng(1).standard_normal(model.n_dof) * model.free
    third = static_solve(model, x0, linear_solver="cg", tol=1e-10)
    assert len(builds) == 2
    np.testing.assert_allclose(third.x, direct.x, rtol=0, atol=1e-6 * scale)
    # a state left by a stiffer model's solve: still converges to the right answer
    soft, stiff = _gravity_cube(6, E=1e4), _gravity_cube(6, E=1e6)
    static_solve(stiff, stiff.x0, linear_solver="cg", tol=1e-10)
    setattr(soft, S.context.ATTRIBUTE, S.context._kept_context(stiff))  # as if the values had changed
    r = static_solve(soft, soft.x0, linear_solver="cg", tol=1e-10)
    np.testing.assert_allclose(r.x, direct.x, rtol=0, atol=1e-7 * scale)
    assert r.residuals[-1][-1] <= 1e-10 * r.force_scale
    # the state goes with the model
    kept = [weakref.ref(S.context._kept_context(m)) for m in (model, stiff)]
    del model, soft, stiff, ctx
    gc.collect()
    assert all(k() is None for k in kept)


def test_static_context_in_use_is_not_shared():
    import msslib.solvers as S

    model = _gravity_cube(3)
    free = np.asarray(model.free, dtype=bool)
    a = S.context._static_context(model, model.x0, free, "cg")
    b = S.context._static_context(model, model.x0, free, "cg")  # `a` is in use (another thread)
    assert b is not a and S.context._kept_context(model) is a
    S.context._release_context(a)
    S.context._release_context(b)
    c = S.context._static_context(model, model.x0, free, "cg")
    assert c is a
    S.context._release_context(c)
    assert S.context._static_context(model, model.x0, free, "direct") is not a
    assert S.context._static_context(model, model.x0, free, lambda K, b: b) is not a  # user solver: never kept


@pytest.mark.parametrize("d,m", [(3, 6), (2, 3)])
def test_smoothed_prolongator_equals_the_dense_formula(d, m):
    import msslib.solvers as S

    rng = np.random.default_rng(d + m)
    nb, nc = 30, 8
    A, M = _random_spd_bsr(nb, d, rng)
    agg = rng.integers(0, nc, nb)
    agg[:nc] = np.arange(nc)
    agg[5] = -1  # a node in no aggregate: an empty row of T
    Td = np.zeros((nb * d, nc * m))
    for i, a in enumerate(agg):
        if a >= 0:
            Td[i * d:(i + 1) * d, a * m:(a + 1) * m] = rng.standard_normal((d, m))
    T = sp.bsr_matrix(Td, blocksize=(d, m))
    dinv = S.amg_kernels._block_diag_inverse(A.indptr, A.indices, A.data)
    p_ptr = np.empty(nb + 1, dtype=np.int64)
    args = (A.indptr, A.indices, A.data, dinv, T.indptr, T.indices, T.data, -0.3, nc, p_ptr)
    assert S.amg_kernels._smoothed_prolongator(*args, np.empty(0, dtype=np.int64), np.empty((0, d, m)))
    p_ind, p_data = np.empty(p_ptr[-1], dtype=np.int64), np.empty((p_ptr[-1], d, m))
    assert S.amg_kernels._smoothed_prolongator(*args, p_ind, p_data)
    P = sp.bsr_matrix((p_data, p_ind, p_ptr), shape=Td.shape)
    ref = Td - 0.3 * sp.block_diag(list(dinv)).toarray() @ M @ Td
    np.testing.assert_allclose(P.toarray(), ref, rtol=0, atol=1e-12 * np.abs(ref).max())
    assert all(np.all(np.diff(p_ind[p_ptr[i]:p_ptr[i + 1]]) > 0) for i in range(nb))  # sorted rows


def test_mid_size_decision_from_the_node_blocks_forms_no_full_tangent(monkeypatch):
    """Between ITERATIVE_THRESHOLD and BAND_PLAN_MAX_DOFS, "auto" decides from the graph of the
    free node blocks when that shows the band too wide: no full tangent is formed, and the
    blocks filled for the decision are the first Newton matrix."""
    import msslib.solvers as S

    model = _gravity_cube(13)  # 7,644 free dofs: banded Cholesky surely too wide
    n = int(model.free.sum())
    assert S.ITERATIVE_THRESHOLD < n <= S.BAND_PLAN_MAX_DOFS
    calls = _count_tangent_fills(monkeypatch, model)
    r = static_solve(model, model.x0)
    assert r.cg_iterations > 0
    assert calls == {"blocks": r.total_iterations, "full": 0}
    monkeypatch.undo()  # the model's own fills again
    ref = static_solve(model, model.x0, linear_solver="direct")
    np.testing.assert_allclose(r.x, ref.x, rtol=0, atol=1e-7 * np.abs(ref.x - model.x0).max())


@pytest.mark.parametrize("d", [3, 2, 6])
def test_block_diagonal_and_its_inverse(d):
    import msslib.solvers as S

    rng = np.random.default_rng(d)
    nb = 12
    blocks = rng.standard_normal((nb, d, d))
    blocks = blocks @ blocks.transpose(0, 2, 1) + 0.1 * np.eye(d)  # SPD, some ill-conditioned
    blocks[4] *= 1e9
    M = sp.block_diag(list(blocks)).tolil()
    M[0, d * 3] = 1.0  # an off-diagonal block
    A = sp.bsr_matrix(M.tocsr(), blocksize=(d, d))
    A.sort_indices()
    dinv = S.amg_kernels._block_diag_inverse(A.indptr, A.indices, A.data)
    ref = np.linalg.inv(blocks)
    for i in range(nb):
        np.testing.assert_allclose(dinv[i], ref[i], rtol=1e-9 * np.linalg.cond(blocks[i]) * 1e-3,
                                   atol=1e-12 * np.abs(ref[i]).max())
    np.testing.assert_array_equal(S.amg_kernels._block_diag(A.indptr, A.indices, A.data), blocks)
    singular = blocks.copy()
    singular[2] = np.outer(np.arange(1.0, d + 1), np.arange(1.0, d + 1))  # rank one
    B = sp.bsr_matrix(sp.block_diag(list(singular)).tocsr(), blocksize=(d, d))
    with pytest.raises(np.linalg.LinAlgError):
        S.amg_kernels._block_diag_inverse(B.indptr, B.indices, B.data)
    # a missing diagonal block: NaN inverse, zero block
    C = sp.bsr_matrix((blocks[:2], np.array([1, 0]), np.array([0, 1, 2])), shape=(2 * d, 2 * d))
    assert np.isnan(S.amg_kernels._block_diag_inverse(C.indptr, C.indices, C.data)).all()
    assert not S.amg_kernels._block_diag(C.indptr, C.indices, C.data).any()
