"""Uniform nested refinement (msslib.mesh.refine): same domain, nested nodes, exact child measures."""

import numpy as np
import pytest

from msslib import fem
from msslib import mesh as M
from msslib.mesh.refine import CHILDREN, uniform


def _cell_sets(mesh, decimals=12):
    """Each cell as the sorted tuple of its rounded node coordinates (independent of numbering)."""
    x = np.round(mesh.points[mesh.cells], decimals)
    return sorted(tuple(sorted(map(tuple, c.tolist()))) for c in x)


@pytest.mark.parametrize("coarse, fine", [
    (lambda: M.quad_grid(1.0, 0.5, 3, 2), lambda: M.quad_grid(1.0, 0.5, 6, 4)),
    (lambda: M.hex_grid(0.4, 0.1, 0.2, 4, 1, 2), lambda: M.hex_grid(0.4, 0.1, 0.2, 8, 2, 4)),
    (lambda: M.triangle_grid_right(1.0, 1.0, 2, 3), lambda: M.triangle_grid_right(1.0, 1.0, 4, 6)),
])
def test_grids_refine_into_the_grid_of_half_the_step(coarse, fine):
    c, f = coarse(), fine()
    r = uniform(c)
    assert r.n_cells == CHILDREN[c.cell_type] * c.n_cells == f.n_cells
    assert r.n_nodes == f.n_nodes
    np.testing.assert_array_equal(r.points[: c.n_nodes], c.points)  # nested numbering
    assert _cell_sets(r) == _cell_sets(f)


def test_triangle_and_tetra_children_have_exactly_an_equal_share():
    rng = np.random.default_rng(3)
    tri = M.orient(M.Mesh(rng.random((3, 2)), np.array([[0, 1, 2]]), "triangle"))
    tet = M.orient(M.Mesh(rng.random((4, 3)), np.array([[0, 1, 2, 3]]), "tetra"))
    for mesh in (tri, tet):
        r = uniform(mesh)
        share = M.cell_measures(r) / M.cell_measures(mesh)[0]
        np.testing.assert_allclose(share, 1.0 / CHILDREN[mesh.cell_type], rtol=1e-12)
        assert r.n_nodes == mesh.n_nodes + len(M.unique_edges(mesh).pairs)


def test_cylinder_twice_refined_keeps_volume_boundary_and_quality():
    c = M.cylinder_mesh(0.01, 0.02, 0.006)
    r = uniform(c, 2)
    assert r.n_cells == 64 * c.n_cells
    M.check_cells(r)  # every child positively oriented and non-degenerate
    assert M.cell_measures(r).sum() == pytest.approx(M.cell_measures(c).sum(), rel=1e-13)
    area = lambda m: M.facet_areas(m, M.boundary_facets(m)).sum()
    assert area(r) == pytest.approx(area(c), rel=1e-13)  # the same (polyhedral) surface
    q = M.cell_measures(r) / M.cell_measures(c).repeat(64)
    np.testing.assert_allclose(q, 1.0 / 64, rtol=1e-10)


def test_distorted_hex_refines_along_its_trilinear_map():
    rng = np.random.default_rng(7)
    ref = M.hex_grid(1.0, 1.0, 1.0, 1, 1, 1)
    x = ref.points + 0.15 * rng.standard_normal(ref.points.shape)
    h = M.Mesh(x, ref.cells, "hexahedron")
    r = uniform(h)
    corners = ref.points  # unit-cube corners in node order
    for p in r.points:
        # the new point is the trilinear map of some half-step parameter point
        found = False
        for s in np.array(np.meshgrid(*[[0, 0.5, 1]] * 3, indexing="ij")).reshape(3, -1).T:
            w = np.prod(np.where(corners == 1, s, 1 - s), axis=1)
            if np.allclose(w @ x, p, atol=1e-14):
                found = True
                break
        assert found
    assert M.cell_measures(r).sum() == pytest.approx(M.cell_measures(h).sum(), rel=1e-12)


def test_groups_follow_the_children():
    base = M.quad_grid(1.0, 1.0, 2, 2)
    top = np.flatnonzero(base.points[:, 1] == 1.0)
    facets = M.boundary_facets(base)
    top_facets = facets[np.all(base.points[facets, 1] == 1.0, axis=1)]
    g = M.Mesh(base.points, base.cells, "quad", cell_groups={"left": np.array([0, 2])},
               node_groups={"top": top}, facet_groups={"top": top_facets})
    r = uniform(g)
    np.testing.assert_array_equal(r.cell_groups["left"], [0, 1, 2, 3, 8, 9, 10, 11])
    assert np.all(r.points[r.node_groups["top"], 1] == 1.0) and len(r.node_groups["top"]) == 5
    rf = r.facet_groups["top"]
    assert len(rf) == 4 and np.all(r.points[rf, 1] == 1.0)
    assert np.all(M.facet_cell_counts(r, rf) == 1)
    assert M.facet_areas(r, rf).sum() == pytest.approx(1.0)
    # orientation kept: refined boundary facets are outward like the parent's
    bf = {tuple(f) for f in M.boundary_facets(r).tolist()}
    assert all(tuple(f) in bf for f in rf.tolist())


def test_nested_spaces_make_the_compliance_grow_monotonically():
    """Galerkin on nested P1 spaces: the compliance f.u of the same load never decreases."""
    mesh = M.cylinder_mesh(0.01, 0.02, 0.006)
    compliance = []
    for k in range(3):
        m = uniform(mesh, k)
        fixed = np.zeros((m.n_nodes, 3), dtype=bool)
        fixed[m.points[:, 2] < 1e-12] = True
        res = fem.solve_linear(m, 15000.0, 0.25, fixed=fixed, body_force=[0.0, 1000.0, 0.0])
        compliance.append(2 * res.strain_energy)
    assert compliance[0] < compliance[1] < compliance[2]


def test_bad_arguments():
    with pytest.raises(ValueError, match="times"):
        uniform(M.quad_grid(1, 1, 1, 1), -1)
    with pytest.raises(ValueError, match="Mesh"):
        uniform("mesh")
    m = M.quad_grid(1, 1, 1, 1)
    assert uniform(m, 0) is m
