"""Tests of the speed fixes of the static solver: one BLAS thread for the banded factorisations,
the kept AMG V-cycle smoothing with the current matrix's diagonal blocks, and a kept hierarchy
given up as soon as CG exceeds its iteration limit."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from solver_problems import lattice_system


def _pools_or_skip():
    from msslib.solvers.blas_threads import _controller

    if _controller() is None:
        pytest.skip("no controllable BLAS thread pool (threadpoolctl)")
    from threadpoolctl import ThreadpoolController

    return ThreadpoolController()


def test_one_blas_thread_limits_and_restores():
    from msslib.solvers.blas_threads import blas_threads, one_blas_thread

    ctl = _pools_or_skip()
    with ctl.limit(limits=2, user_api="blas"):
        assert blas_threads() == 2
        with one_blas_thread():
            assert blas_threads() == 1
        assert blas_threads() == 2
        with one_blas_thread(False):
            assert blas_threads() == 2
        with pytest.raises(RuntimeError), one_blas_thread():
            raise RuntimeError("inside the block")
        assert blas_threads() == 2  # restored after an exception too


def _grid_laplacian(nx, ny, shift=0.0):
    """5-point Laplacian of an nx x ny grid (Dirichlet), minus ``shift`` on the diagonal, CSR."""
    def t(n):
        return sp.diags([-np.ones(n - 1), 2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])

    A = sp.kronsum(t(nx), t(ny)) - shift * sp.identity(nx * ny)
    A = sp.csr_matrix(A)
    A.sort_indices()
    return A


@pytest.mark.parametrize("shift", [0.0, 0.05])  # SPD: banded Cholesky; indefinite: banded LU
def test_banded_factorisations_run_on_one_blas_thread(monkeypatch, shift):
    """The blocked factorisations (bandwidth >= 65) run with one BLAS thread, the unblocked ones
    (narrower bands) are left alone; the solution is the sparse LU one."""
    import scipy.linalg
    from scipy.linalg import lapack

    from msslib import solvers as S
    from msslib.solvers.blas_threads import BLOCKED_BANDWIDTH, blas_threads

    ctl = _pools_or_skip()
    seen = []
    chol, gbtrf = scipy.linalg.cholesky_banded, lapack.dgbtrf

    def chol_spy(*a, **k):
        seen.append(("cholesky", blas_threads()))
        return chol(*a, **k)

    def gbtrf_spy(*a, **k):
        seen.append(("lu", blas_threads()))
        return gbtrf(*a, **k)

    monkeypatch.setattr(scipy.linalg, "cholesky_banded", chol_spy)
    monkeypatch.setattr(lapack, "dgbtrf", gbtrf_spy)
    rng = np.random.default_rng(1)
    with ctl.limit(limits=2, user_api="blas"):
        for nx, ny in ((80, 80), (30, 30)):
            A = _grid_laplacian(nx, ny, shift)
            b = rng.standard_normal(A.shape[0])
            seen.clear()
            x = S.direct._banded_cholesky_solve(A, b, {})
            bw = S.direct._band_plan(A, None)["bw"]
            assert (bw >= BLOCKED_BANDWIDTH) == (nx == 80)
            ref = spla.spsolve(A.tocsc(), b)
            np.testing.assert_allclose(x, ref, rtol=0, atol=1e-9 * np.abs(ref).max())
            kinds = [k for k, _ in seen]
            assert kinds == (["cholesky"] if shift == 0 else ["cholesky", "lu"])
            assert {t for _, t in seen} == {1 if bw >= BLOCKED_BANDWIDTH else 2}
        assert blas_threads() == 2


def _spd_update(A, factor=1.5):
    """``A`` with its diagonal blocks scaled by ``factor`` (symmetric, positive definite)."""
    from msslib.solvers.amg_kernels import _block_diag

    D = _block_diag(A.indptr, A.indices, A.data)
    return sp.bsr_matrix(A + sp.block_diag(list((factor - 1.0) * D)).tobsr(blocksize=A.blocksize))


_lattice = lattice_system


@pytest.mark.parametrize("single", [False, True])
def test_refreshed_diagonal_keeps_the_kept_cycle_symmetric(single):
    pytest.importorskip("pyamg")
    from msslib import solvers as S

    A, B, _ = _lattice(8)
    cycle = S.amg_cycle._VCycle.build(S.amg._sa_solver(A, B, 3), single=single)
    A2 = _spd_update(A)
    A2.sort_indices()
    assert cycle.update(A2)
    rng = np.random.default_rng(4)
    b, c = rng.standard_normal(A.shape[0]), rng.standard_normal(A.shape[0])

    def asymmetry():
        cb = c @ (cycle @ b)
        return abs(cb - b @ (cycle @ c)) / abs(cb)

    assert asymmetry() > 1e-3  # the inverses of the old diagonal blocks: not symmetric
    assert cycle.refresh_diagonal()
    blocks = [A2.data[p] for i in range(A2.shape[0] // 3) for p in range(A2.indptr[i], A2.indptr[i + 1])
              if A2.indices[p] == i]
    np.testing.assert_allclose(cycle.levels[0]["dinv"], np.linalg.inv(np.array(blocks)), rtol=1e-12, atol=0)
    # single precision: the sweeps read the rounded matrix (relative changes ~6e-8), the inverses
    # are those of the unrounded blocks, as when the cycle is built
    assert asymmetry() <= (1e-7 if single else 1e-10)
    assert c @ (cycle @ c) > 0
    # a singular diagonal block: nothing changes
    A3 = A2.copy()
    A3.data[A3.indptr[0] + np.flatnonzero(A3.indices[A3.indptr[0]:A3.indptr[1]] == 0)[0]] = 0.0
    kept = cycle.levels[0]["dinv"].copy()
    assert cycle.update(A3)
    assert not cycle.refresh_diagonal()
    np.testing.assert_array_equal(cycle.levels[0]["dinv"], kept)


def test_kept_hierarchy_is_given_up_at_the_iteration_limit():
    """A kept preconditioner that makes CG slow is replaced once CG passes the limit
    ``2 x (iterations per decade) x decades + 10``, not after ``maxiter`` iterations."""
    pytest.importorskip("pyamg")
    from msslib import solvers as S

    A, _, ctx = _lattice(8)
    b = np.random.default_rng(2).standard_normal(A.shape[0])
    rtol = 1e-8
    identity = spla.LinearOperator(A.shape, matvec=lambda v: np.array(v, dtype=float).ravel())
    _, info, plain = S.linear._pcg(A, b, identity, rtol, 5000)
    limit = 2.0 * 1.0 * 8 + 10  # per decade 1, 8 decades
    assert info == 0 and plain > 3 * limit  # unpreconditioned CG is far slower
    ctx = dict(ctx, cache={"M": identity, "shape": A.shape, "per_decade": 1.0})
    messages = []
    x = S.linear.solve_linear_system(A, b, "cg", True, messages, ctx, rtol)
    rebuilt = ctx["cache"]["M"]
    assert rebuilt is not identity
    _, info, fresh = S.linear._pcg(A, b, rebuilt, rtol, 5000)
    assert info == 0
    assert ctx["cg_iterations"] == (int(limit) + 1) + fresh  # capped, then solved with the new one
    assert np.linalg.norm(b - A @ x) <= rtol * np.linalg.norm(b)
    assert messages == []


def test_cylinder_load_steps_keep_the_hierarchy_and_match_the_direct_solve(monkeypatch):
    """Lloyd's tetrahedral cylinder (2 568 free dofs, AMG-CG) under a shear traction in 4 load
    steps: the kept hierarchy serves every load step (the first solve of each step used to stall
    for 1 000 CG iterations) and the result is the one of the direct solver."""
    pytest.importorskip("pyamg")
    pytest.importorskip("gmsh")
    from msslib import solvers as S
    from msslib.scene import load_scene, prepare

    scene = load_scene({
        "name": "cylinder", "model": "lloyd_tetrahedron_volume",
        "geometry": {"generator": "cylinder_mesh", "args": {"radius": 0.01, "height": 0.02, "h": 0.002}},
        "materials": [{"E": 15000.0, "nu": 0.25}],
        "boundary": [{"select": {"plane": ["z", 0.0]}, "fix": "all"}],
        "loads": [{"type": "traction", "select": {"box": [[None, None, 0.0199], [None, None, None]]},
                   "traction": [0.0, 750.0, 0.0]}]})
    model = prepare(scene).model
    assert int(model.free.sum()) > S.ITERATIVE_THRESHOLD
    built = []
    real = S.amg._preconditioner

    def counting(*a, **k):
        built.append(1)
        return real(*a, **k)

    monkeypatch.setattr(S.linear, "_preconditioner", counting)  # where the linear solve looks it up
    r = S.static_solve(model, model.x0, load_steps=4, linear_solver="cg")
    monkeypatch.undo()
    assert r.converged and len(r.iterations) == 4
    assert len(built) == 1, f"hierarchy built {len(built)} times"
    assert r.cg_iterations <= 20 * r.total_iterations
    d = S.static_solve(model, model.x0, load_steps=4, linear_solver="direct")
    u, ud = r.x - model.x0, d.x - model.x0
    # both converged to ||f|| <= 1e-8 F_ref: the same equilibrium, far within 1e-6 of |u|
    assert np.abs(u - ud).max() <= 1e-6 * np.abs(ud).max()
