"""Tests of msslib.terms and msslib.system: derivatives, assembly, builders, loads, corrections."""

from __future__ import annotations


import numpy as np
import pytest
import scipy.sparse as sp

from msslib.models.baudet import baudet_correction, baudet_cube_springs
from msslib.models.common import assemble_springs
from msslib.models.golec import golec_cube_springs
from msslib.models.lloyd import lloyd_square_springs, lloyd_tet_springs, lloyd_triangle_springs, van_gelder_springs
from msslib import mesh as M
from msslib.system import Model
from msslib.terms import (
    BaudetCorrection,
    Gravity,
    HexVolume,
    NodalForces,
    Springs,
    TetVolume,
    Traction,
)

E0, NU0, T0 = 2.0e3, 0.3, 0.01


@pytest.fixture
def params():
    from msslib import parameters

    return parameters


# --------------------------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------------------------


def perturbed(mesh, amount, seed):
    rng = np.random.default_rng(seed)
    return mesh.points.ravel() + amount * rng.uniform(-1, 1, mesh.points.size)


def dense_hessian(term, x):
    rows, cols, vals = term.hessian_coo(x)
    return sp.coo_matrix((vals, (rows, cols)), shape=(x.size, x.size)).toarray()


def check_derivatives(term, x, h=1e-5, rtol=1e-6):
    n = x.size
    g = term.gradient(x)
    g_fd = np.empty(n)
    H_fd = np.empty((n, n))
    for i in range(n):
        e = np.zeros(n)
        e[i] = h
        g_fd[i] = (term.energy(x + e) - term.energy(x - e)) / (2 * h)
        H_fd[:, i] = (term.gradient(x + e) - term.gradient(x - e)) / (2 * h)
    assert np.linalg.norm(g) > 0
    assert np.linalg.norm(g - g_fd) <= rtol * np.linalg.norm(g)
    H = dense_hessian(term, x)
    assert np.linalg.norm(H - H_fd) <= rtol * np.linalg.norm(H)
    assert np.allclose(H, H.T, rtol=0, atol=1e-12 * np.abs(H).max())


# --------------------------------------------------------------------------------------------
# finite differences of every conservative term
# --------------------------------------------------------------------------------------------


def test_springs_2d_derivatives_prestrained():
    mesh = M.triangle_grid_right(1.0, 1.0, 2, 2)
    pairs = M.unique_edges(mesh).pairs
    rng = np.random.default_rng(0)
    k = rng.uniform(1.0, 3.0, len(pairs))
    rest = np.linalg.norm(np.diff(mesh.points[pairs], axis=1)[:, 0], axis=1) * rng.uniform(0.8, 1.2, len(pairs))
    term = Springs(pairs, k, rest, dim=2)
    check_derivatives(term, perturbed(mesh, 0.1, 1))


def test_springs_3d_derivatives_prestrained():
    mesh = M.tet_grid(1.0, 1.0, 1.0, 1, 1, 1)
    pairs = M.unique_edges(mesh).pairs
    rng = np.random.default_rng(2)
    rest = np.linalg.norm(np.diff(mesh.points[pairs], axis=1)[:, 0], axis=1) * rng.uniform(0.8, 1.2, len(pairs))
    term = Springs(pairs, rng.uniform(1.0, 3.0, len(pairs)), rest, dim=3)
    check_derivatives(term, perturbed(mesh, 0.1, 3))


@pytest.mark.parametrize("k_v", [2.0, -0.5])
def test_tet_volume_derivatives(k_v):
    mesh = M.tet_grid(1.0, 1.0, 1.0, 1, 1, 1, scheme=5)
    V0 = M.cell_measures(mesh)
    term = TetVolume(mesh.cells, k_v, V0 * 1.1)
    check_derivatives(term, perturbed(mesh, 0.1, 4))


@pytest.mark.parametrize("kappa", [3.0, -1.0])
def test_hex_volume_derivatives(kappa):
    mesh = M.hex_grid(1.0, 1.0, 1.0, 1, 1, 1)
    term = HexVolume(mesh.cells, kappa, 0.9)
    check_derivatives(term, perturbed(mesh, 0.1, 5))


def test_external_terms_derivatives():
    mesh = M.quad_grid(1.0, 1.0, 1, 1)
    grav = Gravity(np.arange(1.0, 5.0), [0.0, -9.81])
    x = perturbed(mesh, 0.1, 6)
    e = np.zeros(x.size)
    e[3] = 1e-3
    assert np.isclose((grav.energy(x + e) - grav.energy(x - e)) / 2e-3, grav.gradient(x)[3])
    assert len(grav.hessian_pattern()[0]) == 0


# --------------------------------------------------------------------------------------------
# assembly
# --------------------------------------------------------------------------------------------


def test_fixed_pattern_csr_equals_coo_assembly():
    mesh = M.tet_grid(1.0, 1.0, 1.0, 2, 1, 1)
    pairs = M.unique_edges(mesh).pairs
    springs = Springs(pairs, 1.5, 0.9 * np.linalg.norm(np.diff(mesh.points[pairs], axis=1)[:, 0], axis=1), 3)
    vol = TetVolume(mesh.cells, 0.7, M.cell_measures(mesh))
    grav = Gravity(np.ones(mesh.n_nodes), [0, 0, -1.0])
    model = Model(mesh, [springs, vol, grav])
    for seed in (7, 8):  # the second call refills the same pattern
        x = perturbed(mesh, 0.05, seed)
        K = model.stiffness(x, load=0.3)
        coo = [t.hessian_coo(x) for t in (springs, vol)]
        ref = sp.coo_matrix((np.concatenate([c[2] for c in coo]),
                             (np.concatenate([c[0] for c in coo]), np.concatenate([c[1] for c in coo]))),
                            shape=(model.n_dof, model.n_dof)).tocsr()
        assert isinstance(K, sp.csr_matrix) and K.nnz == model.nnz
        assert abs(K - ref).max() <= 1e-12 * abs(ref).max()
    # the model's force and stiffness are consistent
    x = perturbed(mesh, 0.05, 9)
    h, i = 1e-6, 10
    e = np.zeros(model.n_dof)
    e[i] = h
    col = -(model.force(x + e, 0.3) - model.force(x - e, 0.3)) / (2 * h)
    assert np.allclose(model.stiffness(x, 0.3)[:, i].toarray().ravel(), col, atol=1e-6 * np.abs(col).max())


def _coo_reference(model, x, load=1.0):
    K = sp.csr_matrix((model.n_dof, model.n_dof))
    for t in model.terms:
        if t.max_node() < 0 or not hasattr(t, "hessian_coo"):
            continue
        try:
            r, c, v = t.hessian_coo(x)
        except NotImplementedError:
            continue
        s = load if t.scales_with_load else 1.0
        K = K + s * sp.coo_matrix((v, (r, c)), shape=K.shape).tocsr()
    return K


FILL_CASES = ["exact", "duplicate_pairs", "partial_rows", "extra_term_pairs"]


def _fill_case_model(case, **kw):
    """Models exercising the block fill paths: every block written once by the springs
    ("exact"), repeated pairs, a node without springs, blocks added by another term."""
    mesh = M.hex_grid(0.03, 0.02, 0.02, 3, 2, 2)
    terms = golec_cube_springs(mesh, [(1e4, 0.3)], 1.0)
    springs = terms[0]
    if case == "duplicate_pairs":
        pairs = np.concatenate([springs.conn, springs.conn[:5]])
        springs = Springs(pairs, np.concatenate([springs.k, 2.0 * springs.k[:5]]),
                          np.concatenate([springs.rest_length, springs.rest_length[:5]]), 3)
        terms = [springs]
    elif case == "partial_rows":  # the last node has no spring
        keep = (springs.conn != mesh.n_nodes - 1).all(axis=1)
        springs = Springs(springs.conn[keep], springs.k[keep], springs.rest_length[keep], 3)
        terms = [springs]
    elif case == "extra_term_pairs":  # edges only: the hex volume term adds the diagonal pairs
        edges = np.abs(np.diff(mesh.points[springs.conn], axis=1)[:, 0]) > 1e-12
        keep = edges.sum(axis=1) == 1
        springs = Springs(springs.conn[keep], springs.k[keep], springs.rest_length[keep], 3)
        terms = [springs, terms[1]]
    else:
        terms = [springs]
    return mesh, Model(mesh, terms, **kw)


@pytest.mark.parametrize("case", FILL_CASES)
def test_block_csr_fill_paths_equal_coo_assembly(case):
    """The springs-only overwrite path (every block written once) and the zero-and-add path
    (repeated pairs, nodes without springs, blocks of another term) give the COO matrix, also
    when refilling an earlier matrix in place with ``out=``."""
    mesh, model = _fill_case_model(case)
    if case == "partial_rows":  # a node outside every element: the generic dof-level path
        assert model._block is None
    else:
        exact = [f[2] for f in model._block[2] if f[0] == "springs"]
        assert exact == [case == "exact"] + [False] * (len(exact) - 1)
    K_prev = None
    for seed in (1, 2):
        x = perturbed(mesh, 0.002, seed)
        ref = _coo_reference(model, x)
        K = model.stiffness(x, out=K_prev)
        if K_prev is not None:
            assert K is K_prev  # refilled in place
        assert abs(K - ref).max() <= 1e-12 * abs(ref).max()
        K_prev = K
    with pytest.raises(ValueError, match="out must be a matrix returned"):
        model.stiffness(x, out=sp.csr_matrix(K.toarray()))


@pytest.mark.parametrize("case", FILL_CASES)
def test_free_node_blocks_filled_directly_equal_the_coo_free_block(case):
    """``Model.stiffness_blocks``: the free-free node blocks (BSR), written straight from the
    terms, equal the free block of the COO matrix on every fill path, also refilled in place;
    None where there is no node-block pattern."""
    mesh = M.hex_grid(0.03, 0.02, 0.02, 3, 2, 2)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[mesh.points[:, 0] < 1e-12] = True  # a clamped face: rows and columns dropped
    mesh, model = _fill_case_model(case, fixed=fixed)
    if case == "partial_rows":
        assert model.stiffness_blocks(model.x0) is None
        return
    idx = np.flatnonzero(model.free)
    B_prev = None
    for seed in (1, 2):
        x = perturbed(mesh, 0.002, seed)
        ref = _coo_reference(model, x).toarray()[np.ix_(idx, idx)]
        B = model.stiffness_blocks(x, out=B_prev)
        assert B.format == "bsr" and B.blocksize == (3, 3)
        B.check_format(full_check=True)
        if B_prev is not None:
            assert B is B_prev  # refilled in place
        assert np.abs(B.toarray() - ref).max() <= 1e-12 * np.abs(ref).max()
        B_prev = B
    # another node mask: its own pattern
    node_free = ~fixed.any(axis=1)
    node_free[-1] = False
    keep = np.repeat(node_free, 3)
    B = model.stiffness_blocks(x, node_free=node_free)
    np.testing.assert_allclose(B.toarray(), model.stiffness(x).toarray()[np.ix_(keep, keep)], rtol=0,
                               atol=1e-12 * np.abs(B.data).max())
    with pytest.raises(ValueError, match="node_free must have shape"):
        model.stiffness_blocks(x, node_free=node_free[:-1])
    # a fixed mask that splits a node's dofs has no node blocks
    part = Model(mesh, model.terms, fixed=np.r_[True, np.zeros(model.n_dof - 1, dtype=bool)])
    assert part.stiffness_blocks(x) is None


# --------------------------------------------------------------------------------------------
# builders: summation of spring constants, validation
# --------------------------------------------------------------------------------------------


def spring_table(springs):
    return {tuple(p): (k, r) for p, k, r in zip(springs.pairs.tolist(), springs.k, springs.rest_length)}


def test_lloyd_square_sums_over_shared_elements(params):
    mesh = M.quad_grid(2.0, 2.0, 2, 2)  # unit squares, centre node 4
    (springs,) = lloyd_square_springs(mesh, [(E0, NU0)], T0)
    p = params.lloyd_square(E0, t=T0)
    table = spring_table(springs)
    assert len(table) == 12 + 8
    k, r = table[(1, 4)]  # interior edge: two squares
    assert np.isclose(k, 2 * p.k_edge) and np.isclose(r, p.rest_factor_edge * 1.0)
    k, r = table[(0, 1)]  # boundary edge: one square
    assert np.isclose(k, p.k_edge)
    k, r = table[(0, 4)]  # diagonal of square 0
    assert np.isclose(k, p.k_diagonal) and np.isclose(r, p.rest_factor_diagonal * np.sqrt(2.0))
    # typed expectations of Lloyd's constants (only in this test file)
    assert np.isclose(p.k_edge, 5 / 16 * E0 * T0) and np.isclose(p.k_diagonal, 7 / 16 * E0 * T0)
    # prestrained, yet in equilibrium at rest
    model = Model(mesh, [springs])
    assert np.abs(model.force(model.x0)).max() <= 1e-12 * E0 * T0
    assert model.energy(model.x0) > 0


def test_lloyd_and_van_gelder_triangles(params):
    mesh = M.triangle_grid_right(2.0, 2.0, 2, 2)
    mesh = M.Mesh(mesh.points, mesh.cells, "triangle", np.arange(mesh.n_cells) % 2)
    materials = [(E0, NU0), (3 * E0, NU0)]
    (lloyd,) = lloyd_triangle_springs(mesh, materials, T0)
    table = spring_table(lloyd)
    unit = params.lloyd_triangle(E0, t=T0).k
    assert np.isclose(unit, np.sqrt(3) / 4 * E0 * T0)
    # diagonal 0-4 is shared by cells 0 (material 0) and 1 (material 1)
    assert np.isclose(table[(0, 4)][0], unit + 3 * unit)
    assert np.isclose(table[(0, 1)][0], unit)  # boundary edge of cell 0 only
    (vg,) = van_gelder_springs(mesh, materials, T0)
    table = spring_table(vg)
    assert np.isclose(table[(0, 4)][0], E0 * T0 * 0.5 / 2 + 3 * E0 * T0 * 0.5 / 2)
    assert np.isclose(table[(1, 4)][0], 3 * E0 * T0 * 0.5 + E0 * T0 * 0.5)  # cells 1 and 2
    for springs in (lloyd, vg):
        model = Model(mesh, [springs])
        assert np.abs(model.force(model.x0)).max() == 0.0
        assert model.energy(model.x0) == 0.0


def test_lloyd_tet_with_volume_term(params):
    mesh = M.tet_grid(1.0, 1.0, 1.0, 1, 1, 1)  # Kuhn split: six tetrahedra share the diagonal 0-7
    springs, vol = lloyd_tet_springs(mesh, [(E0, 0.4)], volume=True)
    l_hat = np.cbrt(6 * np.sqrt(2) * (1.0 / 6))
    p = params.lloyd_tetrahedron_volume(E0, l=l_hat, nu=0.4)
    diag = tuple(sorted((int(np.argmin(mesh.points.sum(1))), int(np.argmax(mesh.points.sum(1))))))
    assert np.isclose(spring_table(springs)[diag][0], 6 * p.k)
    assert isinstance(vol, TetVolume) and np.allclose(vol.k_v, p.k_volume)
    model = Model(mesh, [springs, vol])
    assert np.abs(model.force(model.x0)).max() <= 1e-12 * E0
    (plain,) = lloyd_tet_springs(mesh, [(E0, 0.4)])
    assert np.isclose(spring_table(plain)[diag][0], 6 * params.lloyd_tetrahedron(E0, l=l_hat).k)


def test_cube_builders(params):
    mesh = M.hex_grid(2.0, 2.0, 2.0, 2, 2, 2)  # 8 unit cubes; the centre node has 6 edges shared by 4
    (springs,) = baudet_cube_springs(mesh, [(E0, NU0)])
    p = params.baudet_cube(E0, nu=NU0, a=1.0)
    counts = M.unique_edges(mesh).counts
    assert len(springs.pairs) == len(counts) + 4 * 8
    centre = int(np.argmin(np.linalg.norm(mesh.points - 1.0, axis=1)))
    table = spring_table(springs)
    central_edges = [key for key in table if centre in key and np.isclose(np.linalg.norm(
        np.subtract(*mesh.points[list(key)])), 1.0)]
    assert len(central_edges) == 6
    assert all(np.isclose(table[key][0], 4 * p.k_edge) for key in central_edges)
    assert np.isclose(table[(0, int(mesh.cells[0, 6]))][0], p.k_diagonal)
    assert np.isclose(p.k_edge, E0 * (4 * NU0 + 1) / (8 * (1 + NU0)))
    springs_g, hexvol = golec_cube_springs(mesh, [(E0, NU0)], A=1.0)
    g = params.golec_cube(E0, nu=NU0, a=1.0, A=1.0)
    assert len(springs_g.pairs) == len(counts) + len(M.face_diagonals(mesh).pairs) + 32
    assert np.allclose(hexvol.kappa, g.kappa) and np.allclose(hexvol.V0, 1.0)
    for terms in ([springs], [springs_g, hexvol]):
        model = Model(mesh, terms)
        assert np.abs(model.force(model.x0)).max() <= 1e-12 * E0
    squashed = M.Mesh(mesh.points * [1.0, 1.0, 1.2], mesh.cells, "hexahedron")
    with pytest.raises(ValueError, match="not cubes"):
        baudet_cube_springs(squashed, [(E0, NU0)])


def test_negative_or_zero_spring_constant_raises_naming_springs():
    pairs = np.array([[0, 1], [1, 2], [2, 0]])
    with pytest.raises(ValueError, match=r"spring 1 \(nodes 1-2\): -2\.0") as err:
        Springs(pairs, [1.0, -2.0, 0.0], [1.0, 1.0, 1.0], dim=2)
    assert "spring 2 (nodes 2-0): 0.0" in str(err.value)
    with pytest.raises(ValueError, match="rest length"):
        Springs(pairs, 1.0, [1.0, 0.0, 1.0], dim=2)
    mesh = M.quad_grid(1.0, 1.0, 1, 1)
    with pytest.raises(ValueError, match="spring"):
        assemble_springs(mesh, "edges", lambda cells, p: np.where(p[:, 0] == 0, -1.0, 1.0))


def test_inverted_cells_detected_before_constants(params):
    mesh = M.triangle_grid_right(1.0, 1.0, 1, 1)
    cells = mesh.cells.copy()
    cells[0] = cells[0, [0, 2, 1]]
    with pytest.raises(ValueError, match="inverted"):
        lloyd_triangle_springs(M.Mesh(mesh.points, cells, "triangle"), [(E0, NU0)], T0)


# --------------------------------------------------------------------------------------------
# loads
# --------------------------------------------------------------------------------------------


def test_gravity_and_traction_totals():
    mesh = M.hex_grid(2.0, 1.0, 1.0, 2, 1, 1)
    masses = M.lumped_masses(mesh, 7.0)
    g = np.array([0.0, 0.0, -9.81])
    grav = Gravity(masses, g)
    assert np.allclose(grav.total, 7.0 * 2.0 * g)
    top = M.boundary_facets(mesh)
    top = top[np.all(np.isclose(mesh.points[top][:, :, 2], 1.0), axis=1)]
    trac = Traction(mesh, top, [0.0, 0.0, 5.0])
    assert np.allclose(trac.total, [0.0, 0.0, 5.0 * 2.0])
    single = Traction(mesh, top[:1], [0.0, 0.0, 5.0])
    assert np.allclose(single.nodal[top[0], 2], 5.0 / 4)  # corner forces of a unit square
    # 2D edge traction with thickness; tetrahedral triangle facets
    quads = M.quad_grid(2.0, 1.0, 2, 1)
    right = np.array([[2, 5]])
    t2 = Traction(quads, right, [3.0, 1.0], thickness=0.1)
    assert np.allclose(t2.total, [0.3, 0.1])
    tets = M.tet_grid(1.0, 1.0, 1.0, 1, 1, 1)
    f = M.boundary_facets(tets)
    f = f[np.all(np.isclose(tets.points[f][:, :, 0], 0.0), axis=1)]
    assert np.allclose(Traction(tets, f, [-2.0, 0.0, 0.0]).total, [-2.0, 0.0, 0.0])
    # loads scale with the load factor, gravity energy is -m g . x
    model = Model(mesh, [grav, trac], masses=masses)
    assert np.allclose(model.force(model.x0, 0.5), 0.5 * (grav.vector + trac.vector))
    assert np.isclose(model.energy(model.x0, 1.0), -(grav.vector + trac.vector) @ model.x0)
    assert np.allclose(model.mass.reshape(-1, 3), masses[:, None])


# --------------------------------------------------------------------------------------------
# Baudet correction
# --------------------------------------------------------------------------------------------


def moment(points, forces):
    return np.cross(points, forces).sum(axis=0)


def test_baudet_correction_single_cube(params):
    mesh = M.hex_grid(1.0, 1.0, 1.0, 1, 1, 1)
    top = mesh.cells[:, 4:]  # top face, counter-clockwise seen from above
    trac = Traction(mesh, top, [0.0, 0.0, 8.0])  # F_i = 8 N on the top face
    corr = baudet_correction(mesh, [(E0, NU0)], [trac])
    c = params.baudet_cube(E0, nu=NU0, a=1.0).correction_factor
    assert np.isclose(c, -(4 * NU0 - 1) / 2)  # derived: resultants per face (erratum of eq. 8)
    assert np.allclose(corr.face_force[0], [0, 8.0, 0, 0, 0, 0])
    f = corr.nodal
    assert np.allclose(f.sum(axis=0), 0.0, atol=1e-12)
    assert np.allclose(moment(mesh.points, f), 0.0, atol=1e-12)
    # node 1 at (1, 0, 0): on the x-max face (outward +x) and the y-min face (outward -y)
    assert np.allclose(f[1], c * 8.0 / 4 * np.array([1.0, -1.0, 0.0]))
    assert np.allclose(f[:, 2], 0.0)  # nothing along the elongation direction
    model = Model(mesh, [trac, corr])
    assert model.energy(model.x0) is None
    assert np.allclose(model.force(model.x0, 0.25), 0.25 * (trac.vector + corr.vector))


def test_baudet_correction_equilibrated_on_distorted_block():
    grid = M.hex_grid(2.0, 1.0, 3.0, 2, 1, 3)
    pts = grid.points + 0.08 * np.random.default_rng(11).uniform(-1, 1, grid.points.shape)
    mesh = M.Mesh(pts, grid.cells, "hexahedron")
    facets = M.boundary_facets(mesh)
    top = facets[np.all(np.isin(facets, np.flatnonzero(grid.points[:, 2] == 3.0)), axis=1)]
    trac = Traction(mesh, top, [0.3, 0.0, 4.0])
    corr = BaudetCorrection(mesh, trac.nodal, np.linspace(-0.1, 0.05, mesh.n_cells))
    assert np.allclose(corr.nodal.sum(axis=0), 0.0, atol=1e-12)
    assert np.allclose(moment(mesh.points, corr.nodal), 0.0, atol=1e-12)
    loaded = np.abs(corr.face_force).sum(axis=1) > 0
    assert loaded.sum() == 2 and loaded[-2:].all()  # only the two top cells
    assert (corr.face_force[-2:, 1] > 0).all()  # tension on the (tilted) top faces
    # zero Jacobian: the stiffness is that of the other terms
    springs = Springs(M.unique_edges(mesh).pairs, 1.0, 1.0, 3)
    with_corr = Model(mesh, [springs, trac, corr])
    without = Model(mesh, [springs, trac])
    x = perturbed(mesh, 0.01, 12)
    assert abs(with_corr.stiffness(x) - without.stiffness(x)).max() == 0.0
    assert with_corr.energy(x) is None and without.energy(x) is not None


# --------------------------------------------------------------------------------------------
# boundary conditions and reactions
# --------------------------------------------------------------------------------------------


def test_reactions_balance_applied_loads(params):
    mesh = M.triangle_grid_right(2.0, 1.0, 4, 2)
    (springs,) = lloyd_triangle_springs(mesh, [(E0, NU0)], T0)
    left = M.select_nodes(mesh, plane=("x", 0.0))
    right = M.select_nodes(mesh, plane=("x", 2.0))
    fixed = np.zeros((mesh.n_nodes, 2), dtype=bool)
    fixed[left] = True
    edges = M.boundary_facets(mesh)
    edges = edges[np.all(np.isin(edges, right), axis=1)]
    trac = Traction(mesh, edges, [0.5, -0.2], thickness=T0)
    on_fixed = np.zeros((mesh.n_nodes, 2))
    on_fixed[left[0]] = [0.1, 0.2]
    model = Model(mesh, [springs, trac, NodalForces(on_fixed)], fixed=fixed)
    # at rest the springs are unloaded: the supports only take the loads on fixed nodes
    assert np.allclose(model.reaction(model.x0), -on_fixed)
    # Newton on the free dofs, then global balance
    x = model.apply_prescribed(model.x0, 1.0)
    free = model.free
    for _ in range(20):
        r = model.force(x)[free]
        if np.linalg.norm(r) < 1e-12:
            break
        K = model.stiffness(x).tocsc()[free][:, free]
        x[free] += sp.linalg.spsolve(K, r)
    assert np.linalg.norm(model.force(x)[free]) < 1e-10
    applied = trac.total + on_fixed.sum(axis=0)
    assert np.allclose(model.reaction(x).sum(axis=0) + applied, 0.0, atol=1e-10)
    assert np.allclose(model.reaction(x)[~fixed.any(axis=1)], 0.0)


def test_prescribed_displacements_and_masks():
    mesh = M.quad_grid(1.0, 1.0, 1, 1)
    fixed = np.zeros((4, 2), dtype=bool)
    fixed[[0, 3]] = True
    presc = np.zeros((4, 2))
    presc[3] = [0.0, 0.2]
    model = Model(mesh, [], fixed=fixed, prescribed=presc, masses=np.full(4, 2.0))
    x = model.apply_prescribed(model.x0 + 1.0, 0.5)
    assert np.allclose(x.reshape(4, 2)[3], [1.0, 1.1]) and np.allclose(x.reshape(4, 2)[1], [2.0, 1.0])
    assert model.free.sum() == 4 and model.symmetric
    assert np.allclose(model.mass, 2.0)
    assert model.stiffness(model.x0).nnz == model.n_dof  # empty model: the diagonal pattern only
    with pytest.raises(ValueError, match="free dofs"):
        Model(mesh, [], prescribed=presc)


def test_baudet_cube_tension_gives_E_and_nu():
    """A single Baudet cube in tension, with the derived correction, has the target E and nu
    (linearised: a lone M2 cube has two zero-energy modes, which the face loads do not excite)."""

    E, nu, F = 1000.0, 0.4, 1e-3
    mesh = M.hex_grid(1.0, 1.0, 1.0, 1, 1, 1)
    top = mesh.cells[:, 4:]
    bottom = mesh.cells[:, [0, 3, 2, 1]]
    loads = [Traction(mesh, top, [0.0, 0.0, F]), Traction(mesh, bottom, [0.0, 0.0, -F])]
    corr = baudet_correction(mesh, [(E, nu)], loads)
    fixed = np.zeros((8, 3), bool)
    c = mesh.cells[0]  # VTK order: pin node 0, node 1 (along x) in y, z and node 3 (along y) in z
    fixed[c[0]] = True
    fixed[c[1], [1, 2]] = True
    fixed[c[3], 2] = True
    model = Model(mesh, baudet_cube_springs(mesh, [(E, nu)]) + loads + [corr], fixed=fixed)
    K = model.stiffness(model.x0).toarray()
    u = np.linalg.lstsq(K, model.force(model.x0), rcond=None)[0].reshape(-1, 3)
    P = mesh.points
    ez = u[P[:, 2] > 0.5, 2].mean() - u[P[:, 2] < 0.5, 2].mean()
    ex = u[P[:, 0] > 0.5, 0].mean() - u[P[:, 0] < 0.5, 0].mean()
    assert F / ez == pytest.approx(E, rel=1e-4)
    assert -ex / ez == pytest.approx(nu, rel=1e-4)


def test_baudet_correction_faces_under_pressure_get_their_full_load():
    """Pressure on all six faces of a cube: every face's elongation force is its own resultant
    (corner nodes carry three faces' loads; each face takes its own normal component)."""
    mesh = M.hex_grid(2.0, 2.0, 2.0, 1, 1, 1)
    p = 3.0
    loads = []
    for f in M.boundary_facets(mesh):
        n = np.cross(mesh.points[f[1]] - mesh.points[f[0]], mesh.points[f[2]] - mesh.points[f[0]])
        loads.append(Traction(mesh, f[None, :], -p * n / np.linalg.norm(n)))
    corr = baudet_correction(mesh, [(E0, NU0)], loads)
    assert np.allclose(corr.face_force, -p * 4.0)
