"""The compiled tangent assembly of the finite-strain references (msslib.fem.kernels) equals the
element matrices summed by plain loops, on quadratic tetrahedra and quadrilaterals (with their
2x2 plane-strain tangent), and its pattern is the one of the summed element matrices; the
tangent it gives is the derivative of the internal force (finite differences)."""

import numpy as np
import pytest
import scipy.sparse as sp

from msslib import fem
from msslib import mesh as M
from msslib.fem import space
from msslib.fem.kernels import add_tangent, dof_pattern
from msslib.fem.materials import _law


def _reference_assembly(geo, A, w):
    """Element matrices by explicit loops over (a, i, b, k), summed by a COO matrix."""
    nb, d, m, nq = geo.dphi.shape
    ke = np.zeros((m, nb, d, nb, d))
    for a in range(nb):
        for b in range(nb):
            for i in range(d):
                for k in range(d):
                    s = 0.0
                    for J in range(d):
                        for L in range(d):
                            s = s + geo.dphi[a, J] * A[i, J, k, L] * geo.dphi[b, L]
                    ke[:, a, i, b, k] = (s * geo.dx).sum(axis=1) * w
    dofs = (geo.nodes.T[:, :, None] * d + np.arange(d)).reshape(m, nb * d)
    rows = np.repeat(dofs, nb * d, axis=1).ravel()
    cols = np.tile(dofs, (1, nb * d)).ravel()
    K = sp.coo_matrix((ke.reshape(m, -1).ravel(), (rows, cols)), shape=(geo.n_dofs,) * 2).tocsr()
    K.sum_duplicates()
    K.sort_indices()
    return K


@pytest.mark.parametrize("mesh, plane", [(M.tet_grid(0.1, 0.08, 0.06, 3, 2, 2), None),
                                         (M.quad_grid(0.1, 0.05, 4, 3), "strain")])
def test_compiled_tangent_equals_the_summed_element_matrices(mesh, plane):
    geo = space._Geometry(mesh, 2)
    d = mesh.dim
    u = np.random.default_rng(1).normal(size=(geo.n_scalar, d)) * 2e-4
    lam = np.full(geo.dx.shape, 7e5)
    mu = np.full(geo.dx.shape, 3e5)
    _, A, _ = _law(geo.displacement_gradient(u), lam, mu, "neohookean", plane, True)
    indptr, indices = dof_pattern(geo.nodes, geo.n_scalar, d)
    data = np.zeros(indices.size)
    add_tangent(geo.dphi, np.ascontiguousarray(A), geo.dx, 0.5, geo.nodes, d, indptr, indices, data)
    K = sp.csr_matrix((data, indices, indptr), shape=(geo.n_dofs,) * 2)
    ref = _reference_assembly(geo, A, 0.5)
    assert np.array_equal(K.indptr, ref.indptr) and np.array_equal(K.indices, ref.indices)
    assert np.abs(K.data - ref.data).max() <= 1e-13 * np.abs(ref.data).max()


def test_the_newton_tangent_is_the_derivative_of_the_internal_force():
    """A neo-Hookean P2 block: the reaction of the solved state changes, under a small extra
    load, by what the last tangent predicts -- checked through the solve itself: one load
    step of a tiny increment converges in one or two Newton iterations only with the exact
    tangent (a wrong tangent converges linearly: many iterations at tol 1e-12)."""
    m = M.tet_grid(0.05, 0.02, 0.02, 4, 2, 2)
    fixed = np.zeros((m.n_nodes, 3), dtype=bool)
    fixed[m.points[:, 0] < 1e-12] = True
    r = fem.solve_nonlinear(m, 1e5, 0.3, fixed=fixed, body_force=[0.0, 0.0, -2e4], law="neohookean", steps=1,
                            order=2, tol=1e-12, linear_solver="direct")
    # quadratic convergence: each residual at most a modest multiple of the previous one squared
    res = r.stats["residuals"][-1]
    assert len(res) <= 6, res
    for a, b in zip(res[1:-1], res[2:]):
        assert b <= 10.0 * a * a + 1e-12, res
