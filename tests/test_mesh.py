"""Tests of msslib.mesh: structured generators, gmsh meshes, I/O, topology and geometry helpers."""

import threading

import meshio
import numpy as np
import pytest

from msslib import mesh as M
from msslib.mesh import core


def enclosed_volume(mesh):
    """Volume from the boundary facets by the divergence theorem (checks their outward orientation)."""
    f = M.boundary_facets(mesh)
    x = mesh.points[f]
    tris = [x[:, [0, 1, 2]]] if f.shape[1] == 3 else [x[:, [0, 1, 2]], x[:, [0, 2, 3]]]
    return sum(np.einsum("ij,ij->", t[:, 0], np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])) for t in tris) / 6.0


def edge_lengths(mesh):
    pairs = M.unique_edges(mesh).pairs
    return np.linalg.norm(mesh.points[pairs[:, 1]] - mesh.points[pairs[:, 0]], axis=1)


# ------------------------------------------------------------------ structured generators


def test_quad_grid_counts_and_area():
    m = M.quad_grid(3.0, 2.0, 3, 2, origin=(1.0, -1.0))
    assert (m.n_nodes, m.n_cells, m.cell_type) == (12, 6, "quad")
    edges = M.unique_edges(m)
    assert len(edges.pairs) == 3 * 3 + 4 * 2  # horizontal + vertical
    assert np.all(edges.pairs[:, 0] < edges.pairs[:, 1])
    assert sorted(np.bincount(edges.counts)[1:]) == [7, 10]  # 10 boundary edges, 7 interior
    np.testing.assert_allclose(M.cell_measures(m), 1.0)
    np.testing.assert_allclose(m.points.min(axis=0), [1.0, -1.0])
    assert M.facet_areas(m, M.boundary_facets(m)).sum() == pytest.approx(10.0)
    diag = M.face_diagonals(m)
    assert len(diag.pairs) == 12 and np.all(diag.counts == 1)


def test_triangle_grid_right():
    m = M.triangle_grid_right(2.0, 1.0, 4, 2)
    assert (m.n_nodes, m.n_cells) == (15, 16)
    assert len(M.unique_edges(m).pairs) == 15 + 16 - 1  # Euler: V - E + F = 1
    np.testing.assert_allclose(M.cell_measures(m), 2.0 / 16)


def test_triangle_grid_equilateral():
    n_rows, used = M.equilateral_rows(1.0, 1.0, 4)
    assert n_rows == 4 and used == pytest.approx(np.sqrt(3) / 2)
    m = M.triangle_grid_equilateral(1.0, 1.0, 4)
    assert (m.n_nodes, m.n_cells) == (5 + 4 + 5 + 4 + 5, n_rows * (2 * 4 - 1))
    np.testing.assert_allclose(edge_lengths(m), 0.25, rtol=1e-12)
    assert np.all(M.cell_measures(m) > 0)
    assert m.points[:, 1].max() == pytest.approx(used)
    assert m.points[:, 0].min() == 0.0 and m.points[:, 0].max() == pytest.approx(1.0)
    with pytest.raises(ValueError, match="height"):
        M.triangle_grid_equilateral(1.0, 0.1, 4)


@pytest.mark.parametrize("n", [1, 2, 3])
def test_hexagon_equilateral(n):
    m = M.hexagon_equilateral(2.0, n)
    assert (m.n_nodes, m.n_cells) == (3 * n * n + 3 * n + 1, 6 * n * n)
    np.testing.assert_allclose(edge_lengths(m), 2.0 / np.sqrt(3) / n, rtol=1e-12)
    assert M.cell_measures(m).sum() == pytest.approx(np.sqrt(3) / 2 * 2.0**2)
    assert m.points[:, 1].max() == pytest.approx(1.0)  # flat top at height / 2


def test_hex_grid_counts():
    m = M.hex_grid(1.0, 1.0, 1.0, 2, 2, 2)
    assert (m.n_nodes, m.n_cells) == (27, 8)
    edges = M.unique_edges(m)
    assert len(edges.pairs) == 54
    # the 6 edges through the centre are shared by 4 cubes; the 12 box edges by one
    assert np.sum(edges.counts == 4) == 6 and np.sum(edges.counts == 1) == 24
    k = int(np.flatnonzero((edges.pairs == [4, 13]).all(axis=1))[0])
    assert len(edges.cells_of(k)) == 4
    diag = M.face_diagonals(m)
    assert len(diag.pairs) == 6 * 4 * 2 + 12 * 2  # boundary faces + interior faces, 2 diagonals each
    assert np.sum(diag.counts == 2) == 24
    inner = M.inner_diagonals(m)
    assert len(inner.pairs) == 32 and np.all(inner.counts == 1)
    np.testing.assert_allclose(M.cell_measures(m), 1.0 / 8)


def test_hex_grid_boundary_area_and_orientation():
    m = M.hex_grid(1.0, 2.0, 3.0, 2, 3, 2, origin=(1.0, 0.0, -1.0))
    f = M.boundary_facets(m)
    assert f.shape == (2 * (2 * 3 + 3 * 2 + 2 * 2), 4)
    assert M.facet_areas(m, f).sum() == pytest.approx(2 * (2 + 3 + 6))
    assert enclosed_volume(m) == pytest.approx(6.0)


def test_hex_volume_trilinear_exact():
    # a distorted hexahedron: compare with a fine tet split of the same trilinear map
    m = M.hex_grid(1.0, 1.0, 1.0, 1, 1, 1)
    pts = m.points[m.cells[0]]  # corners in hexahedron order
    pts[6] += [0.3, 0.2, 0.4]
    pts[1] += [0.1, -0.1, 0.0]
    exact = M.cell_measures(M.Mesh(pts, np.arange(8)[None], "hexahedron"))[0]
    assert exact > 1.0

    def tet_approx(n):  # volume of the tets of an n^3 grid mapped through the trilinear map
        fine = M.tet_grid(1.0, 1.0, 1.0, n, n, n)
        u = fine.points
        shape = np.prod(np.where(core._HEX_REF01[None] == 1, u[:, None, :], 1 - u[:, None, :]), axis=2)
        return M.cell_measures(M.Mesh(shape @ pts, fine.cells, "tetra")).sum()

    v4, v8 = tet_approx(4), tet_approx(8)
    assert exact == pytest.approx(v8 + (v8 - v4) / 3, rel=1e-4)  # Richardson, O(h^2) error


@pytest.mark.parametrize("scheme", [5, 6])
def test_tet_grid_volumes_and_conformity(scheme):
    nx, ny, nz = 3, 2, 2
    m = M.tet_grid(1.0, 2.0, 3.0, nx, ny, nz, scheme=scheme)
    assert m.n_cells == scheme * nx * ny * nz and m.n_nodes == 4 * 3 * 3
    vol = M.cell_measures(m)
    assert np.all(vol > 0)
    assert vol.sum() == pytest.approx(6.0)
    # every triangular face is shared by one (boundary) or two (interior) tetrahedra
    faces = np.sort(m.cells[:, core._LOCAL_FACETS["tetra"]].reshape(-1, 3), axis=1)
    _, counts = np.unique(faces, axis=0, return_counts=True)
    assert set(counts) == {1, 2}
    # boundary triangles cover the box surface exactly: no hanging faces
    f = M.boundary_facets(m)
    assert len(f) == np.sum(counts == 1) == 2 * 2 * (nx * ny + ny * nz + nz * nx)
    assert M.facet_areas(m, f).sum() == pytest.approx(2 * (2 + 6 + 3))
    assert enclosed_volume(m) == pytest.approx(6.0)
    with pytest.raises(ValueError):
        M.tet_grid(1, 1, 1, 1, 1, 1, scheme=4)


def test_l_block_hex():
    m = M.l_block_hex(2.0, 4)
    assert m.n_cells == 3 * 4**3 // 4
    assert m.n_nodes == 5 * (25 - 4)  # the 2 x 2 nodes strictly inside the notch go
    assert M.cell_measures(m).sum() == pytest.approx(0.75 * 8)
    assert M.facet_areas(m, M.boundary_facets(m)).sum() == pytest.approx(2 * 3.0 + 4 * 2.0 * 2.0)
    assert not np.any((m.points[:, 0] > 1.0 + 1e-12) & (m.points[:, 2] > 1.0 + 1e-12))
    with pytest.raises(ValueError, match="even"):
        M.l_block_hex(1.0, 3)


# ------------------------------------------------------------------ gmsh meshes


def assert_clean_simplices(m):
    assert np.all(M.cell_measures(m) > 0)
    assert np.array_equal(np.unique(m.cells), np.arange(m.n_nodes))  # only used nodes


def test_polygon_mesh():
    m = M.polygon_mesh([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], h=0.25)
    assert m.cell_type == "triangle" and m.dim == 2
    assert_clean_simplices(m)
    assert M.cell_measures(m).sum() == pytest.approx(3.0)
    assert M.facet_areas(m, M.boundary_facets(m)).sum() == pytest.approx(8.0)
    clockwise = M.polygon_mesh([[0, 0], [0, 1], [1, 1], [1, 0]], h=0.5)
    assert_clean_simplices(clockwise)


def test_cylinder_mesh_volume_and_determinism():
    r, height = 0.5, 1.0
    m = M.cylinder_mesh(r, height, h=0.12)
    assert_clean_simplices(m)
    assert M.cell_measures(m).sum() == pytest.approx(np.pi * r**2 * height, rel=0.03)
    assert enclosed_volume(m) == pytest.approx(M.cell_measures(m).sum())
    assert m.points[:, 2].min() == pytest.approx(0.0) and m.points[:, 2].max() == pytest.approx(height)
    again = M.cylinder_mesh(r, height, h=0.12)
    assert np.array_equal(m.points, again.points) and np.array_equal(m.cells, again.cells)


def test_cylinder_with_hole_volume():
    r, height, rh = 0.5, 1.0, 0.25
    m = M.cylinder_with_hole_mesh(r, height, rh, h=0.12)
    assert_clean_simplices(m)
    expected = np.pi * r**2 * height - 4 / 3 * np.pi * rh**3
    assert M.cell_measures(m).sum() == pytest.approx(expected, rel=0.03)
    # no node inside the cavity
    assert np.linalg.norm(m.points - [0, 0, height / 2], axis=1).min() >= rh * (1 - 1e-6)
    with pytest.raises(ValueError):
        M.cylinder_with_hole_mesh(r, height, 0.6, h=0.1)


def test_cone_mesh_volume():
    rb, rt, height = 0.5, 0.25, 1.0
    m = M.cone_mesh(rb, rt, height, h=0.12)
    assert_clean_simplices(m)
    assert M.cell_measures(m).sum() == pytest.approx(np.pi * height * (rb**2 + rb * rt + rt**2) / 3, rel=0.03)


def test_l_block_tet_from_another_thread():
    out = []
    worker = threading.Thread(target=lambda: out.append(M.l_block_tet(1.0, h=0.3)))
    worker.start()
    worker.join()
    (m,) = out
    assert_clean_simplices(m)
    assert M.cell_measures(m).sum() == pytest.approx(0.75)
    assert enclosed_volume(m) == pytest.approx(0.75)


# ------------------------------------------------------------------ I/O


def test_vtu_round_trip_3d(tmp_path):
    m = M.tet_grid(1.0, 1.0, 1.0, 2, 1, 1, scheme=5)
    m = M.Mesh(m.points, m.cells, "tetra", np.arange(m.n_cells) % 3)
    u = m.points * 0.01
    path = M.write_vtu(tmp_path / "out.vtu", m, point_data={"u": u}, cell_data={"vol": M.cell_measures(m)})
    assert [p.name for p in tmp_path.iterdir()] == ["out.vtu"]  # no temporary file left behind
    raw = meshio.read(path)
    np.testing.assert_allclose(raw.point_data["u"], u)
    np.testing.assert_allclose(raw.cell_data["vol"][0], M.cell_measures(m))
    back = M.read(path)
    assert back.cell_type == "tetra"
    np.testing.assert_allclose(back.points, m.points)
    np.testing.assert_array_equal(back.cells, m.cells)
    np.testing.assert_array_equal(back.material, m.material)


def test_vtu_round_trip_2d_padded(tmp_path):
    m = M.quad_grid(2.0, 1.0, 2, 1)
    path = tmp_path / "q.vtu"
    M.write_vtu(path, m, point_data={"u": np.ones((m.n_nodes, 2))})
    raw = meshio.read(path)
    assert raw.points.shape == (6, 3) and raw.point_data["u"].shape == (6, 3)
    back = M.read(path)
    assert back.dim == 2 and back.cell_type == "quad"
    np.testing.assert_allclose(back.points, m.points)
    with pytest.raises(ValueError, match="rows"):
        M.write_vtu(path, m, point_data={"bad": np.ones(3)})


def test_read_picks_highest_dimension_and_drops_unused_nodes(tmp_path):
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [5, 5, 5]], dtype=float)
    cells = [("triangle", np.array([[0, 1, 2]])), ("tetra", np.array([[0, 1, 2, 3]])), ("vertex", np.array([[4]]))]
    path = tmp_path / "mixed.vtu"
    meshio.write(path, meshio.Mesh(points, cells))
    m = M.read(path)
    assert m.cell_type == "tetra" and m.n_nodes == 4


def test_read_errors(tmp_path):
    missing = tmp_path / "nope.vtu"
    with pytest.raises(FileNotFoundError, match="nope.vtu"):
        M.read(missing)
    path = tmp_path / "lines.vtu"
    meshio.write(path, meshio.Mesh(np.zeros((2, 3)) + [[0, 0, 0], [1, 0, 0]], [("line", np.array([[0, 1]]))]))
    with pytest.raises(ValueError, match="line"):
        M.read(path)


# ------------------------------------------------------------------ checks and helpers


def test_check_cells_inverted_and_degenerate():
    m = M.triangle_grid_right(1.0, 1.0, 2, 2)
    assert len(M.check_cells(m)) == m.n_cells
    cells = m.cells.copy()
    cells[5] = cells[5, [0, 2, 1]]
    inverted = M.Mesh(m.points, cells, "triangle")
    with pytest.raises(ValueError, match=r"inverted.*cell 5 \(measure -1\.250e-01\)"):
        M.check_cells(inverted)
    fixed = M.orient(inverted)
    np.testing.assert_allclose(M.cell_measures(fixed), 0.125)
    cells[5] = [0, 1, 2]  # three collinear nodes on y = 0
    with pytest.raises(ValueError, match=r"degenerate.*cell 5"):
        M.check_cells(M.Mesh(m.points, cells, "triangle"))

    t = M.tet_grid(1.0, 1.0, 1.0, 1, 1, 1, scheme=6)
    tc = t.cells.copy()
    tc[3] = tc[3, [1, 0, 2, 3]]
    with pytest.raises(ValueError, match="cell 3"):
        M.check_cells(M.Mesh(t.points, tc, "tetra"))
    assert np.all(M.cell_measures(M.orient(M.Mesh(t.points, tc, "tetra"))) > 0)


def test_select_nodes():
    m = M.hex_grid(1.0, 1.0, 1.0, 2, 2, 2)
    bottom = M.select_nodes(m, plane=("z", 0.0))
    np.testing.assert_array_equal(bottom, np.arange(9))
    corner = M.select_nodes(m, box=((0.6, 0.6, None), (None, None, 0.4)))
    np.testing.assert_array_equal(corner, [8])
    both = M.select_nodes(m, box=((None, None, None), (0.5, None, None)), plane=(2, 1.0))
    np.testing.assert_array_equal(both, [18, 19, 21, 22, 24, 25])
    assert len(M.select_nodes(m)) == 27
    with pytest.raises(ValueError, match="no node"):
        M.select_nodes(m, plane=("x", 0.25))


def test_lumped_masses():
    m = M.quad_grid(2.0, 1.0, 2, 1)
    masses = M.lumped_masses(m, density=1000.0, thickness=0.01)
    assert masses.sum() == pytest.approx(1000.0 * 2.0 * 0.01)
    np.testing.assert_allclose(masses, [2.5, 5, 2.5, 2.5, 5, 2.5])
    t = M.tet_grid(1.0, 1.0, 1.0, 2, 2, 2, scheme=5)
    assert M.lumped_masses(t, 7800.0).sum() == pytest.approx(7800.0)
    with pytest.raises(ValueError):
        M.lumped_masses(t, 7800.0, thickness=0.1)
