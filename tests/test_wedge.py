"""The wedge (6-node triangular prism), the worked example of a cell type added as one module
(msslib/mesh/cells/wedge.py): its quadrature rule, its linear FEM element against an exact symbolic
stiffness and a patch test, refinement, facets of two types, export and the result writer, the
quality check, and ``plan`` refusing it (no quadratic element) in one line."""

from __future__ import annotations

from fractions import Fraction
from math import factorial

import meshio
import numpy as np
import pytest
import yaml

from msslib import mesh as M
from msslib.mesh import cells
from msslib.mesh.refine import uniform

WEDGE = cells.get("wedge")


def _box(nx=2, ny=2, nz=3):
    return M.wedge_grid(2.0, 1.0, 3.0, nx, ny, nz)


# --------------------------------------------------------------------------------------------
# quadrature
# --------------------------------------------------------------------------------------------


def test_the_rule_weights_sum_to_the_reference_volume_and_integrate_polynomials_exactly():
    points, weights = WEDGE.linear.rule
    assert weights.sum() == pytest.approx(0.5, abs=1e-15)  # the unit triangle (1/2) times [0, 1]
    for a in range(3):
        for b in range(3 - a):
            for c in range(4):
                exact = Fraction(factorial(a) * factorial(b), factorial(a + b + 2)) / (c + 1)
                value = weights @ (points[0] ** a * points[1] ** b * points[2] ** c)
                assert value == pytest.approx(float(exact), rel=1e-14, abs=1e-16), (a, b, c)


def test_the_fem_basis_integrates_the_volume_where_scikit_fems_own_wedge_rule_does_not():
    import skfem

    from msslib.fem.space import _Geometry

    mesh = M.wedge_grid(1.0, 2.0, 3.0, 1, 1, 1)  # two wedges of volume 3 each
    assert _Geometry(mesh).dx.sum() == pytest.approx(6.0, rel=1e-14)
    own = skfem.Basis(skfem.MeshWedge1(), skfem.ElementWedge1()).dx.sum()  # the unit cube, two wedges
    if abs(own - 1.0) < 1e-12:
        pytest.skip("this scikit-fem's own wedge rule is right: the rule of msslib is no longer needed")
    assert own == pytest.approx(0.5, rel=1e-12)  # scikit-fem 12.0.2: weights summing to 1/4, not 1/2


# --------------------------------------------------------------------------------------------
# the linear element against an exact stiffness, and a patch test
# --------------------------------------------------------------------------------------------


def _exact_stiffness(coords, E, nu):
    """K = int B^T D B dV of a wedge whose map is affine (a prism with parallel, congruent
    triangles), integrated exactly with SymPy from the shape functions written out here."""
    import sympy as sp

    xi, eta, zeta = sp.symbols("xi eta zeta")
    L = [1 - xi - eta, eta, xi]
    N = [li * (1 - zeta) for li in L] + [li * zeta for li in L]
    X = sp.Matrix([[sp.nsimplify(v) for v in row] for row in coords])
    dN = sp.Matrix([[sp.diff(n, r) for r in (xi, eta, zeta)] for n in N])
    J = X.T * dN
    assert all(sp.diff(e, r) == 0 for e in J for r in (xi, eta, zeta)), "not an affine prism"
    grad = dN * J.inv()
    B = sp.zeros(6, 18)
    for a in range(6):
        gx, gy, gz = grad[a, 0], grad[a, 1], grad[a, 2]
        B[0, 3 * a], B[1, 3 * a + 1], B[2, 3 * a + 2] = gx, gy, gz
        B[3, 3 * a + 1], B[3, 3 * a + 2] = gz, gy
        B[4, 3 * a], B[4, 3 * a + 2] = gz, gx
        B[5, 3 * a], B[5, 3 * a + 1] = gy, gx
    E, nu = sp.nsimplify(E), sp.nsimplify(nu)
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    D = sp.zeros(6, 6)
    D[:3, :3] = sp.ones(3, 3) * lam
    for i in range(3):
        D[i, i] += 2 * mu
        D[3 + i, 3 + i] = mu

    def integrate(e):
        poly = sp.Poly(sp.expand(e), xi, eta, zeta)
        return sum(c * sp.Rational(factorial(p) * factorial(q), factorial(p + q + 2)) / (r + 1)
                   for (p, q, r), c in poly.terms())

    K = (B.T * D * B * J.det()).applyfunc(integrate)
    return np.array(K.evalf(), dtype=float)


@pytest.mark.parametrize("coords", [
    [[0, 0, 0], [0, 1, 0], [2, 0, 0], [0, 0, 3], [0, 1, 3], [2, 0, 3]],  # a right prism
    [[0, 0, 0], [0.5, 1, 0], [2, 0.25, 0], [1, 0.5, 3], [1.5, 1.5, 3], [3, 0.75, 3]],  # an oblique one
])
def test_the_element_stiffness_is_the_exact_stiffness(coords):
    from msslib.fem.solve import element_stiffness

    coords = np.array(coords, dtype=float)
    K = element_stiffness("wedge", coords, 7.0, 0.3)
    exact = _exact_stiffness(coords, 7.0, 0.3)
    np.testing.assert_allclose(K, exact, rtol=0, atol=1e-12 * np.abs(exact).max())
    assert np.count_nonzero(np.abs(np.linalg.eigvalsh(K)) < 1e-10 * np.abs(exact).max()) == 6  # rigid modes


def test_a_linear_displacement_is_reproduced_exactly_patch_test():
    from msslib.fem import solve_linear

    mesh = M.wedge_grid(1.0, 1.0, 1.0, 2, 2, 2)
    rng = np.random.default_rng(3)
    inner = np.flatnonzero(np.all((mesh.points > 0.01) & (mesh.points < 0.99), axis=1))
    points = mesh.points.copy()
    points[inner] += rng.uniform(-0.1, 0.1, (len(inner), 3))  # distorted, not right prisms
    mesh = M.Mesh(points, mesh.cells, "wedge")
    G = np.array([[1e-3, 2e-3, -1e-3], [0.5e-3, -2e-3, 1e-3], [3e-3, 0.0, 1e-3]])
    exact = mesh.points @ G.T + [1e-3, -2e-3, 0.5e-3]
    fixed = np.ones((mesh.n_nodes, 3), dtype=bool)
    fixed[inner] = False
    res = solve_linear(mesh, 1e4, 0.3, fixed=fixed, prescribed=exact)
    np.testing.assert_allclose(res.displacement, exact, rtol=0, atol=1e-12)


# --------------------------------------------------------------------------------------------
# the mesh: generator, measure, orientation, facets of two types, refinement, quality
# --------------------------------------------------------------------------------------------


def test_wedge_grid_fills_the_box_with_positive_wedges():
    mesh = _box()
    assert mesh.n_cells == 2 * 2 * 2 * 3 and mesh.n_nodes == 3 * 3 * 4
    measures = M.check_cells(mesh)
    np.testing.assert_allclose(measures, 2.0 * 1.0 * 3.0 / 24, rtol=1e-14)


def test_orient_flips_inverted_wedges_back():
    mesh = _box()
    cells_ = mesh.cells.copy()
    cells_[::3] = cells_[::3][:, [3, 4, 5, 0, 1, 2]]  # upside down: negative
    flipped = M.Mesh(mesh.points, cells_, "wedge")
    assert (M.cell_measures(flipped)[::3] < 0).all()
    fixed = M.orient(flipped)
    np.testing.assert_allclose(M.cell_measures(fixed), M.cell_measures(mesh), rtol=1e-14)


def test_boundary_facets_are_triangles_and_quads_pointing_out():
    nx, ny, nz = 2, 2, 3
    mesh = _box(nx, ny, nz)
    by_type = M.boundary_facets_by_type(mesh)
    assert {k: len(f) for k, (f, _) in by_type.items()} == {"triangle": 2 * 2 * nx * ny,
                                                           "quad": 2 * (nx * nz + ny * nz)}
    total = np.zeros(3)
    for kind, (facets, owner) in by_type.items():
        x = mesh.points[facets]
        if kind == "triangle":
            normal = 0.5 * np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
        else:
            normal = 0.5 * np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 1])
        out = x.mean(axis=1) - mesh.points[mesh.cells[owner]].mean(axis=1)
        assert (np.einsum("ij,ij->i", normal, out) > 0).all(), kind
        total += normal.sum(axis=0)
        assert (M.facet_cell_counts(mesh, facets) == 1).all()
    np.testing.assert_allclose(total, 0.0, atol=1e-13)  # a closed surface
    area = sum(M.facet_areas(mesh, f).sum() for f, _ in by_type.values())
    assert area == pytest.approx(2 * (2 * 1 + 2 * 3 + 1 * 3), rel=1e-14)
    with pytest.raises(ValueError, match=r"^mesh: wedge cells have facets of several types \(triangle, quad\), "
                                         r"which one array of facets cannot hold \(so no tractions or pressures "
                                         r"on them\); allowed: cells with facets of one type, or "
                                         r"msslib.mesh.boundary_facets_by_type$"):
        M.boundary_facets(mesh)


def test_edges_face_diagonals_and_pieces():
    nx, ny, nz = 2, 2, 3
    mesh = _box(nx, ny, nz)
    hexes = M.hex_grid(2.0, 1.0, 3.0, nx, ny, nz)
    # the hexahedra's edges and the diagonal of every bottom and top face of a cube
    assert len(M.unique_edges(mesh).pairs) == len(M.unique_edges(hexes).pairs) + nx * ny * (nz + 1)
    quads = (nx + 1) * ny * nz + nx * (ny + 1) * nz + nx * ny * nz  # sides of the cubes, the cut inside each
    assert len(M.face_diagonals(mesh).pairs) == 2 * quads
    from msslib.mesh.topology import facet_connected_cells

    assert facet_connected_cells(mesh)[0] == 1
    cut = M.Mesh(mesh.points, mesh.cells[[0, 1, len(mesh.cells) - 1]], "wedge")  # two pieces apart
    assert facet_connected_cells(cut)[0] == 2


def test_refinement_is_nested_and_keeps_the_volume_and_the_facet_groups():
    mesh = _box(1, 1, 1)
    top = np.flatnonzero(np.isclose(mesh.points[:, 2], 3.0))
    tri = [f for f in M.boundary_facets_by_type(mesh)["triangle"][0] if set(f) <= set(top)]
    side = [f for f in M.boundary_facets_by_type(mesh)["quad"][0] if np.isclose(mesh.points[f, 0], 0.0).all()]
    mesh = M.Mesh(mesh.points, mesh.cells, "wedge", facet_groups={"top": tri, "side": side},
                  cell_groups={"first": [0]}, node_groups={"top": top})
    fine = uniform(mesh, 2)
    assert fine.n_cells == 64 * mesh.n_cells
    np.testing.assert_array_equal(fine.points[:mesh.n_nodes], mesh.points)
    measures = M.check_cells(fine)
    np.testing.assert_allclose(measures, 6.0 / fine.n_cells, rtol=1e-13)  # children of equal volume
    assert len(fine.facet_groups["top"]) == 16 * 2 and len(fine.facet_groups["side"]) == 16
    assert M.facet_areas(fine, fine.facet_groups["top"]).sum() == pytest.approx(2.0, rel=1e-14)
    assert M.facet_areas(fine, fine.facet_groups["side"]).sum() == pytest.approx(3.0, rel=1e-14)
    assert (M.facet_cell_counts(fine, fine.facet_groups["top"]) == 1).all()
    np.testing.assert_array_equal(fine.cell_groups["first"], np.arange(64))
    assert np.isclose(fine.points[fine.node_groups["top"], 2], 3.0).all()
    assert len(fine.node_groups["top"]) == 5 * 5
    # the same nodes as the wedge grid of four times the resolution
    grid = M.wedge_grid(2.0, 1.0, 3.0, 4, 4, 4)
    key = lambda p: np.round(p, 12).tolist()
    assert sorted(key(fine.points)) == sorted(key(grid.points))


def test_the_quality_check_finds_an_inverted_wedge():
    from msslib.mesh.quality import check_state, relative_jacobians

    mesh = _box(1, 1, 1)
    np.testing.assert_allclose(relative_jacobians(mesh, mesh.points), 1.0, rtol=1e-14)
    stretched = mesh.points * [2.0, 1.0, 1.0]
    np.testing.assert_allclose(relative_jacobians(mesh, stretched), 2.0, rtol=1e-14)
    moved = mesh.points.copy()
    node = mesh.cells[0, 3]  # a top node of cell 0, pushed below its bottom face
    moved[node, 2] = -3.0
    state = check_state(mesh, moved)
    assert state.n_inverted >= 1 and state.state[0] == 2 and state.ratio[0] < 0


# --------------------------------------------------------------------------------------------
# files and results
# --------------------------------------------------------------------------------------------


def test_a_wedge_mesh_round_trips_through_vtu_and_meshio_reads_wedges(tmp_path):
    mesh = _box()
    M.write_vtu(tmp_path / "w.vtu", mesh)
    raw = meshio.read(tmp_path / "w.vtu")
    assert [b.type for b in raw.cells] == ["wedge"]
    np.testing.assert_array_equal(raw.cells[0].data, mesh.cells)
    back = M.read(tmp_path / "w.vtu")
    assert back.cell_type == "wedge"
    np.testing.assert_array_equal(back.cells, mesh.cells)
    np.testing.assert_array_equal(back.points, mesh.points)


def _wedge_file(tmp_path):
    """A gmsh 2 file of two wedges with groups 7 (two triangles), 8 (two quads) and 9 (a triangle
    and a quad)."""
    mesh = _box(1, 1, 1)
    by_type = M.boundary_facets_by_type(mesh)
    tri, quad = by_type["triangle"][0][:2], by_type["quad"][0][:2]
    cells_ = [("wedge", mesh.cells), ("triangle", tri[:2]), ("quad", quad[:2]), ("triangle", tri[:1]),
              ("quad", quad[:1])]
    data = {"gmsh:physical": [np.zeros(2, int), np.full(2, 7), np.full(2, 8), np.full(1, 9), np.full(1, 9)],
            "gmsh:geometrical": [np.zeros(2, int), np.ones(2, int), np.ones(2, int), np.full(1, 2), np.full(1, 2)]}
    meshio.write(tmp_path / "w.msh", meshio.Mesh(mesh.points, cells_, cell_data=data), file_format="gmsh22",
                 binary=False)
    return tri, quad


def test_the_triangles_and_quads_of_a_wedge_file_are_facet_groups(tmp_path):
    from msslib.errors import MsslibWarning

    tri, quad = _wedge_file(tmp_path)
    with pytest.warns(MsslibWarning, match=r"facet group '9' has facets of several types \(quad, triangle\): read "
                                           r"as a node group \(a facet group holds facets of one type\)"):
        back = M.read(tmp_path / "w.msh")
    assert back.cell_type == "wedge" and back.n_cells == 2 and sorted(back.facet_groups) == ["7", "8"]
    np.testing.assert_array_equal(back.facet_groups["7"], tri)
    np.testing.assert_array_equal(back.facet_groups["8"], quad)
    assert sorted(back.node_groups) == ["9"]
    np.testing.assert_array_equal(back.node_groups["9"], np.union1d(tri[0], quad[0]))


def test_the_result_writer_names_the_wedge_volume_shape(tmp_path):
    from msslib.results.conventions import VOLUME_SHAPES
    from msslib.results.netcdf import (
        make_dataset,
        mesh_from_result,
        read_result,
        write_result,
    )

    mesh = _box(1, 1, 1)
    ds = make_dataset(mesh, np.zeros((mesh.n_nodes, 3)), model="fem_linear", E=1e4, nu=0.3)
    assert (ds["cell_shape"].values == VOLUME_SHAPES.index("wedge")).all()
    assert ds["cells"].attrs["cell_type"] == "wedge"
    write_result(tmp_path / "r.nc", ds)
    back = mesh_from_result(read_result(tmp_path / "r.nc"))
    assert back.cell_type == "wedge"
    np.testing.assert_array_equal(back.cells, mesh.cells)


# --------------------------------------------------------------------------------------------
# plan: no quadratic reference
# --------------------------------------------------------------------------------------------


def _scene(tmp_path):
    M.write_vtu(tmp_path / "w.vtu", _box(1, 1, 2))
    return {"geometry": {"file": str(tmp_path / "w.vtu")}, "materials": [{"E": 1e8, "nu": 0.3, "density": 1000.0}],
            "model": "fem_linear", "boundary": [{"select": {"box": [[-1, -1, -1], [3, 2, 0.01]]}, "fix": "all"}],
            "loads": [{"type": "gravity", "g": [0.0, 0.0, -9.81]}], "solver": {"type": "static"}}


def test_a_scene_on_a_wedge_mesh_file_solves_with_linear_fem(tmp_path):
    from msslib.scene.run import run_scene

    ds = run_scene(_scene(tmp_path), progress=False)
    weight = 1000.0 * 9.81 * (2.0 * 1.0 * 3.0)  # rho g V of the box
    np.testing.assert_allclose(ds["reaction_force"].sum(dim="node").values, [0.0, 0.0, weight], atol=1e-9 * weight)
    assert ds["cells"].attrs["cell_type"] == "wedge" and float(ds["displacement"].min()) < 0


def test_a_scene_names_the_wedge_grid_generator_declared_by_the_cell_module(tmp_path):
    """wedge_grid is a scene generator because the wedge module declares it (its example's generator);
    the generated scene solves like the same mesh read from a file."""
    from msslib.scene import GENERATORS
    from msslib.scene.run import run_scene

    assert GENERATORS["wedge_grid"] == 3 and "wedge_grid" in WEDGE.mesh_generators
    scene = _scene(tmp_path)
    scene["geometry"] = {"generator": "wedge_grid", "args": {"lx": 2.0, "ly": 1.0, "lz": 3.0, "nx": 1, "ny": 1, "nz": 2}}
    generated = run_scene(scene, progress=False)
    from_file = run_scene(_scene(tmp_path), progress=False)
    assert generated["cells"].attrs["cell_type"] == "wedge"
    np.testing.assert_array_equal(generated["displacement"].values, from_file["displacement"].values)
    # its size is known before it is built: a grid of 2.7e10 nodes is refused by the memory check
    scene["geometry"]["args"].update(nx=3000, ny=3000, nz=3000)
    with pytest.raises(ValueError, match=r"^scene.geometry \(wedge_grid with .*\): 2.7e\+10 nodes would need about"):
        run_scene(scene, progress=False)
    scene["geometry"]["args"]["nw"] = 1
    with pytest.raises(ValueError, match=r"^scene.geometry.args.nw: unknown argument of wedge_grid; expected one of "
                                         r"lx, ly, lz, nx, ny, nz, origin"):
        run_scene(scene, progress=False)


def _surface_loads(scene):
    from msslib.scene import load_scene, prepare

    return prepare(load_scene(scene)).surface_forces


def _area(facet_points):
    """Area of a planar triangle or of a planar quad (half the cross product of its diagonals)."""
    p = np.asarray(facet_points, dtype=float)
    if len(p) == 3:
        return 0.5 * np.linalg.norm(np.cross(p[1] - p[0], p[2] - p[0]))
    return 0.5 * np.linalg.norm(np.cross(p[2] - p[0], p[3] - p[1]))


def test_a_traction_on_a_wedge_mesh_acts_on_its_triangles_and_quads(tmp_path):
    """A traction on the whole surface of the 2 x 1 x 3 box (triangles on top and bottom, quads on
    the sides; 22 m^2) is balanced by the support: the reaction is -traction x 22 m^2; on the side
    x = 2 (quads, 3 m^2) and on the top z = 3 (triangles, 2 m^2) the loads are those areas'."""
    from msslib.scene.run import run_scene

    t = np.array([0.0, 0.0, -1e3])
    scene = _scene(tmp_path)
    scene["loads"] = [{"type": "traction", "select": {"box": [[-1, -1, -1], [3, 2, 4]]}, "traction": t.tolist()}]
    ds = run_scene(scene, progress=False)
    np.testing.assert_allclose(ds["reaction_force"].sum(dim="node").values, -22.0 * t, rtol=1e-12, atol=1e-12 * 22e3)
    for select, area in (({"plane": ["x", 2.0]}, 3.0), ({"plane": ["z", 3.0]}, 2.0)):
        scene["loads"] = [{"type": "traction", "select": select, "traction": t.tolist()}]
        np.testing.assert_allclose(_surface_loads(scene).sum(axis=0), area * t, rtol=1e-13)


def test_a_traction_on_facet_groups_of_a_wedge_file(tmp_path):
    """Each facet group of a wedge file carries its own traction, on its nodes only: a group of two
    triangles, a group of two quads."""
    tri, quad = _wedge_file(tmp_path)
    points = M.wedge_grid(2.0, 1.0, 3.0, 1, 1, 1).points
    scene = _scene(tmp_path)
    scene["geometry"] = {"file": str(tmp_path / "w.msh")}
    scene["boundary"] = [{"select": {"plane": ["z", 0.0]}, "fix": "all"}]
    t = np.array([1e3, 0.0, 0.0])
    for group, facets in (("7", tri), ("8", quad)):
        scene["loads"] = [{"type": "traction", "select": {"group": group}, "traction": t.tolist()}]
        with pytest.warns(Warning, match="facet group '9'"):
            surface = _surface_loads(scene)
        area = sum(_area(points[f]) for f in facets)
        np.testing.assert_allclose(surface.sum(axis=0), area * t, rtol=1e-13)
        np.testing.assert_array_equal(np.flatnonzero(np.abs(surface).sum(axis=1)), np.unique(facets))


def test_a_pressure_on_a_wedge_mesh_is_refused_in_one_line_naming_it(tmp_path, capsys):
    from msslib.cli import main as cli

    scene = _scene(tmp_path)
    scene["loads"] = [{"type": "pressure", "select": {"plane": ["z", 3.0]}, "pressure": 1e3}]
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(scene))
    assert cli(["run", str(tmp_path / "p.yaml"), "--out", str(tmp_path / "p.nc"), "--quiet"]) == 1
    err = capsys.readouterr().err
    assert err == ("msslib: error: scene.loads[0].select: a pressure on wedge cells, whose facets are of several types "
                   "(quad, triangle), is not supported; allowed: a pressure on meshes of triangle, quad, tetra, "
                   "hexahedron cells\n"), err
    assert not (tmp_path / "p.nc").exists()


def test_plan_refuses_a_wedge_mesh_in_one_line(tmp_path, capsys):
    from msslib.cli import main as cli

    (tmp_path / "w.yaml").write_text(yaml.safe_dump(_scene(tmp_path)))
    code = cli(["plan", str(tmp_path / "w.yaml"), "--max-error", "0.1"])
    err = capsys.readouterr().err
    assert code != 0 and err.count("\n") == 1, err
    assert err.startswith("msslib: error: ")
    assert ("scene.geometry: wedge cells have no quadratic FEM element (scikit-fem has none), so plan has no "
            "reference to measure errors against; allowed: meshes of triangle, quad, tetra, hexahedron cells") in err
