"""The FEM references run on msslib.solvers: their linear systems go through the policy of the
mass-spring models (banded Cholesky / SuperLU / AMG-CG), their Newton iteration is static_solve,
and the answers equal SuperLU's."""

import numpy as np
import scipy.sparse.linalg as spla

from msslib import fem
from msslib.fem import space as fem_space
from msslib import mesh as M
from msslib.solvers import linear as solvers_linear


def _block(n):
    m = M.hex_grid(0.1, 0.1, 0.1, n, n, n)
    fixed = np.zeros((m.n_nodes, 3), dtype=bool)
    fixed[m.points[:, 2] < 1e-12] = True
    return m, fixed


def _counting(monkeypatch):
    calls = []
    real = solvers_linear.solve_linear_system

    def counted(A, b, method, *args, **kw):
        calls.append((A.shape[0], method))
        return real(A, b, method, *args, **kw)

    monkeypatch.setattr(solvers_linear, "solve_linear_system", counted)
    monkeypatch.setattr("msslib.solvers.statics.solve_linear_system", counted)
    return calls


def test_linear_fem_on_amg_cg_equals_superlu(monkeypatch):
    """12^3 hexahedra (6084 free dofs, a compact body: the policy takes AMG-CG) under gravity: the
    solution equals SuperLU's on the same matrix to 1e-9, and the reaction balances the weight."""
    calls = _counting(monkeypatch)
    m, fixed = _block(12)
    r = fem.solve_linear(m, 1e6, 0.3, fixed=fixed, body_force=[0.0, 0.0, -1e4])
    assert calls and calls[0][0] == 6084
    assert r.stats["solver"].endswith(": cg"), r.stats["solver"]
    geo = fem_space._Geometry(m)
    lam, mu = fem.lame(np.full(m.n_cells, 1e6), np.full(m.n_cells, 0.3))
    K = fem_space._linear_stiffness(geo, lam, mu).tocsc()
    free = ~fixed.ravel()
    f = geo.body_load([0.0, 0.0, -1e4], 1.0).ravel()
    u = np.zeros(K.shape[0])
    u[free] = spla.spsolve(K[free][:, free], f[free])
    assert np.abs(r.displacement.ravel() - u).max() <= 1e-9 * np.abs(u).max()
    np.testing.assert_allclose(r.reaction.sum(axis=0), [0.0, 0.0, 1e4 * 0.1**3], rtol=1e-9, atol=1e-12)


def test_small_fem_is_solved_directly_and_equals_superlu(monkeypatch):
    calls = _counting(monkeypatch)
    m, fixed = _block(3)
    r = fem.solve_linear(m, 1e6, 0.3, fixed=fixed, body_force=[0.0, 0.0, -1e4])
    assert calls and r.stats["solver"].endswith(": direct")
    lin = fem.solve_linear(m, 1e6, 0.3, fixed=fixed, body_force=[0.0, 0.0, -1e4], linear_solver="cg")
    assert np.abs(lin.displacement - r.displacement).max() <= 1e-9 * np.abs(r.displacement).max()


def test_nonlinear_fem_newton_is_static_solve_on_the_policy(monkeypatch):
    """Quadratic neo-Hookean on 4^3 hexahedra (2187 dofs): every Newton system goes through the
    solvers' linear solve with the policy ("auto"); the reaction equals the weight."""
    calls = _counting(monkeypatch)
    m, fixed = _block(4)
    r = fem.solve_nonlinear(m, 1e6, 0.3, fixed=fixed, body_force=[0.0, 0.0, -1e4], law="neohookean", order=2,
                            steps=1)
    assert len(calls) == sum(r.stats["iterations"]) and all(meth == "auto" for _, meth in calls)
    assert "msslib.solvers" in r.stats["solver"]
    np.testing.assert_allclose(r.reaction.sum(axis=0), [0.0, 0.0, 1e4 * 0.1**3], rtol=1e-8, atol=1e-12)
