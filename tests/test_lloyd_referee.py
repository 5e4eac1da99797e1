"""Lloyd et al. items a referee asked for: the zero patterns of the element matrices (Figs. 5, 7, 8),
the one-point-quadrature bilinear reference of Sec. 5.3 and the equilateral mesh with the paper's
counts (Sec. 5.1).  Expected values come from closed forms written here (the bilinear square's
stiffness entries, eq. 6 of the paper), not from the code under test."""

from __future__ import annotations

import numpy as np
import pytest

from experiments.lloyd.studies import sparsity

E, T = 14630.0, 0.01


def spring_matrix(X, pairs, k, rest_factor=None):
    """Eq. 6 of the paper summed over springs, with the prestrain term of a spring whose rest length
    is c times its length: k (1 - c) I + k c d d^T / l^2 per block."""
    n, d = X.shape
    K = np.zeros((n * d, n * d))
    for s, (i, j) in enumerate(pairs):
        v = X[j] - X[i]
        L = np.linalg.norm(v)
        c = 1.0 if rest_factor is None else rest_factor[s]
        A = k[s] * ((1 - c) * np.eye(d) + c * np.outer(v, v) / L**2)
        for a, b, sign in ((i, i, 1), (j, j, 1), (i, j, -1), (j, i, -1)):
            K[a * d:(a + 1) * d, b * d:(b + 1) * d] += sign * A
    return K


def test_bilinear_square_at_one_third_has_zeros_on_three_antidiagonals():
    # closed form of the plane-stress bilinear square (any side), in units of E t / (1 - nu^2): the
    # diagonal entry is 1/2 - nu/6; the coupling of x at one node with y at its neighbour (3 nu - 1)/8,
    # zero at nu = 1/3
    K = sparsity.simulator("square_fem")
    scale = E * T / (1 - (1 / 3) ** 2)
    assert K[0, 0] == pytest.approx(scale * (1 / 2 - (1 / 3) / 6))
    assert K[0, 3] == pytest.approx(0.0, abs=1e-12 * scale) and K[0, 7] == pytest.approx(0.0, abs=1e-12 * scale)
    zero = ~sparsity.numerical_mask(K)
    i, j = np.nonzero(zero)
    assert zero.sum() == 16
    assert set((i + j + 2).tolist()) == {5, 9, 13}
    # at another nu the same element has no zero
    other = sparsity.fem.element_stiffness("quad", np.array(sparsity.square_coords(0.01), float), E, 0.3, thickness=T)
    assert sparsity.numerical_mask(other).all()


def test_square_springs_match_eq6_with_and_without_prestrain():
    X = np.array(sparsity.square_coords(sparsity.SIDE), float)
    p = sparsity.lloyd_square(E, t=T)
    pairs = sparsity.SQ_EDGES + sparsity.SQ_DIAGONALS
    k = [p.k_edge] * 4 + [p.k_diagonal] * 2
    plain = spring_matrix(X, pairs, k)
    np.testing.assert_allclose(sparsity.simulator("square_mss_plain"), plain, atol=1e-9 * np.abs(plain).max())
    assert sparsity.numerical_mask(plain).sum() == 40  # 4 node blocks full, 8 edge blocks with 1 entry, 4 diagonal-spring blocks full
    c = [p.rest_factor_edge] * 4 + [p.rest_factor_diagonal] * 2
    pre = spring_matrix(X, pairs, k, c)
    np.testing.assert_allclose(sparsity.simulator("square_mss_prestrain"), pre, atol=1e-9 * np.abs(pre).max())
    # eqs. 10-11 are exact: the prestrained springs' matrix is the FEM's at nu = 1/3
    np.testing.assert_allclose(pre, sparsity.simulator("square_fem"), atol=1e-9 * np.abs(pre).max())


def test_regular_tetrahedron_springs_match_eq6_and_eq12():
    X = np.array(sparsity.tet_coords(sparsity.EDGE), float)
    k = 2 * np.sqrt(2) / 25 * sparsity.EDGE * E  # eq. 12
    K = spring_matrix(X, sparsity.TET_PAIRS, [k] * 6)
    np.testing.assert_allclose(sparsity.simulator("tet_mss"), K, atol=1e-9 * np.abs(K).max())
    # the edge 0-1 lies on the x axis: the block K_01 has its xx entry only
    assert np.count_nonzero(np.abs(K[0:3, 3:6]) > 1e-9 * np.abs(K).max()) == 1


def test_generic_orientation_fills_every_matrix():
    for name in ("square_mss_plain", "tet_mss", "tet_fem", "square_fem"):
        R = sparsity.rotation(2 if name.startswith("square") else 3)
        np.testing.assert_allclose(R @ R.T, np.eye(len(R)), atol=1e-12)
        assert sparsity.numerical_mask(sparsity.simulator(name, R)).all(), name


# ------------------------------------------------------------------------------------------------
# one-point quadrature of bilinear quads (the "constant strain rectangle" of Sec. 5.3)
# ------------------------------------------------------------------------------------------------

from msslib import fem as F  # noqa: E402
from msslib import mesh as MESH  # noqa: E402
from msslib.errors import MsslibWarning  # noqa: E402


def distorted_grid(n=4, side=0.05, amount=0.003, seed=1):
    mesh = MESH.quad_grid(side, side, n, n)
    p = mesh.points.copy()
    inner = (p[:, 0] > 1e-9) & (p[:, 0] < side - 1e-9) & (p[:, 1] > 1e-9) & (p[:, 1] < side - 1e-9)
    p[inner] += np.random.default_rng(seed).uniform(-amount, amount, (inner.sum(), 2))
    return MESH.Mesh(p, mesh.cells, "quad"), inner


def test_one_point_quads_pass_the_patch_test():
    mesh, inner = distorted_grid()
    p = mesh.points
    exact = np.column_stack([1e-3 * p[:, 0] + 2e-3 * p[:, 1], -0.5e-3 * p[:, 0] + 3e-3 * p[:, 1]]) + [1e-4, -2e-4]
    fixed = np.zeros((mesh.n_nodes, 2), dtype=bool)
    fixed[~inner] = True
    r = F.solve_linear(mesh, E, 1 / 3, fixed=fixed, prescribed=exact, thickness=T, quadrature="one_point")
    np.testing.assert_allclose(r.displacement, exact, atol=1e-12 * np.abs(exact).max())
    assert r.stats["quadrature"] == "one_point"
    assert abs(r.stats["hourglass_energy_fraction"]) < 1e-10  # a linear field has no hourglass part
    # the constant strain's energy: E t A / (1 - nu^2) (e_xx^2 + e_yy^2 + 2 nu e_xx e_yy) / 2 + G t A g^2 / 2
    exx, eyy, gxy, nu = 1e-3, 3e-3, 2e-3 - 0.5e-3, 1 / 3
    A = 0.05**2
    energy = E * T * A / (1 - nu**2) * (exx**2 + eyy**2 + 2 * nu * exx * eyy) / 2 + E / (2 * (1 + nu)) * T * A * gxy**2 / 2
    assert r.strain_energy == pytest.approx(energy, rel=1e-10)


def test_one_point_element_has_two_hourglass_modes():
    m1 = MESH.quad_grid(0.01, 0.01, 1, 1)
    cell = m1.cells[0]  # corners counter-clockwise
    full = np.linalg.eigvalsh(F.element_stiffness("quad", m1.points[cell], E, 1 / 3, thickness=T))
    hourglass = np.zeros((4, 2))
    hourglass[cell, 0] = np.array([1.0, -1.0, 1.0, -1.0]) * 1e-4  # the x hourglass mode
    fixed = np.ones((4, 2), dtype=bool)
    with pytest.warns(MsslibWarning, match="hourglass"):
        r = F.solve_linear(m1, E, 1 / 3, fixed=fixed, prescribed=hourglass, thickness=T, quadrature="one_point")
    assert r.strain_energy == pytest.approx(0.0, abs=1e-12 * E * T * 1e-8)
    assert r.stats["hourglass_energy_fraction"] == pytest.approx(1.0)
    assert (full < 1e-10 * full.max()).sum() == 3  # the fully integrated element: rigid modes only
    assert F.solve_linear(m1, E, 1 / 3, fixed=fixed, prescribed=hourglass, thickness=T).strain_energy > 0


def test_one_point_singular_supports_and_wrong_cells_stop_with_one_line():
    m1 = MESH.quad_grid(0.05, 0.05, 1, 1)
    fixed = np.zeros((4, 2), dtype=bool)
    fixed[np.isclose(m1.points[:, 1], 0.0)] = True  # bottom fixed: the fully integrated quad is stable
    f = np.zeros((4, 2))
    f[2:] = [1.0, 0.0]
    F.solve_linear(m1, E, 1 / 3, fixed=fixed, nodal_forces=f, thickness=T)
    with pytest.raises(np.linalg.LinAlgError, match="hourglass"):
        F.solve_linear(m1, E, 1 / 3, fixed=fixed, nodal_forces=f, thickness=T, quadrature="one_point")
    tri = MESH.Mesh(np.array([[0, 0], [1, 0], [0, 1.0]]), np.array([[0, 1, 2]]), "triangle")
    with pytest.raises(ValueError, match="bilinear quads"):
        F.solve_linear(tri, E, 1 / 3, fixed=np.ones((3, 2), bool), quadrature="one_point")
    with pytest.raises(ValueError, match="quadrature must be"):
        F.solve_linear(m1, E, 1 / 3, fixed=fixed, quadrature="two_point")


def test_one_point_reference_is_softer_in_shear_and_says_how_much():
    """Sec. 5.3's 5 x 5 membrane, bottom fixed, sheared: the one-point system is regular, softer than
    the bilinear one, and names the share of the hourglass energy."""
    mesh = MESH.quad_grid(0.05, 0.05, 5, 5)
    fixed = np.zeros((mesh.n_nodes, 2), dtype=bool)
    fixed[np.isclose(mesh.points[:, 1], 0.0)] = True
    top = np.isclose(mesh.points[:, 1], 0.05)
    f = np.zeros((mesh.n_nodes, 2))
    f[top, 0] = 1.0
    full = F.solve_linear(mesh, E, 1 / 3, fixed=fixed, nodal_forces=f, thickness=T)
    with pytest.warns(MsslibWarning, match="hourglass"):
        one = F.solve_linear(mesh, E, 1 / 3, fixed=fixed, nodal_forces=f, thickness=T, quadrature="one_point")
    # reactions balance the load (an independent number: the applied total)
    np.testing.assert_allclose(one.reaction.sum(axis=0), -f.sum(axis=0), atol=1e-9)
    assert one.strain_energy > full.strain_energy  # same load, fewer constraints on the energy: softer
    assert 0.05 < one.stats["hourglass_energy_fraction"] < 1


# ------------------------------------------------------------------------------------------------
# Sec. 5.1 with the paper's counts
# ------------------------------------------------------------------------------------------------


def _springs_and_triangles(mesh):
    pairs = {tuple(sorted((int(c[a]), int(c[b])))) for c in mesh.cells for a, b in ((0, 1), (1, 2), (2, 0))}
    return len(pairs), len(mesh.cells)


def test_counts_mesh_has_the_papers_39_nodes_and_92_springs():
    from experiments.lloyd.studies import ratio_causes as rc

    mesh = rc.membrane("5.1", counts=True)
    assert mesh.n_nodes == 39
    springs, triangles = _springs_and_triangles(mesh)
    assert springs == 92 and triangles == 54  # Euler: springs = nodes + triangles - 1
    edges = np.linalg.norm(np.diff(mesh.points[mesh.cells][:, [0, 1, 2, 0]], axis=1), axis=2)
    np.testing.assert_allclose(edges, edges.mean(), rtol=1e-9)  # equilateral
    assert np.ptp(mesh.points[:, 1]) == pytest.approx(0.052, abs=5e-5)  # "5.2 cm high"
    # the file's mesh: same nodes, one triangle more, hence 93 springs
    file_mesh = rc.membrane("5.1")
    assert file_mesh.n_nodes == 39 and _springs_and_triangles(file_mesh) == (93, 55)
    # the MSS built on the counts mesh has one spring per mesh edge
    springs_terms = rc.lloyd_triangle_springs(mesh, [(E, 1 / 3)], T)
    assert sum(len(t.k) for t in springs_terms) == 92
