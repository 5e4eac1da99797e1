"""Where the numbers point to a mistake, a run ends in one line that names it, not in a solver
failure: a body whose pieces meet only at a vertex or an edge (a hinge: a mechanism that the
rigid-body check of the whole part does not see), loads far above what Young's modulus can carry
(E given in MPa with loads in Pa), and a sliver cell that stalls Newton's method."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from msslib import mesh as M
from msslib.cli import main
from msslib.errors import MsslibWarning
from msslib.scene import load_scene, prepare, run_scene

MAT = {"E": 1.0e6, "nu": 0.3}
CUBE = M.hex_grid(0.1, 0.1, 0.1, 1, 1, 1)  # node 7 at (0.1, 0.1, 0.1), nodes 5 and 7 on the edge x = z = 0.1


def _two_cubes(offset) -> M.Mesh:
    """The unit cube of edge 0.1 m and a copy moved by ``offset``, the nodes they share numbered once."""
    moved = CUBE.points + np.asarray(offset, dtype=float)
    points = list(CUBE.points)
    index = []
    for p in moved:
        same = np.flatnonzero(np.all(np.isclose(CUBE.points, p), axis=1))
        if len(same):
            index.append(int(same[0]))
        else:
            index.append(len(points))
            points.append(p)
    return M.Mesh(np.array(points), np.vstack([CUBE.cells, np.array(index)[CUBE.cells]]), "hexahedron")


def _scene(geometry, *, E=MAT["E"], loads=None, model="golec_cube", **changes) -> dict:
    scene = {
        "geometry": geometry,
        "materials": [{"E": E, "nu": MAT["nu"]}],
        "model": model,
        "boundary": [{"select": {"plane": ["x", 0.0]}, "fix": "all"}],
        "loads": loads if loads is not None else
        [{"type": "traction", "select": {"plane": ["x", 0.2]}, "traction": [5.0e4, 0.0, 0.0]}],
        "solver": {"type": "static", "load_steps": 1, "tol": 1.0e-10},
    }
    scene.update(changes)
    return scene


def _cli_error(tmp_path, capsys, scene: dict) -> str:
    """Run the scene through the command line: it must fail with exactly one line."""
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(scene, sort_keys=False))
    out = tmp_path / "out.nc"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 1
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("msslib: error: "), captured.err
    assert not out.exists()
    return lines[0]


# --------------------------------------------------------------------------------------------
# hinges: pieces that meet at a vertex or an edge
# --------------------------------------------------------------------------------------------


def test_pieces_joined_through_facets_vertices_and_edges():
    face, edge, vertex = _two_cubes([0.1, 0, 0]), _two_cubes([0.1, 0, 0.1]), _two_cubes([0.1, 0.1, 0.1])
    assert (face.n_nodes, edge.n_nodes, vertex.n_nodes) == (12, 14, 15)
    for mesh, n in ((face, 1), (edge, 2), (vertex, 2)):
        assert M.connected_parts(mesh)[0] == 1  # one part by shared nodes in every case
        n_pieces, piece = M.topology.facet_connected_cells(mesh)
        assert n_pieces == n and list(piece) == [0, n - 1]
    grid = M.tet_grid(0.1, 0.1, 0.1, 2, 2, 2)
    assert M.topology.facet_connected_cells(grid)[0] == 1


def test_cube_hanging_on_a_corner_is_refused_naming_the_hinge(tmp_path, capsys):
    M.write_vtu(tmp_path / "corner.vtu", _two_cubes([0.1, 0.1, 0.1]))
    scene = _scene({"file": "corner.vtu"})
    with pytest.raises(ValueError, match=r"scene\.boundary: the mesh \(2 hexahedron cells, node 0 at \(0, 0, 0\)\) is "
                                         r"a mechanism: 1 hexahedron cell\(s\) hang on the rest only at node 7 at "
                                         r"\(0\.1, 0\.1, 0\.1\), a hinge \(the cells there share no face\), and can "
                                         r"turn about it \(3 free mode\(s\)\)"):
        prepare(load_scene(scene, base_dir=tmp_path))
    line = _cli_error(tmp_path, capsys, scene | {"geometry": {"file": str(tmp_path / "corner.vtu")}})
    assert "node 7 at (0.1, 0.1, 0.1)" in line and "hinge" in line
    # the hanging cube held too: no mechanism
    mesh = M.read(tmp_path / "corner.vtu")
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[np.isclose(mesh.points[:, 0], 0.0)] = True
    (hinged,) = M.loose_parts(mesh, fixed)
    assert (hinged.hinges, hinged.hanging_cells, hinged.n_free, hinged.floating) == ((7,), 1, 3, False)
    fixed[np.isclose(mesh.points[:, 0], 0.2)] = True
    assert M.loose_parts(mesh, fixed) == []


def test_cube_hanging_on_an_edge_turns_about_it(tmp_path):
    M.write_vtu(tmp_path / "edge.vtu", _two_cubes([0.1, 0, 0.1]))
    with pytest.raises(ValueError, match=r"only at the edge from node 5 at \(0\.1, 0, 0\.1\) to node 7 at "
                                         r"\(0\.1, 0\.1, 0\.1\), a hinge .*\(1 free mode\(s\)\)"):
        prepare(load_scene(_scene({"file": "edge.vtu"}), base_dir=tmp_path))


def test_triangles_meeting_at_a_vertex_in_2d():
    points = np.array([[0.0, 0.0], [0.1, 0.0], [0.1, 0.1], [0.2, 0.1], [0.2, 0.2], [0.0, 0.1]])
    mesh = M.Mesh(points, np.array([[0, 1, 2], [0, 2, 5], [2, 3, 4]]), "triangle")
    fixed = np.zeros((6, 2), dtype=bool)
    fixed[[0, 5]] = True
    (hinged,) = M.loose_parts(mesh, fixed)
    assert (hinged.hinges, hinged.hanging_cells, hinged.n_free) == ((2,), 1, 1)
    assert "share no edge" in hinged.describe(mesh)
    fixed[4] = True
    assert M.loose_parts(mesh, fixed) == []


def test_cubes_sharing_a_face_solve_and_the_reaction_is_the_load(tmp_path):
    M.write_vtu(tmp_path / "face.vtu", _two_cubes([0.1, 0, 0]))
    ds = run_scene(load_scene(_scene({"file": "face.vtu"}), base_dir=tmp_path), progress=False)
    reaction = ds["reaction_force"].values.sum(axis=0)
    np.testing.assert_allclose(reaction, [-5.0e4 * 0.01, 0.0, 0.0], atol=1e-8 * 5.0e2)
    assert 0 < ds["displacement"].values[:, 0].max() < 0.1 * 0.2


# --------------------------------------------------------------------------------------------
# loads far above Young's modulus: E in MPa, loads in Pa
# --------------------------------------------------------------------------------------------


def _cube_scene(E, loads, **changes) -> dict:
    grid = {"generator": "hex_grid", "args": {"lx": 0.1, "ly": 0.1, "lz": 0.1, "nx": 2, "ny": 2, "nz": 2}}
    scene = _scene(grid, E=E, loads=loads, **changes)
    scene["materials"][0]["density"] = 1000.0
    return scene


PULL = [{"type": "traction", "select": {"plane": ["x", 0.1]}, "traction": [5.0e4, 0.0, 0.0]}]


def test_modulus_in_mpa_with_a_load_in_pa_is_refused_naming_the_ratio(tmp_path, capsys):
    scene = _cube_scene(1.0, PULL)  # 1 MPa meant, 1 Pa read: 5e4 Pa / 1 Pa
    with pytest.raises(ValueError, match=r"^scene\.loads\[0\]: the load is 5 x 10\^4 E \(traction \|t\| = 5e\+04 Pa "
                                         r"against the smallest Young's modulus E = 1 Pa, scene\.materials\[0\]\): "
                                         r"strains of order 5 x 10\^4.*E is in Pa \(an E given in MPa"):
        prepare(load_scene(scene))
    line = _cli_error(tmp_path, capsys, scene)
    assert "the load is 5 x 10^4 E" in line and "E is in Pa" in line


def test_the_same_scene_with_e_in_pa_solves_and_the_reaction_is_the_load():
    ds = run_scene(load_scene(_cube_scene(1.0e6, PULL)), progress=False)
    np.testing.assert_allclose(ds["reaction_force"].values.sum(axis=0), [-5.0e4 * 0.01, 0.0, 0.0], atol=1e-8 * 5.0e2)
    # 5 % strain: the mean stretch of the loaded face is of that order
    u = ds["displacement"].values[np.isclose(ds["rest_position"].values[:, 0], 0.1), 0].mean()
    assert 0.02 * 0.1 < u < 0.1 * 0.1


def test_gravity_and_nodal_force_ratios():
    hang = [{"type": "gravity", "g": [0.0, 0.0, -9.81]}]  # rho g L = 1000 x 9.81 x 0.1 = 981 Pa
    boundary = [{"select": {"plane": ["z", 0.1]}, "fix": "all"}]
    with pytest.raises(ValueError, match=r"the load is 9\.81 x 10\^2 E \(gravity rho g L = 1e\+03 kg/m\^3 x 9\.81 "
                                         r"m/s\^2 x 0\.1 m = 981 Pa"):
        prepare(load_scene(_cube_scene(1.0, hang, boundary=boundary)))
    assert prepare(load_scene(_cube_scene(1.0e6, hang, boundary=boundary))).gravity is not None
    # a body nothing holds falls freely under gravity: no stress to compare
    free_fall = _cube_scene(1.0, hang, boundary=[], solver={"type": "dynamic", "dt": 1e-3, "t_end": 1e-2})
    assert prepare(load_scene(free_fall)).model is not None
    # 100 N over the cross-section 0.01 m^2 across it: 1e4 Pa
    push = [{"type": "nodal_force", "select": {"plane": ["x", 0.1]}, "total": [100.0, 0.0, 0.0]}]
    with pytest.raises(ValueError, match=r"the load is 1 x 10\^2 E \(nodal force \|F\| = 100 N over the mean "
                                         r"cross-section 0\.01 m\^2 across it = 1e\+04 Pa"):
        prepare(load_scene(_cube_scene(100.0, push)))
    with pytest.raises(ValueError, match=r"the load is 10 E"):
        prepare(load_scene(_cube_scene(1.0e3, push)))


def test_a_load_above_e_but_within_ten_times_is_a_warning_not_a_refusal():
    push = [{"type": "nodal_force", "select": {"plane": ["x", 0.1]}, "total": [100.0, 0.0, 0.0]}]
    with pytest.warns(MsslibWarning, match=r"scene\.loads\[0\]: the load is 2 E .*strains above 1 ahead"):
        setup = prepare(load_scene(_cube_scene(5.0e3, push)))
    assert setup.model is not None


def test_the_softest_material_is_named(tmp_path):
    two = _two_cubes([0.1, 0, 0])
    M.write_vtu(tmp_path / "two.vtu", M.Mesh(two.points, two.cells, two.cell_type, [0, 1]))
    scene = _scene({"file": "two.vtu"}, loads=[{"type": "traction", "select": {"plane": ["x", 0.2]},
                                                "traction": [0.0, 3.0e4, 0.0]}])
    scene["materials"] = [{"E": 2.0e8, "nu": 0.3}, {"E": 2.0e3, "nu": 0.3}]
    with pytest.raises(ValueError, match=r"the load is 15 E \(traction .* E = 2000 Pa, scene\.materials\[1\]\)"):
        prepare(load_scene(scene, base_dir=tmp_path))


# --------------------------------------------------------------------------------------------
# a sliver that stalls Newton's method (Delingette's triangle)
# --------------------------------------------------------------------------------------------


def _plate_with_sliver(height: float) -> M.Mesh:
    """A 4 x 2 plate of right triangles (0.04 x 0.02 m) and one more triangle on its lower edge,
    cell 16 (nodes 1, 15, 2): the apex, node 15, ``height`` below the midpoint of that edge."""
    plate = M.triangle_grid_right(0.04, 0.02, 4, 2)
    points = np.vstack([plate.points, [[0.015, -height]]])
    return M.Mesh(points, np.vstack([plate.cells, [[1, 15, 2]]]), "triangle")


def _plate_scene(path) -> dict:
    return {"model": "delingette_triangle", "geometry": {"file": str(path)},
            "materials": [{"E": 1.0e4, "nu": 0.3}], "thickness": 0.01,
            "boundary": [{"select": {"plane": ["x", 0.0]}, "fix": "all"}],
            "loads": [{"type": "traction", "select": {"plane": ["x", 0.04]}, "traction": [1000.0, 0.0]}],
            "solver": {"type": "static", "load_steps": 1, "tol": 1.0e-10}}


def test_cell_shapes_of_regular_cells_and_a_sliver():
    aspect, angle = M.hygiene.cell_shapes(_plate_with_sliver(1e-6))
    assert aspect[:16] == pytest.approx(2.0) and angle[:16] == pytest.approx(45.0)  # right isosceles
    # the sliver: base 0.01 m, height 1e-6 m: longest edge / height = 1e4, base angles atan(1e-6 / 0.005)
    assert aspect[16] == pytest.approx(1.0e4, rel=1e-6)
    assert angle[16] == pytest.approx(np.degrees(np.arctan(2.0e-4)), rel=1e-6)
    cube, _ = M.hygiene.cell_shapes(M.hex_grid(0.1, 0.2, 0.1, 1, 1, 1))
    assert cube == pytest.approx([2.0])  # 0.2 / 0.1


def test_sliver_that_stalls_delingette_is_named(tmp_path, capsys):
    from msslib.errors import ConvergenceError

    # (at 1e-6 m the static solver's retry with a shifted tangent converges: the plate as without it)
    M.write_vtu(tmp_path / "sliver.vtu", _plate_with_sliver(1e-8))
    scene = _plate_scene(tmp_path / "sliver.vtu")
    with pytest.raises(ConvergenceError, match=r"line search failed.*triangle cell 16 \(nodes 1, 15, 2\), a sliver "
                                               r"\(smallest angle 0\.000115 deg, aspect ratio 1e\+06\)"):
        run_scene(load_scene(scene), progress=False)
    assert "triangle cell 16 (nodes 1, 15, 2), a sliver" in _cli_error(tmp_path, capsys, scene)


def test_well_shaped_extra_triangle_solves_and_the_reaction_is_the_load(tmp_path):
    M.write_vtu(tmp_path / "plate.vtu", _plate_with_sliver(0.005))
    ds = run_scene(load_scene(_plate_scene(tmp_path / "plate.vtu")), progress=False)
    # traction 1000 Pa on the edge x = 0.04 (0.02 m long, 0.01 m thick): 0.2 N
    np.testing.assert_allclose(ds["reaction_force"].values.sum(axis=0), [-0.2, 0.0], atol=1e-9)
