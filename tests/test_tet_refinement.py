"""The tetrahedral refinement study: per-element FEM and spring stiffness, fit residuals, element
quality, strains, the load continuation, and the mirror symmetry of a spring tetrahedron."""

import numpy as np
import pytest

from experiments.lloyd.studies import tet_refinement as T
from msslib.models.lloyd import lloyd_tet_springs
from msslib import fem
from msslib import mesh as M
from msslib.system import Model
from msslib.mesh.quality import relative_jacobians

E, NU = 14630.0, 0.25
L = 0.003
REGULAR = L * np.array([[0, 0, 0], [1, 0, 0], [0.5, np.sqrt(3) / 2, 0], [0.5, np.sqrt(3) / 6, np.sqrt(2 / 3)]])
CORNER = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)


def _random_tets(n, seed=0):
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(n, 4, 3)) * 0.01
    _, V = T.gradients(X)
    X[V < 0] = X[V < 0][:, [0, 2, 1, 3]]  # positive orientation
    return X


def test_fem_element_stiffness_equals_msslib():
    X = _random_tets(5)
    K = T.fem_stiffness(X, E, NU)
    for x, k in zip(X, K):
        np.testing.assert_allclose(k, fem.element_stiffness("tetra", x, E, NU), rtol=1e-10, atol=1e-12 * np.abs(k).max())


def test_spring_basis_equals_finite_differences_of_a_spring():
    X = _random_tets(1, seed=3)[0]
    S = T.spring_basis(X[None])[0]
    h = 1e-7 * 0.01

    def grad(x, a, b):
        d = x[b] - x[a]
        g = np.zeros((4, 3))
        f = (np.linalg.norm(d) - np.linalg.norm(X[b] - X[a])) * d / np.linalg.norm(d)
        g[b], g[a] = f, -f
        return g.ravel()

    for e, (a, b) in enumerate(T.EDGES):
        H = np.empty((12, 12))
        for j in range(12):
            dx = np.zeros(12)
            dx[j] = h
            H[:, j] = (grad((X.ravel() + dx).reshape(4, 3), a, b) - grad((X.ravel() - dx).reshape(4, 3), a, b)) / (2 * h)
        np.testing.assert_allclose(S[e], H, atol=1e-6)


def test_lloyd_builder_sums_per_element_constants_over_shared_edges():
    """The model's stiffness at rest equals the sum over elements of eq. 12 with the edge of eq. 13
    on that element's six edges: every edge shared by several tetrahedra gets each one's constant once."""
    mesh = M.tet_grid(0.02, 0.01, 0.01, 2, 1, 1, scheme=5)
    mesh = M.Mesh(mesh.points * [1.0, 1.3, 0.8], mesh.cells, "tetra")  # irregular tetrahedra
    model = Model(mesh, lloyd_tet_springs(mesh, [(E, NU)]))
    X = mesh.points[mesh.cells]
    _, V = T.gradients(X)
    k = T.K12 * E * T.equivalent_edge(V)
    K_expected = T.assemble(mesh, k[:, None, None] * T.spring_basis(X).sum(axis=1)).toarray()
    np.testing.assert_allclose(model.stiffness(model.x0).toarray(), K_expected, rtol=1e-10, atol=1e-9 * np.abs(K_expected).max())


def test_regular_tetrahedron_fit_is_eq12_with_the_derived_residual():
    import sympy as sp

    from derivations.elements import tetrahedron
    from derivations.elasticity import nu

    _, V = T.gradients(REGULAR[None])
    assert T.equivalent_edge(V)[0] == pytest.approx(L, rel=1e-12)
    fit = T.fit_residuals(REGULAR[None], E, NU)
    assert fit["k1_over_lloyd"][0] == pytest.approx(1.0, rel=1e-12)  # eq. 12 is the least-squares constant
    rel2 = float(tetrahedron.springs_only().relative_residual.subs(nu, sp.Rational(1, 4)))
    assert fit["lloyd"][0] ** 2 == pytest.approx(rel2, rel=1e-10)
    assert fit["best6"][0] == pytest.approx(fit["lloyd"][0], rel=1e-10)  # by symmetry the six are equal
    assert not fit["negative6"][0]


def test_irregular_fit_is_worse_and_best6_bounds_best1():
    X = _random_tets(50, seed=1)
    fit = T.fit_residuals(X, E, NU)
    assert np.all(fit["best6"] <= fit["best1"] + 1e-12)
    assert np.all(fit["best1"] <= fit["lloyd"] + 1e-12)
    assert np.all(fit["lloyd"] > 0.2)


def test_quality_of_known_tetrahedra():
    rho, dmin = T.quality(np.stack([REGULAR, CORNER]))
    assert rho[0] == pytest.approx(1.0, rel=1e-12)
    assert dmin[0] == pytest.approx(np.degrees(np.arccos(1 / 3)), rel=1e-12)
    # corner tetrahedron: r_in = 3V / area = 1/2 / (3/2 + sqrt(3)/2), r_circ = sqrt(3)/2
    assert rho[1] == pytest.approx(3 * (0.5 / (1.5 + np.sqrt(3) / 2)) / (np.sqrt(3) / 2), rel=1e-12)
    assert dmin[1] == pytest.approx(np.degrees(np.arccos(1 / np.sqrt(3))), rel=1e-12)
    sliver = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.001], [1, 1, 0]], dtype=float)
    r, d = T.quality(sliver[None])
    assert r[0] < 0.01 and d[0] < 1.0


def test_element_strain_of_an_affine_field():
    X = _random_tets(4, seed=2)
    A = np.array([[0.01, 0.02, -0.03], [0.0, -0.02, 0.01], [0.04, 0.0, 0.005]])
    eps = T.element_strain(X, np.einsum("ij,maj->mai", A, X))
    np.testing.assert_allclose(eps, np.broadcast_to(0.5 * (A + A.T), eps.shape), atol=1e-14)


def test_mirrored_spring_tetrahedron_has_no_energy():
    """A spring tetrahedron's energy depends on its edge lengths only: its mirror image (inverted,
    relative Jacobian -1) is another state of zero energy, which FEM would not allow."""
    mesh = M.Mesh(REGULAR, np.array([[0, 1, 2, 3]]), "tetra")
    model = Model(mesh, lloyd_tet_springs(mesh, [(E, NU)]))
    mirrored = REGULAR * [1.0, 1.0, -1.0]
    assert relative_jacobians(mesh, mirrored)[0] == pytest.approx(-1.0, rel=1e-12)
    assert model.energy(mirrored.ravel(), 0.0) == pytest.approx(0.0, abs=1e-18)
    assert model.energy((REGULAR * [1.0, 1.0, 0.5]).ravel(), 0.0) > 0


def test_continuation_reaches_the_direct_solution():
    from msslib.scene import load_scene, prepare
    from msslib.solvers import static_solve

    st = prepare(load_scene(T.cylinder_scene(0.008, "lloyd_tetrahedron", "shear", 0.3)))
    rows, failed = T.continuation(st, [0.4, 1.0], eig=False)
    assert failed is None and [r[0] for r in rows] == [0.4, 1.0]
    direct = static_solve(st.model, st.model.x0, load_steps=3, tol=1e-10).x
    u = direct - st.model.x0
    assert np.abs(rows[-1][1] - direct).max() < 1e-6 * np.abs(u).max()


def test_lowest_eigenvalue_of_a_known_matrix():
    class Diag:
        free = np.array([True, False, True])

        def stiffness(self, x, load):
            import scipy.sparse as sps
            return sps.diags([2.0, 5.0, 4.0]).tocsr()

    assert T.lowest_eigenvalue(Diag(), None, 1.0) == pytest.approx(2.0 / 3.0, rel=1e-10)


def test_compressed_spring_has_negative_lateral_stiffness():
    """Tangent of one spring k/2 (|x1 - x0| - L0)^2 stretched to l: k along it, k (1 - L0/l) across it,
    negative when compressed (l < L0)."""
    from msslib.terms import Springs

    k, L0 = 100.0, 0.01
    spring = Springs(np.array([[0, 1]]), [k], [L0], 3)
    model = Model(M.Mesh(REGULAR, np.array([[0, 1, 2, 3]]), "tetra"), [spring])
    for l in (0.8 * L0, 1.2 * L0):
        x = REGULAR.copy()
        x[1] = x[0] + [l, 0.0, 0.0]
        K = model.stiffness(x.ravel()).toarray()[3:6, 3:6]
        np.testing.assert_allclose(np.diag(K), [k, k * (1 - L0 / l), k * (1 - L0 / l)], rtol=1e-12, atol=1e-12 * k)
