"""Every cell type of the registry (msslib.mesh.cells), tested for free: its faces close its
surface and point out, its measure equals the divergence-theorem volume of its faces, its flip
turns it inside out, its shape gradients reproduce linear fields, its refinement splits it into
children of equal measure, its scikit-fem elements integrate its volume and carry a uniform strain
with the exact energy, its quality check is 1 at rest, and a mesh of it goes through a VTU file
and a result.  The functions take the cell type's name, so the throw-away cell type of
tests/test_new_cell_type.py runs them too."""

from __future__ import annotations

import numpy as np
import pytest

from msslib import mesh as M
from msslib.mesh import cells
from msslib.mesh.refine import uniform

NAMES = cells.names()
#: a fixed affine map (det > 0) per dimension: a sheared, stretched, turned image of the reference cell
_AFFINE = {2: (np.array([[1.3, 0.4], [-0.2, 0.9]]), np.array([0.5, -1.0])),
           3: (np.array([[1.1, 0.3, -0.2], [0.1, 0.8, 0.25], [-0.3, 0.2, 1.4]]), np.array([0.5, -1.0, 2.0]))}


def _one_cell(name: str, affine: bool = False) -> M.Mesh:
    ct = cells.get(name)
    x = ct.reference
    if affine:
        A, b = _AFFINE[ct.dim]
        x = x @ A.T + b
    return M.Mesh(x, np.arange(ct.nodes)[None, :], name)


def _face_volume(ct, x: np.ndarray) -> float:
    """(1 / dim) sum over the faces of x0 . S (S the outward area vector of the planar face): the
    divergence theorem, from the faces alone."""
    total = 0.0
    for face in ct.faces:
        p = x[list(face)]
        if ct.dim == 2:
            d = p[1] - p[0]
            area = np.array([d[1], -d[0]])
        else:
            area = 0.5 * sum(np.cross(p[i], p[(i + 1) % len(p)]) for i in range(len(p)))
        total += p[0] @ area
    return total / ct.dim


@pytest.mark.parametrize("name", NAMES)
def test_faces_close_the_surface_and_use_the_edges(name):
    ct = cells.get(name)
    edges = {tuple(sorted(e)) for e in ct.edges.tolist()}
    assert len(edges) == len(ct.edges)  # no edge twice
    if ct.dim == 2:
        assert {tuple(sorted(f)) for f in ct.faces} == edges
        return
    directed = [(f[i], f[(i + 1) % len(f)]) for f in ct.faces for i in range(len(f))]
    assert len(set(directed)) == len(directed)
    assert {(b, a) for a, b in directed} == set(directed)  # each edge in two faces, once each way
    assert {tuple(sorted(e)) for e in directed} == edges
    assert set(ct.facet_types) <= {"triangle", "quad"}
    assert sum(len(f) for f in ct.facets_by_type().values()) == len(ct.faces)


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("affine", [False, True])
def test_the_measure_is_the_volume_of_the_faces_and_the_flip_negates_it(name, affine):
    ct = cells.get(name)
    mesh = _one_cell(name, affine)
    x = mesh.points
    volume = _face_volume(ct, x)
    assert volume > 0
    measure = M.cell_measures(mesh)
    np.testing.assert_allclose(measure, volume, rtol=1e-13)
    if affine:
        A, _ = _AFFINE[ct.dim]
        np.testing.assert_allclose(measure, np.linalg.det(A) * _face_volume(ct, ct.reference), rtol=1e-13)
    flipped = M.Mesh(x, mesh.cells[:, list(ct.flip)], name)
    np.testing.assert_allclose(M.cell_measures(flipped), -volume, rtol=1e-13)
    np.testing.assert_array_equal(M.orient(flipped).cells, flipped.cells[:, list(ct.flip)])


@pytest.mark.parametrize("name", NAMES)
def test_shape_gradients_reproduce_linear_fields(name):
    ct = cells.get(name)
    rng = np.random.default_rng(1)
    pts = np.vstack([ct.sample_points, ct.reference.mean(axis=0), 0.5 * (ct.reference[0] + ct.reference[-1])])
    pts = np.vstack([pts, pts[-1] + 0.01 * rng.standard_normal(ct.dim)])
    grad = ct.gradients(pts)  # (p, nodes, dim)
    assert grad.shape == (len(pts), ct.nodes, ct.dim)
    np.testing.assert_allclose(grad.sum(axis=1), 0.0, atol=1e-14)  # constants have no gradient
    np.testing.assert_allclose(np.einsum("ai,pad->pid", ct.reference, grad), np.broadcast_to(np.eye(ct.dim),
                               (len(pts), ct.dim, ct.dim)), atol=1e-14)  # the coordinates are their own field


@pytest.mark.parametrize("name", NAMES)
def test_refinement_splits_a_cell_into_children_of_equal_measure(name):
    ct = cells.get(name)
    mesh = _one_cell(name, affine=True)
    fine = uniform(mesh, 1)
    n = ct.refinement.n_children
    assert fine.n_cells == n
    np.testing.assert_array_equal(fine.points[:ct.nodes], mesh.points)
    np.testing.assert_allclose(M.check_cells(fine), M.cell_measures(mesh)[0] / n, rtol=1e-12)
    # the new nodes are the means of the corners that define them, shared: no node twice
    assert len(np.unique(np.round(fine.points, 12), axis=0)) == fine.n_nodes == len(ct.refinement.virtual)
    # a boundary facet of every type, refined with the cell: 4 children each, same area, still on the boundary
    for kind, local in ct.facets_by_type().items():
        group = M.Mesh(mesh.points, mesh.cells, name, facet_groups={"f": mesh.cells[0, local[:1]]})
        refined = uniform(group, 1).facet_groups["f"]
        assert len(refined) == cells.refinement_of(kind).n_children
        before = M.facet_areas(group, group.facet_groups["f"]).sum()
        assert M.facet_areas(fine, refined).sum() == pytest.approx(before, rel=1e-12)
        from msslib.mesh.topology import facet_cell_counts

        assert (facet_cell_counts(fine, refined) == 1).all()


def _isotropic(dim, E, nu):
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    if dim == 2:  # plane stress
        lam = 2 * lam * mu / (lam + 2 * mu)
    return lam, mu


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("order", [1, 2])
def test_the_fem_elements_integrate_the_volume_and_a_uniform_strain_exactly(name, order):
    from msslib.fem.solve import solve_linear
    from msslib.fem.space import _Geometry

    ct = cells.get(name)
    if order == 2 and ct.quadratic is None:
        with pytest.raises(ValueError, match=rf"^order must be 1 for {name} cells \(scikit-fem has no quadratic "):
            _Geometry(_one_cell(name), order=2)
        return
    mesh = uniform(_one_cell(name, affine=True), 1)
    volume = M.cell_measures(mesh).sum()
    assert _Geometry(mesh, order=order).dx.sum() == pytest.approx(volume, rel=1e-13)
    # a uniform strain prescribed on every node: the energy is 1/2 eps : C : eps times the volume
    d = ct.dim
    G = 1e-3 * np.arange(1, d * d + 1, dtype=float).reshape(d, d)
    eps = 0.5 * (G + G.T)
    E, nu = 1e4, 0.3
    lam, mu = _isotropic(d, E, nu)
    energy = 0.5 * (lam * np.trace(eps) ** 2 + 2 * mu * np.sum(eps * eps)) * volume
    res = solve_linear(mesh, E, nu, fixed=np.ones((mesh.n_nodes, d), dtype=bool), prescribed=mesh.points @ G.T,
                       order=order)
    assert res.strain_energy == pytest.approx(energy, rel=1e-12)


@pytest.mark.parametrize("name", NAMES)
def test_the_quality_check_is_one_at_rest_and_negative_inside_out(name):
    from msslib.mesh.quality import relative_jacobians

    ct = cells.get(name)
    mesh = uniform(_one_cell(name, affine=True), 1)
    np.testing.assert_allclose(relative_jacobians(mesh, mesh.points), 1.0, rtol=1e-12)
    mirrored = mesh.points * np.r_[-1.0, np.ones(ct.dim - 1)]
    np.testing.assert_allclose(relative_jacobians(mesh, mirrored), -1.0, rtol=1e-12)


@pytest.mark.parametrize("name", NAMES)
def test_a_mesh_goes_through_a_vtu_file_and_a_result(name, tmp_path):
    import meshio

    from msslib.results.netcdf import make_dataset, mesh_from_result

    ct = cells.get(name)
    mesh = uniform(_one_cell(name, affine=True), 1)
    M.write_vtu(tmp_path / "m.vtu", mesh)
    raw = meshio.read(tmp_path / "m.vtu")
    assert [b.type for b in raw.cells] == [ct.meshio]
    back = M.read(tmp_path / "m.vtu")
    same = next(n for n, c in cells.registry().items() if c.meshio == ct.meshio)  # the type read for it
    assert back.cell_type == same
    np.testing.assert_array_equal(back.cells, mesh.cells)
    ds = make_dataset(mesh, np.zeros((mesh.n_nodes, ct.dim)), model="fem_linear", E=1e4, nu=0.3)
    again = mesh_from_result(ds)
    assert again.cell_type == name
    np.testing.assert_array_equal(again.cells, mesh.cells)
    if ct.dim == 3:
        from msslib.results.conventions import VOLUME_SHAPES

        assert (ds["cell_shape"].values == VOLUME_SHAPES.index(ct.volume_shape)).all()


def test_the_mesh_tables_are_read_from_the_registry():
    assert list(M.CELL_TYPES) == list(NAMES)
    for name, ct in cells.registry().items():
        assert M.CELL_TYPES[name] == (ct.dim, ct.nodes)
    with pytest.raises(ValueError, match=r"^unknown cell_type 'pyramid'; expected one of \["):
        M.Mesh(np.zeros((5, 3)), np.arange(5)[None, :], "pyramid")


def test_the_derivation_engine_numbers_its_cells_as_the_registry_does():
    """The engine's cell list (derivations.element_stiffness, kept apart: msslib imports nothing of
    derivations) has the registry's reference nodes in the same order, and its shape functions have
    the registry's gradients, for every type it knows."""
    import sympy as sp

    from derivations.element_stiffness import _REF, shape_functions

    assert set(_REF) <= set(NAMES)
    for name, nodes in _REF.items():
        ct = cells.get(name)
        np.testing.assert_array_equal(np.array(nodes, dtype=float), ct.reference, err_msg=name)
        N, ref = shape_functions(name)
        point = ct.reference.mean(axis=0) + 0.05 * np.arange(1, ct.dim + 1)
        grad = np.array([[float(sp.diff(n, r).subs(dict(zip(ref, point)))) for r in ref] for n in N])
        np.testing.assert_allclose(grad, ct.gradients(point[None])[0], atol=1e-14, err_msg=name)
